"""The current budget on every count of running motors, under the scale and the reject policy:
expected values computed from the seeds, judged on the simulated wire.
"""

import math
import unittest

from harness import (DEFAULT_MT, ERR, MOTORS, ZERO, VehicleTestCase, budget_limit, poll, speed_byte)
from vehicle_checks import hexes


# --------------------------------------------------------------------------------------------
# The current budget, on every count of running motors
# --------------------------------------------------------------------------------------------

# Motors picked for a count n: the first n of a permutation, so each count uses other motors.
MOTOR_ORDER = [0, 3, 6, 1, 4, 7, 2, 5]
MAGNITUDES = [8850, 8000, 7200, 6400, 5600, 4800, 4400, 4000]


def demand_for(n, magnitudes=MAGNITUDES):
    values = [0] * MOTORS
    for k in range(n):
        values[MOTOR_ORDER[k]] = magnitudes[k] * (1 if k % 2 == 0 else -1)
    return values


class BudgetScaleTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def check_sim(self, values, tolerate_rounding=True):
        """Waits until every simulated thruster shows the expected order for `values` (floats
        allowed: a scaled value may round either way by one unit)."""
        def matches():
            speeds = self.rig.sim_speeds()
            for i, v in enumerate(values):
                ok = {speed_byte(math.floor(v)), speed_byte(math.ceil(v)), speed_byte(int(v))}
                if speeds[i] not in ok:
                    return False
            return speeds
        return poll(matches, 10, message="simulated thrusters never showed %r (now %s)" %
                    (values, hexes(self.rig.sim_speeds())))

    def test_scale_on_every_count(self):
        for n in range(1, MOTORS + 1):
            with self.subTest(running=n):
                values = demand_for(n)
                limit = budget_limit(n)
                self.rig.thrust(values)
                largest = max(abs(v) for v in values)
                factor = limit / largest
                expected = [v * factor for v in values]
                self.check_sim(expected)
                # The orders on the wire are complete and well-formed: [SPEED, INFO, CSUM].
                orders = self.rig.sim_last_orders()
                speeds = self.rig.sim_speeds()
                for i in range(MOTORS):
                    s = speeds[i]
                    self.assertEqual(list(orders[i]), [s, 100, (DEFAULT_MT[i] + s + 100) & 0xFF])
                # The daemon reports what it did.
                self.assertEqual(self.rig.vget("BudgetLimit"), limit)
                self.assertTrue(self.rig.vget("Saturated"))
                self.assertEqual(list(self.rig.vget("RequestedValues")), values)
                mv = self.rig.motor_values()
                self.assertEqual(max(abs(v) for v in mv), limit, "the largest motor is held at the limit")
                for i in range(MOTORS):
                    self.assertLessEqual(abs(mv[i]), limit)
                    self.assertAlmostEqual(mv[i], expected[i], delta=1.0,
                                           msg="motor %d: one factor for all motors keeps the direction" % i)
                    self.assertEqual(mv[i] == 0, values[i] == 0)
                    self.assertEqual(mv[i] > 0, values[i] > 0)

    def test_within_budget_is_not_scaled(self):
        for n in range(1, MOTORS + 1):
            with self.subTest(running=n):
                limit = budget_limit(n)
                values = demand_for(n, [limit] * MOTORS)
                self.rig.thrust(values)
                self.rig.wait_sim_speeds([speed_byte(v) for v in values])
                self.assertEqual(self.rig.motor_values(), values)
                self.assertFalse(self.rig.vget("Saturated"))
                self.assertEqual(self.rig.vget("BudgetLimit"), limit)

    def test_one_over_the_limit_is_scaled(self):
        # limit + 1 on one motor: the budget must not be exceeded even by one unit.
        for n in (2, 4, 8):
            with self.subTest(running=n):
                limit = budget_limit(n)
                values = demand_for(n, [limit] * MOTORS)
                values[MOTOR_ORDER[0]] = limit + 1
                self.rig.thrust(values)
                mv = self.rig.motor_values()
                self.assertLessEqual(max(abs(v) for v in mv), limit)
                self.assertTrue(self.rig.vget("Saturated"))
                self.check_sim([v * limit / (limit + 1) for v in values])


class BudgetRejectTest(VehicleTestCase):
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "budget_policy": "reject"}

    def setUp(self):
        self.rig.reset()

    def test_policy_property(self):
        self.assertEqual(self.rig.vget("BudgetPolicy"), "reject")

    def test_reject_on_every_count(self):
        base = [500, 0, 0, 0, 0, 0, 0, -500]
        for n in range(1, MOTORS + 1):
            with self.subTest(running=n):
                self.rig.thrust(base)
                self.rig.wait_sim_speeds([speed_byte(v) for v in base])
                limit = budget_limit(n)
                over = demand_for(n, [limit] * MOTORS)
                over[MOTOR_ORDER[n - 1]] += 1 if over[MOTOR_ORDER[n - 1]] > 0 else -1
                before = self.rig.sim_snapshot()
                self.assertDBusError(ERR + "OverBudget", self.rig.thrust, over)
                self.rig.wait_orders_refreshed()
                self.assertEqual(self.rig.sim_snapshot(), before, "a rejected command changed the thrusters")
                self.assertEqual(list(self.rig.vget("RequestedValues")), base)
                self.assertEqual(self.rig.motor_values(), base)
                self.assertFalse(self.rig.vget("Saturated"))
                # Exactly at the limit is accepted and reaches the thrusters unchanged.
                at = demand_for(n, [limit] * MOTORS)
                self.rig.thrust(at)
                self.rig.wait_sim_speeds([speed_byte(v) for v in at])
                self.assertEqual(self.rig.motor_values(), at)

    def test_reject_motion_over_budget(self):
        # y = 1 drives four motors at full scale: over the 4-motor limit.
        self.rig.thrust([0] * MOTORS)
        self.assertDBusError(ERR + "OverBudget", self.rig.motion, y=1.0)
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)


if __name__ == "__main__":
    unittest.main()
