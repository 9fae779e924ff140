// caracara-bridge against the Foxglove WebSocket protocol's reference client
// (@foxglove/ws-protocol), through a real `ssh -L` forward of its Unix socket, judged on the
// simulator's side (its inspection API and wire log). Run by test_bridge.py, which starts the
// private bus, caracara-sim, caracarad, the bridge, a private sshd and the forward.
import { test, after } from "node:test";
import assert from "node:assert/strict";
import { bound } from "./bounds.mjs";
import net from "node:net";
import WebSocket from "ws";
import {
  DEFAULT_MT, ERR, MOTORS, MOTOR_MAX, PILOT_LOST_MS, X_AXIS, ZERO, connect, firstZeros, hold, killEdges, poll, rearm, simSpeeds,
  simThruster, sleep, speedByte, URL, vget, wireLog, wireNext,
} from "./lib.mjs";

const TOPICS = ["/vehicle/state", "/vehicle/motors", ...[...Array(MOTORS).keys()].map((i) => `/thruster/${i}`),
  "/teensy", "/i2c", "/events", "/tf"];

const clients = [];
async function client() {
  const c = await connect();
  clients.push(c);
  c.subscribeAll();
  return c;
}
after(async () => {
  for (const c of clients) {
    if (!c.closed) await c.close().catch(() => {});
    assert.deepEqual(c.invalid, [], "messages that do not validate against their channel's schema");
  }
});

// Holds a motion from a client: the bridge re-sends nothing by itself, the pilot does (as
// Foxglove's publish panel does), well inside CommandTimeoutMs.
function keepPublishing(c, id, msg, everyMs = 100) {
  c.publish(id, msg);
  const timer = setInterval(() => { if (!c.closed) c.publish(id, msg); }, everyMs);
  return () => clearInterval(timer);
}

// Orders other than zero to a thruster on the wire since a wire log index.
const nonZero = (since) => wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 &&
  DEFAULT_MT.includes(e.addr << 1) && e.data[0] !== ZERO);

// The SPEED bytes of the seed's x (port) demand v: a Twist's linear.y (left, REP 103) of v.
const xMotion = (v) => [...Array(MOTORS).keys()].map((i) => (i in X_AXIS ? speedByte(X_AXIS[i] * Math.round(v * MOTOR_MAX)) : ZERO));

test("serverInfo, the subprotocol, and every channel advertised with a JSON Schema", async () => {
  const c = await client();
  assert.equal(c.ws.protocol, "foxglove.websocket.v1");
  assert.equal(c.serverInfo.name, "caracara-bridge");
  assert.ok(c.serverInfo.capabilities.includes("clientPublish"));
  assert.deepEqual([...c.channels.keys()].sort(), [...TOPICS].sort());
  for (const ch of c.channels.values()) {
    assert.equal(ch.encoding, "json");
    assert.equal(ch.schemaEncoding, "jsonschema");
    assert.equal(JSON.parse(ch.schema).type, "object", ch.topic);
  }
  assert.equal(c.channels.get("/events").schemaName, "foxglove.Log");
  assert.equal(c.channels.get("/tf").schemaName, "foxglove.FrameTransform");
  // Every channel but /events (nothing has happened yet) sends its current state at once.
  for (const topic of TOPICS.filter((t) => t !== "/events")) await c.waitFor(topic);
  const state = await c.waitFor("/vehicle/state");
  assert.equal(state.state, vget("State"));
});

test("a thrust set over D-Bus shows on /vehicle/motors; thruster telemetry equals the simulator's", async () => {
  await rearm();
  const c = await client();
  const values = [1000, -1000, 0, 0, 0, 0, 0, 500];
  const p = hold("thrust", ...values, "--for", 20);
  try {
    await c.waitFor("/vehicle/motors", (m) => JSON.stringify(m.applied) === JSON.stringify(values) &&
                                               JSON.stringify(m.requested) === JSON.stringify(values));
    await poll(() => simSpeeds().every((s, i) => s === speedByte(values[i])), 10000, "the wire to carry the thrust");
    for (let i = 0; i < MOTORS; i++) {
      await poll(() => {
        const t = c.latest.get(`/thruster/${i}`)?.msg;
        return t && t.index === i && t.reachable && t.ordered_value === values[i] &&
          speedByte(t.speed) === simThruster(i, "ActualSpeed") &&
          Math.abs(t.temperature - simThruster(i, "Temperature")) < 1 &&
          Math.abs(t.current - simThruster(i, "Current")) < 0.11;
      }, 10000, `/thruster/${i} to equal the simulator's thruster`);
    }
  } finally {
    p.kill("SIGTERM");
  }
  await poll(() => simSpeeds().every((s) => s === ZERO), 10000, "zero after the holder left");
});

