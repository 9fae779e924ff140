// Which pages may drive (issue 46), in Debian's chromium through `caracaractl bridge`'s forward
// (its key, ForwardRelay) to the rig's bridge (its Origin check): the forward without its key
// or with a wrong one refused, the cockpit with it driving; a page of another local origin
// that opens ws://localhost:PORT and publishes motion refused by the bridge (its WebSocket
// carries the key's cookie: cookies do not tell localhost's ports apart), nothing on the wire
// and the refusal in the bridge's log; a page of another site refused by the forward (no
// cookie: SameSite); the same page from the allow-listed origin driving; the reference client,
// which sends no Origin, driving with the printed ws:// address. Judged on the simulator's
// wire log. Run by test_cockpit.py.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import http from "node:http";
import { armPad, launch, openCockpit } from "./chromium.mjs";
import { DEFAULT_MT, ZERO, connect, poll, rearm, sleep, vget, wireLog, wireNext } from "./lib.mjs";

const FORWARD_HTTP = process.env.CARACARA_FORWARD_HTTP; // http://localhost:PORT/?key=...
const FORWARD_WS = process.env.CARACARA_FORWARD_WS;
const PORT = Number(process.env.CARACARA_FORWARD_PORT);
const OTHER = Number(process.env.CARACARA_OTHER_PORT);     // a page of another origin
const ALLOWED = Number(process.env.CARACARA_ALLOWED_PORT); // the bridge's --allow-origin http://localhost:ALLOWED
const BRIDGE_LOG = process.env.CARACARA_BRIDGE_LOG;
const FORWARD_LOG = process.env.CARACARA_FORWARD_LOG;
// How long a refused page is watched trying: the same page from the allowed origin must move the
// vehicle well within it (checked below), so a page that got through would have been seen.
const WATCH_MS = 3000;

// The page another site would serve: it opens the bridge's WebSocket (again every 200 ms when
// refused) and publishes a forward Twist at 20 Hz on /command/motion once open.
const PAGE = `<!doctype html><meta charset="utf-8"><title>another page</title><script>
window.result = { opened: 0, refused: 0, sent: 0 };
const twist = new TextEncoder().encode(JSON.stringify({ linear: { x: 0.5, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } }));
function open() {
  const ws = new WebSocket("ws://localhost:${PORT}/", ["foxglove.websocket.v1"]);
  let timer = null;
  ws.onopen = () => {
    result.opened++;
    ws.send(JSON.stringify({ op: "advertise", channels: [{ id: 1, topic: "/command/motion", encoding: "json", schemaName: "geometry_msgs/Twist" }] }));
    timer = setInterval(() => {
      const f = new Uint8Array(5 + twist.length);
      f[0] = 1;
      new DataView(f.buffer).setUint32(1, 1, true);
      f.set(twist, 5);
      ws.send(f);
      result.sent++;
    }, 50);
  };
  ws.onclose = () => { clearInterval(timer); if (!result.opened) { result.refused++; setTimeout(open, 200); } };
}
open();
</script>`;

let chromium;
let browser;
const servers = [];

before(async () => {
  chromium = await launch();
  browser = chromium.browser;
  for (const port of [OTHER, ALLOWED]) {
    const server = http.createServer((req, res) => { res.setHeader("Content-Type", "text/html"); res.end(PAGE); });
    await new Promise((resolve) => server.listen(port, "127.0.0.1", resolve));
    servers.push(server);
  }
});
after(async () => {
  await chromium?.close();
  for (const s of servers) s.close();
});

// Orders of a motor value other than zero on the wire since `since`.
const nonZeroOrders = (since) => wireLog(since).filter((e) => e.bus === "i2c" && !e.read && e.data.length === 3 &&
  DEFAULT_MT.includes(e.addr << 1) && e.data[0] !== ZERO);
const read = (file) => fs.readFileSync(file, "utf8");

async function pageOf(url) {
  const page = await browser.newPage();
  await page.goto(url, { waitUntil: "load" });
  return page;
}

test("the forward refuses a browser without its key or with a wrong one, with the reason", async () => {
  for (const [url, why] of [[`http://localhost:${PORT}/`, /needs the key of its session/],
    [`http://localhost:${PORT}/?key=${"0".repeat(64)}`, /wrong key for this forward/]]) {
    const page = await browser.newPage();
    const res = await page.goto(url, { waitUntil: "load" });
    assert.equal(res.status(), 403, url);
    assert.match(await page.evaluate(() => document.body.textContent), why);
    await page.close();
  }
  assert.match(read(FORWARD_LOG), new RegExp(`refused a connection to localhost:${PORT} without the key`));
  assert.match(read(FORWARD_LOG), new RegExp(`refused a connection to localhost:${PORT} with a wrong key`));
});

