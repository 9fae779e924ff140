// A Kill and a client's close while another client lists a full dive directory (issue 35):
// shared by bounds.test.mjs (which asserts the bounds) and bench/bridge_bench.mjs (which prints
// the figures). `url` is the bridge's WebSocket URL (with ?token= on TCP), `listUrl` its
// /dives/ URL; a lister fetches the list back to back meanwhile. Times: the publish or the
// close (process.hrtime, CLOCK_MONOTONIC) to the simulator's wire log (the same clock).
import { spawn } from "node:child_process";
import { createInterface } from "node:readline";
import {
  DEFAULT_MT, ROOT, VEHICLE, X_AXIS, ZERO, busctl, connect, firstZeros, killEdges, poll, rearm, simSpeeds, sleep, vget,
  wireNext,
} from "./lib.mjs";

export function stats(v) {
  const s = [...v].sort((a, b) => a - b);
  const pct = (q) => s[Math.min(Math.max(Math.ceil((q * s.length) / 100), 1), s.length) - 1];
  return { n: s.length, min: s[0], p50: pct(50), p90: pct(90), p99: pct(99), max: s[s.length - 1] };
}

// The other client, in a process of its own (another tab): lists back to back until stopped,
// and says when each listing starts and ends; `busy` is true while one is in progress.
const LISTER = `
const url = process.argv[1];
for (;;) {
  console.log("start");
  const r = await fetch(url);
  if (r.status !== 200) { console.log("failed GET /dives/: " + r.status); process.exit(1); }
  console.log("done " + (await r.json()).length);
}`;

export function startLister(listUrl) {
  const l = { busy: false, done: 0, ms: [], failed: null, dives: 0 };
  // The other tab runs on the pilot's laptop, not on the vehicle: here it shares the CPU with
  // the vehicle's processes, so it runs under SCHED_IDLE to stand for that. The bridge's
  // listing is what is measured, not a browser's JSON parsing on the vehicle's cores.
  const child = spawn("chrt", ["--idle", "0", process.execPath, "--input-type=module", "-e", LISTER, listUrl],
                      { stdio: ["ignore", "pipe", "inherit"] });
  let t0 = 0;
  createInterface({ input: child.stdout }).on("line", (line) => {
    if (line === "start") {
      l.busy = true;
      t0 = Date.now();
    } else if (line.startsWith("done ")) {
      l.busy = false;
      l.done += 1;
      l.dives = Number(line.slice(5));
      l.ms.push(Date.now() - t0);
    } else {
      l.failed = new Error(line);
    }
  });
  const exited = new Promise((resolve) => child.on("exit", resolve));
  l.stop = async () => { child.kill("SIGTERM"); await exited; };
  return l;
}

// A Kill from client c: publish -> the kill output's edge, in ms (from ready, after a ClearKill).
async function killOnce(c, kill, when = async () => {}) {
  if (vget("State") === "killed") busctl("call", VEHICLE, ROOT, VEHICLE, "ClearKill");
  await poll(() => vget("State") === "ready", 20000, "ready again");
  await when();
  await sleep(Math.random() * 20); // somewhere in the listing, not at its start
  const since = wireNext();
  const t0 = process.hrtime.bigint();
  c.publish(kill, {});
  await sleep(30); // the kill's path is not shared with busctl's start-ups (poll below)
  const [edge] = await poll(() => { const k = killEdges(since); return k.length ? k : null; }, 5000, "the kill output");
  return Number(edge.time_ns - t0) / 1e6;
}

// `idleSamples` Kills from a client with no listing (the yardstick on this machine, now), then
// `samples` each while a listing is in progress: publish -> the kill output's edge, in ms.
export async function killsDuringListing(url, listUrl, samples, idleSamples = samples) {
  const c = await connect(url);
  const kill = c.publisher("/command/kill");
  const idle = [], listing = [];
  let lister = null;
  try {
    for (let i = 0; i < idleSamples; i++) idle.push(await killOnce(c, kill));
    lister = startLister(listUrl);
    await poll(() => lister.done >= 1 || lister.failed, 60000, "a first listing");
    for (let i = 0; i < samples && !lister.failed; i++)
      listing.push(await killOnce(c, kill, () => poll(() => lister.busy, 10000, "a listing in progress")));
  } finally {
    if (lister) await lister.stop();
    await c.close();
  }
  if (lister.failed) throw lister.failed;
  return { kill_output_ms: stats(listing), kill_output_no_listing_ms: stats(idle), listings: lister.done,
           listing_ms: stats(lister.ms), dives: lister.dives };
}

// A client drives x, then closes while a listing is in progress: the close -> the last of the
// first zero orders to the four motors it drove, in ms (`samples` times).
export async function closesDuringListing(url, listUrl, samples) {
  const lister = startLister(listUrl);
  const out = [];
  const driven = new Set(Object.keys(X_AXIS).map((i) => DEFAULT_MT[i] >> 1)); // 7-bit addresses
  try {
    for (let i = 0; i < samples; i++) {
      await rearm();
      const c = await connect(url);
      const motion = c.publisher("/command/motion");
      const timer = setInterval(() => { if (!c.closed) c.publish(motion, { linear: { y: 0.2 } }); }, 50);
      try {
        c.publish(motion, { linear: { y: 0.2 } });
        await poll(() => simSpeeds()[2] !== ZERO, 10000, "the motion on the wire");
        await poll(() => lister.busy, 10000, "a listing in progress");
        await sleep(Math.random() * 20);
      } finally {
        clearInterval(timer);
      }
      const since = wireNext();
      const closedAt = process.hrtime.bigint();
      c.ws.terminate(); // the tab's connection gone, as a closed tab's is
      const zeros = await poll(() => firstZeros(since, driven), 5000, "zero orders to the four motors it drove");
      out.push(Number(zeros.reduce((a, b) => (a > b ? a : b)) - closedAt) / 1e6);
    }
  } finally {
    await lister.stop();
  }
  if (lister.failed) throw lister.failed;
  return { close_to_zeros_ms: stats(out), listings: lister.done };
}
