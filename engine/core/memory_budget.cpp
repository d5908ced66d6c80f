#include "core/memory_budget.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace streamrt {

namespace {

std::atomic<double> g_limit{0.0};

/// The first number in a file such as memory.max (0 when it cannot be read; "max" is none).
double read_number(const std::string& path) {
    std::ifstream in(path);
    double v = 0;
    return in >> v ? v : 0.0;
}

/// A value of a key from a "key value" file such as memory.stat (-1 when absent).
double read_key(const std::string& path, std::string_view key) {
    std::ifstream in(path);
    std::string k;
    double v = 0;
    while (in >> k >> v)
        if (k == key) return v;
    return -1;
}

/// Room in this process's control group: its limit less its usage (without its inactive file
/// pages, reclaimed first), or -1 when it has no limit (or none can be read). cgroup v2
/// (memory.max, memory.current) and v1 (memory.limit_in_bytes, memory.usage_in_bytes), at the
/// group's path or, inside a container whose view starts at the group, at the mount's root.
double cgroup_room() {
    std::ifstream self("/proc/self/cgroup");
    std::string line;
    double room = -1;
    const auto consider = [&](const std::string& dir, const char* max_file, const char* usage_file,
                              const char* inactive_key) {
        const double limit = read_number(dir + "/" + max_file);
        if (!(limit > 0) || limit >= 1e18) return false;  // "max", or v1's "unlimited" (2^63 - page)
        double usage = read_number(dir + "/" + usage_file);
        if (const double inactive = read_key(dir + "/memory.stat", inactive_key); inactive > 0)
            usage = std::max(0.0, usage - inactive);
        const double r = std::max(0.0, limit - usage);
        room = room < 0 ? r : std::min(room, r);
        return true;
    };
    while (std::getline(self, line)) {
        // "0::/path" (v2) or "4:memory:/path" (v1).
        const std::size_t a = line.find(':'), b = line.find(':', a + 1);
        if (a == std::string::npos || b == std::string::npos) continue;
        const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
        if (controllers.empty()) {
            if (!consider("/sys/fs/cgroup" + path, "memory.max", "memory.current", "inactive_file"))
                consider("/sys/fs/cgroup", "memory.max", "memory.current", "inactive_file");
        } else if (("," + controllers + ",").find(",memory,") != std::string::npos) {
            if (!consider("/sys/fs/cgroup/memory" + path, "memory.limit_in_bytes", "memory.usage_in_bytes",
                          "total_inactive_file"))
                consider("/sys/fs/cgroup/memory", "memory.limit_in_bytes", "memory.usage_in_bytes",
                         "total_inactive_file");
        }
    }
    return room;
}

}  // namespace

std::string format_bytes(double bytes) {
    const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    int u = 0;
    while (u < 4 && bytes >= 1024) {
        bytes /= 1024;
        ++u;
    }
    char buf[64];
    if (bytes >= 1e6) std::snprintf(buf, sizeof buf, "%.3g %s", bytes, units[u]);
    else if (u == 0) std::snprintf(buf, sizeof buf, "%.0f %s", bytes, units[u]);
    else std::snprintf(buf, sizeof buf, "%.1f %s", bytes, units[u]);
    return buf;
}

double parse_memory_size(std::string_view text, std::string_view option) {
    const auto bad = [&] {
        return UsageError(std::string(option) + ": " + quote(text) +
                          " is not a size (a number of bytes, or with K, M, G or T: 512M, 1.5GiB)");
    };
    std::size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
    if (i == 0) throw bad();
    double value = 0;
    try {
        std::size_t used = 0;
        value = std::stod(std::string(text.substr(0, i)), &used);
        if (used != i) throw bad();
    } catch (const std::logic_error&) {
        throw bad();
    }
    std::string unit(text.substr(i));
    for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
    double scale = 0;
    if (unit.empty() || unit == "B") scale = 1;
    else if (unit == "K" || unit == "KB" || unit == "KIB") scale = 1024.0;
    else if (unit == "M" || unit == "MB" || unit == "MIB") scale = 1024.0 * 1024;
    else if (unit == "G" || unit == "GB" || unit == "GIB") scale = 1024.0 * 1024 * 1024;
    else if (unit == "T" || unit == "TB" || unit == "TIB") scale = 1024.0 * 1024 * 1024 * 1024;
    else throw bad();
    value *= scale;
    if (!(value >= 1) || !std::isfinite(value)) throw bad();
    return value;
}

double resident_bytes() {
    std::ifstream in("/proc/self/statm");
    double size = 0, resident = 0;
    if (!(in >> size >> resident)) return 0;
    const long page = ::sysconf(_SC_PAGESIZE);
    return resident * double(page > 0 ? page : 4096);
}

double system_available_bytes() {
    double available = read_key("/proc/meminfo", "MemAvailable:") * 1024.0;
    if (!(available > 0)) {
        const long pages = ::sysconf(_SC_AVPHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
        available = pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
    }
    if (const double group = cgroup_room(); group >= 0) available = available > 0 ? std::min(available, group) : group;
    return available;
}

void MemoryBudget::set_limit(double bytes) { g_limit.store(bytes > 0 ? bytes : 0.0); }

double MemoryBudget::limit() { return g_limit.load(); }

MemoryBudget MemoryBudget::now() {
    if (const double l = limit(); l > 0) return MemoryBudget(std::max(0.0, l - resident_bytes()), Source::Limit, l);
    const double available = system_available_bytes();
    if (!(available > 0)) return MemoryBudget(1e300, Source::Available);  // unknown: no check (as before)
    const double margin = std::min(available / 16, 1024.0 * 1024 * 1024);
    return MemoryBudget(available - margin, Source::Available);
}

void MemoryBudget::need(double bytes, std::string_view what) {
    if (bytes > left())
        throw MemoryShortage(std::string(what) + " would need about " + format_bytes(bytes) +
                             (used_ > 0 ? " more than the " + format_bytes(used_) + " counted already" : std::string()) +
                             ", past " + describe() + "; --memory-limit raises it");
    used_ += bytes;
}

void MemoryBudget::release(double bytes) { used_ = std::max(0.0, used_ - bytes); }

std::string MemoryBudget::describe() const {
    const std::string of = "the memory budget of " + format_bytes(room_);
    switch (source_) {
    case Source::Limit: return of + " (--memory-limit " + format_bytes(limit_) + " less what the process held before)";
    case Source::Available: return of + " (the available memory less a margin)";
    case Source::Given: break;
    }
    return of;
}

}  // namespace streamrt
