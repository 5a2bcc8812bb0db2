//! Issue 25, "Presets a woodworker recognises": each observable fact about quilted maple,
//! birdseye maple and knotty pine listed in notes/presets.md ("Observable facts") as a number
//! measured on the gallery's flat-sawn face (120 mm from the pith, 3° slope along the grain,
//! 260 × 110 mm, seed 7 as on the README board), with a negative control that fails: the preset
//! as it was before issue 25 (tests/data/issue25_controls/<preset>.toml) or, where that one
//! happens to pass, a named variant without the feature.

use glam::Vec3;
use std::path::Path;
use xylem::wood::{self, Needs, WoodParams, WoodTexel, WoodVolume};

const SEED: u64 = 7;
/// The face: u along the grain (tree z) over [−130, 130] mm, v across over [−55, 55] mm.
const LEN: f32 = 260.0;
const WID: f32 = 110.0;

fn control(name: &str) -> WoodParams {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("tests/data/issue25_controls")
        .join(format!("{name}.toml"));
    WoodParams::from_toml_file(path).unwrap()
}

/// The preset as its file reads now (`every_preset_parses_and_validates` checks the embedded copy
/// is the same).
fn current(name: &str) -> WoodParams {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes/presets")
        .join(format!("{name}.toml"));
    WoodParams::from_toml_file(path).unwrap()
}

/// The flat-sawn face point at (u, v): 120 mm from the pith at u = 0, rising 3° along the grain.
fn face_point(u: f32, v: f32) -> Vec3 {
    let slope = wood::SHOWCASE_SLOPE_DEG.to_radians().tan();
    Vec3::new(wood::SHOWCASE_PITH_DISTANCE_MM + u * slope, v, u)
}

/// A grid over the face at `step` mm: (nu, nv, texels), row-major in v.
struct Face {
    nu: usize,
    nv: usize,
    step: f32,
    t: Vec<WoodTexel>,
}

impl Face {
    fn new(p: &WoodParams, step: f32, needs: Needs) -> Face {
        let vol = WoodVolume::new(p.clone(), SEED).unwrap();
        let (nu, nv) = ((LEN / step) as usize, (WID / step) as usize);
        let pts: Vec<Vec3> = (0..nv)
            .flat_map(|j| (0..nu).map(move |i| (i, j)))
            .map(|(i, j)| {
                face_point(
                    -0.5 * LEN + (i as f32 + 0.5) * step,
                    -0.5 * WID + (j as f32 + 0.5) * step,
                )
            })
            .collect();
        let mut t = vec![WoodTexel::default(); pts.len()];
        vol.eval_many(&pts, needs, &mut t);
        Face { nu, nv, step, t }
    }
    fn uv(&self, i: usize, j: usize) -> (f32, f32) {
        (
            -0.5 * LEN + (i as f32 + 0.5) * self.step,
            -0.5 * WID + (j as f32 + 0.5) * self.step,
        )
    }
}

fn lum(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// 4-connected components of `mask` on an nu × nv grid: each a list of cell indices.
fn components(mask: &[bool], nu: usize, nv: usize) -> Vec<Vec<usize>> {
    let mut label = vec![usize::MAX; mask.len()];
    let mut out = Vec::new();
    for start in 0..mask.len() {
        if !mask[start] || label[start] != usize::MAX {
            continue;
        }
        let id = out.len();
        let mut cells = vec![start];
        label[start] = id;
        let mut k = 0;
        while k < cells.len() {
            let c = cells[k];
            k += 1;
            let (i, j) = (c % nu, c / nu);
            let mut push = |n: usize| {
                if mask[n] && label[n] == usize::MAX {
                    label[n] = id;
                    cells.push(n);
                }
            };
            if i > 0 {
                push(c - 1);
            }
            if i + 1 < nu {
                push(c + 1);
            }
            if j > 0 {
                push(c - nu);
            }
            if j + 1 < nv {
                push(c + nu);
            }
        }
        out.push(cells);
    }
    out
}

fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return f32::NAN;
    }
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

// ---------------------------------------------------------------------------------------------
// Birdseye maple

