// caracara-bridge's bounds (issue 35), on a TCP bridge with its token whose dive directory is
// full (test_bridge.py test_6 starts it): a Kill and a close are not held up by another
// client's dive listing, and a client that sends without reading is paused, then closed with
// the reason, with the bridge's memory bounded. Bounds from tests/e2e/bounds.py (passed in the
// environment by test_bridge.py).
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import WebSocket from "ws";
import { bound } from "./bounds.mjs";
import { connect, poll, sleep } from "./lib.mjs";
import { closesDuringListing, killsDuringListing } from "./listing_load.mjs";

const URL = process.env.CARACARA_TCP_URL; // ws://127.0.0.1:PORT/?token=T
const LIST_URL = URL.replace(/^ws:/, "http:").replace("/?", "/dives/?");
const BRIDGE_PID = Number(process.env.CARACARA_BRIDGE_PID);
const BRIDGE_LOG = process.env.CARACARA_BRIDGE_LOG;
const KILL_MS_MAX = Number(process.env.CARACARA_KILL_OUTPUT_LISTING_MS_MAX);
const HELD_MS = Number(process.env.CARACARA_KILL_HELD_BY_LISTING_MS);
const ZERO_MS_MAX = Number(process.env.CARACARA_CLIENT_LOSS_ZERO_MS_MAX);
// How far the bridge's RSS may grow under a client that floods it without reading (tests/bounds.json).
const RSS_GROWTH_KIB_MAX = bound("BRIDGE_FLOOD_RSS_GROWTH_KIB_MAX");
const FRAME_MAX = 64 * 1024; // the bridge's largest client message (SessionConfig::max_message_bytes)

// A sanitized build (CARACARA_TEST_SANITIZED): ASan keeps freed memory in its quarantine, so the
// bridge's RSS growth is the instrumentation's; it is judged on the plain build only.
const SANITIZED = process.env.CARACARA_TEST_SANITIZED === "1";
const rssKib = () => Number(/VmRSS:\s+(\d+)/.exec(fs.readFileSync(`/proc/${BRIDGE_PID}/status`, "utf8"))[1]);

test("a Kill published while another client lists a full dive directory reaches the kill output at once", async () => {
  // 60 Kills, each inside a listing: the median and the worst are judged here; the p99 is the
  // bench's figure (bench/bridge_bench.mjs listing, 200 samples).
  const r = await killsDuringListing(URL, LIST_URL, 60, 20);
  console.log(`# ${JSON.stringify(r)}`);
  assert.ok(r.dives >= 3000, `the directory lists ${r.dives} dives`);
  // The median, against the same run's without a listing: the machine's load moves both alike
  // (the p99 is the bench's figure). A Kill held behind a listing would take the listing's time.
  assert.ok(r.kill_output_ms.p50 <= r.kill_output_no_listing_ms.p50 + KILL_MS_MAX,
            `Kill to the kill output p50 ${r.kill_output_ms.p50} ms during listings, ` +
            `${r.kill_output_no_listing_ms.p50} ms without (bound: ${KILL_MS_MAX} ms more)`);
  assert.ok(r.kill_output_ms.max < HELD_MS,
            `a Kill took ${r.kill_output_ms.max} ms during listings (a listing takes ${r.listing_ms.p50} ms; bound ${HELD_MS} ms)`);
});

test("a client closed while another lists a full dive directory is zeroed within the client-loss bound", async () => {
  const r = await closesDuringListing(URL, LIST_URL, 5);
  console.log(`# ${JSON.stringify(r)}`);
  assert.ok(r.close_to_zeros_ms.max <= ZERO_MS_MAX,
            `zeroed ${r.close_to_zeros_ms.max} ms after the close (bound ${ZERO_MS_MAX} ms)`);
});

// A raw client (ws) that stops reading its socket once the bridge's greeting is in.
async function deafClient() {
  const ws = new WebSocket(URL, ["foxglove.websocket.v1"]);
  const c = { ws, statuses: 0, closed: null };
  ws.on("message", (data, binary) => { if (!binary && JSON.parse(data).op === "status") c.statuses += 1; });
  ws.on("close", (code, reason) => { c.closed = { code, reason: reason.toString() }; });
  let greeted = 0;
  await new Promise((resolve, reject) => {
    ws.on("message", (data, binary) => { if (!binary && ++greeted === 2) resolve(); }); // serverInfo, advertise
    ws.on("error", reject);
  });
  ws._socket.pause(); // read nothing more: the bridge's writes back up
  return c;
}

const unadvertise = (zeros, pad = 0) => {
  const head = '{"op":"unadvertise","channelIds":[';
  const tail = pad ? `],"pad":"${"x".repeat(pad)}"}` : "]}";
  return head + "0,".repeat(zeros - 1) + "0" + tail;
};

test("a 64 KiB unadvertise of zeros from a client that never reads: closed with the reason, memory bounded", async () => {
  const before = rssKib();
  const c = await deafClient();
  const zeros = Math.floor((FRAME_MAX - 40) / 2);
  const flood = unadvertise(zeros);
  assert.ok(flood.length <= FRAME_MAX);
  for (let i = 0; i < 50; i++) c.ws.send(flood); // 3.2 MB, each frame ~32 k error replies (2.4 MB)
  await poll(() => fs.readFileSync(BRIDGE_LOG, "utf8").includes("its replies passed their bound"), 10000,
             "the bridge to log why it closes the client");
  const grown = rssKib() - before;
  console.log(`# the bridge's RSS: ${before} KiB before, +${grown} KiB with the flood`);
  if (!SANITIZED) assert.ok(grown <= RSS_GROWTH_KIB_MAX, `the bridge grew ${grown} KiB (bound ${RSS_GROWTH_KIB_MAX} KiB)`);
  c.ws._socket.resume();
  await poll(() => c.closed, 10000, "the connection to close");
  console.log(`# closed: ${JSON.stringify(c.closed)}`);
  if (c.closed.code !== 1006) { // the close frame got out before the bridge's close timer
    assert.equal(c.closed.code, 1008);
    assert.match(c.closed.reason, /replies passed their bound/);
  }
  // The bridge serves on.
  const other = await connect(URL);
  await other.close();
});

test("a client that sends and does not read is read no further until it reads; no reply is lost", async () => {
  const before = rssKib();
  const c = await deafClient();
  // Each frame: 1000 error replies (~75 KB, over the 64 KiB at which reading pauses, under the
  // 256 KiB that closes), and 60 KB of padding: 24 MB, more than the socket buffers hold.
  const frame = unadvertise(1000, 60000);
  const frames = 400;
  for (let i = 0; i < frames; i++) c.ws.send(frame);
  await sleep(2000);
  const buffered = c.ws.bufferedAmount;
  const grown = rssKib() - before;
  console.log(`# paused: ${buffered} bytes not taken by the bridge, its RSS +${grown} KiB`);
  assert.ok(buffered > 0, "the bridge read on while its replies were not read");
  assert.equal(c.closed, null, "closed, though its replies stayed within their bound");
  if (!SANITIZED) assert.ok(grown <= RSS_GROWTH_KIB_MAX, `the bridge grew ${grown} KiB (bound ${RSS_GROWTH_KIB_MAX} KiB)`);
  c.ws._socket.resume();
  await poll(() => c.statuses === frames * 1000, 60000, "every reply");
  assert.equal(c.ws.bufferedAmount, 0);
  c.ws.close();
});
