#include "tools/ros/range_subscribers.hpp"

#include "tests/catch.hpp"

#include <cctype>
#include <string>

using caracara::ros::RangeLayout;
using caracara::ros::RangeSubscribers;

// The hashes rosidl generates for sensor_msgs/msg/Range (tests/ros/type_hash.mjs computes them from
// the published definitions; the e2e test announces them from a real second vendor's reader).
static const std::string kWithVariance = "RIHS01_b42b62562e93cbfe9d42b82fe5994dfa3d63d7d5c90a317981703f7388adff3a";
static const std::string kWithoutVariance = "RIHS01_9430b1915b94d4268ff903679e8ecd09b6a67d331bd028738ec1eeb592891ebd";

TEST_CASE("a Range subscriber's USER_DATA: the layout it asks for, and why") {
    SECTION("Jazzy's hash, as rmw_dds_common writes it: Jazzy") {
        const auto a = RangeSubscribers::asked("typehash=" + kWithVariance + ";");
        CHECK(a.layout == RangeLayout::Jazzy);
        CHECK(a.why.find("Jazzy's") != std::string::npos);
    }
    SECTION("the hash among other items, in any place: still read") {
        CHECK(RangeSubscribers::asked("enclave=/;typehash=" + kWithVariance + ";x=1;").layout == RangeLayout::Jazzy);
        CHECK(RangeSubscribers::asked("typehash=" + kWithVariance).layout == RangeLayout::Jazzy); // no final ;
    }
    SECTION("the Range without variance: Humble's layout") {
        CHECK(RangeSubscribers::asked("typehash=" + kWithoutVariance + ";").layout == RangeLayout::Humble);
    }
    SECTION("none (Humble), or empty: Humble's") {
        CHECK(RangeSubscribers::asked("").layout == RangeLayout::Humble);
        CHECK(RangeSubscribers::asked("enclave=/;").layout == RangeLayout::Humble);
        CHECK(RangeSubscribers::asked("").why == "no typehash (Humble announces none)");
    }
    SECTION("a hash of no Range known here: no layout, the hash named, unprintable bytes shown as ?") {
        const auto a = RangeSubscribers::asked(std::string("typehash=RIHS01_00\x01zz;", 21));
        CHECK_FALSE(a.layout.has_value());
        CHECK(a.why == "typehash RIHS01_00?zz: no sensor_msgs/Range known here");
    }
    SECTION("a near miss (one digit off, upper case) is not Jazzy's") {
        std::string off = kWithVariance;
        off.back() = 'b';
        CHECK_FALSE(RangeSubscribers::asked("typehash=" + off + ";").layout.has_value());
        std::string upper = kWithVariance;
        for (char& c : upper)
            c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        CHECK_FALSE(RangeSubscribers::asked("typehash=" + upper + ";").layout.has_value());
    }
}
