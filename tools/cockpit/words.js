// The vehicle's state in a pilot's words (docs/cockpit.md): kill sources, failsafe conditions,
// the controller, and the banner of everything that holds the vehicle back.
const KILL_SOURCES = {
  "": "none",
  start: "daemon start (every start is killed)",
  dbus: "Kill command (a pilot or caracaractl)",
  switch: "the kill switch",
  packet: "a kill packet",
  bus: "I2C bus lost",
  device: "hardware (a kill line gone or a thruster failing)",
  failsafe: "a failsafe",
};
const CONDITIONS = {
  "water-detect": "water in the thruster",
  "ground-fault": "ground fault",
  overtemp: "over-temperature",
  stall: "stalled motor",
  hall: "hall sensor error",
  "pilot-lost": "no pilot left",
  "thruster-unreachable": "a thruster does not answer",
  "bus-lost": "I2C bus lost",
  "teensy-link-lost": "Teensy link lost",
  "kill-switch-unreadable": "kill switch unreadable",
};

const escape = (t) => String(t).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);

export const killSourceWords = (source) => KILL_SOURCES[source] ?? source;

export function conditionWords(f) {
  const what = CONDITIONS[f.condition] ?? f.condition;
  return f.thruster >= 0 ? `${what} (thruster ${f.thruster})` : what;
}

// The commanding client: its process where the bridge could name it; "this page" while it drives.
export function controllerWords(state, driving) {
  if (!state.controller) return "none";
  const bridgeClient = state.controller_name?.includes("this bridge");
  if (driving && bridgeClient) return "this page";
  return state.controller_name || `client ${state.controller}`;
}

// A countdown the daemon gave as `leftMs` when the state came, `sinceMs` ago: seconds left, never below 0.
const secondsLeft = (leftMs, sinceMs) => (Math.max(0, leftMs - sinceMs) / 1000).toFixed(1);

// [{kind, level, text}]: what keeps the vehicle from doing what the pilot asks, most urgent first.
// `sinceStateMs`: how long ago the state came (its countdowns run on); `pilotLostMs`: the
// daemon's pilot-lost persistence as last heard (null before the first state); `seat`: the
// bridge's last word on the pilot's seat (null: none, or no link); `seatLost`: {by, at (ms since
// the epoch)} when another client took it over from this page.
export function banner({ state, up, lostMs, killNotSentMs, refusal, sinceStateMs = 0, pilotLostMs = null, seat = null,
  seatLost = null }) {
  const out = [];
  const add = (kind, level, text) => out.push({ kind, level, text: escape(text) });
  if (seatLost && !seat?.yours)
    add("seat-lost", "alarm", `SEAT TAKEN OVER by ${seatLost.by} at ${new Date(seatLost.at).toTimeString().slice(0, 8)}: ` +
      "this page no longer drives (its thrust was zeroed)");
  else if (seat?.holder && !seat.yours)
    add("seat", "warn", `SEAT: ${seat.holder} holds the pilot's seat; this page does not drive (Take over… to drive)`);
  if (killNotSentMs !== null)
    add("kill-not-sent", "alarm", `KILL NOT SENT ${(killNotSentMs / 1000).toFixed(0)} s ago: no link to the bridge. ` +
      "Press KILL again once connected, or use the kill switch");
  if (!up) {
    const s = lostMs / 1000;
    const left = pilotLostMs === null ? null : secondsLeft(pilotLostMs, lostMs);
    add("link-lost", "alarm", `LINK LOST ${s.toFixed(1)} s: this page cannot kill. The vehicle zeroed this page's thrust; ` +
      (left === null ? "pilot-lost kill after the vehicle's persistence unless another pilot drives"
        : Number(left) > 0 ? `pilot-lost kill in ${left} s unless another pilot drives`
          : "pilot-lost kill due unless another pilot drives"));
  }
  if (!state || !up) return out;
  if (state.pilot_lost_left_ms >= 0)
    add("pilot-lost", "alarm", `PILOT LOST: the last pilot left; kill in ${secondsLeft(state.pilot_lost_left_ms, sinceStateMs)} s ` +
      "unless a pilot drives");
  for (const f of state.failsafes ?? []) {
    if (f.action === "surface")
      add("surfacing", "alarm", `SURFACING: ${conditionWords(f)}. ` + (state.ascent_left_ms >= 0
        ? `Ascent: ${secondsLeft(state.ascent_left_ms, sinceStateMs)} s left, then the vehicle kills itself; motion is refused`
        : state.state === "killed" || state.state === "powered-off"
          ? "Ascent over or ended by a kill; Clear kill is refused while it holds"
          : "Ascent starting (its time to come with the next state), then the vehicle kills itself; motion is refused"));
    else if (f.action === "exclude")
      add("excluded", "alarm", `THRUSTER ${f.thruster} EXCLUDED: ${CONDITIONS[f.condition] ?? f.condition}; held at zero, the others drive`);
    else if (f.action === "kill")
      add("failsafe-kill", "alarm", `FAILSAFE: ${conditionWords(f)}; killed, Clear kill refused while it holds`);
    else
      add("warning", "warn", `WARNING: ${conditionWords(f)}`);
  }
  if (state.motor_test?.thruster >= 0)
    add("motor-test", "warn", `MOTOR TEST: thruster ${state.motor_test.thruster} at ${state.motor_test.value}, the others held at zero`);
  if (refusal && refusal !== "SeatTaken" && state.state === "ready" && !(state.surfacing_ms >= 0))
    add("refused", "warn", `Motion refused (${refusal}): release the deadman, centre the sticks and press it again`);
  return out;
}
