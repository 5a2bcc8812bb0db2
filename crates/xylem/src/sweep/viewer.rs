//! The sweep viewer: one self-contained HTML page (no server, no network, no external script) that
//! scrubs the frames with a slider, shows the light angle and plots mean radiance against it.
//! Frames are referenced by relative path (`frame_NNNN.png`), so the page works from `file://`.

use super::sequence::{frame_stem, FrameRecord, ANIMATION, CONTACT_SHEET, CSV};

/// Escapes text for HTML element content and attribute values.
pub(crate) fn html_escape(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '&' => "&amp;".to_string(),
            '<' => "&lt;".to_string(),
            '>' => "&gt;".to_string(),
            '"' => "&quot;".to_string(),
            '\'' => "&#39;".to_string(),
            c => c.to_string(),
        })
        .collect()
}

/// The per-frame data the page's script reads: file, light angle, mean luminance, region means.
fn frames_json(records: &[FrameRecord]) -> String {
    let items: Vec<serde_json::Value> = records
        .iter()
        .map(|r| {
            serde_json::json!({
                "src": format!("{}.png", frame_stem(r.index)),
                "deg": r.light_deg,
                "mean": r.mean_luminance,
                "regions": r.regions.iter().map(|g| serde_json::json!([g.name, g.luminance])).collect::<Vec<_>>(),
            })
        })
        .collect();
    // `</` inside a script element would end it early.
    serde_json::Value::Array(items)
        .to_string()
        .replace("</", "<\\/")
}

