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
// state other than ready or a refused motion command, nothing is sent until the pilot has
// released the deadman with the sticks centred ("release") and pressed it again ("press").
const ARM_RELEASE = "release", ARM_PRESS = "press", ARM_ARMED = "armed";
const cockpit = { state: null, motors: null, thrusters: [], teensy: null, i2c: null, sent: 0, kills: 0,
  arm: ARM_RELEASE, killNotSentAt: null, refusal: null, clearHeldSince: null, connects: 0,
  stateAt: 0, pilotLostMs: null };
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
    onOpen: () => { connected = true; retries = 0; cockpit.connects++; disarm(); },
    onMessage: (topic, msg) => { lastMessageAt = performance.now(); show(topic, msg); },
    onStatus: (level, text, id) => bridgeStatus(level, text, id),
    onClose: () => {
      connected = false;
      commissioning.lost();
      // What the vehicle is now is unknown: the old state is not kept as if it were current.
      cockpit.state = null;
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
  showBanner(up);
  showArming();
}

// The state the daemon last said, and only while it is current: never "ready" from memory.
function showStateWords(up) {
  const m = cockpit.state;
  const state = up && m ? m.state : "unknown";
  $("state").textContent = state;
  $("state").className = `state ${state}`;
  $("state").title = m && !up ? `last known: ${m.state}` : "";
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
  else if (cockpit.state.surfacing_ms >= 0) text = "surfacing: the vehicle refuses motion";
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

function showState(m) {
  const before = cockpit.state;
  cockpit.state = m;
  cockpit.stateAt = performance.now(); // the banner counts the daemon's time left down from here
  // Configuration, not state: kept through a lost link, whose countdown it is.
  if (m.pilot_lost_ms >= 0) cockpit.pilotLostMs = m.pilot_lost_ms;
  // Not ready, or surfacing: what was armed is no more; the same once it changed under us.
  if (m.state !== "ready" || m.surfacing_ms >= 0 || (before && before.state !== "ready")) disarm();
  if (m.state === "killed") cockpit.killNotSentAt = null; // killed after all (another pilot, the vehicle)
  if (m.state === "ready" && m.surfacing_ms < 0 && before?.state !== "ready") cockpit.refusal = null;
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
  if (!p) {
    cockpit.clearHeldSince = null;
    return stopDriving();
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
  const ready = fresh() && cockpit.state?.state === "ready" && !(cockpit.state.surfacing_ms >= 0);
  if (!ready) {
    if (cockpit.arm !== ARM_RELEASE) cockpit.arm = ARM_RELEASE;
    return stopDriving();
  }
  if (cockpit.arm === ARM_RELEASE && !s.held && s.centred) cockpit.arm = ARM_PRESS;
  else if (cockpit.arm === ARM_PRESS && s.held && s.centred) {
    cockpit.arm = ARM_ARMED;
    cockpit.refusal = null; // armed again on purpose: a new refusal makes a new event
  }
  if (!s.held || cockpit.arm !== ARM_ARMED) return stopDriving();
  driving = true;
  $("deadman").textContent = "HELD";
  $("deadman").className = "pill held";
  sendMotion(s.motion);
}

document.addEventListener("visibilitychange", () => {
  if (document.visibilityState !== "visible") { stopDriving(); commissioning.release(); }
});
window.addEventListener("gamepaddisconnected", () => stopDriving());
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
