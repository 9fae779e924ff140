// The cockpit (docs/cockpit.md): one Foxglove WebSocket client of the bridge that serves this
// page, showing the vehicle live, killing from anywhere on the page, and piloting with a gamepad.
import { FoxgloveClient } from "./foxglove.js";
import { AXES, GAINS, loadMapping, sample, saveMapping, stepGain, validMapping } from "./gamepad.js";
import { degrees, drawAttitude } from "./attitude.js";
import { showDives } from "./dives.js";

const MOTORS = 8, MOTOR_MAX = 8850;
const SEND_MS = 50;        // motion commands while the deadman is held: 20 per second
const STALE_MS = 1500;     // no message for this long while connected: shown as lost
const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("token");
const wsUrl = `ws://${location.host}/${token ? `?token=${encodeURIComponent(token)}` : ""}`;

let client = null;
let lastMessageAt = 0;     // performance.now() of the last message from the bridge
let connected = false;
const cockpit = { state: null, motors: null, thrusters: [], teensy: null, i2c: null, sent: 0, kills: 0 };
window.cockpit = cockpit;  // for the tests and the curious

// --- the connection ------------------------------------------------------------------------------
function connect() {
  client = new FoxgloveClient(wsUrl, {
    onOpen: () => { connected = true; },
    onMessage: (topic, msg) => { lastMessageAt = performance.now(); show(topic, msg); },
    onStatus: (level, text) => logEvent(level >= 2 ? 4 : 2, "bridge", text, Date.now()),
    onClose: () => {
      connected = false;
      stopDriving();
      setTimeout(connect, 2000);
    },
  });
}

function showLink() {
  const el = $("link");
  const age = lastMessageAt ? ((performance.now() - lastMessageAt) / 1000).toFixed(1) : null;
  const fresh = connected && age !== null && age * 1000 < STALE_MS;
  el.className = `link ${fresh ? "up" : "down"}`;
  el.dataset.lost = fresh ? "false" : "true";
  // What is shown is only the last thing heard: dimmed until the data is fresh again.
  document.body.classList.toggle("stale", !fresh);
  el.textContent = fresh ? "connected"
    : `${connected ? "NO DATA" : "CONNECTION LOST"}${age === null ? "" : ` — last message ${age} s ago`}`;
}

// --- what the vehicle says ---------------------------------------------------------------------
function show(topic, m) {
  if (topic === "/vehicle/state") return showState(m);
  if (topic === "/vehicle/motors") return showMotors(m);
  if (topic.startsWith("/thruster/")) return showThruster(m);
  if (topic === "/teensy") return showTeensy(m);
  if (topic === "/i2c") return showI2c(m);
  if (topic === "/events") {
    // A kill closes a dive and arming opens one: the list follows.
    if (m.name === "kill" || m.name === "arming") setTimeout(() => showDives($("dives"), $("dive-plot"), token), 500);
    return logEvent(m.level, m.name, m.message, m.timestamp.sec * 1000 + m.timestamp.nsec / 1e6);
  }
}

function showState(m) {
  cockpit.state = m;
  $("state").textContent = m.state;
  $("state").className = `state ${m.state}`;
  $("kill-source").textContent = m.kill_source || "none";
  $("kill-source").className = `state ${m.kill_source ? "killed" : ""}`;
  $("budget").textContent = m.budget_limit;
  $("profile").textContent = `${m.profile} ×${m.profile_factor}`;
  $("saturated").textContent = m.saturated ? "SATURATED" : "not saturated";
  $("saturated").className = m.saturated ? "pill bad" : "pill ok";
  $("controller").textContent = m.controller || "none";
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
  $("yaw").textContent = degrees(yaw);
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
  // The kill first: nothing of ours goes out ahead of it.
  if (!client?.publish("/command/kill", {}))
    logEvent(4, "cockpit", "kill NOT sent: no connection to the bridge (the vehicle zeroes a lost pilot's thrust)", Date.now());
  stopDriving();
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
$("clear-kill").addEventListener("click", () => $("confirm-clear").showModal());
$("confirm-clear").addEventListener("close", () => {
  if ($("confirm-clear").returnValue === "clear") client?.publish("/command/clear_kill", {});
});

// --- gamepad -------------------------------------------------------------------------------------
let mapping = loadMapping();
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

function sendMotion(motion) {
  const at = performance.now();
  cockpit.sent++;
  // When the command changed (bench/bridge_bench.mjs times a sample to the wire from here).
  if (AXES.some((a) => motion[a] !== cockpit.lastSent?.motion[a])) cockpit.lastChange = { motion, at };
  cockpit.lastSent = { motion, at };
  client?.publish("/command/motion", motion);
}

const ZERO = Object.fromEntries(AXES.map((a) => [a, 0]));

// Released, hidden, unplugged, killed or disconnected: zero at once, then nothing more.
function stopDriving() {
  if (driving) sendMotion(ZERO);
  driving = false;
  $("deadman").textContent = "released";
  $("deadman").className = "pill";
}

function tick() {
  const p = document.visibilityState === "visible" ? pad() : null;
  $("pad").textContent = p ? p.id || "gamepad" : "no gamepad";
  if (!p) return stopDriving();
  // The gain buttons act on their press, not while held.
  const press = (i) => Boolean(p.buttons[i]?.pressed);
  for (const [button, step] of [[mapping.gain_up, 1], [mapping.gain_down, -1]]) {
    if (press(button) && !gainButtons.has(button)) setGain(stepGain(mapping.gain, step));
    if (press(button)) gainButtons.add(button); else gainButtons.delete(button);
  }
  const s = sample(p, mapping);
  $("pad-motion").textContent = AXES.map((a) => `${a} ${s.motion[a].toFixed(2)}`).join(" · ");
  // Not ready (killed, arming, fault): nothing to send, the daemon would refuse it.
  if (!s.held || cockpit.state?.state !== "ready") return stopDriving();
  driving = true;
  $("deadman").textContent = "HELD";
  $("deadman").className = "pill held";
  sendMotion(s.motion);
}

document.addEventListener("visibilitychange", () => { if (document.visibilityState !== "visible") stopDriving(); });
window.addEventListener("gamepaddisconnected", () => stopDriving());
window.addEventListener("pagehide", () => { stopDriving(); client?.close(); });

function mappingForm() {
  const form = $("mapping");
  form.innerHTML = "";
  const fields = [...AXES, "deadman", "gain_up", "gain_down", "deadzone", "expo"];
  for (const k of fields) {
    const label = document.createElement("label");
    label.textContent = k;
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
  reset.addEventListener("click", () => { localStorage.removeItem("caracara.cockpit.mapping"); mapping = loadMapping(); mappingForm(); });
  form.append(reset);
  const gain = $("gain");
  gain.innerHTML = GAINS.map((g) => `<option value="${g}">${g * 100} %</option>`).join("");
  gain.value = String(mapping.gain);
}
$("gain").addEventListener("change", (e) => setGain(Number(e.target.value)));

// --- start ---------------------------------------------------------------------------------------
mappingForm();
drawAttitude($("attitude"), 0, 0, 0);
for (let i = 0; i < MOTORS; i++) thrusterRow(i);
connect();
sendTimer = setInterval(tick, SEND_MS);
setInterval(showLink, 100);
showDives($("dives"), $("dive-plot"), token);
