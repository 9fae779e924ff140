// Catch2 2 (Debian 12: one header) or Catch2 3 (Debian 13: split headers, its own main), chosen
// by tests/CMakeLists.txt through CARACARA_CATCH2_MAJOR. The tests are written against the
// Catch2 2 spelling: Approx, Catch::Contains and Catch::StartsWith on strings.
#pragma once

#if CARACARA_CATCH2_MAJOR >= 3
#include <catch2/catch_approx.hpp>
#include <catch2/catch_test_macros.hpp>
#include <catch2/matchers/catch_matchers_string.hpp>

#include <string>

using Catch::Approx;

namespace Catch {
// Catch2 3 renamed the substring matcher (Matchers::Contains now means "range contains").
inline Matchers::StringContainsMatcher Contains(const std::string& str,
                                               CaseSensitive cs = CaseSensitive::Yes) {
    return Matchers::ContainsSubstring(str, cs);
}
using Matchers::StartsWith;
} // namespace Catch
#else
#include <catch2/catch.hpp>
#endif
