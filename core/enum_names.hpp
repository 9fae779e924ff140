// The one way an enum's values are named (on D-Bus, in the journal, in the config and the dive
// files): a table of {value, name} beside the enum, EnumNames<E>, every value in the enum's order
// (consecutive from its first value, which a wire format may start at 1). name_of() names a value, parse_name() reads a name back; tests/unit/test_enum_names
// walks every table (each value named once, each name read back to its value).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

namespace caracara {

template <typename E>
struct EnumName {
    E value;
    std::string_view name;
};

// Specialised beside each enum: `static constexpr std::array<EnumName<E>, N> table{...};`
template <typename E>
struct EnumNames;

template <typename E>
constexpr std::size_t index_of(E e) {
    return static_cast<std::size_t>(e) - static_cast<std::size_t>(EnumNames<E>::table[0].value);
}

// The table lists consecutive values in order: value first + i is at index i.
template <typename E>
constexpr bool names_in_order() {
    const auto& t = EnumNames<E>::table;
    for (std::size_t i = 0; i < t.size(); ++i)
        if (index_of(t[i].value) != i || t[i].name.empty())
            return false;
    return true;
}

template <typename E>
constexpr std::string_view name_of(E e) {
    static_assert(names_in_order<E>(), "EnumNames<E>::table must list every value, in order, each with a name");
    const auto& t = EnumNames<E>::table;
    const std::size_t i = index_of(e);
    return i < t.size() ? t[i].name : std::string_view("?");
}

template <typename E>
constexpr std::optional<E> parse_name(std::string_view name) {
    for (const EnumName<E>& n : EnumNames<E>::table)
        if (n.name == name)
            return n.value;
    return std::nullopt;
}

} // namespace caracara
