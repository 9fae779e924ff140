#include "core/toml_text.hpp"

#include <algorithm>
#include <cstddef>

namespace caracara {

std::string non_ascii_outside_comments(std::string_view text) {
    // Just enough of TOML's lexing to know where comments are: strings (whose quotes and
    // escapes could hide a '#'), comments, and the rest.
    enum class In { Code, Comment, Basic, Literal, MultiBasic, MultiLiteral } in = In::Code;
    std::size_t line = 1, column = 0;
    auto run_of = [&](std::size_t i, char q) {
        std::size_t n = 0;
        while (i + n < text.size() && text[i + n] == q)
            ++n;
        return n;
    };
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        ++column;
        if (c == '\n') {
            ++line;
            column = 0;
            // Single-line strings and comments end here (an unterminated string is toml++'s error).
            if (in != In::MultiBasic && in != In::MultiLiteral)
                in = In::Code;
            continue;
        }
        if (static_cast<unsigned char>(c) >= 0x80) {
            if (in == In::Comment)
                continue;
            const auto b = static_cast<unsigned char>(c);
            return "line " + std::to_string(line) + ", column " + std::to_string(column) + ": non-ASCII byte 0x" +
                   "0123456789abcdef"[b >> 4] + "0123456789abcdef"[b & 15] +
                   " outside a comment (keys and values in this file are ASCII)";
        }
        switch (in) {
        case In::Code:
            if (c == '#') {
                in = In::Comment;
            } else if (c == '"' || c == '\'') {
                const bool multi = run_of(i, c) >= 3;
                in = c == '"' ? (multi ? In::MultiBasic : In::Basic) : (multi ? In::MultiLiteral : In::Literal);
                if (multi) {
                    i += 2;
                    column += 2;
                }
            }
            break;
        case In::Comment: break;
        case In::Basic:
        case In::MultiBasic:
            // An escaped quote or backslash is skipped; a newline or non-ASCII byte after the
            // backslash is left to the checks above.
            if (c == '\\' && i + 1 < text.size() && (text[i + 1] == '"' || text[i + 1] == '\\')) {
                ++i;
                ++column;
            } else if (c == '"' && in == In::Basic) {
                in = In::Code;
            } else if (c == '"' && run_of(i, '"') >= 3) {
                // Up to two quotes may stand just inside the closing delimiter: the run ends it.
                const std::size_t n = std::min<std::size_t>(run_of(i, '"'), 5);
                i += n - 1;
                column += n - 1;
                in = In::Code;
            }
            break;
        case In::Literal:
        case In::MultiLiteral:
            if (c == '\'' && in == In::Literal) {
                in = In::Code;
            } else if (c == '\'' && run_of(i, '\'') >= 3) {
                const std::size_t n = std::min<std::size_t>(run_of(i, '\''), 5);
                i += n - 1;
                column += n - 1;
                in = In::Code;
            }
            break;
        }
    }
    return {};
}

} // namespace caracara