test("a published Twist (linear.y, left: the seed's port) reaches the wire as the mixing says; a closed client zeroes it within the client-loss bound, and the last pilot's kill follows after pilot-lost's persistence", async () => {
  await rearm();
  const c = await client();
  const id = c.publisher("/command/motion");
  const stop = keepPublishing(c, id, { linear: { x: 0, y: 0.2, z: 0 }, angular: { x: 0, y: 0, z: 0 } });
  try {
    await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(0.2)), 10000, "the motion on the wire");
    const state = await c.waitFor("/vehicle/state", (s) => s.controller !== "");
    assert.ok(state.command_age_ms >= 0);
  } finally {
    stop();
  }
  const since = wireNext();
  const closedAt = process.hrtime.bigint(); // CLOCK_MONOTONIC, as the wire log's times
  await c.close();
  const driven = new Set(Object.keys(X_AXIS).map((i) => DEFAULT_MT[i] >> 1)); // 7-bit addresses
  const zeroTimes = await poll(() => firstZeros(since, driven), 5000, "zero orders to the four motors it drove");
  const worstMs = Number(zeroTimes.reduce((a, b) => (a > b ? a : b)) - closedAt) / 1e6;
  console.log(`# close to the last zero order: ${worstMs.toFixed(1)} ms`);
  assert.ok(worstMs <= bound("CLIENT_LOSS_ZERO_MS_MAX"),
            `zeroed ${worstMs} ms after the close (bound ${bound("CLIENT_LOSS_ZERO_MS_MAX")} ms, tests/bounds.json)`);
  // It was the last pilot: the kill output after pilot-lost's persistence, never before it (a
  // reader's client sees it as a failsafe), then a plain clear-kill re-arms.
  const watcher = await client();
  const [edge] = await poll(() => { const k = killEdges(since); return k.length ? k : null; }, PILOT_LOST_MS + 5000,
                            "the pilot-lost kill");
  const killMs = Number(edge.time_ns - closedAt) / 1e6;
  console.log(`# close to the kill output: ${killMs.toFixed(0)} ms (pilot-lost persistence ${PILOT_LOST_MS} ms)`);
  assert.ok(killMs >= PILOT_LOST_MS, `killed ${killMs} ms after the close, before the persistence`);
  assert.ok(Number(edge.time_ns) > Number(zeroTimes.reduce((a, b) => (a > b ? a : b))), "the kill before the zeros");
  await watcher.waitFor("/vehicle/state", (s) => s.state === "killed" && s.kill_source === "failsafe");
  await poll(() => watcher.events.some((l) => l.name === "failsafe" && l.message.includes("pilot-lost -> kill")), 5000,
             "the pilot-lost failsafe on /events");
  watcher.publish(watcher.publisher("/command/clear_kill"), {});
  await watcher.waitFor("/vehicle/state", (s) => s.state === "ready", 20000);
  await watcher.close(); // its clear-kill took the free pilot's seat: it goes with it
});

