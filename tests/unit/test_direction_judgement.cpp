// Direction detection's decision against the seed's mixing: the sign of the measured rotation
// along the thruster's row, the threshold, rotation across the row, and the fragment written.
#include "core/config.hpp"
#include "core/direction_judgement.hpp"

#include "tests/catch.hpp"

using namespace caracara;

namespace {
const MixMatrix& seed() { return default_mix_matrix(); }
}

TEST_CASE("a horizontal thruster: yaw the way its row says is ok, the other way reversed") {
    // Motor 0: +1 yaw in the seed's table.
    auto j = judge_direction(seed(), 0, 3000, {0.03, 0.001, -0.001}, 0.01);
    CHECK(j.verdict == DirectionVerdict::Ok);
    CHECK(j.along == Approx(0.03).margin(1e-9));
    CHECK(j.margin == Approx(3.0).margin(1e-6));
    CHECK(judge_direction(seed(), 0, 3000, {-0.03, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Reversed);
    // A negative pulse expects the opposite rotation.
    CHECK(judge_direction(seed(), 0, -3000, {-0.03, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Ok);
    // Motor 4: -1 yaw.
    CHECK(judge_direction(seed(), 4, 3000, {-0.03, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Ok);
}

TEST_CASE("a vertical thruster is judged on pitch and roll together") {
    // Motor 1: pitch -1, roll -1.
    CHECK(judge_direction(seed(), 1, 3000, {0.0, -0.02, -0.02}, 0.01).verdict == DirectionVerdict::Ok);
    CHECK(judge_direction(seed(), 1, 3000, {0.0, 0.02, 0.02}, 0.01).verdict == DirectionVerdict::Reversed);
    // Motor 7: pitch -1, roll +1.
    CHECK(judge_direction(seed(), 7, 3000, {0.002, -0.02, 0.02}, 0.01).verdict == DirectionVerdict::Ok);
}

TEST_CASE("too small, or the wrong rotation, is inconclusive, never ok") {
    // A disconnected thruster: only noise.
    auto j = judge_direction(seed(), 2, 3000, {0.004, -0.002, 0.001}, 0.01);
    CHECK(j.verdict == DirectionVerdict::Inconclusive);
    CHECK(j.margin < 1.0);
    // Motor 1 should pitch and roll; a turn in yaw alone is not its doing.
    CHECK(judge_direction(seed(), 1, 3000, {0.05, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Inconclusive);
    // Pitch against roll: along the row is nothing.
    CHECK(judge_direction(seed(), 1, 3000, {0.0, 0.03, -0.03}, 0.01).verdict == DirectionVerdict::Inconclusive);
    CHECK(judge_direction(seed(), 0, 0, {0.05, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Inconclusive);
    CHECK(judge_direction(seed(), 8, 3000, {0.05, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Inconclusive);
}

TEST_CASE("a thruster with no rotation in its row cannot be told") {
    MixMatrix m = seed();
    m[0] = {1.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    CHECK(judge_direction(m, 0, 3000, {0.05, 0.0, 0.0}, 0.01).verdict == DirectionVerdict::Inconclusive);
}

TEST_CASE("the fragment flips the reversed ones, keeps the rest, and parses") {
    DaemonConfig cfg;
    cfg.thrusters[3].reversed = true;
    std::array<DirectionJudgement, kMotorCount> found{};
    for (auto& f : found)
        f.verdict = DirectionVerdict::Ok;
    found[1].verdict = DirectionVerdict::Reversed;
    found[3].verdict = DirectionVerdict::Reversed; // configured reversed, found reversed again: not reversed
    found[6].verdict = DirectionVerdict::Inconclusive;
    cfg.thrusters[6].reversed = true;
    const std::string text = reversal_fragment(cfg.thrusters, found);
    CHECK(text.find("motor 6: inconclusive, kept as configured") != std::string::npos);
    const ConfigResult r = parse_config_string(text);
    REQUIRE(r.ok());
    for (size_t i = 0; i < kMotorCount; ++i) {
        INFO("motor " << i);
        CHECK(r.config->thrusters[i].mt == cfg.thrusters[i].mt);
        CHECK(r.config->thrusters[i].reversed == (i == 1 || i == 6));
    }
}
