// The recorded dives, as `caracaractl dives` lists them, from the bridge's /dives/ (JSON), with
// each dive's .cdive and MCAP for download and a plot of its thrust drawn here as SVG.
const SVG = "http://www.w3.org/2000/svg";

export async function showDives(table, plotBox, token) {
  const q = token ? `?token=${encodeURIComponent(token)}` : "";
  const body = table.tBodies[0];
  let list;
  try {
    const r = await fetch(`/dives/${q}`);
    if (!r.ok) throw new Error(`${r.status}`);
    list = await r.json();
  } catch (e) {
    body.innerHTML = `<tr><td colspan="6" class="dim">no dives served (${e.message})</td></tr>`;
    return;
  }
  body.innerHTML = "";
  if (!list.length) body.innerHTML = `<tr><td colspan="6" class="dim">no dive recorded yet</td></tr>`;
  for (const d of list) {
    const tr = document.createElement("tr");
    const link = (ext, label) => `<a href="/dives/${d.name}.${ext}${q}" download>${label}</a>`;
    tr.innerHTML = `<td>${d.name}</td><td>${new Date(d.start_ms).toLocaleString()}</td><td>${d.seconds.toFixed(1)}</td>` +
      `<td>${d.samples}</td><td>${link("cdive", ".cdive")} ${link("mcap", "MCAP")}</td><td><button>plot</button></td>`;
    tr.querySelector("button").addEventListener("click", () => plot(d.name, plotBox, q));
    body.append(tr);
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