test("kill from a client, a refused command as a status with the daemon's error name, events as foxglove.Log", async () => {
  await rearm();
  const c = await client();
  const kill = c.publisher("/command/kill");
  const clear = c.publisher("/command/clear_kill");
  const motion = c.publisher("/command/motion");
  c.publish(kill, {});
  await c.waitFor("/vehicle/state", (s) => s.state === "killed" && s.kill_source === "dbus");
  await c.waitFor("/events", (l) => l.name === "kill" && l.level === 3);
  c.publish(motion, { linear: { x: 0.1 } });
  const refused = await c.waitStatus((s) => s.level === 2 && s.message.includes(ERR + "Killed"));
  assert.match(refused.message, /\/command\/motion/);
  assert.equal(vget("State"), "killed");
  c.publish(clear, {});
  await c.waitFor("/events", (l) => l.name === "arming");
  await c.waitFor("/vehicle/state", (s) => s.state === "ready", 20000);
  const leds = c.publisher("/command/leds");
  c.publish(leds, { red: 1, green: 2, blue: 3 });
  await poll(() => JSON.stringify(vget("Leds")) === "[1,2,3]", 5000, "the LEDs");
  await c.waitFor("/vehicle/state", (s) => JSON.stringify(s.leds) === "[1,2,3]");
  const profile = c.publisher("/command/profile");
  c.publish(profile, { name: "no-such-profile" });
  await c.waitStatus((s) => s.message.includes(ERR + "UnknownProfile"));
  // The commissioning commands: the bridge's named error for a body that is not theirs, the
  // daemon's for a thruster out of range; nothing on the wire.
  const since = wireNext();
  const test = c.publisher("/command/motor_test");
  c.publish(test, { thruster: 2 });
  await c.waitStatus((s) => s.level === 2 && s.message === "/command/motor_test: motor_test needs 'value': an integer");
  c.publish(test, { thruster: 8, value: 500 });
  await c.waitStatus((s) => s.level === 2 && s.message.startsWith(`/command/motor_test refused: ${ERR}OutOfRange`));
  assert.deepEqual(wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] !== ZERO), []);
  await c.close();
});

test("the seed's flat axes on /command/motion are refused by name, never read as a Twist; /command/drive takes a pilot's words", async () => {
  await rearm();
  const c = await client();
  const since = wireNext();
  const motion = c.publisher("/command/motion");
  for (const old of [{ x: 0.5 }, { y: 0.5 }, { yaw: 0.5 }, { x: 0, y: 0.2, z: 0, yaw: 0, pitch: 0, roll: 0 }]) {
    const n = c.statuses.length;
    c.publish(motion, old);
    const s = await poll(() => c.statuses.slice(n).find((m) => m.level === 2), 5000, `a refusal of ${JSON.stringify(old)}`);
    assert.match(s.message, /^\/command\/motion: motion is a Twist in body FLU, .*the flat '(x|y|z|yaw|pitch|roll)' of the seed's axes is refused/);
  }
  const drive = c.publisher("/command/drive");
  c.publish(drive, { surge: 0.5 });
  await c.waitStatus((m) => m.level === 2 &&
    m.message === "/command/drive: drive takes forward, starboard, up, turn_right, nose_up, roll_right, not 'surge'");
  assert.deepEqual(wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] !== ZERO), [],
                   "nothing moved");
  // The words: starboard 0.2 is the seed's x of -0.2.
  const stop = keepPublishing(c, drive, { starboard: 0.2 });
  try {
    await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(-0.2)), 10000, "the drive on the wire");
  } finally {
    stop();
  }
  c.publish(drive, {});
  await poll(() => simSpeeds().every((v) => v === ZERO), 5000, "zero");
  await c.close();
});

test("a second client keeps its own pilot rules; while it is connected, another leaving kills nothing", async () => {
  await rearm();
  const a = await client();
  const b = await client();
  const stopA = keepPublishing(a, a.publisher("/command/motion"), { linear: { y: 0.2 } });
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(0.2)), 10000, "A's motion");
  const controllerA = (await a.waitFor("/vehicle/state", (s) => s.controller !== "")).controller;
  stopA();
  // A holds the pilot's seat: B takes it over, in so many words.
  b.publish(b.publisher("/command/seat"), { action: "take-over" });
  await poll(() => seatNews(b).some((n) => n.yours), 5000, "the seat B's");
  const stopB = keepPublishing(b, b.publisher("/command/motion"), { linear: { y: -0.2 } });
  try {
    await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(-0.2)), 10000, "B's motion");
    const controllerB = (await b.waitFor("/vehicle/state", (s) => s.controller !== "" && s.controller !== controllerA)).controller;
    assert.notEqual(controllerA, controllerB, "each client has its own connection to caracarad");
    // A leaves: it no longer commands, so B's thrust stays; B is a pilot still, so no kill.
    const since = wireNext();
    await a.close();
    await sleep(Math.max(700, PILOT_LOST_MS + 300)); // past CommandTimeoutMs and pilot-lost's persistence
    // The speeds first: busctl runs synchronously, and a long wire log read would hold B's re-sends
    // past CommandTimeoutMs.
    assert.deepEqual(simSpeeds(), xMotion(-0.2));
    assert.deepEqual(killEdges(since), [], "killed while a pilot was still connected");
  } finally {
    stopB();
  }
  await b.close();
  await poll(() => simSpeeds().every((s) => s === ZERO), 2000, "zero once B left");
});

