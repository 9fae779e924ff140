// The attitude instrument, read as an aircraft's: an artificial horizon (nose up puts the horizon
// below the centre; roll right, right side down, turns the horizon counter-clockwise on the
// screen, its right end up) and a heading scale (a clockwise turn brings higher headings in from
// the right), drawn on a canvas from the Teensy's angles in radians: heading clockwise from
// above, pitch nose up, roll right side down (core/frames.hpp, docs/frames.md).
const DEG = 180 / Math.PI;

export function drawAttitude(canvas, yaw, pitch, roll) {
  const ctx = canvas.getContext("2d");
  const w = canvas.width, h = canvas.height, r = Math.min(w, h * 0.8) / 2 - 4;
  const cx = w / 2, cy = r + 4;
  const pxPerDeg = r / 45;
  ctx.clearRect(0, 0, w, h);
  ctx.save();
  ctx.beginPath();
  ctx.arc(cx, cy, r, 0, 2 * Math.PI);
  ctx.clip();
  ctx.translate(cx, cy);
  ctx.rotate(-roll); // the canvas's y is down: a negative angle turns counter-clockwise on screen
  const shift = pitch * DEG * pxPerDeg; // nose up: the horizon drawn lower
  ctx.translate(0, shift);
  ctx.fillStyle = "#2d6fa8"; // water above
  ctx.fillRect(-2 * r, -4 * r, 4 * r, 4 * r);
  ctx.fillStyle = "#6b4b2a"; // below
  ctx.fillRect(-2 * r, 0, 4 * r, 4 * r);
  ctx.strokeStyle = "#fff";
  ctx.fillStyle = "#fff";
  ctx.lineWidth = 2;
  ctx.font = `${Math.round(r / 9)}px sans-serif`;
  ctx.beginPath();
  ctx.moveTo(-2 * r, 0);
  ctx.lineTo(2 * r, 0);
  ctx.stroke();
  for (let d = -60; d <= 60; d += 10) {
    if (d === 0) continue;
    const y = -d * pxPerDeg, half = d % 20 === 0 ? r / 3 : r / 6;
    ctx.beginPath();
    ctx.moveTo(-half, y);
    ctx.lineTo(half, y);
    ctx.stroke();
    // A label only where all of it is inside the instrument (the rim would cut it).
    const label = String(d), font = r / 9, far = half + 4 + ctx.measureText(label).width;
    if (d % 20 === 0 && Math.hypot(far, Math.abs(y + shift) + font / 2) <= r - 3) ctx.fillText(label, half + 4, y + 4);
  }
  ctx.restore();
  // The vehicle's fixed symbol and the rim.
  ctx.strokeStyle = "#ffcc00";
  ctx.lineWidth = 4;
  ctx.beginPath();
  ctx.moveTo(cx - r * 0.55, cy);
  ctx.lineTo(cx - r * 0.15, cy);
  ctx.lineTo(cx, cy + r * 0.1);
  ctx.lineTo(cx + r * 0.15, cy);
  ctx.lineTo(cx + r * 0.55, cy);
  ctx.stroke();
  ctx.strokeStyle = "#ccc";
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.arc(cx, cy, r, 0, 2 * Math.PI);
  ctx.stroke();
  // Heading scale below: 90 degrees either side of the yaw.
  const top = 2 * r + 14, span = w - 20, heading = ((yaw * DEG) % 360 + 360) % 360;
  ctx.fillStyle = "#111";
  ctx.fillRect(10, top, span, h - top - 2);
  ctx.save();
  ctx.beginPath();
  ctx.rect(10, top, span, h - top - 2);
  ctx.clip();
  ctx.strokeStyle = "#ddd";
  ctx.fillStyle = "#ddd";
  ctx.lineWidth = 1;
  const pxPerHeadingDeg = span / 180;
  const names = { 0: "N", 90: "E", 180: "S", 270: "W" };
  for (let d = Math.floor((heading - 90) / 10) * 10; d <= heading + 90; d += 10) {
    const x = w / 2 + (d - heading) * pxPerHeadingDeg, n = ((d % 360) + 360) % 360;
    ctx.beginPath();
    ctx.moveTo(x, top);
    ctx.lineTo(x, top + (n % 30 === 0 ? 12 : 6));
    ctx.stroke();
    const label = names[n] ?? String(n), half = ctx.measureText(label).width / 2;
    // Whole labels only: one cut by the scale's ends reads as another heading.
    if (n % 30 === 0 && x - half >= 12 && x + half <= 8 + span) ctx.fillText(label, x - half, top + 26);
  }
  ctx.restore();
  ctx.fillStyle = "#ffcc00";
  ctx.beginPath();
  ctx.moveTo(w / 2 - 6, top);
  ctx.lineTo(w / 2 + 6, top);
  ctx.lineTo(w / 2, top + 10);
  ctx.fill();
}

export const degrees = (rad) => (Math.abs(rad * DEG) < 0.05 ? 0 : rad * DEG).toFixed(1);
// A heading as a compass reads it: 0 up to 360, clockwise.
export const headingDegrees = (rad) => (((Number(degrees(rad)) % 360) + 360) % 360).toFixed(1);
