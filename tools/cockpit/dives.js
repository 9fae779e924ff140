// The recorded dives, as `caracaractl dives` lists them, from the bridge's /dives/ (JSON), with
// each dive's .cdive and MCAP for download and a plot of its thrust drawn here as SVG.
const SVG = "http://www.w3.org/2000/svg";

// The list is fetched once per change for all of this browser's tabs: one tab (holding a Web
// Lock) fetches when a kill closed a dive, and the others get the list from it on a
// BroadcastChannel. Where locks are not offered (a page not from localhost) each tab fetches.
const CHANNEL = "caracara.cockpit.dives";
const SETTLE_MS = 500; // the kills of one event (a failsafe, then its kill) make one fetch

export class DiveList {
  constructor(table, plotBox, token) {
    this.table = table;
    this.plotBox = plotBox;
    this.q = token ? `?token=${encodeURIComponent(token)}` : "";
    this.fetches = 0;
    this.timer = null;
    this.leader = !navigator.locks;
    this.shown = null;
    this.channel = typeof BroadcastChannel === "function" ? new BroadcastChannel(CHANNEL) : null;
    if (this.channel) this.channel.onmessage = (e) => this.show(e.data);
    navigator.locks?.request(CHANNEL, () => { this.leader = true; return new Promise(() => {}); });
  }

  // The list as it is now, for this tab (at load).
  load() { return this.fetch(false); }

  // A dive may have closed: the leading tab fetches once things settle, and tells the others.
  changed() {
    if (!this.leader) return;
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.fetch(true), SETTLE_MS);
  }

  async fetch(share) {
    this.fetches++;
    let result;
    try {
      const r = await fetch(`/dives/${this.q}`);
      if (!r.ok) throw new Error(`${r.status}`);
      result = { list: await r.json() };
    } catch (e) {
      result = { error: e.message };
    }
    this.show(result);
    if (share && this.channel && !result.error) this.channel.postMessage(result);
  }

  show({ list, error }) {
    const body = this.table.tBodies[0];
    if (error) {
      body.innerHTML = `<tr><td colspan="6" class="dim">no dives served (${error})</td></tr>`;
      return;
    }
    const key = JSON.stringify(list);
    if (key === this.shown) return;
    this.shown = key;
    body.innerHTML = "";
    if (!list.length) body.innerHTML = `<tr><td colspan="6" class="dim">no dive recorded yet</td></tr>`;
    // Newest first: the dive a pilot just made is the one looked for.
    for (const d of [...list].sort((a, b) => b.start_ms - a.start_ms)) {
      const tr = document.createElement("tr");
      const link = (ext, label) => `<a href="/dives/${d.name}.${ext}${this.q}" download>${label}</a>`;
      tr.innerHTML = `<td>${d.name}</td><td>${new Date(d.start_ms).toLocaleString()}</td><td>${d.seconds.toFixed(1)}</td>` +
        `<td>${d.samples}</td><td>${link("cdive", ".cdive")} ${link("mcap", "MCAP")}</td><td><button>plot</button></td>`;
      tr.querySelector("button").addEventListener("click", () => plot(d.name, this.plotBox, this.q));
      body.append(tr);
    }
  }
}

async function plot(name, box, q) {
  const r = await fetch(`/dives/${name}.json${q}`);
  if (!r.ok) { box.textContent = `cannot load ${name}: ${r.status}`; return; }
  const { t, applied, end } = await r.json(); // t: seconds; applied: [motor][sample]
  const w = 1000, h = 240, tmax = Math.max(1e-3, t[t.length - 1] ?? 1);
  const svg = document.createElementNS(SVG, "svg");
  svg.setAttribute("viewBox", `0 0 ${w} ${h}`);
  svg.setAttribute("preserveAspectRatio", "none");
  const colors = ["#e6194b", "#3cb44b", "#ffe119", "#4363d8", "#f58231", "#911eb4", "#46f0f0", "#f032e6"];
  applied.forEach((series, m) => {
    const line = document.createElementNS(SVG, "polyline");
    line.setAttribute("fill", "none");
    line.setAttribute("stroke", colors[m % colors.length]);
    line.setAttribute("vector-effect", "non-scaling-stroke");
    line.setAttribute("points", series.map((v, i) => `${(t[i] / tmax) * w},${h / 2 - (v / 8850) * (h / 2 - 4)}`).join(" "));
    svg.append(line);
  });
  const title = document.createElement("p");
  title.className = "dim";
  title.textContent = `${name}: applied thrust of motors 0..7 (-8850..8850) over ${tmax.toFixed(1)} s, ended: ${end}`;
  box.replaceChildren(title, svg);
}
