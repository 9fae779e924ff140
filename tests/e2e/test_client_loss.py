"""A topside client is a pilot: when the commanding client leaves the bus, its thrust goes (and
what it had sent reached the wire first); another client leaving changes nothing. When it was
the last pilot, the vehicle is killed after pilot-lost's persistence (test_pilot_lost has the
rest of that failsafe).
"""

import time
import unittest

import dbus
import dbus.bus
import dbus.lowlevel

import harness
from harness import (DEFAULT_MT, MOTORS, ROOT, VEHICLE, ZERO, VehicleTestCase, poll, speed_byte)
from test_failsafes import kill_edges

PILOT_LOST_MS = 1000


class ClientLossTest(VehicleTestCase):
    """The command timeout is 60 s here: only the client leaving can zero the thrusters. The
    test's own connection is no pilot unless a test commands through it."""
    EXTRA_CONFIG = {"failsafe": {"pilot-lost": {"action": "kill", "persistence_ms": PILOT_LOST_MS}}}

    def setUp(self):
        self.rig.rearm()

    def test_commanding_process_exits(self):
        rig = self.rig
        values = [0, 0, 0, 0, 2222, -2222, 0, 0]
        proc, name = harness.start_client(rig, values)
        try:
            rig.wait_sim_speeds([speed_byte(v) for v in values])
            self.assertEqual(rig.vget("Controller"), name)
            # Still driving while the client is connected.
            time.sleep(0.3)
            self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
            since = rig.wire_next()
        finally:
            left_at = time.monotonic_ns()
            proc.stdin.close()
            proc.wait(10)
            proc.stdout.close()
            proc.stderr.close()
        rig.wait_sim_zero(10)
        self.assertEqual(rig.motor_values(), [0] * MOTORS)
        self.assertEqual(rig.vget("Controller"), "")
        self.assertEqual(rig.state(), "ready", "the zeros come at once, the kill after the persistence")
        # It was the last pilot: the kill output, after pilot-lost's persistence.
        rig.wait_state("killed")
        self.assertEqual(rig.vget("KillSource"), "failsafe")
        edge = poll(lambda: kill_edges(rig.wire_log(since)[1]), 5, message="no kill output edge")[0]
        self.assertGreaterEqual((edge.time_ns - left_at) / 1e6, PILOT_LOST_MS)
        zeros = [e for e in rig.wire_log(since)[1] if e.bus == "i2c" and not e.read and e.data[:1] == bytes([ZERO])]
        self.assertTrue(zeros and zeros[0].index < edge.index, "the zeros did not come before the kill")

    def test_other_client_leaving_changes_nothing(self):
        rig = self.rig
        values = [900, 900, 0, 0, 0, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        proc, name = harness.start_client(rig)  # connects, commands nothing
        proc.stdin.close()
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
        time.sleep(0.3)
        rig.wait_orders_refreshed()
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        self.assertEqual(rig.vget("Controller"), rig.conn.get_unique_name())

    def test_busctl_one_shot(self):
        rig = self.rig
        wire_from = rig.wire_next()
        r = rig.busctl("call", "--", VEHICLE, ROOT, VEHICLE, "SetThrust", "ai", 8, 3000, 0, 0, 0, 0, 0, 0, -3000)
        self.assertEqual(r.returncode, 0, r.stderr)
        # busctl left the bus right after the reply: the thrusters end at zero...
        rig.wait_sim_zero(10)
        poll(lambda: rig.motor_values() == [0] * MOTORS, 10)
        self.assertEqual(rig.vget("Controller"), "")
        self.assertEqual(rig.state(), "ready")
        # ...and the accepted command reached the wire before the zero order.
        self.assert_order_then_zero(wire_from, {0: 3000, 7: -3000})
        rig.wait_orders_refreshed()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_client_gone_before_its_reply(self):
        # The call and the disconnect arrive together, so the daemon learns that the client
        # left before its loop had a chance to send the orders: they still go out first.
        rig = self.rig
        rig.thrust([0] * MOTORS)  # a pilot stays: the rounds are about the orders, not pilot-lost
        for round_ in range(5):
            with self.subTest(round=round_):
                wire_from = rig.wire_next()
                conn = dbus.bus.BusConnection(rig.address)
                msg = dbus.lowlevel.MethodCallMessage(VEHICLE, ROOT, VEHICLE, "SetThrust")
                msg.append(dbus.Array([0, 0, 1500 + round_, 0, 0, 0, 0, 0], signature="i"), signature="ai")
                conn.send_message(msg)
                conn.flush()
                conn.close()
                self.assert_order_then_zero(wire_from, {2: 1500 + round_})
                poll(lambda: rig.vget("Controller") == "", 10)

    def assert_order_then_zero(self, wire_from, commanded, timeout=10.0):
        """Each thruster's commanded order appears on the wire, and its last order is zero."""
        def orders():
            _, log = self.rig.wire_log(wire_from)
            return {i: [e.data[0] for e in log if e.bus == "i2c" and not e.read and e.addr == DEFAULT_MT[i] >> 1]
                    for i in commanded}

        def done():
            got = orders()
            return all(speed_byte(v) in got[i] and got[i][-1] == ZERO for i, v in commanded.items())

        try:
            poll(done, timeout)
        except harness.Timeout:
            got = {i: sorted(set(speeds)) for i, speeds in orders().items()}
            self.fail(f"commanded {commanded} (SPEED {[speed_byte(v) for v in commanded.values()]}): "
                      f"the wire carried only SPEED {got}")


if __name__ == "__main__":
    unittest.main()
