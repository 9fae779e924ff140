"""The checked-in interface XML (dbus/*.xml) is the contract: compare it, semantically, with what
the running daemon introspects on each of its objects.

Compared: methods (argument names, types and directions, in order), properties (type, access,
the effective EmitsChangedSignal value with "true" when absent, other annotations), signals
(argument names and types, in order) and annotations. Comments and whitespace do not matter;
annotations sd-bus adds on its own under org.freedesktop.systemd1.* are ignored.
"""

import unittest

import harness
from harness import BUS_PATH, MOTORS, ROOT, TEENSY_PATH, VEHICLE, VehicleTestCase, parse_interfaces

INTROSPECTABLE = "org.freedesktop.DBus.Introspectable"
OBJECT_MANAGER = "org.freedesktop.DBus.ObjectManager"
EMITS = harness.EMITS

# Where each contract interface lives.
OBJECTS = {
    "org.caracara.Vehicle1": [ROOT],
    "org.caracara.Vehicle1.Thruster": [harness.thruster_path(i) for i in range(MOTORS)],
    "org.caracara.Vehicle1.Teensy": [TEENSY_PATH],
    "org.caracara.Vehicle1.Bus": [BUS_PATH],
}


def relevant(annotations):
    return {k: v for k, v in annotations.items() if not k.startswith("org.freedesktop.systemd1.")}


def normalise(iface):
    """A comparable form of one parsed interface."""
    props = {}
    for name, p in iface["properties"].items():
        ann = relevant(p["annotations"])
        emits = ann.pop(EMITS, "true")
        props[name] = {"type": p["type"], "access": p["access"], "emits": emits, "annotations": ann}
    return {
        "methods": {name: {"args": m["args"], "annotations": relevant(m["annotations"])}
                    for name, m in iface["methods"].items()},
        "properties": props,
        "signals": {name: {"args": [(a[0], a[1]) for a in s["args"]], "annotations": relevant(s["annotations"])}
                    for name, s in iface["signals"].items()},
        "annotations": relevant(iface["annotations"]),
    }


class IntrospectionTest(VehicleTestCase):

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.contract = harness.load_contract()

    def live(self, path):
        xml = self.rig.obj(VEHICLE, path).Introspect(dbus_interface=INTROSPECTABLE)
        return parse_interfaces(str(xml))

    def compare(self, name, expected, actual):
        exp, act = normalise(expected), normalise(actual)
        self.assertEqual(sorted(act["methods"]), sorted(exp["methods"]), "%s: method names" % name)
        for m in exp["methods"]:
            self.assertEqual(act["methods"][m], exp["methods"][m], "%s.%s()" % (name, m))
        self.assertEqual(sorted(act["properties"]), sorted(exp["properties"]), "%s: property names" % name)
        for p in exp["properties"]:
            self.assertEqual(act["properties"][p], exp["properties"][p], "%s.%s" % (name, p))
        self.assertEqual(sorted(act["signals"]), sorted(exp["signals"]), "%s: signal names" % name)
        for s in exp["signals"]:
            self.assertEqual(act["signals"][s], exp["signals"][s], "%s.%s signal" % (name, s))
        self.assertEqual(act["annotations"], exp["annotations"], "%s: interface annotations" % name)

    def test_contract_files(self):
        # The four checked-in files, one interface each, and nothing else in them.
        files = sorted(i["file"] for i in self.contract.values())
        self.assertEqual(files, sorted(n + ".xml" for n in OBJECTS))
        self.assertEqual(sorted(self.contract), sorted(OBJECTS))

    def test_live_interfaces_match_the_xml(self):
        for name, paths in OBJECTS.items():
            for path in paths:
                with self.subTest(interface=name, path=path):
                    live = self.live(path)
                    self.assertIn(name, live, "%s does not implement %s" % (path, name))
                    self.compare(name, self.contract[name], live[name])
                    # No other org.caracara interface on the object.
                    own = sorted(i for i in live if i.startswith("org.caracara."))
                    self.assertEqual(own, [name])

    def test_busctl_xml_interface(self):
        # The same, through busctl's XML output, for the root object.
        r = self.rig.busctl("--xml-interface", "introspect", VEHICLE, ROOT)
        self.assertEqual(r.returncode, 0, r.stderr)
        live = parse_interfaces(r.stdout)
        self.compare(VEHICLE, self.contract[VEHICLE], live[VEHICLE])

    def test_object_tree(self):
        root = self.live(ROOT)
        self.assertIn(OBJECT_MANAGER, root, "ObjectManager on the root")
        managed = self.rig.obj(VEHICLE, ROOT).GetManagedObjects(dbus_interface=OBJECT_MANAGER)
        children = {str(p): sorted(str(i) for i in ifaces if str(i).startswith("org.caracara.")) for p, ifaces in
                    managed.items()}
        for name, paths in OBJECTS.items():
            if name == VEHICLE:
                continue
            for path in paths:
                self.assertEqual(children.get(path), [name], path)

    def test_the_comparison_can_fail(self):
        # Guard against a comparison that accepts anything: a mutated contract must differ.
        name = "org.caracara.Vehicle1"
        live = self.live(ROOT)[name]
        import copy
        mutated = copy.deepcopy(self.contract[name])
        mutated["methods"]["SetThrust"]["args"][0] = ("values", "au", "in")
        with self.assertRaises(AssertionError):
            self.compare(name, mutated, live)
        mutated = copy.deepcopy(self.contract[name])
        mutated["properties"]["BudgetPolicy"]["annotations"] = {}
        with self.assertRaises(AssertionError):
            self.compare(name, mutated, live)


if __name__ == "__main__":
    unittest.main()