// What a client heard of the pilot's seat: the bridge's statuses whose id is /command/seat.
const seatNews = (c) => c.statuses.filter((s) => s.id === "/command/seat").map((s) => JSON.parse(s.message));

test("one pilot's seat: a second Foxglove client is refused by name and moves nothing; an explicit take-over is told to the holder at once and zeroes its thrust; its leaving frees the seat", async () => {
  await rearm();
  const a = await client();
  const b = await client();
  // Each is told the seat when it joins: free.
  await poll(() => seatNews(a).length && seatNews(b).length, 5000, "the seat told at the join");
  assert.deepEqual(seatNews(b)[0], { holder: "", yours: false, change: "now", by: "" });
  // A's first motion takes the free seat; B hears who holds it.
  const stopA = keepPublishing(a, a.publisher("/command/motion"), { linear: { y: 0.2 } }, 50);
  try {
    await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(0.2)), 10000, "A's motion");
    const holder = (await poll(() => seatNews(b).find((n) => n.change === "claimed"), 5000, "B told of A's claim")).holder;
    assert.match(holder, /^client #\d+$/);
    assert.equal(seatNews(a).at(-1).yours, true);
    // B without the seat: motion, drive, thrust, clear-kill, a claim: each refused by name, and
    // nothing of B's on the wire (A's motion alone, throughout).
    const since = wireNext();
    const n = b.statuses.length;
    for (const [topic, msg] of [["/command/motion", { linear: { y: -0.9 } }], ["/command/drive", { forward: 0.9 }],
      ["/command/thrust", { values: [3000, 3000, 3000, 3000, 3000, 3000, 3000, 3000] }], ["/command/clear_kill", {}],
      ["/command/seat", { action: "claim" }]]) {
      const id = b.publisher(topic);
      for (let i = 0; i < 5; i++) { b.publish(id, msg); await sleep(50); }
      const r = await poll(() => b.statuses.slice(n).find((s) => s.level === 2 && s.message.startsWith(`${topic} refused`)), 5000,
                           `${topic} refused`);
      assert.match(r.message, new RegExp(`^${topic} refused: org\\.caracara\\.Bridge\\.Error\\.SeatTaken: the pilot's seat is held by ${holder}[;]`));
    }
    const a02 = new Set(xMotion(0.2));
    const others = wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 && DEFAULT_MT.includes(e.addr << 1) &&
      !a02.has(e.data[0]));
    assert.deepEqual(others, [], "an order on the wire that is not A's");
    assert.deepEqual(simSpeeds(), xMotion(0.2));
    // B takes it over, in so many words: A told at once, A's thrust zeroed (B holds the vehicle
    // at zero), A's commands refused from then on.
    const sinceTake = wireNext();
    const takenAt = process.hrtime.bigint();
    b.publish(b.publisher("/command/seat"), { action: "take-over", name: "teleop on the laptop" });
    const told = await poll(() => seatNews(a).find((m) => m.change === "taken-over"), 5000, "A told of the take-over");
    assert.deepEqual(told, { holder: told.by, yours: false, change: "taken-over", by: told.by });
    assert.match(told.by, /^client #\d+ \(teleop on the laptop\)$/);
    const driven = new Set(Object.keys(X_AXIS).map((i) => DEFAULT_MT[i] >> 1));
    const zeros = await poll(() => firstZeros(sinceTake, driven), 5000, "A's thrust zeroed");
    const zeroedAt = zeros.reduce((x, y) => (x > y ? x : y));
    const ms = Number(zeroedAt - takenAt) / 1e6;
    console.log(`# take-over published to A's zeros on the wire: ${ms.toFixed(1)} ms`);
    assert.ok(ms <= bound("CLIENT_LOSS_ZERO_MS_MAX"), `A zeroed ${ms} ms after the take-over`);
    await a.waitStatus((s) => s.level === 2 && s.message.startsWith("/command/motion refused: org.caracara.Bridge.Error.SeatTaken"));
    await sleep(300);
    assert.ok(simSpeeds().every((v) => v === ZERO), "A's motion after the take-over");
    // From the take-over's zeros on (A's orders before them are A's motion still going out).
    assert.deepEqual(nonZero(sinceTake).filter((e) => e.time_ns > zeroedAt), [], "A's motion on the wire after the take-over");
  } finally {
    stopA();
  }
  // Kill needs no seat: A (without it) kills.
  const since = wireNext();
  a.publish(a.publisher("/command/kill"), {});
  await poll(() => killEdges(since).length, 5000, "A's kill on the kill output");
  await a.waitFor("/vehicle/state", (s) => s.state === "killed");
  // B leaves: the seat is free, and A hears it.
  await b.close();
  await poll(() => seatNews(a).some((m) => m.change === "left" && m.holder === ""), 5000, "A told the seat is free");
  a.publish(a.publisher("/command/clear_kill"), {});
  await poll(() => seatNews(a).at(-1).yours && seatNews(a).at(-1).change === "claimed", 5000, "A's clear-kill taking the free seat");
  await a.waitFor("/vehicle/state", (s) => s.state === "ready", 20000);
  await a.close();
});

