// The cockpit (docs/cockpit.md): one Foxglove WebSocket client of the bridge that serves this
// page, showing the vehicle live, killing from anywhere on the page, and piloting with a gamepad.
import { FoxgloveClient } from "./foxglove.js";
import { AXES, CLEAR_HOLD_MS, GAINS, KEY, loadMapping, sample, saveMapping, stepGain, validMapping } from "./gamepad.js";
import { degrees, drawAttitude, headingDegrees } from "./attitude.js";
import { DiveList } from "./dives.js";
import { Commissioning } from "./commissioning.js";
import { banner, controllerWords, killSourceWords } from "./words.js";

const MOTORS = 8, MOTOR_MAX = 8850;
const SEND_MS = 50;        // motion commands while the deadman is held: 20 per second
const STALE_MS = 1500;     // no message for this long while connected: shown as lost
const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("token");
const wsUrl = `ws://${location.host}/${token ? `?token=${encodeURIComponent(token)}` : ""}`;

let client = null;
let lastMessageAt = 0;     // performance.now() of the last message from the bridge
let connected = false;
let lostAt = null;         // performance.now() when the link was first seen lost; null while fresh
// Arming on purpose (docs/cockpit.md): after a page load, a reconnect, a kill, a Clear kill, a
// state other than ready, a refused motion command, the gamepad gone or another one, the page
// hidden, or the pilot's seat lost, nothing is sent until the pilot has released the deadman
// with the sticks centred ("release") and pressed it again ("press").
const ARM_RELEASE = "release", ARM_PRESS = "press", ARM_ARMED = "armed";
// The pilot's seat (docs/cockpit.md): the bridge lets one client command at a time and tells
// every client who holds it, in a status whose id is this topic.
const SEAT_TOPIC = "/command/seat";
// How this page is named to the others (the bridge takes up to 64 printable ASCII characters).
const PAGE_NAME = `cockpit, ${navigator.platform || "a browser"}, opened ${new Date().toTimeString().slice(0, 8)}`
  .replace(/[^\x20-\x7e]/g, " ").slice(0, 64);
const cockpit = { state: null, motors: null, thrusters: [], teensy: null, i2c: null, sent: 0, kills: 0,
  arm: ARM_RELEASE, killNotSentAt: null, refusal: null, clearHeldSince: null, connects: 0,
  stateAt: 0, pilotLostMs: null, seat: null, seatLost: null, pad: null, name: PAGE_NAME };
window.cockpit = cockpit;  // for the tests and the curious
const dives = new DiveList($("dives"), $("dive-plot"), token);
const commissioning = new Commissioning((topic, obj) => client?.publish(topic, obj) ?? false,
  (level, text) => logEvent(level, "cockpit", text, Date.now()));
cockpit.commissioning = commissioning; // for the tests

// Back to the start of arming: the pilot must release, centre and press again.
function disarm() {
  cockpit.arm = ARM_RELEASE;
  stopDriving();
}
const fresh = () => connected && lastMessageAt !== 0 && performance.now() - lastMessageAt < STALE_MS;

// --- the connection ------------------------------------------------------------------------------
let retries = 0;
function connect() {
  client = new FoxgloveClient(wsUrl, {
    onOpen: () => { connected = true; retries = 0; cockpit.connects++; cockpit.seat = null; disarm(); },
    onMessage: (topic, msg) => { lastMessageAt = performance.now(); show(topic, msg); },
    onStatus: (level, text, id) => bridgeStatus(level, text, id),
    onClose: () => {
      connected = false;
      commissioning.lost();
      // What the vehicle is now is unknown: the old state is not kept as if it were current.
      cockpit.state = null;
      cockpit.seat = null; // the seat goes with the connection: the bridge frees it
      disarm();
      // Soon the first time (a dropped connection comes back within pilot-lost's persistence), then calmly.
      setTimeout(connect, retries++ ? 2000 : 250);
    },
  });
  cockpit.client = client; // the tests drop it
}

