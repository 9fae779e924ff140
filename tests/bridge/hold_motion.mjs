// A pilot held by a Python test (tests/e2e/vehicle_motion.py's judge() is the referee): one JSON
// line in, the motion held for its seconds and then stopped, one JSON line out. Two pilots:
//
//   node hold_motion.mjs cockpit   the cockpit in chromium (CARACARA_HTTP_URL) with its scripted
//       gamepad, armed on purpose; in: {"seconds": S, "axes": {"1": -1}, "buttons": {"15": 1}}:
//       those stick axes and button values with the deadman held, then all released (the page
//       sends its zero); out: {"sent": commands the page sent meanwhile}
//   node hold_motion.mjs foxglove  the reference client (CARACARA_WS_URL); in: {"seconds": S,
//       "topic": T, "message": M}: M published on T every 50 ms, then a zero Twist; out:
//       {"sent": N, "tf": [the /tf rotation before, the first one after the stop, or the last
//       one when none comes within a second]}
//
// "ready" is printed once the pilot can take a line; end of input ends it.
import { createInterface } from "node:readline";
import { connect, sleep } from "./lib.mjs";

const mode = process.argv[2];
const say = (obj) => process.stdout.write(`${JSON.stringify(obj)}\n`);

async function cockpit() {
  const { armPad, launch, openCockpit } = await import("./chromium.mjs");
  const chromium = await launch();
  const { page, log } = await openCockpit(chromium.browser, process.env.CARACARA_HTTP_URL);
  await page.waitForFunction(() => document.getElementById("state").textContent === "ready", { timeout: 20000 });
  await armPad(page); // armed, deadman held, sticks centred: a release does not disarm
  await page.evaluate(() => { window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; });
  return {
    async hold({ seconds, axes = {}, buttons = {} }) {
      const before = await page.evaluate(() => window.cockpit.sent);
      await page.evaluate((axes, buttons) => {
        for (const [i, v] of Object.entries(axes)) window.__pad.axes[Number(i)] = v;
        for (const [i, v] of Object.entries(buttons)) window.__pad.buttons[Number(i)] = { pressed: v > 0.5, touched: true, value: v };
        window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 };
      }, axes, buttons);
      await sleep(seconds * 1000);
      await page.evaluate(() => {
        window.__pad.axes.fill(0);
        window.__pad.buttons = window.__pad.buttons.map(() => ({ pressed: false, touched: false, value: 0 }));
      });
      // The release's zero goes at the page's next tick (50 ms).
      await page.waitForFunction(() => !Object.values(window.cockpit.lastSent?.motion ?? {}).some((v) => v !== 0),
                                 { timeout: 2000 });
      const sent = await page.evaluate(() => window.cockpit.sent);
      if (log.errors.length) throw new Error(`the page's errors: ${log.errors.join("; ")}`);
      return { sent: sent - before };
    },
    close: () => chromium.close(),
  };
}

async function foxglove() {
  const c = await connect(process.env.CARACARA_WS_URL);
  c.subscribeAll();
  const publishers = new Map();
  const publisher = (topic) => {
    if (!publishers.has(topic)) publishers.set(topic, c.publisher(topic));
    return publishers.get(topic);
  };
  await c.waitFor("/tf");
  return {
    async hold({ seconds, topic, message }) {
      const id = publisher(topic);
      const before = c.latest.get("/tf").msg.rotation;
      let sent = 0;
      const end = Date.now() + seconds * 1000;
      while (Date.now() < end) { // within CommandTimeoutMs, as Foxglove's Teleop panel at 20 Hz
        c.publish(id, message);
        sent++;
        await sleep(50);
      }
      c.publish(id, { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } });
      // The attitude after the stop: /tf comes when the Teensy's angles change (at the daemon's
      // telemetry rate), so not at all after a translation.
      const n = c.counts.get("/tf");
      await c.waitFor("/tf", () => c.counts.get("/tf") > n, 1000).catch(() => {});
      const refusals = c.statuses.filter((s) => s.level >= 2);
      if (refusals.length) throw new Error(`refused: ${refusals.map((s) => s.message).join("; ")}`);
      return { sent, tf: [before, c.latest.get("/tf").msg.rotation] };
    },
    close: () => c.close(),
  };
}

const pilot = mode === "cockpit" ? await cockpit() : mode === "foxglove" ? await foxglove() : null;
if (!pilot) throw new Error("mode: cockpit | foxglove");
say("ready");
try {
  for await (const line of createInterface({ input: process.stdin })) {
    if (line.trim()) say(await pilot.hold(JSON.parse(line)));
  }
} finally {
  await pilot.close();
}
