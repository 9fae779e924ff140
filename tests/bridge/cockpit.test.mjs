// The cockpit (tools/cockpit, docs/cockpit.md) in Debian's chromium, headless, driven by
// puppeteer-core, loaded from caracara-bridge through a real ssh -L forward; judged on the
// simulator's side (inspection API, wire log). Run by test_cockpit.py.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { bound } from "./bounds.mjs";
import fs from "node:fs";
import net from "node:net";
import path from "node:path";
import { armPad, forwardDemand, launch, openCockpit } from "./chromium.mjs";
import { execFileSync } from "node:child_process";
import { BUILD, DEFAULT_MT, MOTORS, MOTOR_MAX, PILOT_LOST_MS, ROOT, SIM, SIM_ROOT, SURFACE_MS, VEHICLE, Y_AXIS, ZERO, busctl, firstZeros, killEdges,
  hold, poll, rearm, simSpeeds, simThruster, sleep, speedByte, vget, wireLog, wireNext } from "./lib.mjs";

const HTTP = process.env.CARACARA_HTTP_URL;
const ART = process.env.CARACARA_ARTIFACTS;
const KILL_OUT = 27; // the simulator's kill output line (tests/e2e/vehicle_checks.py)
let chromium;
let browser;

before(async () => {
  chromium = await launch();
  browser = chromium.browser;
});
after(async () => { await chromium?.close(); });

const open = () => openCockpit(browser, HTTP);
const text = (page, sel) => page.$eval(sel, (e) => e.textContent.trim());
const shot = (page, name) => page.screenshot({ path: path.join(ART, `${name}.png`), fullPage: true });
const setPad = (page, fn) => page.evaluate(fn);
const shotView = (page, name) => page.screenshot({ path: path.join(ART, `${name}.png`) }); // what is on screen
const button = (i, on) => `window.__pad.buttons[${i}] = { pressed: ${on}, touched: ${on}, value: ${on ? 1 : 0} }`;
const deadman = (page, on) => page.evaluate(button(4, on));
const stick = (page, v) => page.evaluate(`window.__pad.axes[1] = ${v}`);
const sent = (page) => page.evaluate(() => window.cockpit.sent);
const arm = (page) => page.$eval("#arm", (e) => e.dataset.arm);
// The element wholly inside the viewport and not covered by another.
async function onScreen(page, sel) {
  const r = await page.$eval(sel, (e) => {
    const b = e.getBoundingClientRect();
    const hit = document.elementFromPoint((b.left + b.right) / 2, (b.top + b.bottom) / 2);
    return { top: b.top, left: b.left, bottom: b.bottom, right: b.right, w: innerWidth, h: innerHeight,
      visible: Boolean(hit && (e.contains(hit) || hit.contains(e))) };
  });
  assert.ok(r.top >= 0 && r.left >= 0 && r.bottom <= r.h && r.right <= r.w && r.visible, `${sel} not on screen: ${JSON.stringify(r)}`);
}
// A banner line's countdown ("... in 2.4 s", "2.4 s left") as the page shows it, and when it was read
// (CLOCK_MONOTONIC ns, as the wire log's times): the kill it counts down to comes then + the
// countdown, give or take the failsafes' lateness (the page shows the daemon's deadline).
// The page redraws the banner every 100 ms: what is read may be that old, plus the read's own time
// (`slackMs`), plus the 0.05 s of its rounding.
const BANNER_REDRAW_MS = 100; // tools/bridge/web: the banner's redraw period
async function countdown(page, sel, pattern) {
  const read = (s, p) => {
    const m = new RegExp(p).exec(document.querySelector(s)?.textContent ?? "");
    return m && Number(m[1]);
  };
  await page.waitForFunction(read, { timeout: 5000, polling: "mutation" }, sel, pattern.source);
  const before = process.hrtime.bigint();
  const seconds = await page.evaluate(read, sel, pattern.source);
  const at = process.hrtime.bigint();
  return { seconds, at, slackMs: Number(at - before) / 1e6 + BANNER_REDRAW_MS + bound("COCKPIT_COUNTDOWN_ROUNDING_MS") };
}
function assertKillWhenCounted(edge, shown, what) {
  const offMs = Number(edge.time_ns - shown.at) / 1e6 - shown.seconds * 1000;
  console.log(`# ${what}: the kill output ${offMs.toFixed(0)} ms after the end of the page's countdown ` +
              `(read within ${shown.slackMs.toFixed(0)} ms)`);
  assert.ok(offMs >= -shown.slackMs, `${what}: killed ${-offMs} ms before the end of the countdown shown`);
  assert.ok(offMs <= bound("FAILSAFE_LATENESS_MS_MAX") + bound("COCKPIT_COUNTDOWN_ROUNDING_MS"),
            `${what}: killed ${offMs} ms after the end of the countdown shown (bound FAILSAFE_LATENESS_MS_MAX, tests/bounds.json)`);
}
const simFault = (i, name, on) =>
  busctl("call", SIM, `${SIM_ROOT}/thruster/${i}`, "org.caracara.Simulator1.Thruster", "SetFault", "sb", name, on);
// I2C orders of a motor value other than zero on the wire since `since`.
const nonZeroOrders = (since) => wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 &&
  DEFAULT_MT.includes(e.addr << 1) && e.data[0] !== ZERO);

// A raw HTTP request (no client-side normalisation of the path): [status line, headers, body].
function raw(request) {
  const u = new URL(HTTP);
  return new Promise((resolve, reject) => {
    const s = net.connect(Number(u.port), u.hostname, () => s.write(request));
    const chunks = [];
    s.on("data", (d) => chunks.push(d));
    s.on("end", () => {
      const all = Buffer.concat(chunks).toString("latin1");
      const [head, body] = [all.slice(0, all.indexOf("\r\n\r\n")), all.slice(all.indexOf("\r\n\r\n") + 4)];
      resolve({ status: head.split("\r\n")[0], head: head.toLowerCase(), body });
    });
    s.on("error", reject);
  });
}