// A refusal of the bridge or the daemon: a motion command refused (a failsafe's ascent, a kill
// on the way) stops the sending and makes one event, not one per command.
function bridgeStatus(level, text, id) {
  if (id === SEAT_TOPIC) return seatNews(JSON.parse(text));
  if (id && commissioning.answer(id, text)) return;
  commissioning.refused(text); // shown in its panel, and logged below
  const refused = /^\/command\/(drive|motion|thrust) refused: \S*?([A-Za-z]+)(?::|$)/.exec(text);
  if (refused) {
    const first = cockpit.refusal === null;
    cockpit.refusal = refused[2];
    disarm();
    if (!first) return;
  }
  logEvent(level >= 2 ? 4 : 2, "bridge", text, Date.now());
}

// The seat as the bridge says: {holder ("" free), yours, change, by}. Lost to another page's
// take-over: said at once in the banner, and this page arms anew (it no longer drives).
function seatNews(n) {
  const had = cockpit.seat?.yours;
  cockpit.seat = n;
  if (n.yours) cockpit.seatLost = null;
  if (had && !n.yours) {
    driving = false; // its connection was replaced: the bridge zeroed what it commanded
    disarm();
    commissioning.lost("the pilot's seat was taken over");
    if (n.change === "taken-over") {
      cockpit.seatLost = { by: n.by, at: Date.now() };
      logEvent(4, "seat", `taken over by ${n.by}: this page no longer drives`, Date.now());
    }
  } else if (n.change !== "now" && !n.yours) {
    logEvent(2, "seat", n.holder ? `${n.holder} holds the pilot's seat` : `the pilot's seat is free (${n.by} ${n.change})`, Date.now());
  }
  showSeat();
  showArming();
}
// This page may command: the seat is its own, or free (its first command takes it).
const seatOpen = () => Boolean(cockpit.seat && (cockpit.seat.yours || cockpit.seat.holder === ""));

function showSeat() {
  const n = cockpit.seat;
  const other = Boolean(connected && n && n.holder && !n.yours);
  $("seat").textContent = !connected || !n ? "unknown" : n.yours ? "this page" : n.holder || "free";
  $("seat").dataset.holder = !connected || !n ? "unknown" : n.yours ? "this page" : n.holder ? "other" : "free";
  $("take-seat").hidden = !other;
}

function showLink() {
  const el = $("link");
  const age = lastMessageAt ? ((performance.now() - lastMessageAt) / 1000).toFixed(1) : null;
  const up = fresh();
  if (up) lostAt = null; else lostAt ??= performance.now();
  if (!up && cockpit.arm !== ARM_RELEASE) disarm();
  el.className = `link ${up ? "up" : "down"}`;
  el.dataset.lost = up ? "false" : "true";
  // What is shown is only the last thing heard: dimmed until the data is fresh again.
  document.body.classList.toggle("stale", !up);
  el.textContent = up ? "connected"
    : `${connected ? "NO DATA" : "CONNECTION LOST"}${age === null ? "" : ` — last message ${age} s ago`}`;
  showStateWords(up);
  showSeat();
  showBanner(up);
  showArming();
}

// The state the daemon last said, and only while it is current: never "ready" from memory.
function showStateWords(up) {
  const m = cockpit.state;
  const state = up && m ? m.state : "unknown";
  // A failsafe's ascent drives the vehicle: the daemon's "ready" is no pilot's, and not shown as such.
  const shown = state === "ready" && surfacing(m) ? "surfacing" : state;
  $("state").textContent = shown;
  $("state").className = `state ${shown}`;
  $("state").title = m && !up ? `last known: ${m.state}` : shown !== state ? "a failsafe drives the vehicle up (the daemon's state: ready)" : "";
  const source = up && m ? m.kill_source : "";
  $("kill-source").textContent = up && m ? killSourceWords(source) : "unknown";
  $("kill-source").dataset.source = source;
  $("kill-source").className = `state small ${source ? "killed" : ""}`;
}

