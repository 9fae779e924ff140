// caracara-bridge's figures (bench/run.py phase "bridge"), with the reference client of
// tests/bridge (its pinned npm packages). Prints one JSON object.
//   latency: a property change to its message at a client: a client publishes /command/leds,
//            the bridge calls SetLeds on the client's connection, caracarad announces Leds, the
//            bridge sends /vehicle/state: from the publish to the message (an upper bound of
//            the change-to-message time, the SetLeds call included)
//   motion:  a motion published by a client to the simulator's wire, against SetMotion over
//            D-Bus from a python3-dbus client, alternating in the same run
//   cockpit: a gamepad sample in the cockpit (tools/cockpit, in chromium with a scripted gamepad,
//            at CARACARA_HTTP_URL) to the order on the wire, against SetMotion over D-Bus,
//            alternating in the same run; the page's clock is tied to CLOCK_MONOTONIC by the
//            tightest of 30 round trips (its half-width is printed as clock_uncertainty_us)
//   load N S: N clients subscribed to every channel for S seconds (run.py reads the bridge's
//            CPU and RSS meanwhile)
//   listing: a Kill published by a client to the kill output's edge on the wire, with no listing
//            and while another client (a process of its own) lists a full dive directory back
//            to back, and a client's close to its zeros on the wire meanwhile (issue 35; the
//            bridge at CARACARA_TCP_URL, tests/bridge/listing_load.mjs)
import { spawn } from "node:child_process";
import { createInterface } from "node:readline";
import { BUS, DEFAULT_MT, MOTOR_MAX, X_AXIS, Y_AXIS, connect, poll, sleep, speedByte, wireLog, wireNext } from "../tests/bridge/lib.mjs";
import { closesDuringListing, killsDuringListing, stats } from "../tests/bridge/listing_load.mjs";

const url = process.env.CARACARA_WS_URL;
const samples = Number(process.env.CARACARA_BENCH_SAMPLES ?? 200);
const mode = process.argv[2];

async function latency() {
  const c = await connect(url);
  c.subscribeAll();
  await c.waitFor("/vehicle/state");
  const leds = c.publisher("/command/leds");
  const out = [];
  let waiting = null;
  c.client.on("message", ({ subscriptionId, data }) => {
    if (!waiting || c.subs.get(subscriptionId)?.topic !== "/vehicle/state") return;
    const m = JSON.parse(new TextDecoder().decode(data));
    if (m.leds[0] === waiting.value) { waiting.resolve(process.hrtime.bigint()); waiting = null; }
  });
  for (let i = 0; i < samples; i++) {
    const value = (i % 250) + 1;
    const arrived = new Promise((resolve) => { waiting = { value, resolve }; });
    const t0 = process.hrtime.bigint();
    c.publish(leds, { red: value, green: 0, blue: 0 });
    const t1 = await arrived;
    out.push(Number(t1 - t0) / 1000);
    await sleep(5 + Math.random() * 15);
  }
  await c.close();
  return { leds_to_state_us: stats(out) };
}

// A python3-dbus client holding its own connection: each line "x" -> SetMotion(x, 0...), prints t0.
const SETMOTION = `
import sys, time, dbus
bus = dbus.bus.BusConnection(sys.argv[1])
v = bus.get_object("org.caracara.Vehicle1", "/org/caracara/Vehicle1", introspect=False)
for line in sys.stdin:
    x = float(line)
    t0 = time.monotonic_ns()
    v.SetMotion(x, 0.0, 0.0, 0.0, 0.0, 0.0, dbus_interface="org.caracara.Vehicle1")
    print(t0, flush=True)
`;

async function motion() {
  const c = await connect(url);
  const pub = c.publisher("/command/motion");
  const py = spawn("/usr/bin/python3", ["-c", SETMOTION, BUS], { stdio: ["pipe", "pipe", "inherit"] });
  const lines = createInterface({ input: py.stdout })[Symbol.asyncIterator]();
  const addr = DEFAULT_MT[2] >> 1; // motor 2 drives +x
  const viaBridge = [], viaDbus = [];
  for (let i = 0; i < samples; i++) {
    // Even samples through the bridge, odd ones over D-Bus; each value differs from the one
    // before, so the order that carries it is new on the wire (not the loop's refresh).
    const value = [0.2, -0.2, 0.3, -0.3][i % 4];
    const speed = speedByte(X_AXIS[2] * Math.round(value * MOTOR_MAX));
    const since = wireNext();
    let t0;
    if (i % 2 === 0) {
      t0 = process.hrtime.bigint();
      c.publish(pub, { linear: { y: value } }); // left, REP 103: the seed's x
    } else {
      py.stdin.write(`${value}\n`);
      t0 = BigInt((await lines.next()).value);
    }
    const at = await poll(() => wireLog(since).find((e) => e.bus === "i2c" && !e.read && e.addr === addr &&
                                                         e.data[0] === speed && e.time_ns > t0), 2000, "the order");
    (i % 2 === 0 ? viaBridge : viaDbus).push(Number(at.time_ns - t0) / 1000);
    await sleep(10 + Math.random() * 20);
  }
  py.stdin.end();
  await c.close();
  return { bridge_motion_to_wire_us: stats(viaBridge), dbus_setmotion_to_wire_us: stats(viaDbus) };
}

