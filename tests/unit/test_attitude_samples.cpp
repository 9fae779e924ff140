// daemon/commissioning/AttitudeSamples, as direction detection samples the Teensy's attitude each
// step: a vehicle at rest over the whole window is still, a turning one is not, and neither is a
// window a late step left holding only its last half (nothing to compare the halves with), nor
// one whose last half has no reading (a stalled poll); a reading looked at again is one sample;
// the yaw averaged around the circle, so a heading near +-pi does not average to zero.
#include "daemon/commissioning/attitude_samples.hpp"

#include "tests/catch.hpp"

#include <cmath>
#include <numbers>

using namespace caracara;

namespace {

constexpr uint64_t kMs = 1'000'000;
constexpr uint64_t kStep = 20 * kMs;    // the detection's step
constexpr uint64_t kWindow = 100 * kMs; // detect_settle_ms at its floor
constexpr double kStillRad = 0.005;     // detect_settle_mrad's default
constexpr uint64_t kT0 = 1'000'000 * kMs;

// Samples every step over (end - span, end], of `attitude(t)`, the window kept as the detection keeps it.
template <typename F>
AttitudeSamples sampled(uint64_t end, uint64_t span, F attitude) {
    AttitudeSamples s;
    for (uint64_t t = end - span; t <= end; t += kStep) {
        s.add(t, attitude(t));
        s.keep_window(kWindow, t);
    }
    return s;
}

} // namespace

TEST_CASE("AttitudeSamples: at rest over the window, still; turning at 1 rad/s, not") {
    const uint64_t now = kT0 + 10 * kWindow;
    const auto rest = sampled(now, 3 * kWindow, [](uint64_t) { return AttitudeSamples::Attitude{0.3, -0.1, 0.05}; });
    CHECK(rest.still(now, kWindow / 2, kStillRad));
    const auto turning = sampled(now, 3 * kWindow, [](uint64_t t) {
        return AttitudeSamples::Attitude{std::remainder(double(t) / 1e9, 2 * std::numbers::pi), 0, 0};
    });
    CHECK_FALSE(turning.still(now, kWindow / 2, kStillRad));
}

TEST_CASE("AttitudeSamples: a window holding only its last half (a late step) is not still, whatever it holds") {
    const uint64_t now = kT0 + 10 * kWindow;
    AttitudeSamples one;
    one.add(now - 2 * kWindow, {0.0, 0, 0}); // before the loop was late: dropped with the window
    one.keep_window(kWindow, now);
    one.add(now, {1.0, 0, 0});
    CHECK_FALSE(one.still(now, kWindow / 2, kStillRad));
    AttitudeSamples late_half;
    late_half.add(now - 40 * kMs, {1.0, 0, 0});
    late_half.add(now - 20 * kMs, {1.0, 0, 0});
    late_half.add(now, {1.0, 0, 0});
    CHECK_FALSE(late_half.still(now, kWindow / 2, kStillRad));
    // Once the steps cover the window again, at rest is still.
    for (uint64_t t = now + kStep; t <= now + kWindow; t += kStep)
        late_half.add(t, {1.0, 0, 0});
    late_half.keep_window(kWindow, now + kWindow);
    CHECK(late_half.still(now + kWindow, kWindow / 2, kStillRad));
}

TEST_CASE("AttitudeSamples: a stalled poll (no reading in the last half window) is not still; a reading looked at again is one sample") {
    const uint64_t now = kT0 + 10 * kWindow;
    // Readings at rest over the first half, then none: the detection's steps find the last one
    // again and again, and add nothing.
    AttitudeSamples stalled;
    for (uint64_t t = now - kWindow; t < now - kWindow / 2; t += kStep)
        stalled.add(t, {0.3, 0, 0});
    const uint64_t last = now - kWindow / 2 - kStep / 2;
    stalled.add(last, {0.3, 0, 0});
    for (uint64_t step = last; step <= now; step += kStep)
        stalled.add(last, {0.3, 0, 0});
    CHECK_FALSE(stalled.still(now, kWindow / 2, kStillRad));
    CHECK_FALSE(stalled.mean_from(now - kWindow / 2).has_value());
    // The poll back: one reading in the last half and the window is judged again.
    stalled.add(now, {0.3, 0, 0});
    CHECK(stalled.still(now, kWindow / 2, kStillRad));
    // Looked at again, a reading weighs once: the mean of 0 and 1 read once each is 0.5.
    AttitudeSamples twice;
    twice.add(kT0, {0.0, 0, 0});
    twice.add(kT0 + kStep, {0.0, 1.0, 0});
    twice.add(kT0 + kStep, {0.0, 1.0, 0});
    twice.add(kT0 + kStep, {0.0, 1.0, 0});
    CHECK((*twice.mean_from(0))[1] == Approx(0.5));
    CHECK_FALSE(AttitudeSamples{}.mean_from(0).has_value());
}

TEST_CASE("AttitudeSamples: yaw averaged around the circle; the change wrapped to (-pi, pi]") {
    const double pi = std::numbers::pi;
    AttitudeSamples s;
    // A heading wobbling across +-pi: its mean is pi, not 0.
    for (int i = 0; i < 10; ++i)
        s.add(kT0 + uint64_t(i) * kStep, {i % 2 ? -pi + 0.01 : pi - 0.01, 0.2, -0.2});
    const auto m = *s.mean_from(0);
    CHECK(std::abs(std::remainder(m[0] - pi, 2 * pi)) < 1e-9);
    CHECK(m[1] == Approx(0.2));
    CHECK(m[2] == Approx(-0.2));
    // Only the samples from `from_ns` on.
    CHECK((*s.mean_from(kT0 + 9 * kStep))[0] == Approx(-pi + 0.01));
    // A turn through pi is a small change, not nearly a full circle.
    const auto c = AttitudeSamples::change({pi - 0.05, 0.1, 0.0}, {-pi + 0.05, 0.3, -0.1});
    CHECK(c[0] == Approx(0.1));
    CHECK(c[1] == Approx(0.2));
    CHECK(c[2] == Approx(-0.1));
}