function showBanner(up) {
  const items = banner({
    state: cockpit.state, up, lostMs: lostAt === null ? 0 : performance.now() - lostAt,
    killNotSentMs: cockpit.killNotSentAt === null ? null : performance.now() - cockpit.killNotSentAt,
    refusal: cockpit.refusal, sinceStateMs: performance.now() - cockpit.stateAt, pilotLostMs: cockpit.pilotLostMs,
    seat: connected ? cockpit.seat : null, seatLost: cockpit.seatLost,
  });
  const list = $("banner");
  const html = items.map((i) => `<li class="${i.level}" data-kind="${i.kind}">${i.text}</li>`).join("");
  if (list.innerHTML !== html) list.innerHTML = html;
  list.hidden = items.length === 0;
}

function showArming() {
  const el = $("arm");
  const p = pad();
  let text = "";
  if (!p) text = "no gamepad";
  else if (!fresh() || cockpit.state?.state !== "ready") text = "not ready: nothing is sent";
  else if (surfacing(cockpit.state)) text = "surfacing: the vehicle refuses motion";
  else if (!seatOpen()) text = cockpit.seat ? "another page drives: take the seat over to drive" : "waiting for the seat";
  else if (cockpit.arm === ARM_RELEASE) text = "to drive: release the deadman and centre the sticks";
  else if (cockpit.arm === ARM_PRESS) text = "to drive: press the deadman";
  else text = "armed: the deadman drives";
  if (cockpit.clearHeldSince !== null)
    text = `Clear kill: hold ${Math.max(0, (CLEAR_HOLD_MS - (performance.now() - cockpit.clearHeldSince)) / 1000).toFixed(1)} s more`;
  el.textContent = text;
  el.dataset.arm = cockpit.arm;
  el.className = `arm ${cockpit.arm}`;
}

// --- what the vehicle says ---------------------------------------------------------------------
function show(topic, m) {
  if (topic === "/vehicle/state") return showState(m);
  if (topic === "/vehicle/motors") return showMotors(m);
  if (topic.startsWith("/thruster/")) return showThruster(m);
  if (topic === "/teensy") return showTeensy(m);
  if (topic === "/i2c") return showI2c(m);
  if (topic === "/events") {
    // A kill closes a dive: the list follows (one fetch for all this browser's tabs).
    if (m.name === "kill") dives.changed();
    return logEvent(m.level, m.name, m.message, m.timestamp.sec * 1000 + m.timestamp.nsec / 1e6);
  }
}

// A surface failsafe's ascent runs (the daemon refuses motion meanwhile).
const surfacing = (m) => Boolean(m && (m.surfacing_ms >= 0 || m.ascent_left_ms >= 0));

function showState(m) {
  const before = cockpit.state;
  cockpit.state = m;
  cockpit.stateAt = performance.now(); // the banner counts the daemon's time left down from here
  // Configuration, not state: kept through a lost link, whose countdown it is.
  if (m.pilot_lost_ms >= 0) cockpit.pilotLostMs = m.pilot_lost_ms;
  // Not ready, or surfacing: what was armed is no more; the same once it changed under us.
  if (m.state !== "ready" || surfacing(m) || (before && before.state !== "ready")) disarm();
  if (m.state === "killed") cockpit.killNotSentAt = null; // killed after all (another pilot, the vehicle)
  if (m.state === "ready" && !surfacing(m) && before?.state !== "ready") cockpit.refusal = null;
  showStateWords(fresh());
  showArming();
  $("budget").textContent = m.budget_limit;
  $("profile").textContent = `${m.profile} ×${m.profile_factor}`;
  $("saturated").textContent = m.saturated ? "SATURATED" : "not saturated";
  $("saturated").className = m.saturated ? "pill bad" : "pill ok";
  $("controller").textContent = controllerWords(m, driving);
  commissioning.showState(m);
}

function thrusterRow(i) {
  let row = $(`thr-${i}`);
  if (row) return row;
  row = document.createElement("tr");
  row.id = `thr-${i}`;
  row.innerHTML = `<td>${i}</td><td class="bars"><div class="bar applied"><span></span></div>` +
    `<div class="bar requested"><span></span></div></td><td class="value"></td><td class="current"></td>` +
    `<td class="temperature"></td><td class="faults"></td><td class="reachable"></td>`;
  const rows = $("thrusters").tBodies[0];
  rows.insertBefore(row, [...rows.rows].find((r) => Number(r.id.slice(4)) > i) ?? null);
  return row;
}

