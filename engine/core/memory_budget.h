#pragma once
// The process's memory budget (docs/robustness.md, "The memory budget"): how much more memory
// reading, building, rendering and writing may take. By default it is what the system can give
// now: the available memory (/proc/meminfo MemAvailable) and, inside a control group with a
// limit, that limit less the group's usage, whichever is smaller, less a margin. With
// --memory-limit SIZE it is SIZE less what the process holds now (its resident set).
//
// The budget is read when a phase starts (a mesh file read, a render set up), not once at
// start-up: two renders started together each see what the other has taken by then. A phase
// then counts what it allocates against its share (MemoryBudget::need), before allocating,
// and stops with MemoryShortage (exit status 1) rather than being killed.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/error.h"

namespace streamrt {

/// Not enough memory within the budget for what the input needs: a real shortage, not a
/// mistake in the input (exit status 1, like every RenderError). One line.
class MemoryShortage : public RenderError {
  public:
    using RenderError::RenderError;
};

/// "12.0 GiB", "512 KiB", "3.5e+70 GiB".
std::string format_bytes(double bytes);

/// Parses a --memory-limit value: a number with an optional unit, K/M/G/T (powers of 1024,
/// with or without "iB"/"B"), e.g. "512M", "1.5GiB", "200000000". Throws UsageError.
double parse_memory_size(std::string_view text, std::string_view option = "--memory-limit");

/// What the process holds now: its resident set (/proc/self/statm), in bytes; 0 if unknown.
double resident_bytes();

/// What the system can give the process now: MemAvailable, and a control group's limit less
/// its usage (its inactive file pages, which the kernel reclaims first, left out), whichever
/// is smaller; no margin. 0 if unknown.
double system_available_bytes();

class MemoryBudget {
  public:
    /// --memory-limit (and the Python keyword): the most the process may hold, in bytes; 0 or
    /// less: the system's (the default). Process-wide.
    static void set_limit(double bytes);
    static double limit();

    /// The share of a phase starting now: what the process may still take. With a limit: the
    /// limit less the resident set; without: system_available_bytes() less a margin (1/16 of
    /// it, at most 1 GiB), so that the rest of the machine keeps some room.
    static MemoryBudget now();
    /// A share of exactly `bytes` (tests, and a phase whose caller has measured already).
    static MemoryBudget of(double bytes) { return MemoryBudget(bytes, Source::Given); }

    /// Counts `bytes` more against the share; throws MemoryShortage("<what> would need about
    /// X more than the Y counted already, past the memory budget of Z (...); --memory-limit
    /// raises it") when they do not fit.
    void need(double bytes, std::string_view what);
    /// Gives back bytes counted before (freed).
    void release(double bytes);

    double room() const { return room_; }                   ///< the share when the phase began
    double used() const { return used_; }                   ///< counted so far
    double left() const { return room_ - used_; }           ///< what need() may still take
    /// How the budget is named in messages: "the memory budget of 1.2 GiB (--memory-limit
    /// 1.5 GiB less what the process held before)" or "... (the available memory less a margin)".
    std::string describe() const;

  private:
    enum class Source { Given, Limit, Available };
    MemoryBudget(double room, Source source, double limit = 0) : room_(room), limit_(limit), source_(source) {}
    double room_ = 0;
    double limit_ = 0;  ///< Source::Limit: the --memory-limit it came from
    Source source_;
    double used_ = 0;
};

}  // namespace streamrt
