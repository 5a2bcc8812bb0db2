//! The figures the species checks read from a preset: colour, chatoyance, ring widths and their
//! sensitivity, the latewood line, pores, ray fleck and ribbon stripe.

use glam::Vec3;
use std::path::{Path, PathBuf};
use xylem::wood::{Needs, SmoothRectangleWave, WoodParams, WoodVolume};
use xylem_lab::appearance::{quantile, Subject};

pub(super) fn base() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The presets measured: scenes/presets/ (the files compiled in), or `XYLEM_SPECIES_DIR`.
pub(super) fn presets() -> PathBuf {
    std::env::var_os("XYLEM_SPECIES_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| base().join("scenes/presets"))
}

/// The presets as they were before issue 25.
pub(super) fn controls() -> PathBuf {
    base().join("tests/data/issue25_controls")
}

/// `name`'s file from `dir` with `edit` applied (each `(from, to)` must occur), in a folder of
/// its own: a control with one feature edited out.
pub(super) fn edited(dir: &Path, name: &str, tag: &str, edit: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(dir.join(format!("{name}.toml"))).unwrap();
    for (from, to) in edit {
        assert!(text.contains(from), "{name}: no `{from}` to edit");
        text = text.replacen(from, to, 1);
    }
    let out =
        std::env::temp_dir().join(format!("xylem_species_{}_{name}_{tag}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join(format!("{name}.toml")), text).unwrap();
    out
}

pub(super) fn params(dir: &Path, name: &str) -> WoodParams {
    WoodParams::from_toml_file(dir.join(format!("{name}.toml"))).unwrap()
}

pub(super) fn volume(dir: &Path, name: &str) -> WoodVolume {
    WoodVolume::new(params(dir, name), 7).unwrap()
}

pub(super) fn lum(c: Vec3) -> f64 {
    xylem::math::luminance(c) as f64
}

/// HSV hue (degrees) and saturation of a linear colour, taken on its sRGB encoding (the hue a
/// woodworker names: 0 red, 30 orange-brown, 60 yellow).
pub(super) fn hue_sat(c: Vec3) -> (f64, f64) {
    let [r, g, b] = [c.x, c.y, c.z].map(|v| xylem::picture::srgb::linear_to_srgb(v) as f64);
    let (mx, mn) = (r.max(g).max(b), r.min(g).min(b));
    let d = mx - mn;
    let h = if d <= 0.0 {
        0.0
    } else if mx == r {
        60.0 * ((g - b) / d).rem_euclid(6.0)
    } else if mx == g {
        60.0 * ((b - r) / d + 2.0)
    } else {
        60.0 * ((r - g) / d + 4.0)
    };
    (h, if mx > 0.0 { d / mx } else { 0.0 })
}

pub(super) fn mean(v: impl Iterator<Item = Vec3>) -> Vec3 {
    let (s, n) = v.fold((Vec3::ZERO, 0usize), |(s, n), c| (s + c, n + 1));
    s / n.max(1) as f32
}

/// Colour of a preset's board face (seed 7, quartersawn 120 mm from the pith, 97.5 mm square):
/// mean diffuse and mean fibre colour.
pub(super) struct FaceColour {
    pub(super) diffuse: Vec3,
    pub(super) fiber: Vec3,
}

pub(super) fn face_colour(subject: &Subject) -> FaceColour {
    let m = subject.maps(base()).unwrap();
    FaceColour {
        diffuse: mean(m.board.diffuse.iter().copied()),
        fiber: mean(m.board.fiber_color.iter().copied()),
    }
}

/// The preset board of `validate appearance` (seed 7, quartersawn 120 mm from the pith).
pub(super) fn board(dir: &Path, name: &str) -> Subject {
    Subject::Preset {
        name: name.into(),
        seed: 7,
        dir: Some(dir.to_path_buf()),
        ring_angle_deg: 90.0,
    }
}

pub(super) fn preset_colour(dir: &Path, name: &str) -> FaceColour {
    face_colour(&board(dir, name))
}

pub(super) fn measured_colour(board: &str) -> FaceColour {
    face_colour(&Subject::Measured {
        dir: format!("data/marschner2005/{board}"),
        grain_along_x: board == "maple",
    })
}

/// Mean diffuse luminance over that of Marschner et al. 2005's measured maple board.
pub(super) fn luminance_vs_maple(c: &FaceColour) -> f64 {
    lum(c.diffuse) / lum(measured_colour("maple").diffuse)
}

/// How much less saturated the fibre highlight is than the diffuse colour: HSV saturation of
/// the mean fibre colour over that of the mean diffuse. Wood's highlight is paler than its body
/// (a metal's is as saturated as its body, or more).
pub(super) fn highlight_saturation_ratio(c: &FaceColour) -> f64 {
    hue_sat(c.fiber).1 / hue_sat(c.diffuse).1
}

/// Chatoyance of a preset board's top-down sweep (`Subject::sweep`: a distant light along the
/// grain over ±60°, 13 frames, 96² pixels, 2 spp): (median, p90/p10) of the per-pixel max/min
/// luminance.
pub(super) fn chatoyance(dir: &Path, name: &str) -> (f64, f64) {
    sweep_chatoyance(&board(dir, name))
}

pub(super) fn sweep_chatoyance(subject: &Subject) -> (f64, f64) {
    let s = subject.sweep(base(), 13, 96, 2).unwrap();
    let c = s.chatoyance();
    (quantile(&c, 0.5), quantile(&c, 0.9) / quantile(&c, 0.1))
}

/// The ring value g (0 earlywood … 1 latewood) at growth time t.
pub(super) fn ring_wave(p: &WoodParams) -> SmoothRectangleWave {
    SmoothRectangleWave::new(p.rings.proportions, 0.0, 1.0)
}

/// Ring widths (mm) between 20 and 220 mm from the pith, from the growth time t(r) (rings at
/// whole years), the seed's tree.
pub(super) fn ring_widths(v: &WoodVolume) -> Vec<f64> {
    let step = 0.01f32;
    let mut last: Option<(f32, f32)> = None;
    let mut edges = Vec::new();
    let mut r = 20.0f32;
    while r < 220.0 {
        let t = v.time(r).0;
        if let Some((r0, t0)) = last {
            if t.floor() > t0.floor() {
                edges.push(r0 + (t.floor() - t0) / (t - t0) * (r - r0));
            }
        }
        last = Some((r, t));
        r += step;
    }
    edges.windows(2).map(|w| (w[1] - w[0]) as f64).collect()
}

/// Coefficient of variation of the ring widths (sd / mean).
pub(super) fn ring_width_cv(v: &WoodVolume) -> f64 {
    let w = ring_widths(v);
    let n = w.len() as f64;
    let m = w.iter().sum::<f64>() / n;
    let sd = (w.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n).sqrt();
    sd / m
}

/// Mean sensitivity of the ring widths (Fritts 1976, "Tree Rings and Climate"): the mean of
/// |2 (w₊ − w) / (w₊ + w)| over neighbouring years, the year-to-year change dendrochronologists
/// measure; a series below about 0.2 is "complacent" (rings of near-equal width).
pub(super) fn mean_sensitivity(v: &WoodVolume) -> f64 {
    let w = ring_widths(v);
    let s: Vec<f64> = w
        .windows(2)
        .map(|p| (2.0 * (p[1] - p[0]) / (p[1] + p[0])).abs())
        .collect();
    s.iter().sum::<f64>() / s.len() as f64
}

/// Share of the radius 20–220 mm from the pith in the latewood half of the ring (g > 0.5): the
/// width of the ring line as a fraction of the ring (a thin ruled line: small).
pub(super) fn latewood_share(v: &WoodVolume) -> f64 {
    let g = ring_wave(v.params());
    let n = 20_000;
    let late = (0..n)
        .filter(|i| g.eval(v.time(20.0 + 200.0 * (*i as f32 + 0.5) / n as f32).0) > 0.5)
        .count();
    late as f64 / n as f64
}

/// Width of the earlywood → latewood transition (g from 0.1 to 0.9) as a fraction of its ring,
/// the median over the rings 20–220 mm from the pith: the softness of the ring line.
pub(super) fn latewood_transition(v: &WoodVolume) -> f64 {
    let g = ring_wave(v.params());
    let step = 0.01f32;
    let (mut lo, mut fr) = (None::<f32>, Vec::new());
    let mut r = 20.0f32;
    let mut prev = g.eval(v.time(r).0);
    let mut year_start = (v.time(r).0.floor(), r);
    while r < 220.0 {
        r += step;
        let t = v.time(r).0;
        if t.floor() > year_start.0 {
            year_start = (t.floor(), r);
        }
        let x = g.eval(t);
        if prev < 0.1 && x >= 0.1 {
            lo = Some(r);
        }
        if prev < 0.9 && x >= 0.9 {
            if let Some(a) = lo.take() {
                // The ring's width at this point: 1 / (dt/dr).
                let width = 1.0 / v.time(r).1;
                fr.push(((r - a) / width) as f64);
            }
        }
        prev = x;
    }
    quantile(&fr, 0.5)
}

/// Texels of a cut: `n` × `n` points, `side` mm square, of a plane through `origin` spanned by
/// `u` and `w`.
pub(super) fn cut(
    v: &WoodVolume,
    origin: Vec3,
    u: Vec3,
    w: Vec3,
    side: f32,
    n: usize,
) -> Vec<xylem::wood::WoodTexel> {
    let pts: Vec<Vec3> = (0..n * n)
        .map(|i| {
            let (a, b) = ((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            origin + u * (side * (a / n as f32 - 0.5)) + w * (side * (b / n as f32 - 0.5))
        })
        .collect();
    let mut out = vec![xylem::wood::WoodTexel::default(); pts.len()];
    v.eval_many(&pts, Needs::ALL, &mut out);
    out
}

/// Pores on the end grain (a 40 mm square of the transverse cut 120 mm from the pith, 0.05 mm
/// texels): (fraction of earlywood area inside a pore, that over the latewood's fraction: the
/// ring porosity, ≫ 1 ring-porous, ≈ 1 diffuse-porous).
pub(super) fn end_grain_pores(v: &WoodVolume) -> (f64, f64) {
    let g = ring_wave(v.params());
    let t = cut(v, Vec3::new(120.0, 0.0, 0.0), Vec3::X, Vec3::Y, 40.0, 800);
    let (mut e, mut ep, mut l, mut lp) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for x in &t {
        let gv = g.eval(x.growth_time);
        let pore = (x.pore_mask > 0.5) as u32 as f64;
        if gv < 0.05 {
            e += 1.0;
            ep += pore;
        } else if gv > 0.95 {
            l += 1.0;
            lp += pore;
        }
    }
    let (fe, fl) = (ep / e.max(1.0), lp / l.max(1.0));
    (fe, fe / fl.max(1e-4))
}

/// Rays on the quartersawn face (a radial plane 100–160 mm from the pith, 60 mm along the
/// trunk, 0.1 mm texels): (area fraction where the ray mask exceeds 0.5, the median height of a
/// fleck along the trunk in mm).
pub(super) fn ray_fleck(v: &WoodVolume) -> (f64, f64) {
    let n = 600;
    let t = cut(v, Vec3::new(130.0, 0.0, 0.0), Vec3::X, Vec3::Z, 60.0, n);
    let on: Vec<bool> = t.iter().map(|x| x.ray_mask > 0.5).collect();
    let frac = on.iter().filter(|&&b| b).count() as f64 / on.len() as f64;
    // Run lengths along z (rows b) in each column a.
    let mut runs = Vec::new();
    for a in 0..n {
        let mut run = 0;
        for b in 0..n {
            if on[b * n + a] {
                run += 1;
            } else if run > 0 {
                runs.push(run as f64 * 0.1);
                run = 0;
            }
        }
    }
    (frac, quantile(&runs, 0.5))
}

/// Ribbon stripe on the quartersawn face (the board maps of `Subject::Preset`, grain along x):
/// the profile across the grain of the mean fibre dip; (its standard deviation in degrees, the
/// dominant period in mm).
pub(super) fn ribbon(dir: &Path, name: &str) -> (f64, f64) {
    let m = board(dir, name).maps(base()).unwrap();
    let (w, h) = (m.board.width as usize, m.board.height as usize);
    let profile: Vec<f64> = (0..h)
        .map(|c| (0..w).map(|a| m.dip_deg(c * w + a)).sum::<f64>() / w as f64)
        .collect();
    let mu = profile.iter().sum::<f64>() / h as f64;
    let sd = (profile.iter().map(|x| (x - mu) * (x - mu)).sum::<f64>() / h as f64).sqrt();
    // Stripe period: twice the mean distance between crossings of the mean (a light and a dark
    // stripe), on the profile smoothed over 1 mm so texel noise does not add crossings.
    let pitch = xylem_lab::appearance::BOARD_MM as f64 / h as f64;
    let k = (0.5 / pitch).round() as usize;
    let smooth: Vec<f64> = (0..h)
        .map(|i| {
            let r = i.saturating_sub(k)..(i + k + 1).min(h);
            let n = r.len() as f64;
            profile[r].iter().sum::<f64>() / n
        })
        .collect();
    let crossings = smooth
        .windows(2)
        .filter(|w| (w[0] - mu).signum() != (w[1] - mu).signum())
        .count();
    (sd, 2.0 * h as f64 * pitch / crossings.max(1) as f64)
}