/// The eyes' dark centres on the face: components of the diffuse lightness below 0.6 of the
/// face's median (maple's latewood is 0.75 of its earlywood, so rings never get there).
struct Eyes {
    /// (u, v) centroid, mean lightness of the centre, mean lightness 1.5–3 mm round it.
    eyes: Vec<(f32, f32, f32, f32)>,
}

fn birdseye_centres(p: &WoodParams) -> Eyes {
    let f = Face::new(p, 0.2, Needs::COLOR);
    let l: Vec<f32> = f.t.iter().map(|t| lum(t.diffuse)).collect();
    let med = median(&mut l.clone());
    let mask: Vec<bool> = l.iter().map(|&x| x < 0.6 * med).collect();
    let mut eyes = Vec::new();
    for c in components(&mask, f.nu, f.nv) {
        if c.len() < 3 {
            continue;
        }
        let (mut su, mut sv, mut sl) = (0.0, 0.0, 0.0);
        for &k in &c {
            let (u, v) = f.uv(k % f.nu, k / f.nu);
            su += u;
            sv += v;
            sl += l[k];
        }
        let n = c.len() as f32;
        let (cu, cv) = (su / n, sv / n);
        // The surround: an annulus 1.5–3 mm from the centroid.
        let (mut sa, mut na) = (0.0, 0);
        let r = (3.0 / f.step) as i64;
        let (ci, cj) = (
            ((cu + 0.5 * LEN) / f.step) as i64,
            ((cv + 0.5 * WID) / f.step) as i64,
        );
        for dj in -r..=r {
            for di in -r..=r {
                let d = (di as f32).hypot(dj as f32) * f.step;
                let (i, j) = (ci + di, cj + dj);
                if (1.5..=3.0).contains(&d)
                    && i >= 0
                    && j >= 0
                    && (i as usize) < f.nu
                    && (j as usize) < f.nv
                {
                    sa += l[j as usize * f.nu + i as usize];
                    na += 1;
                }
            }
        }
        eyes.push((cu, cv, sl / n, sa / na.max(1) as f32));
    }
    Eyes { eyes }
}

/// Eyes per 10 cm² of face.
fn eye_density(e: &Eyes) -> f32 {
    e.eyes.len() as f32 / (LEN * WID / 1000.0)
}

/// Eyes in the sparsest of the face's four quarters (halves along and across the grain) and in
/// the sparsest of the three strips along the grain (edge, middle, edge), per 10 cm², over the
/// face's mean: 1 when uniform, 0 when a part has none.
fn eye_spread(e: &Eyes) -> (f32, f32) {
    let mean = eye_density(e);
    let mut quarters = [0usize; 4];
    let mut strips = [0usize; 3];
    for &(u, v, ..) in &e.eyes {
        quarters[(u > 0.0) as usize + 2 * (v > 0.0) as usize] += 1;
        strips[(((v + 0.5 * WID) / WID * 3.0) as usize).min(2)] += 1;
    }
    let q = *quarters.iter().min().unwrap() as f32 / (LEN * WID / 4000.0);
    let s = *strips.iter().min().unwrap() as f32 / (LEN * WID / 3000.0);
    if mean > 0.0 {
        (q / mean, s / mean)
    } else {
        (0.0, 0.0)
    }
}

/// Median over eyes of centre lightness / surround lightness.
fn eye_centre_ratio(e: &Eyes) -> f32 {
    median(&mut e.eyes.iter().map(|e| e.2 / e.3).collect::<Vec<_>>())
}

/// The eyes' ring deflection: components where the growth time differs by more than 0.2 years
/// (half a millimetre of ring) from the same tree without the eyes (`eyes` removed, or where
/// there is none, `distortion.radial`: the pre-issue-25 eyes), with their equivalent diameters (mm) and largest |Δt| (years).
fn eye_dimples(p: &WoodParams) -> Vec<(f32, f32)> {
    let mut plain = p.clone();
    if plain.eyes.is_some() {
        plain.eyes = None;
    } else {
        plain.distortion.radial = None;
    }
    let step = 0.2;
    let a = Face::new(p, step, Needs::COLOR);
    let b = Face::new(&plain, step, Needs::COLOR);
    let dt: Vec<f32> =
        a.t.iter()
            .zip(&b.t)
            .map(|(x, y)| x.growth_time - y.growth_time)
            .collect();
    let mask: Vec<bool> = dt.iter().map(|d| d.abs() > 0.2).collect();
    components(&mask, a.nu, a.nv)
        .into_iter()
        .filter(|c| c.len() >= 5)
        .map(|c| {
            let area = c.len() as f32 * step * step;
            let peak = c.iter().map(|&k| dt[k].abs()).fold(0.0, f32::max);
            (2.0 * (area / std::f32::consts::PI).sqrt(), peak)
        })
        .collect()
}

