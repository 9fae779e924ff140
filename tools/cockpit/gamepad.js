// Gamepad piloting (docs/cockpit.md): the Gamepad API's standard mapping to the six motions, named
// in a pilot's words (core/frames.hpp's PilotAxis; the bridge's /command/drive converts them).
// Each motion is a sum of terms ("-a1", "b6-b7": aN a stick axis, bN a button's value),
// each stick term through a dead zone and an expo curve, then times the gain. Nothing moves
// unless the deadman button is held. Kill on a button's press; Clear kill on another held for
// CLEAR_HOLD_MS, never on a tap.
export const AXES = ["forward", "starboard", "up", "turn_right", "nose_up", "roll_right"];
// The mapping's axes before issue 43, the seed's (x was port, +z deeper): a mapping saved with
// them would drive the wrong way, so it is not taken, and the page says so.
export const OLD_AXES = ["x", "y", "z", "yaw", "pitch", "roll"];
export const GAINS = [0.25, 0.5, 0.75, 1.0];
export const CLEAR_HOLD_MS = 2000;
export const KEY = "caracara.cockpit.mapping";

export const DEFAULT_MAPPING = {
  forward: "-a1",          // left stick forward: forward (back: backward)
  starboard: "a0",         // left stick right: starboard (left: port)
  up: "b6-b7",             // left trigger: up; right trigger: down
  turn_right: "a2",        // right stick right: turn right, clockwise from above
  nose_up: "-a3",          // right stick forward: nose up (back: nose down)
  roll_right: "b15-b14",   // d-pad right: roll right, right side down (left: roll left)
  deadman: 4,    // left bumper, held
  gain_up: 12,   // d-pad up: the next gain
  gain_down: 13, // d-pad down: the one before
  kill: 1,       // B (right face button): kills on its press
  clear_kill: 9, // Start, held for CLEAR_HOLD_MS: clears the kill
  deadzone: 0.1,
  expo: 0.3,
  gain: 0.5,
};

// "b6-b7" -> [{sign:1,kind:"b",index:6},{sign:-1,kind:"b",index:7}]; throws on anything else.
export function parseTerms(text) {
  const s = String(text).replace(/\s+/g, "");
  if (s === "" || s === "0") return [];
  const terms = [];
  const re = /([+-]?)([ab])(\d{1,2})/gy;
  let at = 0;
  for (let m; at < s.length && (m = re.exec(s)); at = re.lastIndex) {
    if (terms.length && !m[1]) break; // terms after the first need their sign: "a1b2" is no mapping
    terms.push({ sign: m[1] === "-" ? -1 : 1, kind: m[2], index: Number(m[3]) });
  }
  if (at !== s.length || !terms.length) throw new Error(`not a mapping: '${text}' (terms like -a1 or b6-b7)`);
  return terms;
}

export function validMapping(m) {
  for (const a of AXES) parseTerms(m[a]);
  for (const [k, lo, hi] of [["deadman", 0, 31], ["gain_up", 0, 31], ["gain_down", 0, 31], ["kill", 0, 31],
    ["clear_kill", 0, 31], ["deadzone", 0, 0.9],
    ["expo", 0, 1], ["gain", 0, 1]]) {
    const v = Number(m[k]);
    if (!Number.isFinite(v) || v < lo || v > hi) throw new Error(`${k} must be ${lo}..${hi}`);
  }
  const buttons = ["deadman", "gain_up", "gain_down", "kill", "clear_kill"].map((k) => Number(m[k]));
  if (new Set(buttons).size !== buttons.length) throw new Error("deadman, gain_up, gain_down, kill and clear_kill need a button each");
  return true;
}

// {mapping, notice}: the stored mapping, or the defaults; notice (null when none) says why a
// stored one was not taken. One with the old axis names is reset to the defaults, stored, so the
// notice is said once.
export function loadMapping(storage = localStorage) {
  let stored;
  try {
    stored = JSON.parse(storage.getItem(KEY) ?? "{}");
  } catch {
    stored = undefined;
  }
  // Only an object is a mapping: a string or an array would spread its indices into it.
  if (stored === null || typeof stored !== "object" || Array.isArray(stored)) {
    return { mapping: { ...DEFAULT_MAPPING }, notice: "The saved gamepad mapping could not be read: the defaults are in use." };
  }
  if (OLD_AXES.some((a) => a in stored)) {
    storage.setItem(KEY, JSON.stringify(DEFAULT_MAPPING));
    return { mapping: { ...DEFAULT_MAPPING }, notice: "The gamepad mapping saved in this browser named the old axes " +
      "(x, y, z, yaw, pitch, roll), which drove the wrong way: it was reset to the defaults (left stick forward: " +
      "forward, right: starboard, left trigger: up). Check the mapping before driving." };
  }
  try {
    const m = { ...DEFAULT_MAPPING, ...stored };
    validMapping(m);
    return { mapping: m, notice: null };
  } catch (err) {
    return { mapping: { ...DEFAULT_MAPPING }, notice: `The saved gamepad mapping was refused (${err.message}): the defaults are in use.` };
  }
}

export function saveMapping(m, storage = localStorage) {
  validMapping(m);
  storage.setItem(KEY, JSON.stringify(m));
}

// The gain after a press of gain_up (+1) or gain_down (-1), within GAINS.
export function stepGain(gain, step) {
  const next = step > 0 ? GAINS.find((g) => g > gain) : GAINS.findLast((g) => g < gain);
  return next ?? (step > 0 ? GAINS[GAINS.length - 1] : GAINS[0]);
}

// Dead zone then expo on one stick value in -1..1.
export function shape(v, deadzone, expo) {
  const a = Math.min(1, Math.abs(v));
  if (a <= deadzone) return 0;
  const t = (a - deadzone) / (1 - deadzone);
  return Math.sign(v) * ((1 - expo) * t + expo * t * t * t);
}

// A gamepad's state -> {held, centred, motion: {forward..roll_right}}; motion is all zero unless the
// deadman is held; centred: every term of every axis inside the dead zone, deadman or not.
export function sample(pad, mapping) {
  const button = (i) => pad.buttons[i]?.value ?? (pad.buttons[i]?.pressed ? 1 : 0);
  const held = Boolean(pad.buttons[mapping.deadman]?.pressed);
  const motion = {};
  let centred = true;
  for (const axis of AXES) {
    let v = 0;
    for (const t of parseTerms(mapping[axis])) {
      const raw = t.kind === "a" ? (pad.axes[t.index] ?? 0) : button(t.index);
      const shaped = shape(raw, mapping.deadzone, mapping.expo);
      if (shaped !== 0) centred = false;
      if (held) v += t.sign * shaped;
    }
    motion[axis] = Math.max(-1, Math.min(1, v * mapping.gain)) || 0;
  }
  return { held, centred, motion };
}
