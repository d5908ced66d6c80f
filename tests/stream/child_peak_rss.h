#pragma once
// Peak resident memory of a `streamrt` child process, for tests that bound what a render
// really holds (tests/stream/depth_memory_test.cpp, tests/render/limits_test.cpp).
#include <doctest/doctest.h>

#include <sys/ptrace.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace streamrt::test {

/// Peak resident memory (KiB, VmHWM) of one `streamrt` run with these arguments, which must
/// succeed (or, given `exit_code`, whose status is stored there); -1 where this process may
/// not trace its children. Read when the child is about to exit (ptrace's exit stop, its
/// memory still mapped): wait4's ru_maxrss would not do, Linux carries the parent's peak
/// across the exec. The child's stderr goes to `stderr_path` when given.
inline long child_peak_rss_kib(const std::vector<std::string>& args, int* exit_code = nullptr,
                               const std::string& stderr_path = "") {
    std::vector<char*> argv{const_cast<char*>(STREAMRT_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        if (::ptrace(PTRACE_TRACEME, 0, nullptr, nullptr) != 0) ::_exit(126);  // not allowed here
        if (!stderr_path.empty() && !std::freopen(stderr_path.c_str(), "w", stderr)) ::_exit(125);
        ::execv(STREAMRT_BINARY, argv.data());
        ::_exit(127);
    }
    int status = 0;
    REQUIRE(::waitpid(pid, &status, 0) == pid);  // stopped at the exec
    if (WIFEXITED(status) && WEXITSTATUS(status) == 126) return -1;
    REQUIRE(WIFSTOPPED(status));
    REQUIRE(::ptrace(PTRACE_SETOPTIONS, pid, nullptr, reinterpret_cast<void*>(long(PTRACE_O_TRACEEXIT))) == 0);
    long peak = -1;
    int signal = 0;
    for (;;) {
        REQUIRE(::ptrace(PTRACE_CONT, pid, nullptr, reinterpret_cast<void*>(long(signal))) == 0);
        REQUIRE(::waitpid(pid, &status, 0) == pid);
        if (!WIFSTOPPED(status)) break;
        signal = 0;
        if (status >> 8 == (SIGTRAP | (PTRACE_EVENT_EXIT << 8))) {
            std::ifstream in("/proc/" + std::to_string(pid) + "/status");
            for (std::string line; std::getline(in, line);)
                if (line.rfind("VmHWM:", 0) == 0) peak = std::stol(line.substr(6));
        } else {
            signal = WSTOPSIG(status);  // not ours: deliver it
        }
    }
    INFO("the child ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0));
    REQUIRE(WIFEXITED(status));
    if (exit_code) *exit_code = WEXITSTATUS(status);
    else REQUIRE(WEXITSTATUS(status) == 0);
    REQUIRE(peak > 0);
    return peak;
}


}  // namespace streamrt::test
