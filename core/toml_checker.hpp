// Checks a parsed TOML table key by key and collects every problem, so one run of the daemon
// shows the user everything to fix: "<key>: <problem> (line N)", unknown keys with a "did you
// mean", integers never wrapped, types named as the user wrote them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <toml++/toml.h>
#include <vector>

namespace caracara {

// What the user wrote, for "got ..." in messages.
std::string written(const toml::node& n);

std::size_t edit_distance(std::string_view a, std::string_view b);

using Keys = std::initializer_list<std::string_view>;

// Collects every problem instead of stopping at the first, so one run of the daemon shows
// the user everything to fix.
class Checker {
public:
    std::vector<std::string> errors;

    void fail(const std::string& key, const std::string& problem, const toml::node* at = nullptr) {
        std::string m = key + ": " + problem;
        if (at && at->source().begin.line > 0)
            m += " (line " + std::to_string(at->source().begin.line) + ")";
        errors.push_back(std::move(m));
    }

    // Unknown keys are errors: a misspelt key would otherwise silently keep its default.
    void only_keys(const toml::table& t, const std::string& prefix, Keys allowed) {
        for (auto&& [k, v] : t) {
            const std::string_view name = k.str();
            if (std::find(allowed.begin(), allowed.end(), name) != allowed.end())
                continue;
            std::string hint;
            for (std::string_view a : allowed)
                if (edit_distance(name, a) <= 2) {
                    hint = "; did you mean '" + prefix + std::string(a) + "'?";
                    break;
                }
            if (hint.empty()) {
                hint = "; known keys: ";
                bool first = true;
                for (std::string_view a : allowed) {
                    hint += (first ? "" : ", ") + std::string(a);
                    first = false;
                }
            }
            std::string m = "unknown key '" + prefix + std::string(name) + "'" + hint;
            if (v.source().begin.line > 0)
                m += " (line " + std::to_string(v.source().begin.line) + ")";
            errors.push_back(std::move(m));
        }
    }

    const toml::table* table(const toml::table& parent, const std::string& prefix, std::string_view key) {
        const toml::node* n = parent.get(key);
        if (!n)
            return nullptr;
        if (!n->is_table()) {
            fail(prefix + std::string(key), "must be a table, got " + written(*n), n);
            return nullptr;
        }
        return n->as_table();
    }

    // Integer in lo..hi; `range` replaces the default "between lo and hi" wording.
    template <typename T>
    bool integer(const toml::table& t, const std::string& prefix, std::string_view key, int64_t lo, int64_t hi,
                 T& out, const std::string& range = {}) {
        const toml::node* n = t.get(key);
        if (!n)
            return false;
        const std::string full = prefix + std::string(key);
        const auto* iv = n->as_integer();
        if (!iv) {
            fail(full, "must be an integer, got " + written(*n), n);
            return false;
        }
        const int64_t v = iv->get();
        if (v < lo || v > hi) {
            fail(full,
                 "must be " + (range.empty() ? "between " + std::to_string(lo) + " and " + std::to_string(hi) : range) +
                     ", got " + std::to_string(v),
                 n);
            return false;
        }
        out = static_cast<T>(v);
        return true;
    }

    template <typename T>
    bool integer(const toml::table& t, const std::string& prefix, std::string_view key, int64_t lo, int64_t hi,
                 std::optional<T>& out, const std::string& range = {}) {
        T v{};
        if (!integer(t, prefix, key, lo, hi, v, range))
            return false;
        out = v;
        return true;
    }

    bool boolean(const toml::table& t, const std::string& prefix, std::string_view key, bool& out) {
        const toml::node* n = t.get(key);
        if (!n)
            return false;
        const auto* b = n->as_boolean();
        if (!b) {
            fail(prefix + std::string(key), "must be true or false, got " + written(*n), n);
            return false;
        }
        out = b->get();
        return true;
    }

    bool string(const toml::table& t, const std::string& prefix, std::string_view key, std::string& out,
                bool allow_empty = false) {
        const toml::node* n = t.get(key);
        if (!n)
            return false;
        const auto* s = n->as_string();
        if (!s) {
            fail(prefix + std::string(key), "must be a string, got " + written(*n), n);
            return false;
        }
        if (!allow_empty && s->get().empty()) {
            fail(prefix + std::string(key), "must not be empty", n);
            return false;
        }
        out = s->get();
        return true;
    }

    bool path(const toml::table& t, const std::string& prefix, std::string_view key, std::string& out) {
        std::string v;
        if (!string(t, prefix, key, v))
            return false;
        if (v.front() != '/') {
            fail(prefix + std::string(key), "must be an absolute path, got \"" + v + "\"", t.get(key));
            return false;
        }
        out = v;
        return true;
    }
};

} // namespace caracara
