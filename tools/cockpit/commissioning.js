// The commissioning panel (docs/cockpit.md, docs/commissioning.md): a motor test run while its
// button is held, and the daemon's direction detection with its result and the [[thruster]]
// fragment to copy. It owns its controls, the motor test's keep-alive timer and what it shows.
const MOTORS = 8;
export const MOTOR_TEST_TOPIC = "/command/motor_test";
export const DETECT_TOPIC = "/command/detect_directions";
// The daemon stops a motor test without a repeat within commissioning.motor_test_keepalive_ms
// (500 ms at most): the page repeats well inside it while the button is held, and only then.
export const MOTOR_TEST_REPEAT_MS = 100;
const VALUE_DEFAULT = 800;
const LIMIT_DEFAULT = 1500; // the daemon's default, until its MotorTestLimit is heard

export class Commissioning {
  // publish(topic, obj): false when not sent; log(level, text): an event in the page's list.
  constructor(publish, log) {
    this.publish = publish;
    this.log = log;
    this.$ = (id) => document.getElementById(id);
    this.limit = LIMIT_DEFAULT;
    this.held = null;          // {thruster, value} while the motor test button is held
    this.timer = null;
    this.sent = 0;             // motor test commands sent (the tests read it)
    this.detecting = false;
    this.detectStarted = 0;
    this.result = null;        // the last detection's answer {thrusters, fragment}
    this.$("mt-thruster").innerHTML = [...Array(MOTORS).keys()].map((i) => `<option value="${i}">${i}</option>`).join("");
    this.$("mt-value").value = VALUE_DEFAULT;
    const run = this.$("mt-run");
    run.addEventListener("pointerdown", (e) => { e.preventDefault(); run.setPointerCapture?.(e.pointerId); this.hold(); });
    for (const ev of ["pointerup", "pointercancel", "lostpointercapture"]) run.addEventListener(ev, () => this.release());
    run.addEventListener("contextmenu", (e) => e.preventDefault()); // a long touch is a hold, not a menu
    this.$("detect-start").addEventListener("click", () => this.detect());
    this.$("detect-copy").addEventListener("click", () => this.copy());
    this.showMotorTest(null);
  }

  // --- motor test ---
  hold() {
    const thruster = Number(this.$("mt-thruster").value);
    const value = Math.trunc(Number(this.$("mt-value").value));
    const error = this.$("mt-error");
    if (!Number.isFinite(value) || Math.abs(value) > this.limit) {
      error.textContent = `the value must be within ±${this.limit} (commissioning.motor_test_limit)`;
      return;
    }
    error.textContent = "";
    this.held = { thruster, value };
    this.$("mt-run").classList.add("held");
    this.repeat();
    this.timer = setInterval(() => this.repeat(), MOTOR_TEST_REPEAT_MS);
  }

  repeat() {
    if (this.held && this.publish(MOTOR_TEST_TOPIC, this.held)) this.sent++;
  }

  // Released, refused, killed, hidden or disconnected: the thruster ordered zero at once (the
  // daemon's keep-alive would stop it anyway), then nothing more.
  release() {
    if (!this.held) return;
    const { thruster } = this.held;
    this.held = null;
    clearInterval(this.timer);
    this.timer = null;
    this.$("mt-run").classList.remove("held");
    if (this.publish(MOTOR_TEST_TOPIC, { thruster, value: 0 })) this.sent++;
  }

  // Stops sending without a last command: a kill is on its way and goes alone.
  stop() {
    this.held = null;
    clearInterval(this.timer);
    this.timer = null;
    this.$("mt-run").classList.remove("held");
  }

  // The vehicle's state: the running motor test and the limit.
  showState(state) {
    if (state?.motor_test_limit > 0 && state.motor_test_limit !== this.limit) {
      this.limit = state.motor_test_limit;
      this.$("mt-value").min = -this.limit;
      this.$("mt-value").max = this.limit;
    }
    this.$("mt-limit").textContent = `±${this.limit}`;
    this.showMotorTest(state);
  }

  showMotorTest(state) {
    const el = this.$("mt-status");
    const t = state?.motor_test;
    const running = t && t.thruster >= 0;
    el.textContent = running ? `thruster ${t.thruster} running at ${t.value}` : state ? "no motor test running" : "—";
    el.className = `pill ${running ? "held" : ""}`;
    el.dataset.thruster = running ? t.thruster : -1;
  }

