//! `crack_growth.html`: the frames of the time series (`output.snapshots`) as a crack map a
//! person opens in a browser, one self-contained file (plain JavaScript on a canvas, no
//! network): particles on the reference shape coloured by tensile damage w_t as in
//! crack_map.svg (light grey intact → dark red at w_t = 1), a slider over the frames and a
//! play button; each frame is labelled with its load fraction, the probe group's
//! displacement and its cracked particles (w_t ≥ 0.99). A 3D run shows its section
//! (`output::section`). The frames are in a JSON block (`id="sppm-frames"`): w_t of each
//! particle as one character of the base64 alphabet, level round(63·w_t) with 63 kept for
//! the cracked particles (w_t ≥ 0.99) alone.

use super::section;
use crate::model::damage_law::CRACKED_WT;
use crate::run::Outcome;
use serde_json::json;

const LEVELS: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// The character of a tensile damage w_t: level round(63·w_t), 63 only when cracked.
pub fn level_char(wt: f64) -> char {
    let level = if wt >= CRACKED_WT {
        63
    } else {
        ((wt.clamp(0.0, 1.0) * 63.0).round() as usize).min(62)
    };
    LEVELS[level] as char
}

/// The cracked particles of a frame's level string (the character of level 63).
pub fn cracked_in(levels: &str) -> usize {
    levels.chars().filter(|&c| c == LEVELS[63] as char).count()
}

/// A coordinate in mm, rounded to 0.1 µm (a short number in the file).
fn mm(x: f64) -> f64 {
    (x * 1e7).round() / 1e4
}

/// The text of crack_growth.html of an outcome with damage and frames (`None` without).
pub fn crack_growth_html(o: &Outcome) -> Option<String> {
    o.damage.as_ref()?;
    if o.snapshots.is_empty() {
        return None;
    }
    // the particles drawn and their in-plane axes: all of a 2D run, a 3D run's section
    let (keep, u, v, title) = if o.dim == 3 {
        let s = section::section(o);
        let names = ["x", "y", "z"];
        let title = format!(
            "{}: crack growth, section {} = {:.1} mm",
            o.summary.scene,
            names[s.normal],
            s.mid * 1e3
        );
        (s.keep, s.u, s.v, title)
    } else {
        (
            (0..o.x0.len()).collect(),
            0,
            1,
            format!("{}: crack growth", o.summary.scene),
        )
    };
    let frames: Vec<serde_json::Value> = o
        .snapshots
        .iter()
        .map(|f| {
            let d = f.damage.as_ref().expect("frames of a run with damage");
            let levels: String = keep.iter().map(|&i| level_char(d[i][0])).collect();
            json!({
                "load_fraction": f.load_fraction,
                "probe_displacement_mm": f.probe_displacement_m * 1e3,
                "cracked": f.cracked(),
                "wt": levels,
            })
        })
        .collect();
    let names = ["x", "y", "z"];
    let data = json!({
        "scene": o.summary.scene,
        "axes": [names[u], names[v]],
        "radius_mm": 0.5 * o.summary.spacing_m * 1e3,
        "x_mm": keep.iter().map(|&i| mm(o.x0[i][u])).collect::<Vec<_>>(),
        "y_mm": keep.iter().map(|&i| mm(o.x0[i][v])).collect::<Vec<_>>(),
        "frames": frames,
    });
    // JSON in a script element: "</" must not end it early
    let data = data.to_string().replace("</", "<\\/");
    Some(
        TEMPLATE
            .replace("{title}", &escape(&title))
            .replace("{data}", &data),
    )
}

/// `text` safe in HTML text.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

const TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body { font-family: sans-serif; margin: 16px; color: #222; }
canvas { border: 1px solid #bbb; display: block; margin: 8px 0; }
#controls { display: flex; align-items: center; gap: 12px; }
#frame { width: 480px; }
</style>
</head>
<body>
<h2>{title}</h2>
<p>Particles on the reference shape coloured by tensile damage w<sub>t</sub>
(light grey 0 → dark red 1, as crack_map.svg). Drag the slider or press play.</p>
<div id="controls">
<button id="play">play</button>
<input id="frame" type="range" min="0" value="0" step="1">
</div>
<div id="label"></div>
<canvas id="map"></canvas>
<script type="application/json" id="sppm-frames">{data}</script>
<script>
"use strict";
const d = JSON.parse(document.getElementById("sppm-frames").textContent);
const alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
const code = {};
for (let k = 0; k < 64; k++) code[alphabet[k]] = k;
const r = d.radius_mm, n = d.x_mm.length;
let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
for (let i = 0; i < n; i++) {
  x0 = Math.min(x0, d.x_mm[i]); x1 = Math.max(x1, d.x_mm[i]);
  y0 = Math.min(y0, d.y_mm[i]); y1 = Math.max(y1, d.y_mm[i]);
}
x0 -= 2 * r; x1 += 2 * r; y0 -= 2 * r; y1 += 2 * r;
let s = 800 / (x1 - x0);
if ((y1 - y0) * s > 800) s = 800 / (y1 - y0);
const cv = document.getElementById("map");
cv.width = Math.ceil((x1 - x0) * s); cv.height = Math.ceil((y1 - y0) * s);
const cx = cv.getContext("2d");
const colour = [];
for (let k = 0; k < 64; k++) {
  const w = k / 63, lerp = (a, b) => Math.round(a + (b - a) * w);
  colour.push("rgb(" + lerp(225, 150) + "," + lerp(225, 0) + "," + lerp(225, 0) + ")");
}
const slider = document.getElementById("frame");
slider.max = d.frames.length - 1;
const label = document.getElementById("label");
function draw(k) {
  const f = d.frames[k];
  cx.fillStyle = "#fff"; cx.fillRect(0, 0, cv.width, cv.height);
  const byLevel = Array.from({ length: 64 }, () => []);
  for (let i = 0; i < n; i++) byLevel[code[f.wt[i]]].push(i);
  const rr = Math.max(r * s, 0.75);
  for (let l = 0; l < 64; l++) {
    if (byLevel[l].length === 0) continue;
    cx.fillStyle = colour[l];
    cx.beginPath();
    for (const i of byLevel[l]) {
      const px = (d.x_mm[i] - x0) * s, py = (y1 - d.y_mm[i]) * s;
      cx.moveTo(px + rr, py); cx.arc(px, py, rr, 0, 2 * Math.PI);
    }
    cx.fill();
  }
  label.textContent = "frame " + (k + 1) + " of " + d.frames.length +
    "   load fraction " + f.load_fraction.toFixed(3) +
    "   probe displacement " + f.probe_displacement_mm.toPrecision(4) + " mm" +
    "   cracked particles (w_t \u2265 0.99): " + f.cracked +
    "   axes " + d.axes[0] + " (right), " + d.axes[1] + " (up)";
}
slider.addEventListener("input", () => draw(+slider.value));
let timer = null;
document.getElementById("play").addEventListener("click", () => {
  if (timer) { clearInterval(timer); timer = null; return; }
  if (+slider.value >= d.frames.length - 1) slider.value = 0;
  draw(+slider.value);
  timer = setInterval(() => {
    if (+slider.value >= d.frames.length - 1) { clearInterval(timer); timer = null; return; }
    slider.value = +slider.value + 1; draw(+slider.value);
  }, 400);
});
slider.value = 0; draw(0);
</script>
</body>
</html>
"##;