test("the bridge serves the cockpit's files over plain HTTP: GET and HEAD only, no way out of its directory", async () => {
  const get = (p, method = "GET") => raw(`${method} ${p} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n`);
  const index = await get("/");
  assert.match(index.status, / 200 /);
  assert.match(index.head, /content-type: text\/html/);
  assert.match(index.body, /<title>Caracara cockpit<\/title>/);
  assert.match((await get("/main.js")).head, /content-type: text\/javascript/);
  assert.match((await get("/cockpit.css")).head, /content-type: text\/css/);
  const head = await get("/cockpit.css", "HEAD");
  assert.match(head.status, / 200 /);
  assert.equal(head.body, "");
  assert.equal(Number(/content-length: (\d+)/.exec(head.head)[1]),
    fs.statSync(new URL("../../tools/cockpit/cockpit.css", import.meta.url)).size);
  for (const p of ["/../../../../etc/passwd", "/..%2f..%2fetc/passwd", "/.hidden", "/nothing.html", "/%2e%2e/x", "//etc/passwd"])
    assert.match((await get(p)).status, / 404 /, p);
  const post = await get("/", "POST");
  assert.match(post.status, / 405 /);
  assert.match(post.head, /allow: get, head/);
});

test("the page shows the state and the values the simulator reports, loading nothing but its own files", async () => {
  const { page, log } = await open();
  await page.waitForFunction((s) => document.getElementById("state").textContent === s, { timeout: 10000 }, vget("State"));
  assert.equal(await text(page, "#state"), "ready");
  assert.equal(await text(page, "#kill-source"), "none");
  assert.equal(await page.$eval("#banner", (e) => e.hidden), true, "no banner with nothing wrong");
  for (let i = 0; i < MOTORS; i++) {
    await poll(async () => {
      const t = Number(await text(page, `#thr-${i} .temperature`));
      const a = Number(await text(page, `#thr-${i} .current`));
      return Math.abs(t - simThruster(i, "Temperature")) < 1.1 && Math.abs(a - simThruster(i, "Current")) < 0.12 &&
        (await text(page, `#thr-${i} .reachable`)) === "ok";
    }, 10000, `thruster ${i} as the simulator has it`);
  }
  assert.match(await text(page, "#i2c-state"), /^ok$/);
  assert.ok(Number(await text(page, "#i2c-transactions")) > 0);
  assert.equal(await text(page, "#teensy-online"), "online");
  assert.match(await text(page, "#distances"), /\d/);
  await shot(page, "ready");
  const origin = new URL(HTTP).origin;
  assert.deepEqual(log.requests.filter((u) => !u.startsWith(origin) && !u.startsWith("data:")), [], "requests elsewhere");
  assert.deepEqual(log.errors, []);
  await page.close();
});

// The SPEED bytes of a "forward" demand v: the seed's y axis, as the mixing has it.
const forwardMotion = (v) => [...Array(MOTORS).keys()].map((i) => (i in Y_AXIS ? speedByte(Y_AXIS[i] * Math.round(v * MOTOR_MAX)) : ZERO));
const allZero = () => simSpeeds().every((s) => s === ZERO);
// A page armed on purpose and driving forward (the stick at -0.6) on a freshly armed vehicle.
async function drivingPage() {
  await rearm();
  const { page } = await open();
  await armPad(page);
  await stick(page, -0.6);
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(forwardMotion(forwardDemand(-0.6))), 10000, "driving");
  return page;
}

test("a scripted gamepad: the left stick forward reaches the wire as the seed's forward axis (the mixing's y), only while the deadman is held", async () => {
  await rearm();
  const { page } = await open();
  await setPad(page, () => { window.__pad.axes[1] = -0.6; });
  await sleep(600);
  assert.ok(allZero(), "stick forward without the deadman: nothing moves");
  assert.equal(await page.evaluate(() => window.cockpit.sent), 0, "no command without the deadman");
  await armPad(page);
  await stick(page, -0.6);
  const expected = forwardMotion(forwardDemand(-0.6));
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(expected), 10000, "the gamepad's forward on the wire");
  assert.equal(await text(page, "#deadman"), "HELD");
  await shot(page, "driving");
  // Held for a second: the page keeps sending (fixed rate), the wire keeps the motion.
  const sent0 = await page.evaluate(() => window.cockpit.sent);
  await sleep(1000);
  const sent1 = await page.evaluate(() => window.cockpit.sent);
  assert.ok(sent1 - sent0 >= 10, `about 20 commands a second while held (${sent1 - sent0})`);
  assert.deepEqual(simSpeeds(), expected);
  // Released: zero at once, then nothing more.
  await setPad(page, () => { window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; });
  await poll(allZero, 2000, "zero once the deadman is released");
  const sent2 = await page.evaluate(() => window.cockpit.sent);
  await sleep(500);
  assert.equal(await page.evaluate(() => window.cockpit.sent), sent2, "nothing sent after the release");
  assert.ok(allZero());
  // Held again, then the gamepad unplugged: zero.
  await setPad(page, () => { window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 }; });
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(expected), 10000, "driving again");
  await setPad(page, () => { window.__pad.connected = false; window.dispatchEvent(new Event("gamepaddisconnected")); });
  await poll(allZero, 2000, "zero once the gamepad is unplugged");
  // Plugged in and held again, then the page hidden (another tab): zero, and nothing sent.
  await setPad(page, () => { window.__pad.connected = true; });
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(expected), 10000, "driving again");
  await page.evaluate(() => {
    Object.defineProperty(document, "visibilityState", { value: "hidden", configurable: true });
    document.dispatchEvent(new Event("visibilitychange"));
  });
  await poll(allZero, 2000, "zero once the page is hidden");
  const sent3 = await page.evaluate(() => window.cockpit.sent);
  await sleep(500);
  assert.equal(await page.evaluate(() => window.cockpit.sent), sent3, "nothing sent while hidden");
  await page.close();
});

