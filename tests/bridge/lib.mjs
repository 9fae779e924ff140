// Helpers of the bridge tests: the reference client (@foxglove/ws-protocol over ws), JSON Schema
// validation (ajv, draft 2020-12), and the private bus through busctl (the simulator's
// inspection API and wire log, caracarad's properties).
import { execFileSync, spawn } from "node:child_process";
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS

import Ajv2020 from "ajv/dist/2020.js";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

export const URL = process.env.CARACARA_WS_URL;
export const BUS = process.env.CARACARA_BUS_ADDRESS;
export const BUILD = process.env.CARACARA_BUILD_DIR;
export const MOTORS = 8;
export const MOTOR_MAX = 8850;
export const ZERO = 0x80;
export const DEFAULT_MT = [0x52, 0x56, 0x58, 0x5a, 0x5c, 0x5e, 0x60, 0x62];
export const VEHICLE = "org.caracara.Vehicle1";
export const ROOT = "/org/caracara/Vehicle1";
export const SIM = "org.caracara.Simulator1";
export const SIM_ROOT = "/org/caracara/Simulator1";
export const ERR = "org.caracara.Vehicle1.Error.";
// The packet seed's x (port) and y (forward) axes (motor: sign), as tests/e2e/harness.py has them.
export const X_AXIS = { 2: +1, 6: +1, 0: -1, 4: -1 };
export const Y_AXIS = { 0: +1, 2: +1, 4: +1, 6: +1 };

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Motor value -> SEABOTIX SPEED byte (tests/e2e/harness.py speed_byte).
export function speedByte(value) {
  const steps = Math.floor((Math.abs(Math.trunc(value)) * 102 + 4425) / 8850);
  if (steps === 0) return ZERO;
  return value > 0 ? 0x80 + steps : 0x7f - steps;
}

export function busctl(...args) {
  const out = execFileSync("busctl", [`--address=${BUS}`, "--json=short", ...args.map(String)], { encoding: "utf8" });
  return out.trim() ? JSON.parse(out) : null;
}
export const vget = (name) => busctl("get-property", VEHICLE, ROOT, VEHICLE, name).data;
export const simThruster = (i, name) =>
  busctl("get-property", SIM, `${SIM_ROOT}/thruster/${i}`, "org.caracara.Simulator1.Thruster", name).data;
export const simSpeeds = () => [...Array(MOTORS).keys()].map((i) => simThruster(i, "OrderedSpeed"));
export const wireNext = () => busctl("call", SIM, SIM_ROOT, SIM, "GetWireLog", "t", "9223372036854775808").data[0];
// [{index, time_ns, bus, addr, read, data}] since a wire log index.
export function wireLog(since) {
  const [, entries] = busctl("call", SIM, SIM_ROOT, SIM, "GetWireLog", "t", since).data;
  return entries.map((e) => ({ index: e[0], time_ns: BigInt(e[1]), bus: e[3], addr: e[4], read: e[5], data: e[6] }));
}

// The times of the first zero order to each of `addrs` (7-bit I2C addresses) since a wire log
// index, once every one has had one; else null.
export function firstZeros(since, addrs) {
  const first = new Map();
  for (const e of wireLog(since))
    if (e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] === ZERO && addrs.has(e.addr) && !first.has(e.addr))
      first.set(e.addr, e.time_ns);
  return first.size === addrs.size ? [...first.values()] : null;
}

// The simulator's kill output line (tests/e2e/vehicle_checks.py KILL_OUT): its asserted edges.
export const KILL_OUT = 27;
export const killEdges = (since) =>
  wireLog(since).filter((e) => e.bus === "gpio" && e.addr === KILL_OUT && e.data.length === 1 && e.data[0] === 1);
// [failsafe.pilot-lost] persistence_ms of the rig (test_bridge.py's BridgeRig).
export const PILOT_LOST_MS = Number(process.env.CARACARA_PILOT_LOST_MS);
// [failsafe.surface] duration_ms of the rig (test_bridge.py's BridgeRig).
export const SURFACE_MS = Number(process.env.CARACARA_SURFACE_MS);

// Kill and ClearKill through busctl (no pilot), then ready: a test that drives starts with no
// pilot-lost pending from an earlier test's pilot that left.
export async function rearm() {
  if (vget("State") !== "killed") busctl("call", VEHICLE, ROOT, VEHICLE, "Kill");
  busctl("call", VEHICLE, ROOT, VEHICLE, "ClearKill");
  await poll(() => vget("State") === "ready", 20000, "ready again");
}

export async function poll(fn, timeoutMs = 10000, message = "condition") {
  const end = Date.now() + timeoutMs;
  let last;
  while (Date.now() < end) {
    last = await fn();
    if (last) return last;
    await sleep(20);
  }
  throw new Error(`timed out waiting for ${message}`);
}

// A process that holds a command on the bus (caracaractl thrust/motion ... --for S).
export function hold(...args) {
  return spawn(`${BUILD}/tools/caracaractl`, ["--bus-address", BUS, ...args.map(String)], { stdio: "ignore" });
}

const ajv = new Ajv2020({ strict: false });
const decoder = new TextDecoder();

// A connected reference client: channels by topic, every message validated against its
// channel's schema (failures collected), the latest message per topic, every /events message,
// status messages.
export async function connect(url = URL) {
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const c = {
    ws, client, serverInfo: null, channels: new Map(), byId: new Map(), validators: new Map(),
    subs: new Map(), latest: new Map(), counts: new Map(), events: [], statuses: [], invalid: [], closed: false,
  };
  client.on("status", (s) => c.statuses.push(s));
  client.on("close", () => { c.closed = true; });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const ch = c.subs.get(subscriptionId);
    if (!ch) return;
    const text = decoder.decode(data);
    const msg = JSON.parse(text);
    const validate = c.validators.get(ch.id);
    if (!validate(msg)) c.invalid.push(`${ch.topic}: ${ajv.errorsText(validate.errors)} in ${text}`);
    c.latest.set(ch.topic, { msg, timestamp });
    if (ch.topic === "/events") c.events.push(msg); // several may come at once (a failsafe, then its kill)
    c.counts.set(ch.topic, (c.counts.get(ch.topic) ?? 0) + 1);
  });
  await new Promise((resolve, reject) => {
    client.on("serverInfo", (info) => { c.serverInfo = info; });
    client.on("advertise", (channels) => {
      for (const ch of channels) {
        c.channels.set(ch.topic, ch);
        c.byId.set(ch.id, ch);
        c.validators.set(ch.id, ajv.compile(JSON.parse(ch.schema)));
      }
      resolve();
    });
    client.on("error", reject);
  });
  c.subscribeAll = () => { for (const ch of c.channels.values()) c.subs.set(client.subscribe(ch.id), ch); };
  c.waitFor = (topic, pred = () => true, ms = 10000) =>
    poll(() => { const l = c.latest.get(topic); return l && pred(l.msg) ? l.msg : null; }, ms, `${topic} to match`);
  c.waitStatus = (pred, ms = 5000) => poll(() => c.statuses.find(pred), ms, "a status message");
  c.publisher = (topic) => client.advertise({ topic, encoding: "json", schemaName: topic });
  c.publish = (id, obj) => client.sendMessage(id, new TextEncoder().encode(JSON.stringify(obj)));
  c.close = async () => { client.close(); await poll(() => c.closed || ws.readyState === WebSocket.CLOSED, 5000, "close"); };
  return c;
}