fn birdseye_new() -> WoodParams {
    current("birdseye_maple")
}

#[test]
fn birdseye_eyes_have_dark_centres_at_a_realistic_density_over_the_whole_face() {
    let new = birdseye_centres(&birdseye_new());
    let old = birdseye_centres(&control("birdseye_maple"));
    let (dn, d0) = (eye_density(&new), eye_density(&old));
    let (sn, s0) = (eye_spread(&new), eye_spread(&old));
    let (cn, c0) = (eye_centre_ratio(&new), eye_centre_ratio(&old));
    println!("birdseye density per 10 cm²: new {dn:.2}, old {d0:.2}");
    println!("birdseye spread (sparsest quarter, sparsest strip / mean): new {sn:?}, old {s0:?}");
    println!("birdseye centre / surround lightness: new {cn:.3}, old {c0:.3}");
    let density_ok = |d: f32| (1.0..=6.0).contains(&d);
    let spread_ok = |s: (f32, f32)| s.0 >= 0.5 && s.1 >= 0.5;
    let centre_ok = |c: f32| c < 0.7;
    assert!(density_ok(dn) && spread_ok(sn) && centre_ok(cn));
    // Negative control: the pre-issue-25 preset fails all three.
    assert!(!density_ok(d0), "old density {d0}");
    assert!(!spread_ok(s0), "old spread {s0:?}");
    assert!(!centre_ok(c0), "old centres {c0}");
}

#[test]
fn birdseye_eyes_are_one_to_six_mm_and_deflect_the_rings() {
    let summarise = |d: &[(f32, f32)]| {
        let mut dia: Vec<f32> = d.iter().map(|x| x.0).collect();
        let mut peak: Vec<f32> = d.iter().map(|x| x.1).collect();
        let inside = dia.iter().filter(|&&x| (1.0..=6.0).contains(&x)).count() as f32
            / dia.len().max(1) as f32;
        (d.len(), median(&mut dia), inside, median(&mut peak))
    };
    let new = summarise(&eye_dimples(&birdseye_new()));
    let old = summarise(&eye_dimples(&control("birdseye_maple")));
    // Big, blister-like bumps: the new eyes scaled ×4 across.
    let mut big = birdseye_new();
    if let Some(e) = big.eyes.as_mut() {
        e.diameter = e.diameter.map(|d| 4.0 * d);
    }
    let big = summarise(&eye_dimples(&big));
    println!("dimples (count, median diameter mm, fraction 1–6 mm, median peak Δt years):");
    println!("  new {new:?}\n  old {old:?}\n  ×4 {big:?}");
    let ok = |s: (usize, f32, f32, f32)| (1.0..=6.0).contains(&s.1) && s.2 >= 0.75 && s.3 >= 0.2;
    assert!(ok(new), "{new:?}");
    assert!(!ok(big), "the ×4 control passes: {big:?}");
}

// ---------------------------------------------------------------------------------------------
// Knotty pine

