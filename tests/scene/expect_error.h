#pragma once
// Scene text that must be refused: a SceneError at an exact line:column of "t.cfg" whose
// message contains a given piece (tests/scene/*_test.cpp).
#include <doctest/doctest.h>

#include <string>

#include "scene/parser.h"

namespace streamrt::test {

/// Parses `text` (as "t.cfg") expecting a SceneError at line:column whose message contains
/// `needle`.
inline void expect_error(const std::string& text, int line, int column, const std::string& needle = "") {
    INFO("scene text: ", text);
    bool thrown = false;
    try {
        parse_scene(text, "t.cfg");
    } catch (const SceneError& e) {
        thrown = true;
        INFO("message: ", std::string(e.what()));
        CHECK(e.where().file == "t.cfg");
        CHECK(e.where().line == line);
        CHECK(e.where().column == column);
        if (!needle.empty()) CHECK(e.message().find(needle) != std::string::npos);
    }
    CHECK_MESSAGE(thrown, "expected a SceneError");
}

}  // namespace streamrt::test
