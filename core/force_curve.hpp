// A thruster's force curve: the thrust in newtons it gives at each motor value, forward and
// reverse (bollard figures). Points at evenly spaced fractions of full demand 0, 1/n, .., 1, linear
// between them; each direction's thrust rises strictly, so every force has one motor value.
#pragma once

#include <string>
#include <vector>

namespace caracara {

// SeaBotix BTD150 datasheet: 2.2 kgf bollard thrust (2.2 x 9.80665 N). The reverse default is
// that same rating: no separate public reverse figure was found (docs/ros2.md says so); a vehicle
// whose reverse is weaker sets [vehicle] thrust_reverse_n from its own bollard test.
inline constexpr double kBtd150ForwardN = 2.2 * 9.80665;
inline constexpr double kBtd150ReverseN = 2.2 * 9.80665;

class ForceCurve {
public:
    // Linear from 0 to the BTD150's full forward and reverse thrust.
    ForceCurve();
    // "" when both lists can be a curve (at least 2 points, the first 0, each finite and above
    // the one before), else why not.
    static std::string check(const std::vector<double>& points_n);
    // Both lists must pass check().
    ForceCurve(std::vector<double> forward_n, std::vector<double> reverse_n);

    // Full demand's thrust in that direction, newtons (> 0).
    double full_n(bool reverse) const;
    // The thrust (signed, newtons) at a fraction of full demand -1..1 (clamped).
    double force_n(double fraction) const;
    // The fraction of full demand (signed) that gives `force_n`; |force_n| must be within full_n.
    double fraction(double force_n) const;

private:
    std::vector<double> forward_n_, reverse_n_;
};

} // namespace caracara