/// Knots crossing the face: (equivalent diameter mm, fraction of the rim on bark, mean |Δt|
/// years 1–10 mm outside the knot against the tree without knots, knot/wood lightness,
/// growth-time range inside the knot in years).
fn pine_knots(p: &WoodParams) -> Vec<(f32, f32, f32, f32, f32)> {
    let step = 0.25;
    let vol = WoodVolume::new(p.clone(), SEED).unwrap();
    let mut plain = p.clone();
    plain.knots = None;
    let a = Face::new(p, step, Needs::COLOR);
    let b = Face::new(&plain, step, Needs::COLOR);
    let (nu, nv) = (a.nu, a.nv);
    let mut inside = vec![false; nu * nv];
    let mut bark = vec![false; nu * nv];
    for j in 0..nv {
        for i in 0..nu {
            let (u, v) = a.uv(i, j);
            if let Some(k) = vol.knot_at(face_point(u, v)) {
                inside[j * nu + i] = k.inside > 0.5;
                bark[j * nu + i] = k.bark > 0.5;
            }
        }
    }
    let l: Vec<f32> = a.t.iter().map(|t| lum(t.diffuse)).collect();
    let wood_l = median(&mut l.clone());
    let mut out = Vec::new();
    for c in components(&inside, nu, nv) {
        // Knots cut by the board's edge are not measured (their size is not the knot's).
        let touches_edge = c.iter().any(|&k| {
            let (i, j) = (k % nu, k / nu);
            i == 0 || j == 0 || i + 1 == nu || j + 1 == nv
        });
        if c.len() < 8 || touches_edge {
            continue;
        }
        let area = c.len() as f32 * step * step;
        let dia = 2.0 * (area / std::f32::consts::PI).sqrt();
        let (mut su, mut sv) = (0.0, 0.0);
        let (mut tmin, mut tmax, mut kl) = (f32::MAX, f32::MIN, 0.0);
        for &k in &c {
            su += (k % nu) as f32;
            sv += (k / nu) as f32;
            tmin = tmin.min(a.t[k].growth_time);
            tmax = tmax.max(a.t[k].growth_time);
            kl += l[k];
        }
        let n = c.len() as f32;
        let (ci, cj) = (su / n, sv / n);
        let radius = 0.5 * dia / step;
        // The rim: knot cells with an outside neighbour; on bark when a bark cell lies within
        // 1 mm of it. |Δt| in the ring 1–10 mm outside the knot's equivalent circle.
        let (mut rim, mut rim_bark, mut sdt, mut ndt) = (0, 0, 0.0, 0);
        let near = (1.0 / step) as i64;
        for &k in &c {
            let (i, j) = ((k % nu) as i64, (k / nu) as i64);
            let at = |i: i64, j: i64| {
                (i >= 0 && j >= 0 && (i as usize) < nu && (j as usize) < nv)
                    .then(|| j as usize * nu + i as usize)
            };
            let edge = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(di, dj)| at(i + di, j + dj).is_some_and(|n| !inside[n]));
            if edge {
                rim += 1;
                let on_bark = (-near..=near)
                    .flat_map(|dj| (-near..=near).map(move |di| (di, dj)))
                    .any(|(di, dj)| at(i + di, j + dj).is_some_and(|n| bark[n]));
                rim_bark += on_bark as usize;
            }
        }
        let reach = (radius + 12.0 / step) as i64;
        for dj in -reach..=reach {
            for di in -reach..=reach {
                let (i, j) = (ci as i64 + di, cj as i64 + dj);
                if i < 0 || j < 0 || i as usize >= nu || j as usize >= nv {
                    continue;
                }
                let k = j as usize * nu + i as usize;
                if inside[k] || bark[k] {
                    continue;
                }
                let d = ((i as f32 - ci).hypot(j as f32 - cj) - radius) * step;
                if (1.0..=10.0).contains(&d) {
                    sdt += (a.t[k].growth_time - b.t[k].growth_time).abs();
                    ndt += 1;
                }
            }
        }
        out.push((
            dia,
            rim_bark as f32 / rim.max(1) as f32,
            sdt / ndt.max(1) as f32,
            kl / n / wood_l,
            tmax - tmin,
        ));
    }
    out
}

#[test]
fn pine_knots_are_realistic_and_the_rings_bend_round_them() {
    let new = pine_knots(&current("knotty_pine"));
    let old = pine_knots(&control("knotty_pine"));
    println!("knots (diameter mm, bark rim fraction, |Δt| 1–10 mm out, lightness ratio, own rings years):");
    println!("  new {new:?}\n  old {old:?}");
    assert!(!new.is_empty(), "no knot on the face");
    let sizes_ok = |k: &[(f32, f32, f32, f32, f32)]| {
        !k.is_empty() && k.iter().all(|k| (10.0..=40.0).contains(&k.0))
    };
    let bend_ok = |k: &[(f32, f32, f32, f32, f32)]| !k.is_empty() && k.iter().all(|k| k.2 >= 1.0);
    let dark_ok = |k: &[(f32, f32, f32, f32, f32)]| k.iter().all(|k| k.3 < 0.75);
    let rings_ok = |k: &[(f32, f32, f32, f32, f32)]| k.iter().all(|k| k.4 >= 3.0);
    let bark_ok = |k: &[(f32, f32, f32, f32, f32)]| k.iter().all(|k| k.1 >= 0.5);
    assert!(sizes_ok(&new), "sizes {new:?}");
    assert!(bend_ok(&new), "ring bend {new:?}");
    assert!(dark_ok(&new) && rings_ok(&new) && bark_ok(&new), "{new:?}");
    // Negative controls: before issue 25 the rings ran straight past the knots.
    assert!(!bend_ok(&old), "old preset's rings bend: {old:?}");
}

