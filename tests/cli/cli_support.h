#pragma once
// What the command-line tests share: a scratch folder, running the streamrt binary
// (STREAMRT_BINARY) with its output captured, and the one-line error check.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cli_support {

namespace fs = std::filesystem;

struct Dir {
    fs::path path;
    Dir() {
        static int counter = 0;
        path = fs::temp_directory_path() /
               ("streamrt_cli_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~Dir() {
        std::error_code ec;
        fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(path, ec);
    }
    fs::path write(const std::string& name, const std::string& text) const {
        std::ofstream(path / name, std::ios::binary) << text;
        return path / name;
    }
    std::vector<std::string> files() const {
        std::vector<std::string> out;
        for (const auto& e : fs::directory_iterator(path)) out.push_back(e.path().filename().string());
        return out;
    }
};

inline std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct Run {
    int code = -1;
    std::string out, err;
};

/// Runs streamrt with `args` (already shell-quoted), capturing stdout and stderr.
inline Run run_streamrt(const std::string& args) {
    static int counter = 0;
    const fs::path base = fs::temp_directory_path() /
                          ("streamrt_cli_io_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    const std::string cmd = std::string("'") + STREAMRT_BINARY + "' " + args + " >'" + base.string() +
                            ".out' 2>'" + base.string() + ".err'";
    const int status = std::system(cmd.c_str());
    Run r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(base.string() + ".out");
    r.err = slurp(base.string() + ".err");
    fs::remove(base.string() + ".out");
    fs::remove(base.string() + ".err");
    return r;
}

inline std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

/// One line on stderr, "streamrt: " then the message.
inline void check_one_line_error(const Run& r, const std::string& needle) {
    INFO("stderr: ", r.err);
    CHECK(r.err.rfind("streamrt: ", 0) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.find(needle) != std::string::npos);
}

}  // namespace cli_support
