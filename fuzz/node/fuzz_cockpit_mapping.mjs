// The cockpit's gamepad mapping as a page reads it back from the browser's storage
// (tools/cockpit/gamepad.js loadMapping, then sample on every gamepad frame), fed generated
// input: any text, any JSON, and mappings with every key bent (terms, numbers out of range,
// NaN, wrong types, the pre-2.0 axis names). Invariants: loading never throws; what it gives is
// a mapping validMapping takes; a refused or unreadable one gives the defaults with a notice and
// leaves the stored text alone, except that one with the old axes is replaced by the defaults;
// an accepted one is the defaults overlaid with what was stored, saves and loads back the same;
// every motion a pad gives through it is a finite number in -1..1, and all zero without the
// deadman held.
//
// Run like a libFuzzer harness (fuzz/run.sh, scripts/fuzz.sh): -max_total_time=S or -runs=N,
// -seed=N, -artifact_prefix=DIR/; other -flags are taken and ignored; each file of the directories
// named is a stored text, checked first (the seeds in fuzz/corpus/cockpit_mapping, regression
// inputs in fuzz/regressions/cockpit_mapping). Prints libFuzzer's stat lines. fast-check (npm,
// fuzz/node/package-lock.json) generates the inputs.
import fc from "fast-check";
import fs from "node:fs";
import path from "node:path";
import { AXES, DEFAULT_MAPPING, KEY, OLD_AXES, loadMapping, sample, saveMapping, validMapping } from "../../tools/cockpit/gamepad.js";

const opts = { max_total_time: 0, runs: 0, seed: Date.now() % 2 ** 31, artifact_prefix: "./" };
const dirs = [];
for (const arg of process.argv.slice(2)) {
  const m = /^-([a-z_]+)=(.*)$/.exec(arg);
  if (m && m[1] in opts) opts[m[1]] = m[1] === "artifact_prefix" ? m[2] : Number(m[2]);
  else if (!arg.startsWith("-")) dirs.push(arg);
}

class Storage {
  constructor(text) { this.items = new Map(text === null ? [] : [[KEY, text]]); }
  getItem(k) { return this.items.has(k) ? this.items.get(k) : null; }
  setItem(k, v) { this.items.set(k, String(v)); }
}

function fail(what, input) {
  const file = `${opts.artifact_prefix}crash-${Date.now()}`;
  fs.writeFileSync(file, input ?? "");
  throw new Error(`invariant failed: ${what} (input written to ${file})`);
}

function parsedObject(text) {
  try {
    const v = JSON.parse(text ?? "{}");
    return v && typeof v === "object" ? v : null;
  } catch {
    return null;
  }
}

let executions = 0;
function check(text, pads) {
  executions++;
  const storage = new Storage(text);
  let got;
  try {
    got = loadMapping(storage);
  } catch (err) {
    fail(`loadMapping threw ${err}`, text);
  }
  const { mapping, notice } = got;
  try {
    validMapping(mapping);
  } catch (err) {
    fail(`loadMapping gave a mapping validMapping refuses: ${err.message}`, text);
  }
  const stored = parsedObject(text);
  const old = stored !== null && OLD_AXES.some((a) => a in stored);
  if (notice !== null) {
    if (JSON.stringify(mapping) !== JSON.stringify(DEFAULT_MAPPING)) fail("a notice without the defaults", text);
    const now = storage.getItem(KEY);
    if (old ? now !== JSON.stringify(DEFAULT_MAPPING) : now !== text) fail("the stored text changed", text);
  } else {
    if (old) fail("a mapping with the old axes taken", text);
    if (JSON.stringify(mapping) !== JSON.stringify({ ...DEFAULT_MAPPING, ...(stored ?? {}) })) fail("not what was stored", text);
    const again = new Storage(null);
    saveMapping(mapping, again);
    const back = loadMapping(again);
    if (back.notice !== null || JSON.stringify(back.mapping) !== JSON.stringify(mapping)) fail("saved, not loaded back the same", text);
  }
  for (const pad of pads) {
    const s = sample(pad, mapping);
    for (const a of AXES) {
      const v = s.motion[a];
      if (typeof v !== "number" || !Number.isFinite(v) || v < -1 || v > 1) fail(`motion ${a} = ${v}`, text);
      if (!s.held && v !== 0) fail(`motion ${a} = ${v} without the deadman`, text);
    }
  }
}

