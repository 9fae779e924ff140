// The cockpit's gamepad mapping (tools/cockpit/gamepad.js) alone, under node: the dead zone and
// expo curve, the terms, the deadman, the clamp, and the mapping kept in (a stand-in for) the
// browser's storage. Run by test_cockpit.py; the browser test drives the same code to the wire.
import { test } from "node:test";
import assert from "node:assert/strict";
import { DEFAULT_MAPPING, loadMapping, parseTerms, sample, saveMapping, shape, stepGain } from "../../tools/cockpit/gamepad.js";

const near = (a, b) => assert.ok(Math.abs(a - b) < 1e-9, `${a} != ${b}`);
function pad({ axes = [0, 0, 0, 0], pressed = [], values = {} } = {}) {
  const buttons = Array.from({ length: 17 }, (_, i) => ({ pressed: pressed.includes(i), value: values[i] ?? (pressed.includes(i) ? 1 : 0) }));
  return { axes, buttons };
}
class Storage {
  constructor() { this.items = new Map(); }
  getItem(k) { return this.items.has(k) ? this.items.get(k) : null; }
  setItem(k, v) { this.items.set(k, String(v)); }
}

test("dead zone then expo: zero inside, continuous at its edge, full at full, odd", () => {
  assert.equal(shape(0.1, 0.1, 0.3), 0);
  assert.equal(shape(-0.05, 0.1, 0.3), 0);
  near(shape(1, 0.1, 0.3), 1);
  near(shape(-1, 0.1, 0.3), -1);
  near(shape(0.55, 0.1, 0), 0.5);            // linear without expo
  near(shape(0.55, 0.1, 1), 0.125);          // cubic with full expo
  near(shape(-0.6, 0.1, 0.3), -(0.7 * (5 / 9) + 0.3 * (5 / 9) ** 3));
  assert.ok(shape(0.1001, 0.1, 0.3) < 0.001);
});

test("terms: axes and buttons with signs; anything else is refused", () => {
  assert.deepEqual(parseTerms("b6-b7"), [{ sign: 1, kind: "b", index: 6 }, { sign: -1, kind: "b", index: 7 }]);
  assert.deepEqual(parseTerms(" -a1 "), [{ sign: -1, kind: "a", index: 1 }]);
  assert.deepEqual(parseTerms("0"), []);
  for (const bad of ["q9", "a", "a1*2", "a1b2", "--a1", "a123"]) assert.throws(() => parseTerms(bad), /not a mapping/, bad);
});

test("nothing without the deadman; with it, the default mapping's six axes", () => {
  const m = { ...DEFAULT_MAPPING, gain: 1, expo: 0, deadzone: 0 };
  const stickOnly = sample(pad({ axes: [0.5, -1, 0.25, 1], values: { 7: 1 } }), m);
  assert.equal(stickOnly.held, false);
  assert.ok(Object.values(stickOnly.motion).every((v) => v === 0));
  const s = sample(pad({ axes: [0.5, -1, 0.25, 1], pressed: [4, 15], values: { 6: 0.5 } }), m);
  assert.equal(s.held, true);
  assert.deepEqual(s.motion, { x: 1, y: 0.5, z: 0.5, yaw: 0.25, pitch: -1, roll: 1 });
});

test("the gain scales and the sum is clamped to -1..1", () => {
  const m = { ...DEFAULT_MAPPING, x: "-a1-a3", gain: 0.5, expo: 0, deadzone: 0 };
  near(sample(pad({ axes: [0, -0.5, 0, 0], pressed: [4] }), m).motion.x, 0.25);
  assert.equal(sample(pad({ axes: [0, -1, 0, -1], pressed: [4] }), { ...m, gain: 1 }).motion.x, 1);
});

test("the mapping is kept in storage; a bad stored one gives the defaults", () => {
  const st = new Storage();
  assert.deepEqual(loadMapping(st), DEFAULT_MAPPING);
  saveMapping({ ...DEFAULT_MAPPING, x: "a1", gain: 0.25 }, st);
  assert.equal(loadMapping(st).x, "a1");
  assert.equal(loadMapping(st).gain, 0.25);
  assert.throws(() => saveMapping({ ...DEFAULT_MAPPING, deadzone: 2 }, st), /deadzone/);
  assert.equal(loadMapping(st).deadzone, DEFAULT_MAPPING.deadzone, "a refused mapping is not stored");
  st.setItem("caracara.cockpit.mapping", "{not json");
  assert.deepEqual(loadMapping(st), DEFAULT_MAPPING);
  st.setItem("caracara.cockpit.mapping", JSON.stringify({ roll: "zz" }));
  assert.deepEqual(loadMapping(st), DEFAULT_MAPPING);
});

test("the gain buttons step through the gains and stop at the ends", () => {
  assert.equal(stepGain(0.5, 1), 0.75);
  assert.equal(stepGain(1, 1), 1);
  assert.equal(stepGain(0.25, -1), 0.25);
  assert.equal(stepGain(0.6, -1), 0.5); // a gain between steps goes to its neighbours
  assert.equal(stepGain(0.6, 1), 0.75);
});

test("centred: every term of every axis inside the dead zone, with or without the deadman", () => {
  const m = { ...DEFAULT_MAPPING };
  assert.equal(sample(pad({ axes: [0.05, -0.09, 0, 0.1] }), m).centred, true);
  assert.equal(sample(pad({ axes: [0.05, -0.09, 0, 0.1], pressed: [4] }), m).centred, true);
  assert.equal(sample(pad({ axes: [0, -0.6, 0, 0] }), m).centred, false, "a stick forward, deadman released");
  assert.equal(sample(pad({ axes: [0, -0.6, 0, 0], pressed: [4] }), m).centred, false);
  assert.equal(sample(pad({ values: { 7: 0.5 } }), m).centred, false, "a trigger pulled (heave)");
  assert.equal(sample(pad({ pressed: [15] }), m).centred, false, "the d-pad (roll)");
  assert.equal(sample(pad({ pressed: [1, 9, 12] }), m).centred, true, "kill, clear-kill and gain buttons are no motion");
});

test("the kill and clear-kill buttons are in the mapping, each a button of its own", () => {
  const st = new Storage();
  assert.equal(loadMapping(st).kill, 1);
  assert.equal(loadMapping(st).clear_kill, 9);
  assert.throws(() => saveMapping({ ...DEFAULT_MAPPING, clear_kill: 4 }, st), /a button each/);
  assert.throws(() => saveMapping({ ...DEFAULT_MAPPING, kill: 40 }, st), /kill must be/);
});
