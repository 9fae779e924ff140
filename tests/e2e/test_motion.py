"""SetMotion through the default mixing matrix: each axis moves the seed's motors, held to the
budget, combined axes keep their direction.
"""

import unittest

from harness import (MOTORS, MOTOR_MAX, SEED_AXIS_MOTORS, ZERO, VehicleTestCase, budget_limit, speed_byte)


# --------------------------------------------------------------------------------------------
# SetMotion through the default mixing matrix
# --------------------------------------------------------------------------------------------

class MotionTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def test_each_axis_moves_the_seed_motors(self):
        for axis, motors in SEED_AXIS_MOTORS.items():
            for demand in (0.5, -0.5):
                with self.subTest(axis=axis, demand=demand):
                    self.rig.motion(**{axis: demand})
                    value = round(demand * MOTOR_MAX)  # 4 motors at 4425: within the 5750 budget
                    expected = [speed_byte(motors[i] * value) if i in motors else ZERO for i in range(MOTORS)]
                    self.rig.wait_sim_speeds(expected)
                    self.assertFalse(self.rig.vget("Saturated"))
                    self.assertEqual(self.rig.motor_values(),
                                     [motors.get(i, 0) * value for i in range(MOTORS)])

    def test_full_axis_is_held_to_the_budget(self):
        self.rig.motion(z=-1.0)
        limit = budget_limit(4)
        motors = SEED_AXIS_MOTORS["z"]
        self.rig.wait_sim_speeds([speed_byte(-motors[i] * limit) if i in motors else ZERO for i in range(MOTORS)])
        self.assertTrue(self.rig.vget("Saturated"))
        self.assertEqual(self.rig.vget("BudgetLimit"), limit)

    def test_combined_axes_keep_direction(self):
        # forward + clockwise yaw: motors 0 and 2 add up (2), 4 and 6 cancel (0); the mix is
        # scaled by one factor (not clipped), leaving two motors at full scale, then the
        # two-motor budget.
        self.rig.motion(y=1.0, yaw=1.0)
        limit = budget_limit(2)
        self.rig.wait_sim_speeds([speed_byte(limit), ZERO, speed_byte(limit), ZERO, ZERO, ZERO, ZERO, ZERO])
        self.assertTrue(self.rig.vget("Saturated"))


if __name__ == "__main__":
    unittest.main()
