#pragma once
// Optional parts of streamrt that pull in large libraries (OpenEXR for .exr files, MPI for
// --mpi) live in modules loaded on first use, so every other run starts without loading
// and relocating those libraries (about 4 ms a process here: docs/performance.md, "Start-up").
#include <string>

namespace streamrt {

/// Where a module is looked for, in order: $STREAMRT_MODULE_DIR; the folder of the program
/// or library that holds this engine (the Python package pip installs keeps the modules
/// beside its extension); lib/streamrt/ in the folders one to four levels above it
/// (build/engine/streamrt, build/tests/... and build/python/streamrt/_native*.so find
/// build/lib/streamrt/, an installed PREFIX/bin/streamrt and
/// PREFIX/lib/python3.X/dist-packages/streamrt/_native*.so find PREFIX/lib/streamrt/); the
/// install folder chosen at configure time.
std::string module_search_path();

/// The address of `symbol` in module `file` (e.g. "libstreamrt_exr.so"), loaded once and
/// kept for the life of the process; nullptr with `error` set when no folder of the search
/// path holds a loadable module. `global`: the module's libraries' symbols are made visible to
/// later loads (MPI loads plugins of its own that expect its library's symbols).
void* module_symbol(const char* file, const char* symbol, bool global, std::string& error);

/// A module's table of functions, or why there is none.
template <class Table>
struct ModuleTable {
    const Table* table = nullptr;
    std::string error;
};

/// Loads module `file` and calls its entry point `symbol` (`const Table* symbol()`); a table
/// whose first member, its version, is not `version` (a module of another build) is refused.
template <class Table>
ModuleTable<Table> load_module_table(const char* file, const char* symbol, int version, bool global) {
    ModuleTable<Table> out;
    using Entry = const Table* (*)();
    if (auto entry = reinterpret_cast<Entry>(module_symbol(file, symbol, global, out.error))) {
        out.table = entry();
        if (out.table->version != version) {
            out.table = nullptr;
            out.error = std::string(file) + " is of another streamrt version";
        }
    }
    return out;
}

}  // namespace streamrt
