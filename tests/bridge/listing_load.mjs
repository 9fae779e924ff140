// A Kill and a client's close while another client lists a full dive directory (issue 35):
// shared by bounds.test.mjs (which asserts the bounds) and bench/bridge_bench.mjs (which prints
// the figures). `url` is the bridge's WebSocket URL (with ?token= on TCP), `listUrl` its
// /dives/ URL; a lister fetches the list back to back meanwhile. Times: the publish or the
// close (process.hrtime, CLOCK_MONOTONIC) to the simulator's wire log (the same clock).
import {
  DEFAULT_MT, ROOT, VEHICLE, X_AXIS, ZERO, busctl, connect, killEdges, poll, rearm, simSpeeds, sleep, vget, wireLog, wireNext,
} from "./lib.mjs";

export function stats(v) {
  const s = [...v].sort((a, b) => a - b);
  const pct = (q) => s[Math.min(Math.max(Math.ceil((q * s.length) / 100), 1), s.length) - 1];
  return { n: s.length, min: s[0], p50: pct(50), p90: pct(90), p99: pct(99), max: s[s.length - 1] };
}

// Lists back to back until stopped; `busy` is true while a listing is in progress.
export function startLister(listUrl) {
  const l = { busy: false, done: 0, ms: [], stopped: false, failed: null };
  l.finished = (async () => {
    while (!l.stopped) {
      const t0 = Date.now();
      l.busy = true;
      try {
        const r = await fetch(listUrl);
        if (r.status !== 200) throw new Error(`GET /dives/: ${r.status}`);
        l.dives = (await r.json()).length;
      } catch (e) {
        l.failed = e;
        break;
      } finally {
        l.busy = false;
      }
      l.done += 1;
      l.ms.push(Date.now() - t0);
    }
  })();
  l.stop = async () => { l.stopped = true; await l.finished; };
  return l;
}

// `samples` Kills from a client, each while a listing is in progress: publish -> the kill
// output's edge, in ms.
export async function killsDuringListing(url, listUrl, samples) {
  const c = await connect(url);
  const kill = c.publisher("/command/kill");
  const lister = startLister(listUrl);
  const out = [];
  try {
    await poll(() => lister.done >= 1 || lister.failed, 60000, "a first listing");
    if (lister.failed) throw lister.failed;
    for (let i = 0; i < samples; i++) {
      if (vget("State") === "killed") busctl("call", VEHICLE, ROOT, VEHICLE, "ClearKill");
      await poll(() => vget("State") === "ready", 20000, "ready again");
      await poll(() => lister.busy, 10000, "a listing in progress");
      await sleep(Math.random() * 20); // somewhere in the listing, not at its start
      const since = wireNext();
      const t0 = process.hrtime.bigint();
      c.publish(kill, {});
      const [edge] = await poll(() => { const k = killEdges(since); return k.length ? k : null; }, 5000, "the kill output");
      out.push(Number(edge.time_ns - t0) / 1e6);
    }
  } finally {
    await lister.stop();
    await c.close();
  }
  if (lister.failed) throw lister.failed;
  return { kill_output_ms: stats(out), listings: lister.done, listing_ms: stats(lister.ms), dives: lister.dives };
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
      const timer = setInterval(() => { if (!c.closed) c.publish(motion, { x: 0.2 }); }, 50);
      try {
        c.publish(motion, { x: 0.2 });
        await poll(() => simSpeeds()[2] !== ZERO, 10000, "the motion on the wire");
        await poll(() => lister.busy, 10000, "a listing in progress");
        await sleep(Math.random() * 20);
      } finally {
        clearInterval(timer);
      }
      const since = wireNext();
      const closedAt = process.hrtime.bigint();
      c.ws.terminate(); // the tab's connection gone, as a closed tab's is
      const zeros = await poll(() => {
        const first = new Map();
        for (const e of wireLog(since))
          if (e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] === ZERO && driven.has(e.addr) &&
              !first.has(e.addr))
            first.set(e.addr, e.time_ns);
        return first.size === driven.size ? [...first.values()] : null;
      }, 5000, "zero orders to the four motors it drove");
      out.push(Number(zeros.reduce((a, b) => (a > b ? a : b)) - closedAt) / 1e6);
    }
  } finally {
    await lister.stop();
  }
  if (lister.failed) throw lister.failed;
  return { close_to_zeros_ms: stats(out), listings: lister.done };
}
