"""The I2C adapter's timeout and retries: the configured ones reach the adapter, the default is
short.
"""

import unittest

from harness import (Rig)


class AdapterLimitsTest(unittest.TestCase):
    """i2c.timeout_ms and i2c.retries reach the adapter as I2C_TIMEOUT and I2C_RETRIES (the
    keys were read but never applied before)."""

    def test_configured_limits_reach_the_adapter(self):
        rig = Rig(control={"arming_delay_ms": 300}, extra_config={"i2c": {"timeout_ms": 25, "retries": 2}})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.assertEqual(int(rig.sim_get("I2cTimeout")), 3)  # 10 ms units, rounded up
        self.assertEqual(int(rig.sim_get("I2cRetries")), 2)

    def test_default_timeout_is_short_and_retries_the_kernels(self):
        # 20 ms, not i2c-bcm2835's one second: what a hung thruster may hold the others up.
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.assertEqual(int(rig.sim_get("I2cTimeout")), 2)
        self.assertEqual(int(rig.sim_get("I2cRetries")), -1)


if __name__ == "__main__":
    unittest.main()