// Inputs: the stored text (any text, any JSON, or a mapping with its keys bent) and gamepads.
const termText = fc.array(fc.constantFrom("a", "b", "-", "+", " ", "0", "1", "2", "3", "7", "9", "15", "31", "99"),
  { maxLength: 8 }).map((p) => p.join(""));
const value = fc.oneof(termText, fc.integer({ min: -3, max: 40 }), fc.double(), fc.constantFrom(NaN, Infinity, null, true, "", "0"),
  fc.string(), fc.anything());
const keys = [...AXES, ...OLD_AXES, "deadman", "gain_up", "gain_down", "kill", "clear_kill", "deadzone", "expo", "gain"];
const bent = fc.dictionary(fc.constantFrom(...keys), value, { maxKeys: 12 }).map((o) => JSON.stringify(o));
const overDefaults = fc.dictionary(fc.constantFrom(...keys), value, { maxKeys: 3 })
  .map((o) => JSON.stringify({ ...DEFAULT_MAPPING, ...o }));
const storedText = fc.oneof(fc.constant(null), fc.string(), fc.json(), bent, overDefaults);
const level = fc.oneof(fc.double({ min: -1, max: 1, noNaN: true }), fc.constantFrom(-1, 0, 1, NaN, 2, -Infinity));
const pad = fc.record({
  axes: fc.array(level, { maxLength: 6 }),
  buttons: fc.array(fc.record({ pressed: fc.boolean(), value: level }), { maxLength: 20 }),
});

const start = Date.now();
// The seeds and regression inputs first, each with the pads of a held deadman and none.
const still = { axes: [0, 0, 0, 0], buttons: [] };
const full = { axes: [1, -1, 1, -1], buttons: Array.from({ length: 17 }, () => ({ pressed: true, value: 1 })) };
let seeds = 0;
try {
  for (const dir of dirs) {
    if (!fs.existsSync(dir)) continue;
    for (const name of fs.readdirSync(dir)) {
      check(fs.readFileSync(path.join(dir, name), "utf8"), [still, full]);
      seeds++;
    }
  }
} catch (err) {
  console.error(`==ERROR: ${err.message}`);
  process.exit(1);
}
console.error(`#${executions}\tINITED exec/s: 0 seeds: ${seeds}`);

const runs = opts.runs > 0 ? Math.max(0, opts.runs - executions) : Number.MAX_SAFE_INTEGER;
const params = { seed: opts.seed, numRuns: runs, endOnFailure: true };
if (opts.max_total_time > 0) Object.assign(params, { interruptAfterTimeLimit: opts.max_total_time * 1000, markInterruptAsFailure: false });
else if (opts.runs <= 0) Object.assign(params, { numRuns: 100000 });
let status = 0;
try {
  fc.assert(fc.property(storedText, fc.array(pad, { maxLength: 3 }), (text, pads) => { check(text, pads); }), params);
} catch (err) {
  console.error(`==ERROR: ${err.cause?.message ?? ""}\n${err.message.split("\n").slice(0, 6).join("\n")}`);
  status = 1;
}
const secs = Math.max(1, Math.round((Date.now() - start) / 1000));
console.error(`#${executions}\tDONE exec/s: ${Math.round(executions / secs)} seed: ${opts.seed}`);
console.error(`stat::number_of_executed_units: ${executions}`);
console.error(`stat::average_exec_per_sec: ${Math.round(executions / secs)}`);
process.exit(status);
