#include "core/mixing.hpp"

#include "tests/catch.hpp"
#include <cmath>
#include <limits>
#include <set>

using namespace caracara;

namespace {

AxisDemand along(Axis axis, double value) {
    AxisDemand d{};
    d[static_cast<std::size_t>(axis)] = value;
    return d;
}

struct AxisRow {
    Axis axis;
    std::set<std::size_t> positive;  // motors the seed sets positive for the + motion
    std::set<std::size_t> negative;
};

// The seed's axis table, written out as the seed states it.
const AxisRow kSeedTable[] = {
    {Axis::X, {2, 6}, {0, 4}},          // towards port: 2/6 positive, 0/4 negative
    {Axis::Y, {0, 2, 4, 6}, {}},        // forward
    {Axis::Z, {1, 3, 5, 7}, {}},        // increase depth
    {Axis::Yaw, {0, 2}, {4, 6}},        // clockwise from above
    {Axis::Pitch, {3, 5}, {1, 7}},      // nose to the sky
    {Axis::Roll, {5, 7}, {1, 3}},       // clockwise from the back
};

} // namespace

TEST_CASE("each axis of the default matrix drives exactly the seed's motors with the seed's signs") {
    for (const AxisRow& row : kSeedTable) {
        const std::size_t a = static_cast<std::size_t>(row.axis);
        INFO("axis " << axis_name(a));
        for (double sign : {1.0, -1.0}) {
            INFO("demand " << sign);
            const MixResult r = mix(along(row.axis, sign));
            REQUIRE(r.ok());
            CHECK_FALSE(r.saturated);
            for (std::size_t m = 0; m < kMotorCount; ++m) {
                INFO("motor " << m);
                if (row.positive.count(m))
                    CHECK(r.motors[m] == static_cast<int32_t>(sign) * kMotorMax);
                else if (row.negative.count(m))
                    CHECK(r.motors[m] == -static_cast<int32_t>(sign) * kMotorMax);
                else
                    CHECK(r.motors[m] == 0);
            }
        }
    }
}

TEST_CASE("axis names follow the matrix column order") {
    CHECK(axis_name(0) == "x");
    CHECK(axis_name(1) == "y");
    CHECK(axis_name(2) == "z");
    CHECK(axis_name(3) == "yaw");
    CHECK(axis_name(4) == "pitch");
    CHECK(axis_name(5) == "roll");
    CHECK(axis_name(6) == "?");
}

TEST_CASE("partial demand scales linearly and rounds to the nearest motor value") {
    MixResult r = mix(along(Axis::Y, 0.5));
    REQUIRE(r.ok());
    CHECK_FALSE(r.saturated);
    CHECK(r.motors == MotorValues{4425, 0, 4425, 0, 4425, 0, 4425, 0});

    r = mix(along(Axis::Z, -0.1));
    REQUIRE(r.ok());
    CHECK(r.motors == MotorValues{0, -885, 0, -885, 0, -885, 0, -885});

    r = mix(along(Axis::Y, 0.00005));  // 0.4425 rounds to 0
    REQUIRE(r.ok());
    CHECK(r.motors == MotorValues{});

    CHECK(mix(AxisDemand{}).motors == MotorValues{});
}

TEST_CASE("saturation scales every motor by one factor, keeping the direction") {
    // forward + half yaw: raw 1.5, 0, 1.5, 0, 0.5, 0, 0.5, 0 -> divided by 1.5
    AxisDemand d{};
    d[1] = 1.0;
    d[3] = 0.5;
    MixResult r = mix(d);
    REQUIRE(r.ok());
    CHECK(r.saturated);
    CHECK(r.motors == MotorValues{8850, 0, 8850, 0, 2950, 0, 2950, 0});

    // Everything at once: whatever saturates, the ratios between motors must be those of
    // the raw mix (within one unit of rounding), and the largest motor is at full scale.
    const AxisDemand all{0.3, -0.9, 0.7, 0.2, -0.6, 0.4};
    r = mix(all);
    REQUIRE(r.ok());
    CHECK(r.saturated);
    std::array<double, kMotorCount> raw{};
    double peak = 0;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        for (std::size_t j = 0; j < kAxisCount; ++j)
            raw[i] += default_mix_matrix()[i][j] * all[j];
        peak = std::max(peak, std::abs(raw[i]));
    }
    REQUIRE(peak > 1.0);
    int32_t largest = 0;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        INFO("motor " << i);
        CHECK(std::abs(r.motors[i] - raw[i] / peak * kMotorMax) <= 0.5 + 1e-9);
        CHECK((r.motors[i] == 0 || (r.motors[i] > 0) == (raw[i] > 0)));
        largest = std::max(largest, std::abs(r.motors[i]));
    }
    CHECK(largest == kMotorMax);
}

TEST_CASE("outputs never leave -8850..8850 for any demand in range") {
    const double steps[] = {-1.0, -0.5, 0.0, 0.5, 1.0};
    for (double a : steps)
        for (double b : steps)
            for (double c : steps)
                for (double d : steps) {
                    const MixResult r = mix(AxisDemand{a, b, c, d, -a, b * c});
                    REQUIRE(r.ok());
                    for (int32_t v : r.motors)
                        REQUIRE(std::abs(v) <= kMotorMax);
                }
}

TEST_CASE("invalid demands are refused with a named error naming the axis") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();

    MixResult r = mix(along(Axis::Yaw, nan));
    CHECK(r.error == MixError::NotFinite);
    CHECK(error_name(r.error) == "NotFinite");
    CHECK(r.axis == 3);
    CHECK_THAT(r.message, Catch::Contains("yaw"));
    CHECK(r.motors == MotorValues{});

    r = mix(along(Axis::Z, -inf));
    CHECK(r.error == MixError::NotFinite);
    CHECK(r.axis == 2);

    r = mix(along(Axis::Roll, 1.01));
    CHECK(r.error == MixError::OutOfRange);
    CHECK(error_name(r.error) == "OutOfRange");
    CHECK(r.axis == 5);
    CHECK_THAT(r.message, Catch::Contains("roll") && Catch::Contains("1.01"));
    CHECK(r.motors == MotorValues{});

    r = mix(along(Axis::X, -1.5));
    CHECK(r.error == MixError::OutOfRange);
    CHECK(r.axis == 0);
}

TEST_CASE("a custom matrix is used as given") {
    MixMatrix m{};
    m[0][static_cast<std::size_t>(Axis::Y)] = 0.5;
    m[7][static_cast<std::size_t>(Axis::Y)] = -1.0;
    const MixResult r = mix(along(Axis::Y, 1.0), m);
    REQUIRE(r.ok());
    CHECK_FALSE(r.saturated);
    CHECK(r.motors == MotorValues{4425, 0, 0, 0, 0, 0, 0, -8850});
}
