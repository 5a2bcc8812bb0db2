//! The light-sweep checks of the validation suite (`xylem validate sweep`):
//!
//! 1. **Highlight tracking** — a flat finished board with uniform fibres dipping α = 0°, 15°, 30°
//!    into the surface, orthographic camera, distant light on an arc: each pixel's brightest
//!    frame lies within one frame step of the light angle predicted from the model (refraction
//!    into the finish and ψh = 0; `validate::highlight`, derivation in notes/sweep.md).
//! 2. **Renderer against the BSDF** — the same setup: every pixel of every frame equals
//!    `eval(wo, wi) · cos θi · E` computed directly from [`WoodBsdf`] (relative error ≤ 1e-3).
//! 3. **Figure signatures** — African mahogany (interlocked grain): the two families of stripes
//!    (fibres tilted out of / into the face) brighten at different light angles, so their mean
//!    radiance curves — each divided by the diffuse term's light dependence g(θi) = T(θi) cos θi,
//!    which both share and which would otherwise dominate — correlate below −0.3, and so do the raw curves, over an arc of ±30° that spans both families' highlights; curly maple: the bright bands shift with the light
//!    angle, i.e. columns along the grain peak at different light angles (spread ≥ 2 frame steps)
//!    in a smooth, banded way (lag-1 autocorrelation of the peak angle along the grain ≥ 0.5).
//!
//! Every scene is written in the public scene format and rendered with the cached sweep
//! renderer, so the checks exercise what users run.

use crate::highlight::{inclined_fibre, peak_in_arc_deg};
use crate::report::{checks_table, markdown_table, Check};
use crate::scene_template::{pair, vec3, SceneTemplate};
use serde::Serialize;
use std::path::Path;
use xylem::bsdf::{Bsdf, WoodBsdf, WoodBsdfParams};
use xylem::math::{luminance, Vec3};
use xylem::picture::plot::{line_plot, PlotOptions, Series, PALETTE};
use xylem::render::Frames;
use xylem::render::RunOptions;
use xylem::scene::{from_str, LoadedScene};
use xylem::sweep::{render_sweep, SweepPath};