test("the mapping and the gain (selector and d-pad) are editable and kept in the browser's storage", async () => {
  const { page } = await open();
  await page.click("details summary");
  await page.$eval("#map-forward", (e) => { e.value = "a1"; e.dispatchEvent(new Event("change")); });
  // The gamepad's d-pad up steps the gain on each press (not while held).
  await setPad(page, () => { window.__pad.buttons[12] = { pressed: true, touched: true, value: 1 }; });
  await page.waitForFunction(() => document.getElementById("gain").value === "0.75", { timeout: 2000 });
  await sleep(300);
  assert.equal(await page.$eval("#gain", (e) => e.value), "0.75", "one step per press");
  await setPad(page, () => { window.__pad.buttons[12] = { pressed: false, touched: false, value: 0 }; });
  await page.select("#gain", "0.25");
  await page.reload({ waitUntil: "load" });
  assert.equal(await page.$eval("#map-forward", (e) => e.value), "a1");
  assert.equal(await page.$eval("#gain", (e) => e.value), "0.25");
  await page.$eval("#map-forward", (e) => { e.value = "q9"; e.dispatchEvent(new Event("change")); });
  assert.match(await text(page, "#mapping-error"), /not a mapping/);
  await page.evaluate(() => localStorage.clear());
  await page.close();
});

test("a mapping saved with the old axis names (x was port) is not taken: reset to the defaults, and the page says so", async () => {
  const { page } = await open();
  // The defaults before issue 43, as a browser kept them.
  const old = { x: "-a1", y: "a0", z: "b6-b7", yaw: "a2", pitch: "-a3", roll: "b15-b14", deadman: 4, gain_up: 12,
    gain_down: 13, kill: 1, clear_kill: 9, deadzone: 0.1, expo: 0.3, gain: 0.5 };
  assert.equal(await page.$eval("#mapping-notice", (e) => e.hidden), true, "no notice with nothing saved");
  await page.evaluate((m) => localStorage.setItem("caracara.cockpit.mapping", JSON.stringify(m)), old);
  await page.reload({ waitUntil: "load" });
  await page.waitForFunction(() => document.getElementById("link").dataset.lost === "false", { timeout: 15000 });
  assert.equal(await page.$eval("#mapping-notice", (e) => e.hidden), false);
  await onScreen(page, "#mapping-notice");
  assert.match(await text(page, "#mapping-notice"), /named the old axes \(x, y, z, yaw, pitch, roll\).*reset to the defaults/);
  assert.match(await text(page, "#events"), /reset to the defaults/);
  assert.equal(await page.$eval("#map-forward", (e) => e.value), "-a1");
  assert.equal(await page.$eval("label[for=map-forward]", (e) => e.textContent), "forward");
  const stored = await page.evaluate(() => JSON.parse(localStorage.getItem("caracara.cockpit.mapping")));
  assert.ok(!("x" in stored) && stored.forward === "-a1", `stored: ${JSON.stringify(stored)}`);
  await shotView(page, "mapping-reset");
  // Said once: the defaults are what is stored now.
  await page.reload({ waitUntil: "load" });
  assert.equal(await page.$eval("#mapping-notice", (e) => e.hidden), true);
  await page.evaluate(() => localStorage.clear());
  await page.close();
});

test("the attitude instrument reads as an aircraft's: nose up puts the horizon below the centre, roll right raises its right end, a clockwise turn moves the heading scale left", async () => {
  const { page } = await open();
  // Drawn on a canvas of its own (the live one follows /teensy); the colour at a point: "water" (above) or "ground".
  const at = (yaw, pitch, roll, points) => page.evaluate(async (yaw, pitch, roll, points) => {
    const { drawAttitude } = await import("./attitude.js");
    const c = document.createElement("canvas");
    c.width = 260; c.height = 300;
    drawAttitude(c, yaw, pitch, roll);
    const ctx = c.getContext("2d");
    return points.map(([x, y]) => {
      const [r, , b] = ctx.getImageData(x, y, 1, 1).data;
      return b > r ? "water" : r > b ? "ground" : "other";
    });
  }, yaw, pitch, roll, points);
  const rad = Math.PI / 180;
  // The instrument's centre is (130, 120), its radius 116 px for 45 degrees of pitch; the vehicle's
  // symbol is the yellow line at y 120 and the chevron below the centre, the points below keep off it.
  assert.deepEqual(await at(0, 0, 0, [[130, 110], [130, 140]]), ["water", "ground"]);
  assert.deepEqual(await at(0, 10 * rad, 0, [[100, 138]]), ["water"], "nose up: the horizon below the centre");
  assert.deepEqual(await at(0, -10 * rad, 0, [[100, 102]]), ["ground"], "nose down: the horizon above the centre");
  // Roll right 20 degrees: the horizon's right end up (right of the centre, a little above it: ground),
  // its left end down (left of the centre, a little below it: water).
  assert.deepEqual(await at(0, 0, 20 * rad, [[190, 108], [70, 132]]), ["ground", "water"], "roll right");
  assert.deepEqual(await at(0, 0, -20 * rad, [[190, 132], [70, 108]]), ["water", "ground"], "roll left");
  // Heading: the scale (240 px for 180 degrees, its top at y 246) has the north tick, 12 px long, under
  // the pointer at heading 0; after a clockwise turn of 20 degrees it is 27 px left of the pointer.
  const tickNear = (yaw, x) => page.evaluate(async (yaw, x) => {
    const { drawAttitude } = await import("./attitude.js");
    const c = document.createElement("canvas");
    c.width = 260; c.height = 300;
    drawAttitude(c, yaw, 0, 0);
    const row = c.getContext("2d").getImageData(x - 3, 246 + 9, 7, 1).data;
    let most = 0;
    for (let i = 0; i < row.length; i += 4) most = Math.max(most, Math.min(row[i], row[i + 1], row[i + 2]));
    return most;
  }, yaw, x);
  const left = Math.round(130 - 20 * 240 / 180);
  assert.ok(await tickNear(20 * rad, left) > 120, "after a clockwise turn the north tick is left of the pointer");
  assert.ok(await tickNear(-20 * rad, left) < 60, "not after a counter-clockwise one");
  assert.ok(await tickNear(-20 * rad, 260 - left) > 120, "after a counter-clockwise one it is right of the pointer");
  // The heading in figures as a compass reads it: 0 to 360, clockwise.
  assert.deepEqual(await page.evaluate(async () => {
    const { headingDegrees } = await import("./attitude.js");
    return [-0.2, 0, 1].map(headingDegrees);
  }), ["348.5", "0.0", "57.3"]);
  await page.close();
});

