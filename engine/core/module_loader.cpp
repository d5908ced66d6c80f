#include "core/module_loader.h"

#include <cstdlib>
#include <mutex>
#include <vector>

#include <dlfcn.h>

#ifndef STREAMRT_MODULE_INSTALL_DIR
#define STREAMRT_MODULE_INSTALL_DIR ""
#endif

namespace streamrt {

namespace {

std::string parent_folder(const std::string& path) {
    const std::size_t slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    return slash == 0 ? std::string("/") : path.substr(0, slash);
}

std::vector<std::string> module_folders() {
    std::vector<std::string> folders;
    if (const char* dir = std::getenv("STREAMRT_MODULE_DIR"); dir && *dir) folders.emplace_back(dir);
    // The file this function was loaded from, symbolic links resolved: the program, or the
    // Python module that links the engine. The loader may name the program as it was
    // started (a relative path); /proc/self/exe is the program's own file.
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&module_folders), &info) && info.dli_fname && *info.dli_fname) {
        char* resolved = realpath(info.dli_fname, nullptr);
        if (!resolved) resolved = realpath("/proc/self/exe", nullptr);
        if (resolved) {
            // Its own folder first: the Python package installed by pip holds the modules
            // beside its extension (site-packages/streamrt/). Then lib/streamrt/ above it:
            // PREFIX/bin/streamrt and build/<folder>/<program> are one level down from the
            // root that holds it, the Python module in build/python/streamrt/ two, and one
            // installed by cmake --install (PREFIX/lib/python3.X/dist-packages/streamrt/) four.
            std::string root = parent_folder(resolved);
            folders.push_back(root);
            for (int up = 0; up < 4 && root.size() > 1; ++up) {
                root = parent_folder(root);
                folders.push_back((root == "/" ? std::string() : root) + "/lib/streamrt");
            }
            std::free(resolved);
        }
    }
    if (*STREAMRT_MODULE_INSTALL_DIR) folders.emplace_back(STREAMRT_MODULE_INSTALL_DIR);
    return folders;
}

}  // namespace

std::string module_search_path() {
    std::string out;
    for (const std::string& f : module_folders()) out += (out.empty() ? "" : ":") + f;
    return out;
}

void* module_symbol(const char* file, const char* symbol, bool global, std::string& error) {
    static std::mutex mutex;  // dlerror's message is per thread, but two first uses may race
    std::lock_guard<std::mutex> lock(mutex);
    std::string reasons;
    for (const std::string& folder : module_folders()) {
        const std::string path = folder + "/" + file;
        void* handle = dlopen(path.c_str(), RTLD_NOW | (global ? RTLD_GLOBAL : RTLD_LOCAL));
        if (!handle) {
            const char* why = dlerror();
            // A missing file is the expected case for all but one folder: name it only when
            // the file is there and could not be loaded.
            if (why && std::string(why).find("No such file") == std::string::npos) reasons += std::string("; ") + why;
            continue;
        }
        if (void* address = dlsym(handle, symbol)) return address;  // the handle stays open
        reasons += "; " + path + " has no " + symbol;
        dlclose(handle);
    }
    error = std::string(file) + " not found in " + module_search_path() + reasons;
    return nullptr;
}

}  // namespace streamrt
