// "Did you mean": the edit distance and the nearest-name choice (core/nearest_name.h), with
// distances counted by hand.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "core/nearest_name.h"

using namespace streamrt;

// Proven against: the swap step left out (edit_distance("sapcing", "spacing") gave 2).
TEST_CASE("nearest name: edit distance counts insertions, deletions, substitutions and neighbour swaps") {
    CHECK(edit_distance("colour", "color") == 1);    // one 'u' deleted
    CHECK(edit_distance("color", "colour") == 1);    // one 'u' inserted
    CHECK(edit_distance("sphere", "sphera") == 1);   // one substitution
    CHECK(edit_distance("sapcing", "spacing") == 1); // 'a' and 'p' swapped: one edit, not two
    CHECK(edit_distance("kitten", "sitting") == 3);  // k->s, e->i, +g
    CHECK(edit_distance("", "abc") == 3);
    CHECK(edit_distance("abc", "") == 3);
    CHECK(edit_distance("same", "same") == 0);
    CHECK(edit_distance("ca", "abc") == 3);          // a swap may not be edited again (optimal alignment)
}

// Proven against: nearest_name taking the last of equally near names ('cone' for "cune").
TEST_CASE("nearest name: the nearest within two edits, the first on a tie, none for an unrelated word") {
    const std::vector<std::string> keys = {"color", "colors", "cone", "cube", "spp"};
    CHECK(nearest_name("colour", keys) == std::optional<std::string>("color"));
    CHECK(nearest_name("colrs", keys) == std::optional<std::string>("colors"));  // 1 from colors, 2 from color
    CHECK(nearest_name("cune", keys) == std::optional<std::string>("cone"));     // 1 from cone and cube: the first
    CHECK(nearest_name("sp", keys) == std::optional<std::string>("spp"));
    CHECK(!nearest_name("zebra", keys));   // 3 or more from every key
    CHECK(!nearest_name("ab", keys));      // 2 edits would rewrite all of a 2-letter word
    CHECK(!nearest_name("cone", std::vector<std::string>{"cone"}));  // the word itself is no suggestion
    CHECK(nearest_name("colour", keys, 0) == std::nullopt);
}
