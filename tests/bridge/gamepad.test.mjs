// The cockpit's gamepad mapping (tools/cockpit/gamepad.js) alone, under node: the dead zone and
// expo curve, the terms, the deadman, the clamp, and the mapping kept in (a stand-in for) the
// browser's storage; and the banner's lines of the pilot's seat (tools/cockpit/words.js). Run by
// test_cockpit.py; the browser test drives the same code to the wire.
import { test } from "node:test";
import assert from "node:assert/strict";
import { DEFAULT_MAPPING, KEY, loadMapping, parseTerms, sample, saveMapping, shape, stepGain } from "../../tools/cockpit/gamepad.js";
import { banner } from "../../tools/cockpit/words.js";

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

test("nothing without the deadman; with it, the default mapping's six motions in a pilot's words", () => {
  const m = { ...DEFAULT_MAPPING, gain: 1, expo: 0, deadzone: 0 };
  const stickOnly = sample(pad({ axes: [0.5, -1, 0.25, 1], values: { 7: 1 } }), m);
  assert.equal(stickOnly.held, false);
  assert.ok(Object.values(stickOnly.motion).every((v) => v === 0));
  const s = sample(pad({ axes: [0.5, -1, 0.25, 1], pressed: [4, 15], values: { 6: 0.5 } }), m);
  assert.equal(s.held, true);
  // Left stick right 0.5 and forward (-1), left trigger half, right stick right 0.25 and back (1), d-pad right.
  assert.deepEqual(s.motion, { forward: 1, starboard: 0.5, up: 0.5, turn_right: 0.25, nose_up: -1, roll_right: 1 });
  // The opposite way: stick back and left, right trigger, right stick left and forward, d-pad left.
  const o = sample(pad({ axes: [-1, 1, -1, -1], pressed: [4, 14], values: { 7: 1 } }), m);
  assert.deepEqual(o.motion, { forward: -1, starboard: -1, up: -1, turn_right: -1, nose_up: 1, roll_right: -1 });
});

test("the gain scales and the sum is clamped to -1..1", () => {
  const m = { ...DEFAULT_MAPPING, forward: "-a1-a3", gain: 0.5, expo: 0, deadzone: 0 };
  near(sample(pad({ axes: [0, -0.5, 0, 0], pressed: [4] }), m).motion.forward, 0.25);
  assert.equal(sample(pad({ axes: [0, -1, 0, -1], pressed: [4] }), { ...m, gain: 1 }).motion.forward, 1);
});

test("the mapping is kept in storage; a bad stored one gives the defaults, and says so", () => {
  const st = new Storage();
  assert.deepEqual(loadMapping(st), { mapping: DEFAULT_MAPPING, notice: null });
  saveMapping({ ...DEFAULT_MAPPING, forward: "a1", gain: 0.25 }, st);
  assert.equal(loadMapping(st).mapping.forward, "a1");
  assert.equal(loadMapping(st).mapping.gain, 0.25);
  assert.equal(loadMapping(st).notice, null);
  assert.throws(() => saveMapping({ ...DEFAULT_MAPPING, deadzone: 2 }, st), /deadzone/);
  assert.equal(loadMapping(st).mapping.deadzone, DEFAULT_MAPPING.deadzone, "a refused mapping is not stored");
  st.setItem(KEY, "{not json");
  assert.deepEqual(loadMapping(st).mapping, DEFAULT_MAPPING);
  assert.match(loadMapping(st).notice, /could not be read/);
  st.setItem(KEY, JSON.stringify({ roll_right: "zz" }));
  assert.deepEqual(loadMapping(st).mapping, DEFAULT_MAPPING);
  assert.match(loadMapping(st).notice, /refused \(not a mapping: 'zz'/);
});

test("a mapping saved with the old axis names (the seed's: x was port) is reset to the defaults, once, with a notice", () => {
  const st = new Storage();
  const oldDefaults = { x: "-a1", y: "a0", z: "b6-b7", yaw: "a2", pitch: "-a3", roll: "b15-b14", deadman: 4, gain_up: 12,
    gain_down: 13, kill: 1, clear_kill: 9, deadzone: 0.1, expo: 0.3, gain: 0.5 };
  for (const old of [oldDefaults, { ...oldDefaults, x: "a0", y: "-a1", gain: 0.25 }, { pitch: "a3" }]) {
    st.setItem(KEY, JSON.stringify(old));
    const { mapping, notice } = loadMapping(st);
    assert.deepEqual(mapping, DEFAULT_MAPPING, "none of it taken, not even its gain");
    assert.match(notice, /named the old axes \(x, y, z, yaw, pitch, roll\).*reset to the defaults/);
    assert.deepEqual(JSON.parse(st.getItem(KEY)), DEFAULT_MAPPING, "the defaults stored");
    assert.deepEqual(loadMapping(st), { mapping: DEFAULT_MAPPING, notice: null }, "said once");
  }
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
  assert.equal(sample(pad({ values: { 7: 0.5 } }), m).centred, false, "a trigger pulled (down)");
  assert.equal(sample(pad({ pressed: [15] }), m).centred, false, "the d-pad (roll right)");
  assert.equal(sample(pad({ pressed: [1, 9, 12] }), m).centred, true, "kill, clear-kill and gain buttons are no motion");
});

test("the kill and clear-kill buttons are in the mapping, each a button of its own", () => {
  const st = new Storage();
  assert.equal(loadMapping(st).mapping.kill, 1);
  assert.equal(loadMapping(st).mapping.clear_kill, 9);
  assert.throws(() => saveMapping({ ...DEFAULT_MAPPING, clear_kill: 4 }, st), /a button each/);
  assert.throws(() => saveMapping({ ...DEFAULT_MAPPING, kill: 40 }, st), /kill must be/);
});

test("the banner and the pilot's seat: who holds it when another does, a take-over from this page in red, names escaped", () => {
  const ready = { state: "ready", failsafes: [], surfacing_ms: -1, pilot_lost_left_ms: -1, motor_test: { thruster: -1 } };
  const base = { state: ready, up: true, lostMs: 0, killNotSentMs: null, refusal: null };
  assert.deepEqual(banner({ ...base, seat: { holder: "", yours: false } }), [], "a free seat: nothing to say");
  assert.deepEqual(banner({ ...base, seat: { holder: "client #1 (cockpit)", yours: true } }), [], "this page's: nothing");
  const held = banner({ ...base, seat: { holder: "client #2 (<b>x</b>)", yours: false } });
  assert.equal(held.length, 1);
  assert.equal(held[0].kind, "seat");
  assert.equal(held[0].level, "warn");
  assert.match(held[0].text, /^SEAT: client #2 \(&lt;b&gt;x&lt;\/b&gt;\) holds the pilot's seat; this page does not drive/);
  const at = new Date(2026, 11, 5, 14, 2, 11).getTime();
  const lost = banner({ ...base, seat: { holder: "client #3", yours: false }, seatLost: { by: "client #3", at } });
  assert.deepEqual(lost.map((l) => [l.kind, l.level]), [["seat-lost", "alarm"]], "the take-over said once, in red");
  assert.equal(lost[0].text, "SEAT TAKEN OVER by client #3 at 14:02:11: this page no longer drives (its thrust was zeroed)");
  // A refusal for want of the seat is the seat's line, not a "Motion refused" beside it.
  assert.deepEqual(banner({ ...base, refusal: "SeatTaken", seat: { holder: "client #3", yours: false } }).map((l) => l.kind), ["seat"]);
  assert.deepEqual(banner({ ...base, refusal: "Surfacing" }).map((l) => l.kind), ["refused"]);
});