function setBar(el, value) {
  const f = Math.max(-1, Math.min(1, value / MOTOR_MAX));
  el.style.left = `${50 + Math.min(0, f) * 50}%`;
  el.style.width = `${Math.abs(f) * 50}%`;
}

function showMotors(m) {
  cockpit.motors = m;
  commissioning.showMotors(m);
  for (let i = 0; i < MOTORS; i++) {
    const row = thrusterRow(i);
    setBar(row.querySelector(".applied span"), m.applied[i]);
    setBar(row.querySelector(".requested span"), m.requested[i]);
    row.querySelector(".value").textContent = `${m.applied[i]} / ${m.requested[i]}`;
    row.dataset.applied = m.applied[i];
    row.dataset.requested = m.requested[i];
  }
}

function showThruster(t) {
  cockpit.thrusters[t.index] = t;
  const row = thrusterRow(t.index);
  row.querySelector(".current").textContent = t.current.toFixed(2);
  row.querySelector(".temperature").textContent = t.temperature.toFixed(1);
  const faults = row.querySelector(".faults");
  faults.textContent = t.fault_bits ? `0x${t.fault_bits.toString(16).padStart(2, "0")} ${t.faults.join(" ")}` : "—";
  faults.className = `faults ${t.fault_bits ? "fault" : ""}`;
  const reach = row.querySelector(".reachable");
  reach.textContent = t.reachable ? "ok" : "LOST";
  reach.className = `reachable pill ${t.reachable ? "ok" : "bad"}`;
}

function showTeensy(t) {
  cockpit.teensy = t;
  const { yaw, pitch, roll } = t.orientation;
  drawAttitude($("attitude"), yaw, pitch, roll);
  $("yaw").textContent = headingDegrees(yaw);
  $("pitch").textContent = degrees(pitch);
  $("roll").textContent = degrees(roll);
  $("teensy-online").textContent = t.online ? "online" : "OFFLINE";
  $("teensy-online").className = `pill ${t.online ? "ok" : "bad"}`;
  $("teensy-task").textContent = t.task;
  $("distances").textContent = t.distances.length ? t.distances.join(" · ") : "—";
}

function showI2c(b) {
  cockpit.i2c = b;
  $("i2c-state").textContent = b.state;
  $("i2c-state").className = `pill ${b.state === "ok" ? "ok" : "bad"}`;
  $("i2c-transactions").textContent = b.transactions;
  $("i2c-errors").textContent = b.errors;
  $("i2c-recoveries").textContent = b.recoveries;
  $("i2c-failures").textContent = b.recovery_failures;
  $("i2c-last-error").textContent = b.last_error ? `last error: ${b.last_error}` : "";
}

function logEvent(level, name, message, ms) {
  const li = document.createElement("li");
  li.className = `lvl${level}`;
  li.textContent = `${new Date(ms).toLocaleTimeString()} ${name}: ${message}`;
  const list = $("events");
  list.prepend(li);
  while (list.children.length > 200) list.lastChild.remove();
}

// --- kill ----------------------------------------------------------------------------------------
function kill() {
  cockpit.kills++;
  // The kill first: nothing of ours goes out ahead of it (nor after it: the motor test stops).
  const sent = client?.publish("/command/kill", {});
  commissioning.stop();
  if (!sent) {
    cockpit.killNotSentAt = performance.now();
    logEvent(4, "cockpit", "kill NOT sent: no connection to the bridge (the vehicle zeroes a lost pilot's thrust)", Date.now());
  }
  disarm();
  const dialog = $("confirm-clear");
  if (dialog.open) dialog.close("cancel"); // a kill answers the question: nothing is cleared
  showLink();
}

function clearKill() {
  if (client?.publish("/command/clear_kill", {})) logEvent(2, "cockpit", "Clear kill sent", Date.now());
  disarm();
}