test("closing the page while driving zeroes the thrusters within the client-loss bound; the kill follows after pilot-lost's persistence, counted down on another page", async () => {
  const page = await drivingPage();
  // Another page, no pilot: it shows the daemon's pilot-lost countdown once the driving one is gone.
  const { page: other } = await open();
  await other.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 10000 });
  const since = wireNext();
  const closedAt = process.hrtime.bigint(); // CLOCK_MONOTONIC, as the wire log's times
  await page.close();
  const driven = new Set(Object.keys(Y_AXIS).map((i) => DEFAULT_MT[i] >> 1));
  const zeroTimes = await poll(() => {
    const first = new Map();
    for (const e of wireLog(since))
      if (e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] === ZERO && driven.has(e.addr) && !first.has(e.addr))
        first.set(e.addr, e.time_ns);
    return first.size === driven.size ? [...first.values()] : null;
  }, 5000, "zero orders to the four motors it drove");
  const shown = await countdown(other, '#banner li[data-kind="pilot-lost"]', /^PILOT LOST: the last pilot left; kill in (\d+\.\d) s/);
  const worstMs = Number(zeroTimes.reduce((a, b) => (a > b ? a : b)) - closedAt) / 1e6;
  console.log(`# page closed to the last zero order: ${worstMs.toFixed(1)} ms`);
  assert.ok(worstMs <= bound("CLIENT_LOSS_ZERO_MS_MAX"),
            `zeroed ${worstMs} ms after the close (bound ${bound("CLIENT_LOSS_ZERO_MS_MAX")} ms, tests/bounds.json)`);
  // The page was the last pilot: the kill output after pilot-lost's persistence, never before.
  const [edge] = await poll(() => { const k = killEdges(since); return k.length ? k : null; }, PILOT_LOST_MS + 5000,
                            "the pilot-lost kill");
  const killMs = Number(edge.time_ns - closedAt) / 1e6;
  console.log(`# page closed to the kill output: ${killMs.toFixed(0)} ms (pilot-lost persistence ${PILOT_LOST_MS} ms)`);
  assert.ok(killMs >= PILOT_LOST_MS, `killed ${killMs} ms after the close, before the persistence`);
  assert.ok(shown.seconds <= PILOT_LOST_MS / 1000, `a countdown of ${shown.seconds} s, longer than the persistence`);
  assertKillWhenCounted(edge, shown, "pilot lost");
  // The other page shows why, and its plain clear-kill re-arms (nothing is left to lose).
  await other.waitForFunction(() => document.getElementById("state").textContent === "killed", { timeout: 10000 });
  assert.equal(await other.$eval("#kill-source", (e) => e.dataset.source), "failsafe");
  assert.equal(await text(other, "#kill-source"), "a failsafe");
  await clearKill(other);
  await other.close();
});

async function killedBy(page, action) {
  const since = wireNext();
  await action();
  await poll(() => wireLog(since).some((e) => e.bus === "gpio" && e.addr === KILL_OUT && e.data[0] === 1), 5000,
    "the kill output on the wire");
  await page.waitForFunction(() => document.getElementById("state").textContent === "killed", { timeout: 5000 });
  assert.equal(await page.$eval("#kill-source", (e) => e.dataset.source), "dbus");
  assert.equal(await text(page, "#kill-source"), "Kill command (a pilot or caracaractl)", "the source in a pilot's words");
  assert.equal(vget("State"), "killed");
}
async function clearKill(page) {
  await page.click("#clear-kill");
  await page.click("#confirm-clear-yes");
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 20000 });
}

test("the kill button and the Space (while driving) and Escape keys each kill; clear-kill asks first", async () => {
  await rearm();
  const { page } = await open();
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 20000 });
  await killedBy(page, () => page.click("#kill"));
  await page.waitForFunction(() => document.querySelector("#events li")?.textContent.includes("kill"), { timeout: 5000 });
  await shot(page, "killed");
  // Cancelled: still killed.
  await page.click("#clear-kill");
  await page.$eval("#confirm-clear", (d) => d.close("cancel"));
  await sleep(500);
  assert.equal(vget("State"), "killed");
  await clearKill(page);
  // Space while driving, with a form control focused: killed, zero, and the page stops sending.
  await armPad(page);
  await stick(page, -0.6);
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(forwardMotion(forwardDemand(-0.6))), 10000, "driving");
  await page.focus("#gain");
  await killedBy(page, () => page.keyboard.press("Space"));
  assert.ok(allZero());
  await sleep(200);
  const sent = await page.evaluate(() => window.cockpit.sent);
  await sleep(500);
  assert.equal(await page.evaluate(() => window.cockpit.sent), sent, "nothing sent to a killed vehicle");
  await setPad(page, () => { window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; });
  await clearKill(page);
  await killedBy(page, () => page.keyboard.press("Escape"));
  // Escape with the Clear-kill question open: killed, and the question gone (Enter clears nothing).
  await clearKill(page);
  await page.click("#clear-kill");
  assert.ok(await page.$eval("#confirm-clear", (d) => d.open));
  await killedBy(page, () => page.keyboard.press("Escape"));
  assert.equal(await page.$eval("#confirm-clear", (d) => d.open), false, "the dialog closed by the kill");
  await page.keyboard.press("Enter");
  await sleep(800);
  assert.equal(vget("State"), "killed", "Enter after the Escape cleared nothing");
  await page.$eval("#confirm-clear", (d) => { if (d.open) d.close("cancel"); }); // Enter may have asked again
  await clearKill(page);
  await page.close();
});

