// The cockpit (tools/cockpit, docs/cockpit.md) in Debian's chromium, headless, driven by
// puppeteer-core, loaded from caracara-bridge through a real ssh -L forward; judged on the
// simulator's side (inspection API, wire log). Run by test_cockpit.py.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { bound } from "./bounds.mjs";
import fs from "node:fs";
import net from "node:net";
import path from "node:path";
import { launch, openCockpit, surge } from "./chromium.mjs";
import { execFileSync } from "node:child_process";
import { BUILD, DEFAULT_MT, MOTORS, MOTOR_MAX, PILOT_LOST_MS, X_AXIS, ZERO, killEdges, poll, rearm, simSpeeds, simThruster,
  sleep, speedByte, vget, wireLog, wireNext } from "./lib.mjs";

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

const xMotion = (v) => [...Array(MOTORS).keys()].map((i) => (i in X_AXIS ? speedByte(X_AXIS[i] * Math.round(v * MOTOR_MAX)) : ZERO));
const allZero = () => simSpeeds().every((s) => s === ZERO);

test("a scripted gamepad drives motion to the wire as the mixing says only while the deadman is held", async () => {
  await rearm();
  const { page } = await open();
  await setPad(page, () => { window.__pad.axes[1] = -0.6; });
  await sleep(600);
  assert.ok(allZero(), "stick forward without the deadman: nothing moves");
  assert.equal(await page.evaluate(() => window.cockpit.sent), 0, "no command without the deadman");
  await setPad(page, () => { window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 }; });
  const expected = xMotion(surge(-0.6));
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(expected), 10000, "the gamepad's surge on the wire");
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
  await page.$eval("#map-x", (e) => { e.value = "a1"; e.dispatchEvent(new Event("change")); });
  // The gamepad's d-pad up steps the gain on each press (not while held).
  await setPad(page, () => { window.__pad.buttons[12] = { pressed: true, touched: true, value: 1 }; });
  await page.waitForFunction(() => document.getElementById("gain").value === "0.75", { timeout: 2000 });
  await sleep(300);
  assert.equal(await page.$eval("#gain", (e) => e.value), "0.75", "one step per press");
  await setPad(page, () => { window.__pad.buttons[12] = { pressed: false, touched: false, value: 0 }; });
  await page.select("#gain", "0.25");
  await page.reload({ waitUntil: "load" });
  assert.equal(await page.$eval("#map-x", (e) => e.value), "a1");
  assert.equal(await page.$eval("#gain", (e) => e.value), "0.25");
  await page.$eval("#map-x", (e) => { e.value = "q9"; e.dispatchEvent(new Event("change")); });
  assert.match(await text(page, "#mapping-error"), /not a mapping/);
  await page.evaluate(() => localStorage.clear());
  await page.close();
});

test("closing the page while driving zeroes the thrusters within the client-loss bound; the kill follows after pilot-lost's persistence", async () => {
  await rearm();
  const { page } = await open();
  await setPad(page, () => { window.__pad.axes[1] = -0.6; window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 }; });
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(surge(-0.6))), 10000, "driving");
  const since = wireNext();
  const closedAt = process.hrtime.bigint(); // CLOCK_MONOTONIC, as the wire log's times
  await page.close();
  const driven = new Set(Object.keys(X_AXIS).map((i) => DEFAULT_MT[i] >> 1));
  const zeroTimes = await poll(() => {
    const first = new Map();
    for (const e of wireLog(since))
      if (e.bus === "i2c" && !e.read && e.data.length === 3 && e.data[0] === ZERO && driven.has(e.addr) && !first.has(e.addr))
        first.set(e.addr, e.time_ns);
    return first.size === driven.size ? [...first.values()] : null;
  }, 5000, "zero orders to the four motors it drove");
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
  // Another page shows why, and its plain clear-kill re-arms (nothing is left to lose).
  const { page: other } = await open();
  await other.waitForFunction(() => document.getElementById("state").textContent === "killed", { timeout: 10000 });
  assert.equal(await text(other, "#kill-source"), "failsafe");
  await clearKill(other);
  await other.close();
});

async function killedBy(page, action) {
  const since = wireNext();
  await action();
  await poll(() => wireLog(since).some((e) => e.bus === "gpio" && e.addr === KILL_OUT && e.data[0] === 1), 5000,
    "the kill output on the wire");
  await page.waitForFunction(() => document.getElementById("state").textContent === "killed", { timeout: 5000 });
  assert.equal(await text(page, "#kill-source"), "dbus");
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
  await setPad(page, () => { window.__pad.axes[1] = -0.6; window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 }; });
  await poll(() => JSON.stringify(simSpeeds()) === JSON.stringify(xMotion(surge(-0.6))), 10000, "driving");
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
  assert.deepEqual(await page.$$eval("#dives tbody tr", (rows) => rows.map((r) => r.cells[0].textContent)), listed);
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

test("a page whose connection drops shows it at once, with the age of the last message", async () => {
  const { page } = await open();
  process.kill(Number(process.env.CARACARA_FORWARD_PID), "SIGTERM"); // the ssh -L forward goes
  await page.waitForFunction(() => document.getElementById("link").dataset.lost === "true", { timeout: 2000 });
  await sleep(1200);
  assert.match(await text(page, "#link"), /CONNECTION LOST — last message \d+\.\d s ago/);
  assert.ok(await page.evaluate(() => document.body.classList.contains("stale")), "the last known values dimmed");
  await shot(page, "lost");
  await page.close();
});
