// Debian's chromium, headless, driven by puppeteer-core, for the cockpit's test and bench: a
// fresh profile each launch, and pages of the cockpit with a scripted standard-mapping gamepad
// (window.__pad) in place of navigator.getGamepads.
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import puppeteer from "puppeteer-core";

export const CHROMIUM = process.env.CARACARA_CHROMIUM ?? "/usr/bin/chromium";
const FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
  "--disable-background-networking", "--disable-component-update", "--disable-sync"];

// The browser; close() also removes its profile.
export async function launch() {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), "caracara-chromium-"));
  const browser = await puppeteer.launch({ executablePath: CHROMIUM, headless: true, userDataDir: profile, args: FLAGS });
  return {
    browser,
    close: async () => { await browser.close(); fs.rmSync(profile, { recursive: true, force: true }); },
  };
}

// A cockpit page at url, connected; every request and console error recorded in log.
export async function openCockpit(browser, url) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1400, height: 900 });
  const log = { requests: [], errors: [] };
  page.on("request", (r) => log.requests.push(r.url()));
  page.on("pageerror", (e) => log.errors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") log.errors.push(m.text()); });
  await page.evaluateOnNewDocument(() => {
    const pad = { id: "scripted gamepad", index: 0, connected: true, mapping: "standard", timestamp: 0,
      axes: [0, 0, 0, 0], buttons: Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 })) };
    window.__pad = pad;
    navigator.getGamepads = () => [pad.connected ? pad : null, null, null, null];
  });
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction(() => document.getElementById("link").dataset.lost === "false", { timeout: 15000 });
  return { page, log };
}

// The default mapping's "forward" (docs/cockpit.md) for the left stick's y, computed on its own:
// "-a1" through the dead zone 0.1 and the expo 0.3, times the gain 0.5.
export function forwardDemand(stick) {
  if (Math.abs(stick) <= 0.1) return 0;
  const t = (Math.abs(stick) - 0.1) / 0.9;
  return -Math.sign(stick) * (0.7 * t + 0.3 * t ** 3) * 0.5;
}

// Arms a cockpit page's scripted gamepad on purpose (docs/cockpit.md, "Arming on purpose"):
// the deadman released with the sticks centred, then pressed; it is left held. A page sends
// no motion before this, after loading, reconnecting or any kill.
export async function armPad(page) {
  await page.evaluate(() => { window.__pad.buttons[4] = { pressed: false, touched: false, value: 0 }; window.__pad.axes.fill(0); });
  await page.waitForFunction(() => document.getElementById("arm").dataset.arm === "press", { timeout: 10000 });
  await page.evaluate(() => { window.__pad.buttons[4] = { pressed: true, touched: true, value: 1 }; });
  await page.waitForFunction(() => document.getElementById("arm").dataset.arm === "armed", { timeout: 2000 });
}
