#pragma once
// One table of names per enum, the only place a value's spelling is written: the scene
// reader, the command line, the Python module and the settings token of shards and
// checkpoints all read it (docs/architecture.md, "Settings").
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace streamrt {

template <class E>
struct EnumName {
    E value;
    std::string_view name;
};

/// The name of `v` in `table` ("" if absent: every table lists every value).
template <class E, std::size_t N>
constexpr std::string_view name_of(const EnumName<E> (&table)[N], E v) {
    for (const EnumName<E>& e : table)
        if (e.value == v) return e.name;
    return {};
}

/// The value named `name`, if any.
template <class E, std::size_t N>
constexpr std::optional<E> value_named(const EnumName<E> (&table)[N], std::string_view name) {
    for (const EnumName<E>& e : table)
        if (e.name == name) return e.value;
    return std::nullopt;
}

/// The names for messages: "stratified, grid or random".
template <class E, std::size_t N>
std::string names_list(const EnumName<E> (&table)[N]) {
    std::string s;
    for (std::size_t i = 0; i < N; ++i) {
        if (i > 0) s += i + 1 == N ? " or " : ", ";
        s += table[i].name;
    }
    return s;
}

/// The names as strings (CLI11's IsMember).
template <class E, std::size_t N>
std::vector<std::string> names_vector(const EnumName<E> (&table)[N]) {
    std::vector<std::string> v;
    for (const EnumName<E>& e : table) v.emplace_back(e.name);
    return v;
}

}  // namespace streamrt
