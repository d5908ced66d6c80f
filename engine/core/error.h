#pragma once
// Two channels: SceneError/UsageError for the user's mistakes (reported with a location,
// never asserted), and STREAMRT_CHECK for our own invariants.
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

namespace streamrt {

/// Where a statement or value came from in a scene file (1-based line and column).
struct SourceLoc {
    std::string file;
    int line = 0;
    int column = 0;
    std::string str() const {
        if (line <= 0) return file;
        return file + ":" + std::to_string(line) + ":" + std::to_string(column);
    }
};

/// 's' for messages: at most 60 bytes, control bytes written as \xNN so that a message is
/// always one printable line (what the user typed may hold any byte).
inline std::string quote(std::string_view s) {
    constexpr std::size_t kMax = 60;
    std::string out = "'";
    for (std::size_t i = 0; i < s.size() && i < kMax; ++i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        if (c < 0x20 || c == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += char(c);
        }
    }
    if (s.size() > kMax) out += "...";
    out += '\'';
    return out;
}

/// A mistake in a scene file: "file:line:col: message". Exit status 2.
class SceneError : public std::runtime_error {
  public:
    SceneError(const SourceLoc& at, std::string_view msg)
        : std::runtime_error(at.str() + ": " + std::string(msg)), where_(at), message_(msg) {}
    const SourceLoc& where() const { return where_; }
    const std::string& message() const { return message_; }

  private:
    SourceLoc where_;
    std::string message_;
};

/// A bad command line. Exit status 2.
class UsageError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// A failure while rendering or writing the image. Exit status 1.
class RenderError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace streamrt

#define STREAMRT_CHECK(cond)                                                              \
    do {                                                                                  \
        if (!(cond)) {                                                                    \
            std::fprintf(stderr, "streamrt: internal check failed at %s:%d: %s\n",        \
                         __FILE__, __LINE__, #cond);                                      \
            std::abort();                                                                 \
        }                                                                                 \
    } while (0)
