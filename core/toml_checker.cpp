#include "core/toml_checker.hpp"

#include <algorithm>
#include <sstream>

namespace caracara {

// What the user wrote, for "got ..." in messages.
std::string written(const toml::node& n) {
    if (auto s = n.as_string())
        return "\"" + s->get() + "\"";
    if (auto i = n.as_integer())
        return std::to_string(i->get());
    if (auto f = n.as_floating_point()) {
        std::ostringstream os;
        os << f->get();
        return os.str();
    }
    if (auto b = n.as_boolean())
        return b->get() ? "true" : "false";
    if (n.is_table())
        return "a table";
    if (n.is_array())
        return "an array";
    return "a date/time";
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j)
        row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0u : 1u)});
            diag = up;
        }
    }
    return row[b.size()];
}

} // namespace caracara