/// Errors that stop the sweep checks (a failed check is a result, not an error).
#[derive(Debug, thiserror::Error)]
pub enum SweepCheckError {
    /// A validation scene could not be built or rendered.
    #[error("validation scene `{name}`: {message}")]
    Scene {
        /// The scene's name.
        name: String,
        /// What went wrong.
        message: String,
    },
    /// A plot could not be written.
    #[error("writing plot {path}: {message}")]
    Plot {
        /// The plot file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// One check's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct CheckOutcome {
    /// The verdict: name, criterion, worst value, case, pass.
    #[serde(flatten)]
    pub verdict: Check,
    /// The measured figure, in words and numbers.
    pub figure: String,
    /// The plot, relative to the report's folder.
    pub plot: Option<String>,
    /// Every number behind the figure.
    pub values: serde_json::Value,
}

/// Refractive index of the finish in the validation boards.
const ETA: f32 = 1.5;
/// Viewing angle of the orthographic camera in the tracking and BSDF checks (degrees from the
/// normal, on the arc's +x side); every inclination then has one peak inside the arc.
const VIEW_DEG: f32 = 40.0;

/// The flat board with constant fibres along x dipping `incl_deg` (validation/scenes/
/// fibre_board.toml), `res`² pixels, lobe width `beta_deg`, `frames` frames over `arc`.
fn fiber_board_toml(
    incl_deg: f32,
    beta_deg: f32,
    frames: usize,
    arc: (f32, f32),
    res: u32,
) -> String {
    let (s, c) = VIEW_DEG.to_radians().sin_cos();
    SceneTemplate::named("fibre_board")
        .set("render.width", res as i64)
        .set("render.height", res as i64)
        .set("camera.eye", vec3(Vec3::new(500.0 * s, 0.0, 500.0 * c)))
        .set(
            "materials.fibres.fiber_dir",
            vec3(inclined_fibre(Vec3::X, incl_deg)),
        )
        .set("materials.fibres.highlight_width_deg", beta_deg as f64)
        .set("materials.fibres.eta", ETA as f64)
        .set("sweep.frames", frames as i64)
        .set("sweep.arc_deg", pair(arc.0, arc.1))
        .text()
}

/// The quartersawn board of `preset` (validation/scenes/preset_board.toml), `res` pixels,
/// `frames` frames over `arc`.
fn preset_board_toml(preset: &str, frames: usize, arc: (f32, f32), res: (u32, u32)) -> String {
    SceneTemplate::named("preset_board")
        .set("render.width", res.0 as i64)
        .set("render.height", res.1 as i64)
        .set("materials.board.preset", preset)
        .set("materials.board.eta", ETA as f64)
        .set("sweep.frames", frames as i64)
        .set("sweep.arc_deg", pair(arc.0, arc.1))
        .text()
}

fn load(name: &str, text: &str) -> Result<LoadedScene, SweepCheckError> {
    from_str(text, name, Path::new("."), name).map_err(|e| SweepCheckError::Scene {
        name: name.into(),
        message: e.to_string(),
    })
}

/// Renders every frame of a loaded scene's sweep with the cached renderer.
fn sweep_all(
    loaded: &LoadedScene,
    run: &RunOptions,
) -> Result<(Frames, SweepPath), SweepCheckError> {
    let err = |message: String| SweepCheckError::Scene {
        name: loaded.name.clone(),
        message,
    };
    let (path, moving) =
        SweepPath::from_scene(loaded, None, None).map_err(|e| err(e.to_string()))?;
    let r = render_sweep(
        &loaded.scene,
        &loaded.settings,
        &path,
        moving,
        0..path.arc.frames,
        run,
    )
    .map_err(|e| err(e.to_string()))?;
    Ok((r, path))
}

/// Luminance of pixel `i` in every frame.
fn pixel_series(r: &Frames, i: usize) -> Vec<f32> {
    r.frames.iter().map(|f| luminance(f.beauty[i])).collect()
}

/// Index of the largest value (the first on ties).
fn argmax(v: &[f32]) -> usize {
    v.iter()
        .enumerate()
        .fold(
            (0, f32::MIN),
            |(bi, bv), (i, &x)| if x > bv { (i, x) } else { (bi, bv) },
        )
        .0
}

/// Pearson's correlation coefficient of two equally long series (0 when either is constant).
pub fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    if n < 2.0 {
        return 0.0;
    }
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

fn write_plot(
    dir: &Path,
    rel: &str,
    series: &[Series],
    opts: &PlotOptions,
) -> Result<(), SweepCheckError> {
    let img = line_plot(series, opts);
    let path = dir.join(rel);
    let err = |message: String| SweepCheckError::Plot {
        path: path.display().to_string(),
        message,
    };
    if let Some(p) = path.parent() {
        std::fs::create_dir_all(p).map_err(|e| err(e.to_string()))?;
    }
    img.write_png(&path).map_err(|e| err(e.to_string()))
}

/// Check 1 for one inclination.
pub fn highlight_tracking(
    incl_deg: f32,
    plots: Option<&Path>,
    run: &RunOptions,
) -> Result<CheckOutcome, SweepCheckError> {
    let (beta_deg, frames, arc, res) = (2.0, 161, (-80.0, 80.0), 12);
    let loaded = load(
        &format!("tracking_{incl_deg}"),
        &fiber_board_toml(incl_deg, beta_deg, frames, arc, res),
    )?;
    let (r, path) = sweep_all(&loaded, run)?;
    let step = path.arc.step_deg().abs();
    let u = inclined_fibre(Vec3::X, incl_deg);
    let (s, c) = VIEW_DEG.to_radians().sin_cos();
    let wo = Vec3::new(s, 0.0, c);
    let predicted = peak_in_arc_deg(u, wo, Vec3::X, ETA, arc.0, arc.1);
    let n = (r.width * r.height) as usize;
    let mut deviations = Vec::with_capacity(n);
    for i in 0..n {
        let k = argmax(&pixel_series(&r, i));
        deviations.push(predicted.map_or(f32::INFINITY, |p| (path.arc.angle_deg(k) - p).abs()));
    }
    let within = deviations.iter().filter(|d| **d <= step + 1e-4).count() as f64 / n as f64;
    let max_dev = deviations.iter().copied().fold(0.0f32, f32::max);
    let passed = predicted.is_some() && within >= 0.99;
    let mut plot = None;
    if let Some(dir) = plots {
        let rel = format!("plots/sweep_tracking_{}.png", incl_deg as i32);
        let centre = (r.height / 2 * r.width + r.width / 2) as usize;
        let curve = pixel_series(&r, centre);
        let top = curve.iter().copied().fold(0.0f32, f32::max) as f64;
        let mut series = vec![Series {
            points: curve
                .iter()
                .enumerate()
                .map(|(k, v)| (path.arc.angle_deg(k) as f64, *v as f64))
                .collect(),
            color: PALETTE[0],
            markers: false,
            label: "pixel".into(),
        }];
        if let Some(p) = predicted {
            series.push(Series {
                points: vec![(p as f64, 0.0), (p as f64, top)],
                color: PALETTE[1],
                markers: false,
                label: "predicted peak".into(),
            });
        }
        let opts = PlotOptions {
            x_title: "light angle °",
            y_title: "radiance",
            ..PlotOptions::default()
        };
        write_plot(dir, &rel, &series, &opts)?;
        plot = Some(rel);
    }
    Ok(CheckOutcome {
        verdict: Check::new(
            format!("highlight tracking, fibres dipping {incl_deg}°"),
            "≥ 99 % of the pixels peak within one frame step of the predicted peak",
            within,
            format!("{n} pixels, step {step:.2}°"),
            passed,
        ),
        figure: match predicted {
            Some(p) => format!(
                "predicted peak {p:.2}°; {:.1} % of {n} pixels peak within one frame step ({step:.2}°); largest deviation {max_dev:.2}°",
                100.0 * within
            ),
            None => "no single predicted peak inside the arc".into(),
        },
        plot,
        values: serde_json::json!({
            "inclination_deg": incl_deg, "beta_deg": beta_deg, "eta": ETA, "view_deg": VIEW_DEG,
            "frames": frames, "arc_deg": [arc.0, arc.1], "step_deg": step,
            "predicted_deg": predicted, "fraction_within_step": within, "max_deviation_deg": max_dev,
            "pixels": n,
        }),
    })
}

/// Check 2: every pixel of every frame against the BSDF evaluated directly.
pub fn renderer_vs_bsdf(run: &RunOptions) -> Result<CheckOutcome, SweepCheckError> {
    let (incl, beta_deg, frames, arc) = (15.0, 8.0, 33, (-80.0, 80.0));
    let loaded = load(
        "renderer_vs_bsdf",
        &fiber_board_toml(incl, beta_deg, frames, arc, 8),
    )?;
    let (r, path) = sweep_all(&loaded, run)?;
    let bsdf = WoodBsdf::new(WoodBsdfParams {
        diffuse: Vec3::new(0.25, 0.2, 0.15),
        fiber_color: Vec3::new(0.6, 0.5, 0.4),
        fiber_dir: inclined_fibre(Vec3::X, incl),
        ray_dir: Vec3::Z,
        ray_mask: 0.0,
        highlight_width: beta_deg.to_radians(),
        eta: ETA,
        roughness: 0.0,
    })
    .map_err(|e| SweepCheckError::Scene {
        name: "renderer_vs_bsdf".into(),
        message: e.to_string(),
    })?;
    let (s, c) = VIEW_DEG.to_radians().sin_cos();
    let wo = Vec3::new(s, 0.0, c);
    let mut worst = 0.0f64;
    let mut compared = 0usize;
    for (k, f) in r.frames.iter().enumerate() {
        let wi = path.plane.direction(path.light_deg(k));
        // E = 1 on a surface facing the light; cos θi = wi·n with n = +z.
        let expected = bsdf.eval(wo, wi) * wi.z;
        for px in &f.beauty {
            for ch in 0..3 {
                let (got, want) = (px[ch] as f64, expected[ch] as f64);
                let err = (got - want).abs() / want.abs().max(1e-6);
                worst = worst.max(err);
                compared += 1;
            }
        }
    }
    Ok(CheckOutcome {
        verdict: Check::new(
            "renderer against eval(wo, wi)·cos θi·E",
            "largest relative error ≤ 1e-3",
            worst,
            format!("{compared} pixel channels, {frames} frames"),
            worst <= 1e-3,
        ),
        figure: format!(
            "largest relative error {worst:.2e} over {compared} pixel channels in {frames} frames (allowed 1e-3)"
        ),
        plot: None,
        values: serde_json::json!({
            "inclination_deg": incl, "beta_deg": beta_deg, "frames": frames,
            "max_relative_error": worst, "compared": compared,
        }),
    })
}

/// The diffuse term's dependence on the light, g(θi) = luminance(f_diffuse(wo, wi)) · cos θi, for
/// the orthographic view straight down (wo = +z) and each frame's light direction, from [`WoodBsdf`]
/// with the fibre lobe switched off (k_f = 0); the substrate albedo only scales it.
fn diffuse_shape(path: &SweepPath, r: &Frames) -> Result<Vec<f64>, SweepCheckError> {
    let bsdf = WoodBsdf::new(WoodBsdfParams {
        diffuse: Vec3::splat(0.5),
        fiber_color: Vec3::ZERO,
        eta: ETA,
        ..WoodBsdfParams::default()
    })
    .map_err(|e| SweepCheckError::Scene {
        name: "mahogany_stripes".into(),
        message: e.to_string(),
    })?;
    Ok((0..r.frames.len())
        .map(|k| {
            let wi = path.plane.direction(path.light_deg(k));
            (luminance(bsdf.eval(Vec3::Z, wi)) * wi.z.max(0.0)) as f64
        })
        .collect())
}

/// Check 3a: the two stripe families of quartersawn African mahogany.
pub fn mahogany_stripes(
    plots: Option<&Path>,
    run: &RunOptions,
) -> Result<CheckOutcome, SweepCheckError> {
    // The arc spans the stripe highlights: interlocked fibres tilt a few degrees out of the face,
    // so both families' highlights fall within ±15° of the view; a wider arc only adds frames in
    // which neither family is near its highlight and the shared diffuse term alone changes.
    let (frames, arc) = (31, (-30.0, 30.0));
    let loaded = load(
        "mahogany_stripes",
        &preset_board_toml("african_mahogany", frames, arc, (96, 64)),
    )?;
    let (r, path) = sweep_all(&loaded, run)?;
    let (fam_a, fam_b) = stripe_families(&r.aov);
    let mean = |idx: &[usize]| -> Vec<f64> {
        r.frames
            .iter()
            .map(|f| {
                idx.iter()
                    .map(|&i| luminance(f.beauty[i]) as f64)
                    .sum::<f64>()
                    / idx.len().max(1) as f64
            })
            .collect()
    };
    let (raw_a, raw_b) = (mean(&fam_a), mean(&fam_b));
    // Both families share the diffuse term, which under a smooth finish factorises exactly as
    // ρ_pixel · g(θi) with g = T(θi) cos θi (notes/bsdf.md §1: Lambertian substrate seen through
    // the interface). Dividing each curve by g, taken from the BSDF itself with the fibre lobe off,
    // leaves a constant plus each family's fibre highlight relative to g, so the correlation
    // compares the highlights alone and is not forced negative by the normalisation.
    let shape = diffuse_shape(&path, &r)?;
    let divide = |c: &[f64]| -> Vec<f64> {
        c.iter()
            .zip(&shape)
            .map(|(v, g)| v / g.max(1e-12))
            .collect()
    };
    let (ca, cb) = (divide(&raw_a), divide(&raw_b));
    let min_pixels = r.aov.len() / 20;
    let enough = fam_a.len() >= min_pixels && fam_b.len() >= min_pixels;
    let rho = pearson(&ca, &cb);
    let rho_raw = pearson(&raw_a, &raw_b);
    let passed = enough && rho < -0.3 && rho_raw < -0.3;
    let peak = |c: &[f64]| {
        path.arc
            .angle_deg(argmax(&c.iter().map(|v| *v as f32).collect::<Vec<_>>()))
    };
    let plot = match plots {
        Some(dir) => Some(stripes_plot(dir, &path, [&ca, &cb])?),
        None => None,
    };
    Ok(CheckOutcome {
        verdict: Check::new(
            "African mahogany: stripe families brighten at different light angles",
            "two stripe families, their mean radiances correlated < −0.3 (shape-divided and raw)",
            if enough { rho.max(rho_raw) } else { f64::NAN },
            format!("{} px rising, {} px dipping", fam_a.len(), fam_b.len()),
            passed,
        ),
        figure: if enough {
            format!(
                "correlation of the two families' mean radiance divided by the diffuse shape T(θi)cos θi {rho:.3} (needs < −0.3), of the raw means {rho_raw:.3} (needs < −0.3 too); rising fibres ({} px) peak at {:.1}°, dipping fibres ({} px) at {:.1}°",
                fam_a.len(), peak(&raw_a), fam_b.len(), peak(&raw_b)
            )
        } else {
            format!(
                "no two stripe families: {} px with fibres rising and {} dipping more than 0.5° (needs {min_pixels} each) — the preset shows no interlocked fibre tilt",
                fam_a.len(), fam_b.len()
            )
        },
        plot,
        values: serde_json::json!({
            "frames": frames, "arc_deg": [arc.0, arc.1], "family_rising_px": fam_a.len(),
            "family_dipping_px": fam_b.len(), "correlation_over_diffuse_shape": rho, "correlation_raw": rho_raw,
            "curve_rising": raw_a, "curve_dipping": raw_b, "diffuse_shape": shape,
        }),
    })
}

/// The pixels of the two stripe families of an interlocked board, by their first hits' fibre
/// axes: (rising out of the face, dipping into it) by more than 0.5°.
fn stripe_families(aov: &[xylem::render::Aov]) -> (Vec<usize>, Vec<usize>) {
    // Fibre axes are unsigned: orient each along +x (the grain), then split by the sign of its
    // component along the normal (+z): rising out of the face or dipping into it.
    let tilt: Vec<f32> = aov
        .iter()
        .map(|a| {
            if a.fiber.x < 0.0 {
                -a.fiber.z
            } else {
                a.fiber.z
            }
        })
        .collect();
    let threshold = 0.5f32.to_radians().sin();
    let fam_a: Vec<usize> = (0..tilt.len()).filter(|&i| tilt[i] > threshold).collect();
    let fam_b: Vec<usize> = (0..tilt.len()).filter(|&i| tilt[i] < -threshold).collect();
    (fam_a, fam_b)
}

/// The plot of the two families' curves (divided by the diffuse shape) against the light
/// angle, written into `dir`; returns its path relative to `dir`.
fn stripes_plot(
    dir: &Path,
    path: &SweepPath,
    curves: [&[f64]; 2],
) -> Result<String, SweepCheckError> {
    let rel = "plots/sweep_mahogany_stripes.png".to_string();
    let series: Vec<Series> = curves
        .iter()
        .enumerate()
        .map(|(k, c)| Series {
            points: c
                .iter()
                .enumerate()
                .map(|(i, v)| (path.arc.angle_deg(i) as f64, *v))
                .collect(),
            color: PALETTE[k],
            markers: false,
            label: format!("stripe {}", ["a", "b"][k]),
        })
        .collect();
    let opts = PlotOptions {
        x_title: "light angle °",
        y_title: "radiance",
        ..PlotOptions::default()
    };
    write_plot(dir, &rel, &series, &opts)?;
    Ok(rel)
}

/// Check 3b: curly maple's bright bands move along the grain as the light moves.
pub fn curly_maple_bands(
    plots: Option<&Path>,
    run: &RunOptions,
) -> Result<CheckOutcome, SweepCheckError> {
    // 1.5° steps: the calibrated curl (fibre dips of ≈ 2° std, as Marschner 2005's measured
    // maple; validation/APPEARANCE.md) moves each column's peak by ≈ 4° of light angle.
    let (frames, arc) = (81, (-60.0, 60.0));
    let loaded = load(
        "curly_maple_bands",
        &preset_board_toml("curly_maple", frames, arc, (128, 48)),
    )?;
    let (r, path) = sweep_all(&loaded, run)?;
    let (w, h) = (r.width as usize, r.height as usize);
    // Column profiles along the grain (image x), per frame.
    let column = |f: usize, x: usize| -> f32 {
        (0..h)
            .map(|y| luminance(r.frames[f].beauty[y * w + x]))
            .sum::<f32>()
            / h as f32
    };
    let peak_deg: Vec<f64> = (0..w)
        .map(|x| {
            let series: Vec<f32> = (0..frames).map(|f| column(f, x)).collect();
            path.arc.angle_deg(argmax(&series)) as f64
        })
        .collect();
    let m = peak_deg.iter().sum::<f64>() / w as f64;
    let spread = (peak_deg.iter().map(|p| (p - m) * (p - m)).sum::<f64>() / w as f64).sqrt();
    let lag1 = pearson(&peak_deg[..w - 1], &peak_deg[1..]);
    let step = path.arc.step_deg().abs() as f64;
    let passed = spread >= 2.0 * step && lag1 >= 0.5;
    let mut plot = None;
    if let Some(dir) = plots {
        let rel = "plots/sweep_curly_maple_bands.png".to_string();
        let s = Series {
            points: peak_deg
                .iter()
                .enumerate()
                .map(|(x, p)| (x as f64, *p))
                .collect(),
            color: PALETTE[2],
            markers: true,
            label: String::new(),
        };
        let opts = PlotOptions {
            x_title: "frame",
            y_title: "peak position",
            ..PlotOptions::default()
        };
        write_plot(dir, &rel, &[s], &opts)?;
        plot = Some(rel);
    }
    Ok(CheckOutcome {
        verdict: Check::new(
            "curly maple: bright bands shift with the light angle",
            format!(
                "spread of the columns' peak angles ≥ {:.1}° (two frame steps) and lag-1 autocorrelation ≥ 0.5",
                2.0 * step
            ),
            spread,
            format!("lag-1 autocorrelation {lag1:.2}"),
            passed,
        ),
        figure: format!(
            "light angle of each column's peak along the grain: spread {spread:.2}° (needs ≥ {:.1}°, two frame steps), lag-1 autocorrelation {lag1:.2} (needs ≥ 0.5: bands, not noise)",
            2.0 * step
        ),
        plot,
        values: serde_json::json!({
            "frames": frames, "arc_deg": [arc.0, arc.1], "step_deg": step,
            "peak_angle_per_column_deg": peak_deg, "spread_deg": spread, "lag1_autocorrelation": lag1,
        }),
    })
}

/// Runs every sweep check; plots go under `plots_root` (the report's folder) when given.
pub fn run_checks(
    plots_root: Option<&Path>,
    run: &RunOptions,
    progress: &dyn Fn(&str),
) -> Result<Vec<CheckOutcome>, SweepCheckError> {
    let mut out = Vec::new();
    for incl in [0.0, 15.0, 30.0] {
        progress("highlight tracking");
        out.push(highlight_tracking(incl, plots_root, run)?);
    }
    progress("renderer against the BSDF");
    out.push(renderer_vs_bsdf(run)?);
    progress("mahogany stripes");
    out.push(mahogany_stripes(plots_root, run)?);
    progress("curly maple bands");
    out.push(curly_maple_bands(plots_root, run)?);
    Ok(out)
}

/// The sweep section of validation/REPORT.md.
pub fn to_markdown(checks: &[CheckOutcome]) -> String {
    let passed = checks.iter().filter(|c| c.verdict.passed).count();
    let mut s = format!(
        "## Light sweeps\n\n`xylem validate sweep`: {passed} of {} checks pass. Setups and the peak \
         derivation: `crates/xylem-lab/src/sweep.rs`, notes/sweep.md. Plots: luminance (vertical) against light \
         angle in degrees (horizontal) unless stated; the axis ranges are printed at the corners.\n\n",
        checks.len()
    );
    let verdicts: Vec<Check> = checks.iter().map(|c| c.verdict.clone()).collect();
    s += &checks_table(&verdicts);
    s += "\n";
    let rows: Vec<Vec<String>> = checks
        .iter()
        .map(|c| vec![c.verdict.check.clone(), c.figure.clone()])
        .collect();
    s += &markdown_table(&["check", "measured"], &rows);
    for c in checks {
        if let Some(p) = &c.plot {
            let caption = if p.contains("tracking") {
                "centre pixel's luminance (blue) and the predicted peak (red line)"
            } else if p.contains("mahogany") {
                "mean luminance of fibres rising out of the face (blue) and dipping into it (red), each divided by the diffuse term's light dependence T(θi) cos θi"
            } else {
                "light angle (vertical, degrees) at which each column along the grain (horizontal, pixels) is brightest"
            };
            s += &format!(
                "\n**{}** — {caption}\n\n![{}]({p})\n",
                c.verdict.check, c.verdict.check
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pearson_of_opposite_and_constant_series() {
        let a = [1.0, 2.0, 3.0, 4.0];
        let b = [4.0, 3.0, 2.0, 1.0];
        assert!((pearson(&a, &b) + 1.0).abs() < 1e-12);
        assert!((pearson(&a, &a) - 1.0).abs() < 1e-12);
        assert_eq!(pearson(&a, &[2.0; 4]), 0.0);
    }

    #[test]
    fn argmax_takes_the_first_maximum() {
        assert_eq!(argmax(&[0.0, 3.0, 1.0, 3.0]), 1);
        assert_eq!(argmax(&[f32::NAN, 1.0]), 1);
    }

    #[test]
    fn validation_scenes_parse() {
        load("t", &fiber_board_toml(15.0, 2.0, 9, (-80.0, 80.0), 4)).unwrap();
        load(
            "p",
            &preset_board_toml("curly_maple", 5, (-60.0, 60.0), (8, 4)),
        )
        .unwrap();
    }
}