test("bad input: a status error or a close, never a crash, never a command", async () => {
  const since = wireNext();
  const c = await client();
  const raw = c.ws;
  const errors = () => c.statuses.filter((s) => s.level === 2).length;
  let n = errors();
  for (const frame of ["not json", "[]", "{}", '{"op":42}', '{"op":"nope"}', '{"op":"subscribe"}',
                       '{"op":"subscribe","subscriptions":[{"id":1,"channelId":9999}]}',
                       '{"op":"advertise","channels":[{"id":7,"topic":"/etc/passwd","encoding":"json"}]}',
                       '{"op":"unsubscribe","subscriptionIds":["x"]}']) {
    raw.send(frame);
    await poll(() => errors() > n, 5000, `a status error for ${frame}`);
    n = errors();
  }
  for (const frame of [Buffer.from([1]), Buffer.from([9, 0, 0, 0, 0]), Buffer.from([1, 99, 0, 0, 0, 123])]) {
    raw.send(frame);
    await poll(() => errors() > n, 5000, "a status error for a bad binary frame");
    n = errors();
  }
  // A command with a body that is not its JSON: refused by the bridge, nothing sent.
  const thrust = c.publisher("/command/thrust");
  c.publish(thrust, { values: [8850, 8850] });
  await poll(() => errors() > n, 5000, "a status error for a short thrust");
  // A subscription flood: past the limit each is refused.
  const flood = [];
  for (let i = 0; i < 400; i++) flood.push({ id: 100000 + i, channelId: 1 });
  raw.send(JSON.stringify({ op: "subscribe", subscriptions: flood }));
  await c.waitStatus((s) => s.message.includes("more than 256 subscriptions"));
  // Oversized: closed.
  raw.send("x".repeat(200 * 1024));
  await poll(() => c.closed, 5000, "the close of an oversized message");
  // Nothing was commanded, and the bridge still serves.
  const orders = wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3);
  assert.deepEqual([...new Set(orders.map((e) => e.data[0]))].filter((s) => s !== ZERO), []);
  const d = await client();
  await d.waitFor("/vehicle/state");
  // Malformed WebSocket framing (an unmasked client frame), and no HTTP at all: closed.
  const where = new globalThis.URL(URL);
  const rawSocket = async (request, then) => {
    const sock = net.connect(Number(where.port), where.hostname);
    let got = "";
    sock.on("data", (d) => { got += d.toString("latin1"); });
    const closed = new Promise((resolve) => sock.on("close", resolve));
    sock.write(request);
    if (then) {
      await poll(() => got.includes("\r\n\r\n"), 5000, "the upgrade's answer");
      assert.match(got, /^HTTP\/1\.1 101/);
      sock.write(then);
    }
    await Promise.race([closed, sleep(5000).then(() => { throw new Error("not closed"); })]);
  };
  await rawSocket("GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n" +
                  "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n" +
                  "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n", Buffer.from([0x81, 0x05, 104, 101, 108, 108, 111]));
  await rawSocket("\x00\x01garbage that is no HTTP\r\n\r\n");
  // Not the protocol at all: refused at the upgrade.
  const plain = new WebSocket(URL, ["not-foxglove"]);
  await new Promise((resolve) => { plain.on("error", resolve); plain.on("unexpected-response", resolve); });
});