// ---------------------------------------------------------------------------------------------
// Quilted maple

/// Fibre dip out of the face (degrees) over the face at 0.5 mm: (std, cell length along the
/// grain, cell width across it, mm). A cell is one rise and fall of the dip: twice the mean
/// distance between sign changes of the dip (about its mean) along a line.
fn quilt_dips(p: &WoodParams) -> (f32, f32, f32) {
    let f = Face::new(p, 0.5, Needs::COLOR_FIBERS);
    let slope = wood::SHOWCASE_SLOPE_DEG.to_radians();
    let normal = Vec3::new(slope.cos(), 0.0, -slope.sin());
    let dip: Vec<f32> =
        f.t.iter()
            .map(|t| t.fiber_dir.dot(normal).clamp(-1.0, 1.0).asin().to_degrees())
            .collect();
    let mean = dip.iter().sum::<f32>() / dip.len() as f32;
    let std = (dip.iter().map(|d| (d - mean).powi(2)).sum::<f32>() / dip.len() as f32).sqrt();
    let crossings = |line: &mut dyn Iterator<Item = f32>| {
        let (mut n, mut prev) = (0usize, None::<bool>);
        for d in line {
            let s = d > mean;
            if prev.is_some_and(|p| p != s) {
                n += 1;
            }
            prev = Some(s);
        }
        n
    };
    let along: usize = (0..f.nv)
        .map(|j| crossings(&mut (0..f.nu).map(|i| dip[j * f.nu + i])))
        .sum();
    let across: usize = (0..f.nu)
        .map(|i| crossings(&mut (0..f.nv).map(|j| dip[j * f.nu + i])))
        .sum();
    let cell = |n: usize, lines: usize, len: f32| 2.0 * len * lines as f32 / n.max(1) as f32;
    (std, cell(along, f.nv, LEN), cell(across, f.nu, WID))
}