async function load(n, seconds) {
  const clients = [];
  for (let i = 0; i < n; i++) {
    const c = await connect(url);
    c.subscribeAll();
    clients.push(c);
  }
  console.error("# loaded");
  await sleep(seconds * 1000);
  const counts = clients.map((c) => [...c.counts.values()].reduce((a, b) => a + b, 0));
  for (const c of clients) await c.close();
  return { clients: n, seconds, messages_per_client: counts };
}

// The first order to motor 2 carrying speed, after t0 (CLOCK_MONOTONIC ns); its time.
async function orderAfter(since, speed, t0) {
  const addr = DEFAULT_MT[2] >> 1;
  const at = await poll(() => wireLog(since).find((e) => e.bus === "i2c" && !e.read && e.addr === addr &&
                                                       e.data[0] === speed && e.time_ns > t0), 2000, "the order");
  return at.time_ns;
}

async function cockpit() {
  const { armPad, forwardDemand, launch, openCockpit } = await import("../tests/bridge/chromium.mjs");
  const chromium = await launch();
  try {
    const { page } = await openCockpit(chromium.browser, process.env.CARACARA_HTTP_URL);
    // Armed on purpose (deadman released with the sticks centred, then pressed), then released:
    // a release does not disarm, so each sample below is a press with the stick out.
    await armPad(page);
    await page.evaluate(() => { window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; });
    let best = null;
    for (let i = 0; i < 30; i++) {
      const t1 = process.hrtime.bigint();
      const p = await page.evaluate(() => performance.now());
      const t2 = process.hrtime.bigint();
      if (!best || t2 - t1 < best.rtt) best = { rtt: t2 - t1, offset: (t1 + t2) / 2n - BigInt(Math.round(p * 1e6)) };
    }
    const py = spawn("/usr/bin/python3", ["-c", SETMOTION, BUS], { stdio: ["pipe", "pipe", "inherit"] });
    const lines = createInterface({ input: py.stdout })[Symbol.asyncIterator]();
    const viaPad = [], viaDbus = [];
    for (let i = 0; i < samples; i++) {
      const since = wireNext();
      if (i % 2 === 0) {
        // Stick and deadman at once; the page's next tick samples and sends; then released (zero).
        const stick = [-0.6, 0.6, -0.7, 0.7][(i / 2) % 4];
        const speed = speedByte(Y_AXIS[2] * Math.round(forwardDemand(stick) * MOTOR_MAX)); // forward: the seed's y
        const before = await page.evaluate(() => window.cockpit.lastChange?.at ?? -1);
        await page.evaluate((s) => { window.__pad.axes[1] = s; window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 }; }, stick);
        const at = await poll(() => page.evaluate((b) => (window.cockpit.lastChange?.at > b ? window.cockpit.lastChange.at : null), before), 2000, "the sample");
        const t0 = BigInt(Math.round(at * 1e6)) + best.offset;
        viaPad.push(Number((await orderAfter(since, speed, t0)) - t0) / 1000);
        await page.evaluate(() => { window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; });
        await poll(() => page.evaluate(() => window.cockpit.lastSent.motion.forward === 0), 2000, "the release");
      } else {
        const value = [0.2, -0.2, 0.3, -0.3][((i - 1) / 2) % 4];
        py.stdin.write(`${value}\n`);
        const t0 = BigInt((await lines.next()).value);
        viaDbus.push(Number((await orderAfter(since, speedByte(X_AXIS[2] * Math.round(value * MOTOR_MAX)), t0)) - t0) / 1000);
      }
      await sleep(10 + Math.random() * 20);
    }
    py.stdin.end();
    return { cockpit_pad_to_wire_us: stats(viaPad), dbus_setmotion_to_wire_us_cockpit_run: stats(viaDbus),
      clock_uncertainty_us: Number(best.rtt) / 2000 };
  } finally {
    await chromium.close();
  }
}

let result;
if (mode === "latency") result = await latency();
else if (mode === "motion") result = await motion();
else if (mode === "cockpit") result = await cockpit();
else if (mode === "listing") {
  const url = process.env.CARACARA_TCP_URL;
  const listUrl = url.replace(/^ws:/, "http:").replace("/?", "/dives/?");
  const k = await killsDuringListing(url, listUrl, samples, samples);
  const c = await closesDuringListing(url, listUrl, 10);
  result = { kill_during_listing_ms: k.kill_output_ms, kill_no_listing_ms: k.kill_output_no_listing_ms,
             listing_ms: k.listing_ms, dives_listed: k.dives, close_during_listing_ms: c.close_to_zeros_ms };
} else if (mode === "load") result = await load(Number(process.argv[3]), Number(process.argv[4]));
else throw new Error("mode: latency | motion | cockpit | listing | load N SECONDS");
console.log(JSON.stringify(result));
