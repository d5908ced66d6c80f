#pragma once
// The text of the exception a call throws, for tests that compare whole messages.
#include <exception>
#include <functional>
#include <string>

namespace streamrt::test {

/// `f`'s exception's what(), or "no error" when it returns.
inline std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace streamrt::test
