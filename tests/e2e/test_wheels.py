"""The Teensy's wheels are motors: the command timeout and a client leaving stop them, a refused
speed changes nothing, and a start, a SIGTERM and a crash of the daemon send Stop (a crash
while the bus is busy leaves no order after the zeros).
"""

import signal
import subprocess
import time
import unittest

import dbus

import harness
from bounds import DEADLINE_SEEN_EARLY_MS_MAX, DEADLINE_SEEN_LATE_MS_MAX
from harness import (ERR, MOTORS, ZERO, DEFAULT_MT, Rig, VehicleTestCase, error_name, poll, speed_byte)


def front_wheels(rig):
    w = rig.sim_teensy("Wheels")
    return (float(w[0]), float(w[1]))


def stop_frames(rig):
    return int(rig.sim_teensy_call("CommandCount", dbus.Byte(0x05), signature="y")[1])


class WheelsAreMotorsTest(VehicleTestCase):
    """The Teensy's SetSpeed is a command like SetThrust: the command timeout and the commanding
    client leaving stop the wheels."""
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 400}

    def setUp(self):
        self.rig.reset()

    def set_speed(self, left, right):
        return self.rig.vcall("SetSpeed", left, right, signature="ii", path=harness.TEENSY_PATH,
                              iface=harness.TEENSY_IFACE)

    def test_command_timeout_stops_the_wheels(self):
        self.set_speed(60, 60)
        t0 = time.monotonic()
        self.assertEqual(front_wheels(self.rig), (60.0, 60.0))
        self.assertNotEqual(self.rig.vget("Controller"), "")
        poll(lambda: front_wheels(self.rig) == (0.0, 0.0), 5, message="the wheels kept turning")
        took_ms = (time.monotonic() - t0) * 1000
        timeout_ms = self.CONTROL["command_timeout_ms"]
        print("\nwheels stopped %.0f ms after SetSpeed (command timeout %d ms)" % (took_ms, timeout_ms))
        self.assertGreaterEqual(took_ms, timeout_ms - DEADLINE_SEEN_EARLY_MS_MAX)
        self.assertLessEqual(took_ms, timeout_ms + DEADLINE_SEEN_LATE_MS_MAX)

    def test_client_leaving_stops_the_wheels(self):
        # A client process commands the wheels itself, then leaves.
        script = (
            "import sys, dbus\n"
            "bus = dbus.bus.BusConnection(sys.argv[1])\n"
            "t = bus.get_object('org.caracara.Vehicle1', '/org/caracara/Vehicle1/teensy', introspect=False)\n"
            "t.SetSpeed(dbus.Int32(40), dbus.Int32(-40), dbus_interface='org.caracara.Vehicle1.Teensy')\n"
            "print(bus.get_unique_name(), flush=True)\n"
            "sys.stdin.read()\n")
        c = subprocess.Popen([harness.PYTHON, "-c", script, self.rig.address], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        who = c.stdout.readline().strip()
        self.assertTrue(who, c.stderr.read() if c.poll() is not None else "")
        poll(lambda: front_wheels(self.rig) == (40.0, -40.0), 5)
        self.assertEqual(self.rig.vget("Controller"), who)
        c.stdin.close()
        c.wait(10)
        poll(lambda: front_wheels(self.rig) == (0.0, 0.0), 5, message="the wheels kept turning after the client left")

    def test_a_refused_speed_changes_nothing(self):
        slept_ms = 150
        time.sleep(slept_ms / 1000)
        self.assertEqual(error_name(self.set_speed, 500, 0), ERR + "OutOfRange")
        # Not taken as a command: the age of the last one kept growing.
        self.assertGreaterEqual(int(self.rig.vget("CommandAgeMs")), slept_ms)



# Sends SetThrust with alternating values (never zero) until the daemon is gone.
STICK_SCRIPT = r"""
import sys, dbus
bus = dbus.bus.BusConnection(sys.argv[1])
vehicle = bus.get_object("org.caracara.Vehicle1", "/org/caracara/Vehicle1", introspect=False)
n = 0
try:
    while True:
        v = 1500 + 100 * (n % 2)
        vehicle.SetThrust(dbus.Array([v, -v] * 4, signature="i"), dbus_interface="org.caracara.Vehicle1")
        if n == 0:
            print("driving", flush=True)
        n += 1
except dbus.DBusException:
    pass
"""


class WheelsStopAtStartAndExitTest(unittest.TestCase):

    def test_start_and_sigterm_send_stop(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)
        before = stop_frames(rig)
        rig.start_daemon()
        self.assertGreater(stop_frames(rig), before, "no Stop to the Teensy at start")
        rig.arm()
        rig.vcall("SetSpeed", 30, 30, signature="ii", path=harness.TEENSY_PATH, iface=harness.TEENSY_IFACE)
        self.assertEqual(front_wheels(rig), (30.0, 30.0))
        self.assertEqual(rig.stop_daemon(), 0)
        self.assertEqual(front_wheels(rig), (0.0, 0.0), "SIGTERM left the wheels turning")

    def test_a_crash_sends_stop(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([1500] * MOTORS)
        rig.vcall("SetSpeed", 30, -30, signature="ii", path=harness.TEENSY_PATH, iface=harness.TEENSY_IFACE)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        proc = rig.procs["caracarad"]
        proc.send_signal(signal.SIGSEGV)
        proc.wait(30)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        self.assertEqual(front_wheels(rig), (0.0, 0.0), "a crash left the wheels turning")
        rig.start_daemon()  # as systemd would; stop_checked wants a clean exit at the end

    def test_a_crash_while_the_bus_is_busy_leaves_no_order_after_the_zeros(self):
        """A fatal signal stops one thread; the bus worker's goes on. Thruster 7 answers slowly
        (15 ms, under the adapter's timeout), so the worker is always on the wire with orders
        queued behind it: none of them may land between or after the crash handler's zeros
        (the emergency stop closes the worker's gate and waits for its transfer)."""
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.sim_thruster_call(7, "SetHang", 15, signature="u")
        # A pilot's stick: new values as fast as the daemon takes them, until it is gone.
        pilot = subprocess.Popen([harness.PYTHON, "-c", STICK_SCRIPT, rig.address], stdout=subprocess.PIPE, text=True)
        self.assertEqual(pilot.stdout.readline().strip(), "driving")
        rig.wait_orders_refreshed(count=3)
        since = rig.wire_next()
        proc = rig.procs["caracarad"]
        proc.send_signal(signal.SIGSEGV)
        proc.wait(30)
        pilot.wait(30)
        rig.sim_thruster_call(7, "SetHang", 0, signature="u")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        orders = [e for e in rig.wire_log(since)[1] if e.bus == "i2c" and not e.read and len(e.data) == 3]
        for mt in DEFAULT_MT:
            mine = [e for e in orders if e.addr == mt >> 1]
            first_zero = next((e.index for e in mine if e.data[0] == ZERO), None)
            self.assertIsNotNone(first_zero, "no zero order to 0x%02x after the crash" % mt)
            late = [e.index for e in mine if e.index > first_zero and e.data[0] != ZERO]
            self.assertEqual(late, [], "orders to 0x%02x after its zero (#%d)" % (mt, first_zero))
        rig.start_daemon()


if __name__ == "__main__":
    unittest.main()
