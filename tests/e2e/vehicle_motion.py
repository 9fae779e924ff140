"""Where the simulated vehicle went: the referee of every interface's axes (docs/frames.md).

A test names the motion it means in words ("forward", "up", "clockwise", ...), commands it through
an interface, and judges what the simulator's rigid body did over the command, read in the
vehicle's own body frame at the start (sim/vehicle_body.hpp: world x port and y forward at yaw
0, depth down; yaw clockwise from above, pitch nose up, roll right side down). The words are the
seed's ("caracara-usb-packet", axis table), never another interface of ours.

    start = pose(rig)
    ... command "forward" through the interface under test for a second or two ...
    assert_moved(self, start, pose(rig), "forward")
"""
import math

from bounds import MOTION_ALONG_AXIS_SHARE_MIN, MOTION_ROTATION_MIN_RAD, MOTION_TRANSLATION_MIN_M
from harness import angle_diff, poll

# Each motion: which of the body's measured components it is (translations: port, forward,
# deeper in metres; rotations: clockwise, nose up, roll right in radians) and its sign.
MOTIONS = {
    "port": ("translation", 0, +1), "starboard": ("translation", 0, -1),
    "forward": ("translation", 1, +1), "backward": ("translation", 1, -1),
    "deeper": ("translation", 2, +1), "up": ("translation", 2, -1),
    "clockwise": ("rotation", 0, +1), "counter-clockwise": ("rotation", 0, -1),
    "nose up": ("rotation", 1, +1), "nose down": ("rotation", 1, -1),
    "roll right": ("rotation", 2, +1), "roll left": ("rotation", 2, -1),
}
# Below the surface (the body cannot rise above depth 0), level, facing an odd heading so that a
# mix-up of the world's and the body's axes shows.
START_DEPTH_M = 5.0
START_HEADING_RAD = 0.6


def settle(rig, timeout=10.0):
    """Every simulated thruster really stopped (ActualSpeed at zero), so the next motion starts
    from rest."""
    poll(lambda: all(int(v) in (0x7F, 0x80) for v in rig.sim_thrusters("ActualSpeed")), timeout,
         message="the simulated thrusters never came to rest")


def place(rig, depth=START_DEPTH_M, heading=START_HEADING_RAD):
    """The simulated vehicle put at rest below the surface (org.caracara.Simulator1.Teensy.Place)."""
    rig.sim_teensy_call("Place", 0.0, 0.0, float(depth), float(heading), 0.0, 0.0, signature="dddddd")


def pose(rig):
    """((x, y, depth), (yaw, pitch, roll)) of the simulated body, in the simulator's world."""
    return tuple(float(v) for v in rig.sim_teensy("Position")), tuple(float(v) for v in rig.sim_teensy("Orientation"))


def body_motion(start, end):
    """What the vehicle did from `start` to `end` in its body frame at the start:
    {"translation": (port, forward, deeper), "rotation": (clockwise, nose up, roll right)}."""
    (p0, a0), (p1, a1) = start, end
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    c, s = math.cos(a0[0]), math.sin(a0[0])
    port = dx * c + dy * s           # the body's port axis is (cos, sin) at yaw a0
    forward = -dx * s + dy * c       # its forward axis (-sin, cos)
    return {"translation": (port, forward, p1[2] - p0[2]),
            "rotation": tuple(angle_diff(a1[i], a0[i]) for i in range(3))}


def describe(m):
    t, r = m["translation"], m["rotation"]
    return ("moved %+.3f m to port, %+.3f m forward, %+.3f m deeper; turned %+.3f rad clockwise, "
            "%+.3f rad nose up, %+.3f rad roll right" % (t + r))


def assert_moved(tc, start, end, motion, what=""):
    """The vehicle went the way `motion` means: that component has the right sign, is at least
    the minimum, and is at least MOTION_ALONG_AXIS_SHARE_MIN of the whole translation (or
    rotation)."""
    kind, index, sign = MOTIONS[motion]
    m = body_motion(start, end)
    v = m[kind]
    along = sign * v[index]
    norm = math.sqrt(sum(x * x for x in v))
    least = MOTION_TRANSLATION_MIN_M if kind == "translation" else MOTION_ROTATION_MIN_RAD
    msg = "%s%s: wanted %s; the simulated vehicle %s" % (what, " " if what else "", motion, describe(m))
    tc.assertGreaterEqual(along, least, msg)
    tc.assertGreaterEqual(along, MOTION_ALONG_AXIS_SHARE_MIN * norm, msg)
    return m


def judge(tc, rig, motion, hold, what="", seconds=1.5):
    """Settles and places the vehicle, runs `hold(seconds)` (the interface under test commands
    `motion` for that long, then stops), and judges where the vehicle went."""
    settle(rig)
    place(rig)
    start = pose(rig)
    hold(seconds)
    return assert_moved(tc, start, pose(rig), motion, what)