/// The viewer page for a complete, index-sorted list of frame records.
pub(crate) fn viewer_html(records: &[FrameRecord], title: &str, fps: u16) -> String {
    let title = html_escape(title);
    let data = frames_json(records);
    let (w, h) = records
        .first()
        .map(|r| (r.width, r.height))
        .unwrap_or((1, 1));
    let fps = fps.max(1);
    format!(
        r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
 body {{ background:#181818; color:#ddd; font:14px system-ui,sans-serif; margin:1.5em; }}
 #frame {{ max-width:100%; image-rendering:auto; background:#000; display:block; }}
 .bar {{ display:flex; gap:1em; align-items:center; margin:0.8em 0; }}
 #slider {{ flex:1; }}
 #angle {{ font:600 20px ui-monospace,monospace; min-width:9ch; }}
 svg {{ background:#222; }}
 a {{ color:#9cf; }}
</style>
</head>
<body>
<h1>{title}</h1>
<img id="frame" width="{w}" height="{h}" alt="sweep frame">
<div class="bar">
 <button id="play">▶ play</button>
 <input id="slider" type="range" min="0" max="{last}" value="0" step="1">
 <span id="angle"></span><span id="info"></span>
</div>
<svg id="plot" width="640" height="180" viewBox="0 0 640 180"></svg>
<p>Light angle from the zenith (degrees) against mean luminance; the dot is the frame shown.
Arrow keys step, space plays. Files: <a href="{sheet}">contact sheet</a>, <a href="{anim}">animated PNG</a>,
<a href="{csv}">CSV</a>.</p>
<script>
const FRAMES = {data};
const FPS = {fps};
const img = document.getElementById('frame'), slider = document.getElementById('slider');
const angle = document.getElementById('angle'), info = document.getElementById('info');
const cache = FRAMES.map(f => {{ const i = new Image(); i.src = f.src; return i; }});
const plot = document.getElementById('plot');
const NS = 'http://www.w3.org/2000/svg';
const series = [{{ name: 'mean', color: '#fc6', get: f => f.mean }}];
(FRAMES[0].regions || []).forEach((r, k) => series.push({{
  name: r[0], color: ['#6cf', '#f69', '#9f6', '#c9f', '#fa6'][k % 5], get: f => f.regions[k][1] }}));
const degs = FRAMES.map(f => f.deg);
const lo = Math.min(...degs), hi = Math.max(...degs);
const vmax = Math.max(1e-12, ...FRAMES.flatMap(f => series.map(s => s.get(f))));
const px = d => 40 + 580 * (hi > lo ? (d - lo) / (hi - lo) : 0.5);
const py = v => 160 - 140 * v / vmax;
function el(tag, attrs) {{ const e = document.createElementNS(NS, tag);
  for (const k in attrs) e.setAttribute(k, attrs[k]); plot.appendChild(e); return e; }}
el('line', {{ x1: 40, y1: 160, x2: 620, y2: 160, stroke: '#666' }});
el('text', {{ x: 40, y: 176, fill: '#aaa', 'font-size': 11 }}).textContent = lo.toFixed(1) + '°';
el('text', {{ x: 590, y: 176, fill: '#aaa', 'font-size': 11 }}).textContent = hi.toFixed(1) + '°';
series.forEach((s, k) => {{
  el('polyline', {{ fill: 'none', stroke: s.color, 'stroke-width': 1.5,
    points: FRAMES.map(f => px(f.deg) + ',' + py(s.get(f))).join(' ') }});
  el('text', {{ x: 46 + 90 * k, y: 14, fill: s.color, 'font-size': 11 }}).textContent = s.name;
}});
const dot = el('circle', {{ r: 4, fill: '#fff' }});
function show(i) {{
  i = Math.max(0, Math.min(FRAMES.length - 1, i)); slider.value = i;
  const f = FRAMES[i]; img.src = cache[i].src;
  angle.textContent = f.deg.toFixed(1) + '°';
  info.textContent = 'frame ' + i + ' / ' + (FRAMES.length - 1) + ', mean luminance ' + f.mean.toPrecision(4);
  dot.setAttribute('cx', px(f.deg)); dot.setAttribute('cy', py(f.mean));
}}
let timer = null;
function toggle() {{
  const b = document.getElementById('play');
  if (timer) {{ clearInterval(timer); timer = null; b.textContent = '▶ play'; return; }}
  b.textContent = '❚❚ pause';
  timer = setInterval(() => show((+slider.value + 1) % FRAMES.length), 1000 / FPS);
}}
slider.addEventListener('input', () => show(+slider.value));
document.getElementById('play').addEventListener('click', toggle);
document.addEventListener('keydown', e => {{
  if (e.key === 'ArrowRight') show(+slider.value + 1);
  else if (e.key === 'ArrowLeft') show(+slider.value - 1);
  else if (e.key === ' ') {{ e.preventDefault(); toggle(); }}
}});
show(0);
</script>
</body>
</html>
"##,
        last = records.len().saturating_sub(1),
        sheet = CONTACT_SHEET,
        anim = ANIMATION,
        csv = CSV,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::sequence::RegionMean;

    fn rec(i: usize) -> FrameRecord {
        FrameRecord {
            index: i,
            frames: 3,
            sweep: Default::default(),
            light_deg: -30.0 + 30.0 * i as f32,
            width: 8,
            height: 4,
            mean_rgb: [0.1; 3],
            mean_luminance: 0.1,
            regions: vec![RegionMean {
                name: "</script>".into(),
                luminance: 0.2,
            }],
        }
    }

    #[test]
    fn page_references_every_frame_and_needs_no_network() {
        let html = viewer_html(&[rec(0), rec(1), rec(2)], "board <1>", 12);
        for i in 0..3 {
            assert!(html.contains(&format!("\"src\":\"frame_{i:04}.png\"")));
        }
        assert!(html.contains("max=\"2\""));
        assert!(html.contains("<title>board &lt;1&gt;</title>"));
        for external in ["src=\"http", "href=\"http", "https://", "<link"] {
            assert!(
                !html.contains(external),
                "no external resources: {external}"
            );
        }
        // The region name cannot close the script early.
        assert_eq!(html.matches("</script>").count(), 1);
    }
}