$("kill").addEventListener("click", kill);
// Space or Escape kill from anywhere on the page, before any other handler sees the key.
window.addEventListener("keydown", (e) => {
  if (e.code === "Space" || e.key === " " || e.key === "Escape") {
    e.preventDefault();
    e.stopPropagation();
    if (!e.repeat) kill();
  }
}, { capture: true });
$("clear-kill").addEventListener("click", () => {
  const dialog = $("confirm-clear");
  if (dialog.open) return;
  dialog.returnValue = "";
  dialog.showModal();
});
$("confirm-clear").addEventListener("close", () => {
  if ($("confirm-clear").returnValue === "clear") clearKill();
});
// Taking the seat from another page is asked first; that page hears of it at once and stops.
$("take-seat").addEventListener("click", () => {
  const dialog = $("confirm-seat");
  if (dialog.open) return;
  $("confirm-seat-holder").textContent = cockpit.seat?.holder || "another client";
  dialog.returnValue = "";
  dialog.showModal();
});
$("confirm-seat").addEventListener("close", () => {
  if ($("confirm-seat").returnValue !== "take") return;
  disarm(); // drives only once armed on purpose, as after any change
  if (client?.publish(SEAT_TOPIC, { action: "take-over", name: cockpit.name }))
    logEvent(3, "cockpit", `took the pilot's seat over from ${cockpit.seat?.holder || "nobody"}`, Date.now());
});

// --- gamepad -------------------------------------------------------------------------------------
let { mapping, notice: mappingNotice } = loadMapping();
let driving = false;       // the deadman was held at the last sample
let sendTimer = null;
const gainButtons = new Set(); // gain buttons held at the last sample

function setGain(gain) {
  mapping = { ...mapping, gain };
  saveMapping(mapping);
  $("gain").value = String(gain);
}

function pad() {
  const pads = navigator.getGamepads ? [...navigator.getGamepads()] : [];
  return pads.find((p) => p && p.connected !== false) ?? null;
}

// In a pilot's words: the bridge's /command/drive converts them (core/frames, docs/frames.md).
function sendMotion(motion) {
  const at = performance.now();
  if (!client?.publish("/command/drive", motion)) return;
  cockpit.sent++;
  // When the command changed (bench/bridge_bench.mjs times a sample to the wire from here).
  if (AXES.some((a) => motion[a] !== cockpit.lastSent?.motion[a])) cockpit.lastChange = { motion, at };
  cockpit.lastSent = { motion, at };
}

const ZERO = Object.fromEntries(AXES.map((a) => [a, 0]));

// Released, hidden, unplugged, killed or disconnected: zero at once, then nothing more.
function stopDriving() {
  if (driving) sendMotion(ZERO);
  driving = false;
  const held = Boolean(pad()?.buttons[mapping.deadman]?.pressed);
  // Held but not driving (not armed, not ready, no link): said as such, never HELD.
  $("deadman").textContent = held ? "held, not driving" : "released";
  $("deadman").className = held ? "pill bad" : "pill";
}