test("the recorded dives: the list as caracaractl dives has it, each one's .cdive and MCAP, and its plot", async () => {
  const { page, log } = await open();
  const listed = execFileSync(`${BUILD}/tools/caracaractl`, ["dives", "--dir", process.env.CARACARA_DIVES_DIR],
    { encoding: "utf8" }).trim().split("\n").slice(1, -1).map((l) => l.split(/\s+/)[0].replace(/\.cdive$/, ""));
  assert.ok(listed.length > 0, "the kills above closed dives");
  await page.waitForFunction((n) => document.querySelectorAll("#dives tbody tr button").length === n, { timeout: 5000 },
    listed.length);
  assert.deepEqual(await page.$$eval("#dives tbody tr", (rows) => rows.map((r) => r.cells[0].textContent)),
    [...listed].reverse(), "newest first");
  const name = listed[0];
  const cdive = await fetch(new URL(`dives/${name}.cdive`, HTTP));
  assert.equal(cdive.status, 200);
  assert.deepEqual(Buffer.from(await cdive.arrayBuffer()), fs.readFileSync(path.join(process.env.CARACARA_DIVES_DIR, `${name}.cdive`)));
  const mcap = Buffer.from(await (await fetch(new URL(`dives/${name}.mcap`, HTTP))).arrayBuffer());
  assert.deepEqual([...mcap.subarray(0, 8)], [0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a], "the MCAP magic");
  for (const p of [`dives/${name}.txt`, "dives/..%2fetc.cdive", `dives/../${name}.cdive`, "dives/nothing.cdive"])
    assert.equal((await fetch(new URL(p, HTTP))).status, 404, p);
  await page.click("#dives tbody tr button");
  await page.waitForSelector("#dive-plot svg");
  assert.equal(await page.$$eval("#dive-plot svg polyline", (l) => l.length), MOTORS);
  await shot(page, "dives");
  assert.deepEqual(log.errors, []);
  await page.close();
});

test("after a kill and Clear kill, or a reconnect, with the deadman and the stick held, nothing moves until released, centred and pressed again", async () => {
  await rearm();
  const { page } = await open();
  assert.match(await text(page, "#arm"), /press the deadman|release the deadman/, "a loaded page says how to arm");
  await armPad(page);
  await stick(page, -0.6);
  const expected = forwardMotion(forwardDemand(-0.6));
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(expected), 10000, "driving");
  await killedBy(page, () => page.click("#kill"));
  const since = wireNext();
  const sent0 = await sent(page);
  await clearKill(page); // deadman and stick held all along
  await page.waitForFunction(() => /release the deadman and centre the sticks/.test(document.getElementById("arm").textContent),
    { timeout: 1000 });
  await shotView(page, "rearm-wait");
  await sleep(1500);
  await deadman(page, false); // released, the stick still forward: not centred
  await sleep(400);
  assert.equal(await arm(page), "release", "the stick is not centred");
  await deadman(page, true); // pressed again with the stick forward
  await sleep(800);
  assert.deepEqual(nonZeroOrders(since).length, 0, "thrust on the wire before arming on purpose");
  assert.equal(await sent(page), sent0, "a motion command sent before arming on purpose");
  assert.equal(vget("State"), "ready");
  // Released, centred, pressed: armed; then the stick drives.
  await armPad(page);
  assert.match(await text(page, "#arm"), /armed/);
  await stick(page, -0.6);
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(expected), 10000, "driving once armed on purpose");
  // The connection drops and comes back within pilot-lost's persistence, deadman and stick held.
  const connects = await page.evaluate(() => window.cockpit.connects);
  await page.evaluate(() => window.cockpit.client.close());
  // While the link is down the page counts pilot-lost's kill down from the daemon's persistence.
  const lost = await countdown(page, '#banner li[data-kind="link-lost"]', /pilot-lost kill in (\d+\.\d) s/);
  assert.ok(lost.seconds <= PILOT_LOST_MS / 1000 &&
            lost.seconds >= (PILOT_LOST_MS - bound("COCKPIT_LINK_LOST_BANNER_MS_MAX")) / 1000,
            `the link-lost countdown began at ${lost.seconds} s, not the daemon's ${PILOT_LOST_MS} ms`);
  await poll(allZero, 2000, "the daemon zeroes the pilot that left");
  const since2 = wireNext();
  await page.waitForFunction((n) => window.cockpit.connects > n && window.cockpit.state !== null, { timeout: PILOT_LOST_MS },
    connects);
  const sent1 = await sent(page);
  await sleep(600);
  assert.equal(await sent(page), sent1, "a motion command sent after the reconnect");
  assert.deepEqual(nonZeroOrders(since2).length, 0, "thrust on the wire after the reconnect");
  // No pilot came back: the daemon's pilot-lost kill, and the page shows the daemon's state.
  await page.waitForFunction(() => document.getElementById("state").textContent === "killed", { timeout: PILOT_LOST_MS + 5000 });
  assert.equal(await page.$eval("#kill-source", (e) => e.dataset.source), "failsafe");
  await deadman(page, false);
  await stick(page, 0);
  await page.close();
});