/// The README board (scenes/sweep_board.toml) flat-sawn as in the gallery with `preset` read
/// from a file, 240 × 120 at 8 spp, the light `angle` degrees from the zenith along the grain:
/// the board's middle (x 25–75 %, y 35–75 % of the frame) as linear RGB times the exposure.
fn quilt_render(preset: &WoodParams, angle: f32) -> (usize, usize, Vec<Vec3>) {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("quilt.toml");
    std::fs::write(&file, toml::to_string(preset).unwrap()).unwrap();
    let mut text = std::fs::read_to_string(dir.join("sweep_board.toml")).unwrap();
    let cut = text.find("[[sweep.regions]]").unwrap();
    let end = text[cut..].find("\n\n").unwrap() + cut;
    text.replace_range(cut..end, "");
    let a = angle.to_radians();
    for (from, to) in [
        (
            "preset = \"african_mahogany\"".to_string(),
            format!("preset_file = {:?}", file.display().to_string()),
        ),
        (
            "ring_angle_deg = 90.0, face_point".into(),
            format!(
                "ring_angle_deg = 0.0, slope_deg = {:.1}, face_point",
                wood::SHOWCASE_SLOPE_DEG
            ),
        ),
        (
            "eye = [0.0, -250.0, 190.0]".into(),
            "eye = [0.0, -140.0, 300.0]".into(),
        ),
        ("fov_deg = 38.0".into(), "fov_deg = 24.0".into()),
        ("width = 512".into(), "width = 240".into()),
        ("height = 384".into(), "height = 120".into()),
        ("spp = 16".into(), "spp = 8".into()),
        (
            "center = [250.0, 0.0, 433.0]".into(),
            format!(
                "center = [{:.2}, 0.0, {:.2}]",
                500.0 * a.sin(),
                18.0 + 500.0 * a.cos()
            ),
        ),
    ] {
        assert!(text.contains(&from), "sweep_board.toml has no {from}");
        text = text.replace(&from, &to);
    }
    let s = xylem::scene::from_str(&text, "quilt_board.toml", &dir, "quilt").unwrap();
    let img = xylem::render::render(&s.scene, &s.settings, &Default::default())
        .unwrap()
        .image;
    let scale = s.exposure.exp2();
    let (w, h) = (img.width as usize, img.height as usize);
    let (x0, x1, y0, y1) = (w / 4, 3 * w / 4, 35 * h / 100, 75 * h / 100);
    let px = (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .map(|(x, y)| img.beauty[y * w + x] * scale)
        .collect();
    (x1 - x0, y1 - y0, px)
}

/// (fraction of pixels with a channel at the exposure's white, figure contrast): the contrast is
/// the standard deviation of lightness over its local mean (a 15-pixel box, ≈ 20 mm), which
/// removes the highlight's broad fall-off and keeps the cells.
fn quilt_look(preset: &WoodParams, angle: f32) -> (f32, f32) {
    let (w, h, px) = quilt_render(preset, angle);
    let clipped = px.iter().filter(|c| c.max_element() >= 1.0).count() as f32 / px.len() as f32;
    let l: Vec<f32> = px.iter().map(|&c| lum(c.min(Vec3::ONE))).collect();
    let r = 7i64;
    let (mut s, mut n) = (0.0f64, 0usize);
    for y in r..h as i64 - r {
        for x in r..w as i64 - r {
            let mut m = 0.0;
            for dy in -r..=r {
                for dx in -r..=r {
                    m += l[((y + dy) * w as i64 + x + dx) as usize];
                }
            }
            m /= ((2 * r + 1) * (2 * r + 1)) as f32;
            let v = l[(y * w as i64 + x) as usize] / m.max(1e-4) - 1.0;
            s += (v * v) as f64;
            n += 1;
        }
    }
    (clipped, (s / n as f64).sqrt() as f32)
}

#[test]
fn quilt_cells_are_pillows_along_the_grain_with_a_wide_dip_spread() {
    let new = quilt_dips(&current("quilted_maple"));
    let old = quilt_dips(&control("quilted_maple"));
    println!("quilt dips (std °, cell along mm, cell across mm): new {new:?}, old {old:?}");
    let ok = |q: (f32, f32, f32)| {
        q.0 >= 5.0
            && (10.0..=40.0).contains(&q.1)
            && (5.0..=40.0).contains(&q.2)
            && q.1 >= 1.3 * q.2
    };
    assert!(ok(new), "{new:?}");
    assert!(!ok(old), "the old quilt passes: {old:?}");
}

#[test]
fn quilt_shows_at_every_light_angle_unclipped() {
    let new = current("quilted_maple");
    let old = control("quilted_maple");
    let mut flat = new.clone();
    flat.distortion.radial = None;
    let mut fails_old = false;
    for angle in [-40.0, 0.0, 40.0] {
        let (cn, kn) = quilt_look(&new, angle);
        let (c0, k0) = quilt_look(&old, angle);
        let (_, kf) = quilt_look(&flat, angle);
        println!(
            "quilt at {angle:+}°: clipped new {:.2} % old {:.2} %; contrast new {kn:.3} old {k0:.3} without quilt {kf:.3}",
            100.0 * cn,
            100.0 * c0
        );
        assert!(cn < 0.005, "clipped {cn} at {angle}");
        assert!(
            kn >= 0.06 && kn >= 2.0 * kf,
            "figure contrast {kn} (flat {kf}) at {angle}"
        );
        fails_old |= c0 >= 0.005 || k0 < 0.06;
        // Negative control of the contrast: the same board without the quilt.
        assert!(
            kf < 0.06,
            "the quilt-free board has figure contrast {kf} at {angle}"
        );
    }
    assert!(fails_old, "the old quilt passes at every angle");
}

// ---------------------------------------------------------------------------------------------
// Rings of all three: not ruled paper

/// Coefficient of variation (std / mean) of the ring widths (mm) along five radii from 40 to 240 mm (years
/// counted where the growth time crosses an integer, 0.05 mm steps).
fn ring_width_cv(p: &WoodParams) -> f32 {
    let vol = WoodVolume::new(p.clone(), SEED).unwrap();
    let mut widths = Vec::new();
    for k in 0..5 {
        let (a, z) = (k as f32 * 1.3, k as f32 * 37.0);
        let mut last: Option<f32> = None;
        let mut prev = vol.eval(Vec3::new(40.0 * a.cos(), 40.0 * a.sin(), z), Needs::COLOR);
        let mut r = 40.0;
        while r < 240.0 {
            r += 0.05;
            let t = vol.eval(Vec3::new(r * a.cos(), r * a.sin(), z), Needs::COLOR);
            if t.growth_time.floor() != prev.growth_time.floor() {
                if let Some(l) = last {
                    widths.push(r - l);
                }
                last = Some(r);
            }
            prev = t;
        }
    }
    let mean = widths.iter().sum::<f32>() / widths.len() as f32;
    let var = widths.iter().map(|w| (w - mean).powi(2)).sum::<f32>() / widths.len() as f32;
    var.sqrt() / mean
}

#[test]
fn ring_widths_vary_year_to_year() {
    for name in ["quilted_maple", "birdseye_maple", "knotty_pine"] {
        let (new, old) = (ring_width_cv(&current(name)), ring_width_cv(&control(name)));
        // Negative control: ruled paper, the same preset without growth variation or radial
        // distortion (every ring the mean width).
        let mut ruled = current(name);
        ruled.growth = None;
        ruled.distortion.radial = None;
        ruled.eyes = None;
        ruled.knots = None;
        let ruled = ring_width_cv(&ruled);
        println!("{name}: ring width CV new {new:.3}, before issue 25 {old:.3}, ruled {ruled:.3}");
        // Year-to-year ring width in real trees varies by tens of per cent of its mean (the
        // variation dendrochronology reads, e.g. Fritts, *Tree Rings and Climate*, 1976); 0.2 is
        // our threshold, not a published one.
        assert!(new >= 0.2, "{name}: {new}");
        assert!(ruled < 0.2, "{name}: the ruled control varies by {ruled}");
    }
}

/// Fraction of radial steps of 0.1 mm, over the showcase board's depth (115–125 mm from the pith,
/// every azimuth and 300 mm of height), where the distorted radius |f(p)|ₓᵧ falls as r rises: a
/// fold of the growth layers, which a tree never lays down. On a face a fold shows as a bright
/// rim round every quilt cell (the layers' slope flips along its line, like a caustic on water).
fn fold_fraction(p: &WoodParams) -> f32 {
    let v = WoodVolume::new(p.clone(), SEED).unwrap();
    let mut rng = xylem::math::Pcg32::new(25, 3);
    let (mut folds, mut steps) = (0usize, 0usize);
    for _ in 0..400 {
        let theta = std::f32::consts::TAU * rng.next_f32();
        let z = 300.0 * rng.next_f32();
        let (s, c) = theta.sin_cos();
        let radius = |r: f32| {
            let q = v.distortion(Vec3::new(r * c, r * s, z)).point;
            q.x.hypot(q.y)
        };
        let mut prev = radius(115.0);
        for i in 1..=100 {
            let now = radius(115.0 + 0.1 * i as f32);
            folds += usize::from(now <= prev);
            steps += 1;
            prev = now;
        }
    }
    folds as f32 / steps as f32
}

#[test]
fn quilt_growth_layers_never_fold() {
    let new = current("quilted_maple");
    // Control: the quilt's bulges as thin in r (8 mm) as their magnitude, as before this check.
    let mut thin = new.clone();
    thin.distortion.radial.as_mut().unwrap().size[0] = 8.0;
    let (f_new, f_thin) = (fold_fraction(&new), fold_fraction(&thin));
    println!(
        "quilt folds: {:.3} % of radial steps; 8 mm bulges {:.3} %",
        100.0 * f_new,
        100.0 * f_thin
    );
    assert!(f_new == 0.0, "the quilt folds its growth layers at {f_new}");
    assert!(
        f_thin > 0.01,
        "the thin-bulge control does not fold: {f_thin}"
    );
}
