#pragma once
// Scene text that must be refused: a SceneError at an exact line:column of "t.cfg" whose
// message contains a given piece (tests/scene/*_test.cpp).
#include <doctest/doctest.h>

#include <string>

#include "scene/parser.h"

namespace streamrt::test {

/// Parses `text` as the file `path` expecting a SceneError at line:column of that file whose
/// message contains `needle`.
inline void expect_error_in(const std::string& path, const std::string& text, int line, int column,
                            const std::string& needle = "") {
    INFO("scene text: ", text);
    bool thrown = false;
    try {
        parse_scene(text, path);
    } catch (const SceneError& e) {
        thrown = true;
        INFO("message: ", std::string(e.what()));
        CHECK(e.where().file == path);
        CHECK(e.where().line == line);
        CHECK(e.where().column == column);
        if (!needle.empty()) CHECK(e.message().find(needle) != std::string::npos);
    }
    CHECK_MESSAGE(thrown, "expected a SceneError");
}

/// The same for the file "t.cfg".
inline void expect_error(const std::string& text, int line, int column, const std::string& needle = "") {
    expect_error_in("t.cfg", text, line, column, needle);
}

}  // namespace streamrt::test