test("the gamepad's B kills on its press; Start clears the kill only when held 2 s, never on a tap", async () => {
  await rearm();
  const { page } = await open();
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 20000 });
  await killedBy(page, () => page.evaluate(button(1, true)));
  await page.evaluate(button(1, false));
  await page.evaluate(button(9, true));
  await sleep(300);
  await page.evaluate(button(9, false));
  await sleep(2500);
  assert.equal(vget("State"), "killed", "a tap of Start cleared the kill");
  await page.evaluate(button(9, true));
  await page.waitForFunction(() => /Clear kill: hold/.test(document.getElementById("arm").textContent), { timeout: 2000 });
  await sleep(1000);
  assert.equal(vget("State"), "killed", "cleared before 2 s");
  await poll(() => vget("State") !== "killed", 5000, "the kill cleared by the long press");
  await page.evaluate(button(9, false));
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 10000 });
  await page.close();
});

test("a failsafe shows in the header's banner, on screen when scrolled, and stops the page sending: surfacing with its time left, an excluded thruster", async () => {
  const page = await drivingPage();
  const surfacing = '#banner li[data-kind="surfacing"]';
  const since = wireNext();
  simFault(3, "water-detect", true);
  try {
    const shown = await countdown(page, surfacing, /^SURFACING: water in the thruster \(thruster 3\)\. Ascent: (\d+\.\d) s left/);
    assert.ok(shown.seconds <= SURFACE_MS / 1000 && shown.seconds >= SURFACE_MS / 1000 - 1,
              `the ascent's countdown began at ${shown.seconds} s, not the configured ${SURFACE_MS} ms`);
    await page.waitForFunction(() => document.getElementById("arm").dataset.arm === "release", { timeout: 2000 });
    const s0 = await sent(page);
    await sleep(1000);
    assert.equal(await sent(page), s0, "motion sent while surfacing");
    const later = await countdown(page, surfacing, /Ascent: (\d+\.\d) s left/);
    assert.ok(later.seconds < shown.seconds, `the countdown stood at ${shown.seconds} s, then ${later.seconds} s`);
    const refusals = await page.$$eval("#events li", (l) => l.filter((e) => /refused/.test(e.textContent)).length);
    assert.ok(refusals <= 1, `${refusals} refusal events (one at most)`);
    await page.evaluate(() => window.scrollTo(0, document.documentElement.scrollHeight));
    await sleep(200);
    for (const sel of ["#kill", "#state", surfacing]) await onScreen(page, sel);
    await shotView(page, "surfacing");
    await page.waitForFunction(() => document.getElementById("state").textContent === "killed", { timeout: 10000 });
    assert.equal(vget("State"), "killed");
    assertKillWhenCounted(killEdges(since)[0], shown, "surfacing");
  } finally {
    simFault(3, "water-detect", false);
  }
  await page.waitForFunction((s) => !document.querySelector(s), { timeout: 10000 }, surfacing);
  await deadman(page, false);
  await stick(page, 0);
  await rearm();
  const excluded = '#banner li[data-kind="excluded"]';
  simFault(2, "overtemp", true);
  try {
    await page.waitForSelector(excluded, { timeout: 5000 });
    assert.match(await text(page, excluded), /^THRUSTER 2 EXCLUDED: over-temperature/);
    assert.deepEqual(vget("Failsafes"), [["overtemp", "exclude", 2]]);
    await shotView(page, "excluded");
  } finally {
    simFault(2, "overtemp", false);
  }
  await page.waitForFunction((s) => !document.querySelector(s), { timeout: 15000 }, excluded);
  await page.close();
});

test("the controller in words: the commanding process by name, \"this page\" while this page drives", async () => {
  const page = await drivingPage();
  await page.waitForFunction(() => document.getElementById("controller").textContent === "this page", { timeout: 5000 });
  await deadman(page, false);
  await stick(page, 0);
  await rearm();
  const p = hold("thrust", 500, 0, 0, 0, 0, 0, 0, 0, "--for", 10);
  try {
    await page.waitForFunction(() => /^caracaractl \(pid \d+\)$/.test(document.getElementById("controller").textContent),
      { timeout: 10000 });
    const pid = Number(/pid (\d+)/.exec(await text(page, "#controller"))[1]);
    assert.equal(pid, p.pid, "the caracaractl that commands");
  } finally {
    p.kill();
  }
  await page.close();
});

test("phone (412 px) and tablet widths: no sideways scrolling; KILL and the state on screen at every scroll position; the Clear-kill question fully on screen", async () => {
  const { page } = await open();
  for (const [w, h, name] of [[412, 915, "phone-412"], [800, 1280, "tablet-800"], [1024, 768, "tablet-1024"], [1400, 900, "desktop"]]) {
    await page.setViewport({ width: w, height: h });
    await sleep(300);
    const [laid, wide] = await page.evaluate(() => [document.documentElement.scrollWidth, innerWidth]);
    assert.ok(laid <= wide, `${name}: laid out ${laid} px wide in ${wide}`);
    for (const f of [0, 0.5, 1]) {
      await page.evaluate((y) => window.scrollTo(0, y * (document.documentElement.scrollHeight - innerHeight)), f);
      await sleep(100);
      for (const sel of ["#kill", "#state", "#kill-source", "#clear-kill", "#link"]) await onScreen(page, sel);
    }
    await shotView(page, name);
    await page.click("#clear-kill");
    for (const sel of ["#confirm-clear", "#confirm-clear-yes"]) await onScreen(page, sel);
    if (w === 412) await shotView(page, `${name}-clear-kill`);
    await page.$eval("#confirm-clear", (d) => d.close("cancel"));
  }
  await page.close();
});