test("the cockpit at the printed address drives: the key traded for a cookie, gone from the address", async () => {
  await rearm();
  const { page, log } = await openCockpit(browser, FORWARD_HTTP);
  assert.equal(page.url(), `http://localhost:${PORT}/`, "the key left the address");
  const since = wireNext();
  await armPad(page);
  await page.evaluate(() => { window.__pad.axes[1] = -0.6; });
  await poll(() => nonZeroOrders(since).length > 0, 10000, "the cockpit's forward on the wire");
  await page.evaluate(() => { window.__pad.axes[1] = 0; window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; });
  assert.deepEqual(log.errors, []);
  await page.close();
});

test("a page of another local origin opens ws://localhost:PORT and publishes motion: refused by the bridge, nothing moves", async () => {
  await rearm(); // ready: a motion that got through would drive
  const since = wireNext();
  const page = await pageOf(`http://localhost:${OTHER}/`);
  await poll(() => page.evaluate(() => window.result.refused > 0), 10000, "the page's WebSocket refused");
  await sleep(WATCH_MS);
  const result = await page.evaluate(() => window.result);
  await page.close();
  console.log(`# http://localhost:${OTHER}: ${result.refused} WebSocket attempts refused`);
  assert.equal(result.opened, 0, "the other origin's WebSocket opened");
  assert.equal(result.sent, 0);
  assert.deepEqual(nonZeroOrders(since), [], "a thruster moved");
  assert.equal(vget("State"), "ready", "the vehicle stayed ready (a motion would have driven)");
  // Its handshake carried the key's cookie (localhost is one site, whatever the port): the
  // forward let it through and the bridge refused it by its Origin, naming it.
  assert.match(read(BRIDGE_LOG), new RegExp(`refused a WebSocket upgrade from origin 'http://localhost:${OTHER}'`));
});

test("a page of another site (127.0.0.1 is not localhost) gets no cookie: refused by the forward, nothing moves", async () => {
  await rearm();
  const since = wireNext();
  const page = await pageOf(`http://127.0.0.1:${OTHER}/`);
  await poll(() => page.evaluate(() => window.result.refused > 0), 10000, "the page's WebSocket refused");
  await sleep(WATCH_MS);
  const result = await page.evaluate(() => window.result);
  await page.close();
  assert.equal(result.opened, 0);
  assert.deepEqual(nonZeroOrders(since), [], "a thruster moved");
  assert.equal(vget("State"), "ready");
  assert.match(read(FORWARD_LOG), new RegExp(`refused a connection to localhost:${PORT} without the key \\(from a page of http://127\\.0\\.0\\.1:${OTHER}\\)`));
});

test("the same page from the allow-listed origin drives", async () => {
  await rearm();
  const since = wireNext();
  const t0 = Date.now();
  const page = await pageOf(`http://localhost:${ALLOWED}/`);
  await poll(() => nonZeroOrders(since).length > 0, 10000, "the allowed page's motion on the wire");
  const movedAfterMs = Date.now() - t0;
  const result = await page.evaluate(() => window.result);
  await page.close();
  console.log(`# http://localhost:${ALLOWED}: on the wire ${movedAfterMs} ms after the page's load began`);
  assert.equal(result.refused, 0);
  assert.ok(movedAfterMs < WATCH_MS, `the allowed page moved the vehicle in ${movedAfterMs} ms, within the refused pages' watch`);
  await rearm(); // it was the last pilot: no pilot-lost kill for the next test
});

test("the reference client, which sends no Origin (as Foxglove desktop), drives with the printed ws:// address", async () => {
  await rearm();
  const since = wireNext();
  const c = await connect(FORWARD_WS);
  const id = c.publisher("/command/motion");
  const timer = setInterval(() => c.publish(id, { linear: { x: 0.5 }, angular: {} }), 50);
  try {
    await poll(() => nonZeroOrders(since).length > 0, 10000, "the reference client's motion on the wire");
  } finally {
    clearInterval(timer);
    await c.close();
  }
  await rearm();
});
