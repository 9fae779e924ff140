// The text of a TOML file before it is parsed (caracarad's configuration, the simulator's, caracara-ros's).
#pragma once

#include <string>
#include <string_view>

namespace caracara {

// "" when every non-ASCII character of `text` is inside a comment, else "line N, column M: ..."
// for the first one that is not. Run before toml::parse: toml++ 3.3 (Debian 12) executes
// __builtin_unreachable when it tests some non-ASCII characters (U+00A1..U+0499 and others)
// for whitespace, which it does wherever one stands outside a string or comment (found by
// fuzz_config; upstream marzer/tomlplusplus#190, #295). No key or value of these files needs
// one; comments may carry any text.
std::string non_ascii_outside_comments(std::string_view text);

} // namespace caracara