test("two tabs fetch the dive list once per change between them, not once each per event", async () => {
  for (const p of await browser.pages()) await p.close(); // only these two tabs of the cockpit
  await rearm();
  const a = await open();
  const b = await open();
  await sleep(1500);
  const fetches = () => [...a.log.requests, ...b.log.requests].filter((u) => new URL(u).pathname === "/dives/").length;
  const rows = (p) => p.$$eval("#dives tbody tr", (r) => r.length);
  const before = fetches();
  const rowsBefore = await rows(a.page);
  busctl("call", VEHICLE, ROOT, VEHICLE, "Kill");
  await sleep(300);
  busctl("call", VEHICLE, ROOT, VEHICLE, "ClearKill");
  await poll(() => vget("State") === "ready", 20000, "ready again");
  await poll(async () => (await rows(a.page)) === rowsBefore + 1 && (await rows(b.page)) === rowsBefore + 1, 5000,
    "the new dive in both tabs");
  await sleep(1500);
  console.log(`# /dives/ fetches for one kill and clear-kill in two tabs: ${fetches() - before}`);
  assert.equal(fetches() - before, 1, "one fetch between the two tabs");
  await a.page.close();
  await b.page.close();
});

// --- commissioning (docs/commissioning.md): the motor test and direction detection from the page ---
// test_cockpit.py's rig mounts thruster 2 reversed in the simulator, with a short detection.
const REVERSED = 2;
const onlyOn = (thruster, value) => [...Array(MOTORS).keys()].map((i) => (i === thruster ? speedByte(value) : ZERO));
const wireIs = (speeds) => JSON.stringify(simSpeeds()) === JSON.stringify(speeds);
const addrOf = (i) => DEFAULT_MT[i] >> 1;

// The commissioning panel scrolled to just under the sticky header.
const toPanel = (page) => page.evaluate(() => window.scrollTo(0, document.getElementById("commissioning").offsetTop -
  document.querySelector("header").offsetHeight - 8));
// A page with the motor test chosen, its button under the mouse.
async function motorTestPage(thruster, value) {
  await rearm();
  const { page, log } = await open();
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 20000 });
  await page.waitForFunction(() => document.getElementById("mt-limit").textContent === "±1500", { timeout: 5000 });
  await page.select("#mt-thruster", String(thruster));
  await page.$eval("#mt-value", (e, v) => { e.value = v; }, String(value));
  await toPanel(page);
  await page.hover("#mt-run");
  await onScreen(page, "#mt-run"); // not under the header: the press is the button's
  return { page, log };
}

test("motor test from the page: the value on that thruster on the wire and the others at zero while held, kept alive by the page; zero once released", async () => {
  const { page, log } = await motorTestPage(5, 800);
  const since = wireNext();
  await page.mouse.down();
  await poll(() => wireIs(onlyOn(5, 800)), 5000, "thruster 5 alone at 800 on the wire");
  // The running test in the header's status banner (from MotorTest in /vehicle/state) and in the panel.
  await page.waitForFunction(() => document.querySelector('#banner li[data-kind="motor-test"]'), { timeout: 5000 });
  assert.equal(await text(page, '#banner li[data-kind="motor-test"]'), "MOTOR TEST: thruster 5 at 800, the others held at zero");
  assert.equal(await page.$eval("#mt-status", (e) => e.dataset.thruster), "5");
  await onScreen(page, "#kill");
  await shotView(page, "motor-test");
  // Held past the daemon's keep-alive (500 ms) twice over: the page's repeats keep it running.
  await sleep(1200);
  assert.ok(wireIs(onlyOn(5, 800)), "the motor test stopped while held");
  const orders = wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 &&
    DEFAULT_MT.includes(e.addr << 1) && e.data[0] !== ZERO);
  assert.ok(orders.length > 0);
  assert.deepEqual([...new Set(orders.map((e) => e.addr))], [addrOf(5)], "a non-zero order to another thruster");
  assert.deepEqual([...new Set(orders.map((e) => e.data[0]))], [speedByte(800)]);
  // Released: zero at once (the page's last order), then nothing more from the page.
  const sinceRelease = wireNext(); // the wire at 800 until the release: its first zero is the release's
  const released = process.hrtime.bigint();
  await page.mouse.up();
  const [zeroAt] = await poll(() => firstZeros(sinceRelease, new Set([addrOf(5)])), 2000, "thruster 5 at zero");
  console.log(`# motor test released to thruster 5's zero order: ${(Number(zeroAt - released) / 1e6).toFixed(1)} ms`);
  await poll(() => wireIs(onlyOn(5, 0)), 2000, "every thruster at zero");
  const sentAfter = await page.evaluate(() => window.cockpit.commissioning.sent);
  await sleep(600);
  assert.equal(await page.evaluate(() => window.cockpit.commissioning.sent), sentAfter, "sent after the release");
  await page.waitForFunction(() => document.getElementById("mt-status").dataset.thruster === "-1", { timeout: 3000 });
  assert.equal(vget("State"), "ready");
  // Beyond the daemon's limit: a named error on the page, nothing sent, nothing on the wire.
  const sinceBad = wireNext();
  await page.$eval("#mt-value", (e) => { e.value = "2000"; });
  await page.mouse.down();
  await sleep(400);
  await page.mouse.up();
  assert.match(await text(page, "#mt-error"), /within ±1500 \(commissioning\.motor_test_limit\)/);
  assert.equal(await page.evaluate(() => window.cockpit.commissioning.sent), sentAfter, "a value beyond the limit sent");
  assert.equal(nonZeroOrders(sinceBad).length, 0);
  assert.deepEqual(log.errors, []);
  await page.close();
});