function tick() {
  const p = document.visibilityState === "visible" ? pad() : null;
  $("pad").textContent = p ? p.id || "gamepad" : "no gamepad";
  // Unplugged, hidden or another gamepad: what was armed is no more (armed again on purpose).
  const key = p ? `${p.index}:${p.id}` : null;
  if (key !== cockpit.pad) { cockpit.pad = key; disarm(); }
  if (!p) {
    cockpit.clearHeldSince = null;
    return disarm();
  }
  // The gain and kill buttons act on their press, not while held.
  const press = (i) => Boolean(p.buttons[i]?.pressed);
  const pressed = (i) => press(i) && !gainButtons.has(i);
  if (pressed(mapping.kill)) kill();
  for (const [button, step] of [[mapping.gain_up, 1], [mapping.gain_down, -1]])
    if (pressed(button)) setGain(stepGain(mapping.gain, step));
  // Clear kill: held for CLEAR_HOLD_MS, once per hold; a tap does nothing.
  if (!press(mapping.clear_kill)) cockpit.clearHeldSince = null;
  else if (pressed(mapping.clear_kill)) cockpit.clearHeldSince = performance.now();
  else if (cockpit.clearHeldSince !== null && performance.now() - cockpit.clearHeldSince >= CLEAR_HOLD_MS) {
    cockpit.clearHeldSince = null;
    clearKill();
  }
  for (const button of [mapping.gain_up, mapping.gain_down, mapping.kill, mapping.clear_kill])
    if (press(button)) gainButtons.add(button); else gainButtons.delete(button);
  const s = sample(p, mapping);
  $("pad-motion").textContent = AXES.map((a) => `${AXIS_WORDS[a]} ${s.motion[a].toFixed(2)}`).join(" · ");
  // Not ready (killed, arming, fault, surfacing, link lost): nothing to send, and arming again.
  const ready = fresh() && cockpit.state?.state === "ready" && !surfacing(cockpit.state) && seatOpen();
  if (!ready) {
    if (cockpit.arm !== ARM_RELEASE) cockpit.arm = ARM_RELEASE;
    return stopDriving();
  }
  if (cockpit.arm === ARM_RELEASE && !s.held && s.centred) cockpit.arm = ARM_PRESS;
  else if (cockpit.arm === ARM_PRESS && s.held && s.centred) {
    cockpit.arm = ARM_ARMED;
    cockpit.refusal = null; // armed again on purpose: a new refusal makes a new event
    // A free seat is claimed (named) before the first motion; refused if another page took it first.
    if (!cockpit.seat.yours) client?.publish(SEAT_TOPIC, { action: "claim", name: cockpit.name });
  }
  if (!s.held || cockpit.arm !== ARM_ARMED) return stopDriving();
  driving = true;
  $("deadman").textContent = "HELD";
  $("deadman").className = "pill held";
  sendMotion(s.motion);
}

document.addEventListener("visibilitychange", () => {
  if (document.visibilityState !== "visible") { disarm(); commissioning.release(); }
});
// Between two ticks too: a gamepad unplugged and plugged back arms anew.
window.addEventListener("gamepaddisconnected", () => disarm());
window.addEventListener("gamepadconnected", () => disarm());
window.addEventListener("pagehide", () => { stopDriving(); commissioning.release(); client?.close(); });

// The mapping's motions as the page labels them.
const AXIS_WORDS = { forward: "forward", starboard: "starboard", up: "up", turn_right: "turn right", nose_up: "nose up",
  roll_right: "roll right" };

function showMappingNotice() {
  $("mapping-notice").textContent = mappingNotice ?? "";
  $("mapping-notice").hidden = !mappingNotice;
  if (mappingNotice) $("mapping-details").open = true;
}

function mappingForm() {
  const form = $("mapping");
  form.innerHTML = "";
  const fields = [...AXES, "deadman", "gain_up", "gain_down", "kill", "clear_kill", "deadzone", "expo"];
  for (const k of fields) {
    const label = document.createElement("label");
    label.textContent = AXIS_WORDS[k] ?? k;
    label.htmlFor = `map-${k}`;
    const input = document.createElement("input");
    input.id = `map-${k}`;
    input.value = mapping[k];
    input.addEventListener("change", () => {
      const next = { ...mapping, [k]: AXES.includes(k) ? input.value : Number(input.value) };
      try {
        validMapping(next);
        saveMapping(next);
        mapping = next;
        $("mapping-error").textContent = "";
      } catch (err) {
        $("mapping-error").textContent = err.message;
      }
    });
    form.append(label, input);
  }
  const reset = document.createElement("button");
  reset.type = "button";
  reset.textContent = "defaults";
  reset.addEventListener("click", () => { localStorage.removeItem(KEY); ({ mapping } = loadMapping()); mappingForm(); });
  form.append(reset);
  const gain = $("gain");
  gain.innerHTML = GAINS.map((g) => `<option value="${g}">${g * 100} %</option>`).join("");
  gain.value = String(mapping.gain);
}
$("gain").addEventListener("change", (e) => setGain(Number(e.target.value)));

// --- start ---------------------------------------------------------------------------------------
mappingForm();
showMappingNotice();
if (mappingNotice) logEvent(3, "cockpit", mappingNotice, Date.now());
drawAttitude($("attitude"), 0, 0, 0);
for (let i = 0; i < MOTORS; i++) thrusterRow(i);
connect();
sendTimer = setInterval(tick, SEND_MS);
setInterval(showLink, 100);
dives.load();
