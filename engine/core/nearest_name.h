#pragma once
// "Did you mean ...?" for a mistyped name (a scene key or statement, a command-line option):
// the known name nearest to the word, if it is close enough to be the one meant.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace streamrt {

/// Edits between a and b: insertions, deletions, substitutions and swaps of two neighbouring
/// bytes (the optimal string alignment distance), so that "colour" is 1 from "color" and a
/// swap such as "sapcing" counts as one slip of the fingers, not two.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
    const std::size_t n = a.size(), m = b.size();
    // Three rows of the table are enough: a swap looks two rows back.
    std::vector<std::size_t> before(m + 1), prev(m + 1), cur(m + 1);
    for (std::size_t j = 0; j <= m; ++j) prev[j] = j;
    for (std::size_t i = 1; i <= n; ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                cur[j] = std::min(cur[j], before[j - 2] + 1);
        }
        std::swap(before, prev);
        std::swap(prev, cur);
    }
    return prev[m];
}

/// The name of `names` nearest to `word` when at most `max_edits` away (the first listed on a
/// tie), nullopt otherwise. Two edits catch the usual slips (a letter missing, doubled, swapped
/// or British) while a short word is not matched to an unrelated short name: a name is only
/// offered when fewer edits separate them than the word has letters.
template <class Names>
std::optional<std::string> nearest_name(std::string_view word, const Names& names, std::size_t max_edits = 2) {
    std::optional<std::string> best;
    std::size_t best_edits = max_edits + 1;
    for (const auto& name : names) {
        const std::string_view n(name);
        if (n == word) continue;
        const std::size_t d = edit_distance(word, n);
        if (d < best_edits && d < word.size()) {
            best_edits = d;
            best = std::string(n);
        }
    }
    return best;
}

}  // namespace streamrt