test("motor test: a dropped connection or a closed page while held stops the thruster (the bridge keeps nothing alive)", async () => {
  const { page } = await motorTestPage(1, -700);
  await page.mouse.down();
  await poll(() => wireIs(onlyOn(1, -700)), 5000, "thruster 1 at -700");
  // The page's socket drops, the button still held: caracarad zeroes the connection that left,
  // and the page, reconnected, sends no motor test until the button is pressed again.
  const connects = await page.evaluate(() => window.cockpit.connects);
  await page.evaluate(() => window.cockpit.client.close());
  await poll(allZero, 2000, "zero once the page's connection dropped");
  await page.waitForFunction((n) => window.cockpit.connects > n, { timeout: 5000 }, connects);
  const since = wireNext();
  await sleep(700);
  assert.equal(nonZeroOrders(since).length, 0, "the motor test came back after the reconnect");
  await page.mouse.up();
  // Pressed again (the vehicle re-armed: the page that left was its last pilot), then the page
  // closed while held.
  await rearm();
  await page.mouse.down();
  await poll(() => wireIs(onlyOn(1, -700)), 5000, "thruster 1 at -700 again");
  const sinceClose = wireNext();
  const closedAt = process.hrtime.bigint();
  await page.close();
  const [zeroAt] = await poll(() => firstZeros(sinceClose, new Set([addrOf(1)])), 2000, "thruster 1 at zero");
  const ms = Number(zeroAt - closedAt) / 1e6;
  console.log(`# page closed during a motor test to the zero order: ${ms.toFixed(1)} ms`);
  assert.ok(ms <= bound("CLIENT_LOSS_ZERO_MS_MAX"), `zeroed ${ms} ms after the close (bound ${bound("CLIENT_LOSS_ZERO_MS_MAX")} ms)`);
  await poll(allZero, 2000, "every thruster at zero");
});

test("direction detection from the page: progress while it pulses, the reversed thruster in the result and in the fragment to copy", async () => {
  await rearm();
  const { page, log } = await open();
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 20000 });
  const origin = new URL(HTTP).origin;
  await browser.defaultBrowserContext().overridePermissions(origin, ["clipboard-read", "clipboard-write", "clipboard-sanitized-write"]);
  await toPanel(page);
  const since = wireNext();
  const started = Date.now();
  await page.click("#detect-start");
  await page.waitForFunction(() => /pulsing thruster \d/.test(document.getElementById("detect-status").textContent),
    { timeout: 30000 });
  assert.ok(await page.$eval("#detect-start", (e) => e.disabled), "start offered again while running");
  await onScreen(page, "#kill");
  await shotView(page, "detection-running");
  await page.waitForFunction(() => document.getElementById("detect-status").dataset.phase !== "running", { timeout: 180000 });
  console.log(`# direction detection from the page: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  assert.equal(await page.$eval("#detect-status", (e) => e.dataset.phase), "done", await text(page, "#detect-status"));
  for (const row of await page.$$eval("#detect-result tbody tr", (rows) => rows.map((r) => r.innerText.replace(/\s+/g, " "))))
    console.log(`# ${row}`);
  const verdicts = await page.$$eval("#detect-result tbody tr", (rows) => rows.map((r) => r.dataset.verdict));
  assert.deepEqual(verdicts, [...Array(MOTORS).keys()].map((i) => (i === REVERSED ? "reversed" : "ok")));
  assert.equal(await text(page, "#detect-status"), `done: reversed ${REVERSED}`);
  // The vehicle's side: each thruster pulsed alone, in turn, and all at zero at the end.
  const pulsed = [];
  for (const e of wireLog(since))
    if (e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] !== ZERO) {
      const i = DEFAULT_MT.indexOf(e.addr << 1);
      if (i >= 0 && pulsed.at(-1) !== i) pulsed.push(i);
    }
  assert.deepEqual(pulsed, [...Array(MOTORS).keys()], "the pulses on the wire, one thruster after the other");
  assert.ok(allZero());
  // The fragment: eight [[thruster]] tables, only thruster 2's reversed flag flipped.
  const fragment = await page.$eval("#detect-fragment", (e) => e.value);
  const tables = fragment.split(/^\[\[thruster\]\]/m).slice(1); // the tables, not the comment naming them
  assert.equal(tables.length, MOTORS);
  tables.forEach((t, i) => assert.match(t, new RegExp(`reversed = ${i === REVERSED}\\n`), `table ${i}`));
  await page.click("#detect-copy");
  await page.waitForFunction(() => document.getElementById("detect-copied").textContent !== "", { timeout: 2000 });
  assert.equal(await text(page, "#detect-copied"), "copied");
  assert.equal(await page.evaluate(() => navigator.clipboard.readText()), fragment, "the clipboard holds the fragment");
  await toPanel(page);
  await shotView(page, "commissioning"); // docs/cockpit-commissioning.png
  assert.deepEqual(log.errors, []);
  await page.close();
});

test("a page whose connection drops shows it at once, with the age of the last message, and a kill it could not send", async () => {
  await rearm();
  const { page } = await open();
  await armPad(page); // held, sticks centred: zero motion at 20 Hz
  process.kill(Number(process.env.CARACARA_FORWARD_PID), "SIGTERM"); // the ssh -L forward goes
  await page.waitForFunction(() => document.getElementById("link").dataset.lost === "true", { timeout: 2000 });
  await sleep(1200);
  assert.match(await text(page, "#link"), /CONNECTION LOST — last message \d+\.\d s ago/);
  assert.ok(await page.evaluate(() => document.body.classList.contains("stale")), "the last known values dimmed");
  assert.equal(await text(page, "#state"), "unknown", "no state from memory");
  assert.match(await text(page, '#banner li[data-kind="link-lost"]'), /^LINK LOST \d+\.\d s/);
  assert.notEqual(await text(page, "#deadman"), "HELD", "the deadman said HELD with no link");
  const s0 = await sent(page);
  await sleep(500);
  assert.equal(await sent(page), s0, "sends counted with no link");
  await page.click("#kill");
  assert.match(await text(page, '#banner li[data-kind="kill-not-sent"]'), /^KILL NOT SENT/);
  await shot(page, "lost");
  await page.close();
});