  // --- direction detection ---
  detect() {
    if (this.detecting) return;
    if (!this.publish(DETECT_TOPIC, {})) {
      this.$("detect-status").textContent = "not sent: no connection to the bridge";
      return;
    }
    this.detecting = true;
    this.detectStarted = performance.now();
    this.$("detect-start").disabled = true;
    this.$("detect-status").textContent = "running: settling before the first pulse";
    this.$("detect-status").dataset.phase = "running";
    this.log(2, "cockpit", "direction detection started");
  }

  // The motors while detection runs: the one pulsed now, said as progress.
  showMotors(m) {
    if (!this.detecting) return;
    const pulsed = m.applied.findIndex((v) => v !== 0);
    const s = ((performance.now() - this.detectStarted) / 1000).toFixed(0);
    this.$("detect-status").textContent = pulsed >= 0
      ? `running ${s} s: pulsing thruster ${pulsed} (${m.applied[pulsed]})`
      : `running ${s} s: settling`;
    this.$("detect-status").dataset.pulsed = pulsed;
  }

  // A command's answer (a status message whose id is its topic): true when it was ours.
  answer(id, text) {
    if (id !== DETECT_TOPIC) return false;
    this.detectEnded("done");
    this.result = JSON.parse(text);
    const body = this.$("detect-result").tBodies[0];
    body.replaceChildren(...this.result.thrusters.map((t) => {
      const row = document.createElement("tr");
      row.dataset.verdict = t.verdict;
      const signed = (v) => `${v >= 0 ? "+" : ""}${v.toFixed(4)}`;
      for (const [text, cls] of [[t.thruster, ""], [t.verdict, `verdict ${t.verdict}`], [signed(t.yaw)], [signed(t.pitch)],
        [signed(t.roll)], [signed(t.along)], [t.margin.toFixed(1)]]) {
        const cell = row.insertCell();
        cell.textContent = text;
        if (cls) cell.className = cls;
      }
      return row;
    }));
    this.$("detect-fragment").value = this.result.fragment;
    this.$("detect-copied").textContent = "";
    this.$("detect-output").hidden = false;
    const undecided = this.result.thrusters.filter((t) => t.verdict === "inconclusive").length;
    const reversed = this.result.thrusters.filter((t) => t.verdict === "reversed").map((t) => t.thruster);
    this.$("detect-status").textContent = `done: ${reversed.length ? `reversed ${reversed.join(", ")}` : "none reversed"}` +
      (undecided ? `, ${undecided} inconclusive (run again)` : "");
    this.log(2, "cockpit", `direction detection: ${this.$("detect-status").textContent}`);
    return true;
  }

  // A refusal of one of our commands ("<topic> refused: <error name>: <message>"): true when ours.
  refused(text) {
    if (text.startsWith(`${DETECT_TOPIC} refused`)) {
      this.detectEnded("refused");
      this.$("detect-status").textContent = text.slice(DETECT_TOPIC.length + 1);
      return true;
    }
    if (text.startsWith(`${MOTOR_TEST_TOPIC} refused`)) {
      this.stop();
      this.$("mt-error").textContent = text.slice(MOTOR_TEST_TOPIC.length + 1);
      return true;
    }
    return false;
  }

  // The connection closed, or the seat went to another page (the bridge replaced this page's
  // connection): the daemon ended a detection of that connection (Busy) and zeroed its test.
  lost(why = "the connection to the bridge closed") {
    this.stop();
    if (this.detecting) {
      this.detectEnded("lost");
      this.$("detect-status").textContent = `ended: ${why}`;
    }
  }

  detectEnded(phase) {
    this.detecting = false;
    this.$("detect-start").disabled = false;
    this.$("detect-status").dataset.phase = phase;
  }

  async copy() {
    const box = this.$("detect-fragment");
    let done = false;
    try {
      await navigator.clipboard.writeText(box.value);
      done = true;
    } catch {
      box.select(); // not a secure context, or no permission: selected for Ctrl+C
      done = document.execCommand?.("copy") ?? false;
    }
    this.$("detect-copied").textContent = done ? "copied" : "selected: press Ctrl+C";
  }
}
