//! What the footprint filter does to aliasing (`xylem validate aliasing`, issue 28): each wood
//! scene rendered several times with other seeds under each setting compared — the wood
//! band-limited (today's default), point-sampled under today's samples, and, through the binary
//! of another commit ([`render_with_binary`]), the default the issue was filed against
//! (independent samples, point-sampled wood) — against a converged point-sampled reference made
//! of independent parts: the pixel filter's average of the unfiltered wood, the supersampled
//! image. Per setting the **high-frequency error energy** of one render (the issue's "aliasing
//! energy": the power of the 3 × 3 high-pass of the difference to the converged image over the
//! wood), split into its **bias** part (the same in every render: what the filter's blur or a
//! deterministic sampling pattern leaves) and its **noise** part (what changes from seed to
//! seed, where independent point samples put the sub-pixel texture's aliasing), each with a
//! jackknife standard error ([`energies`]), and ratios between settings with Fieller's interval
//! ([`ratio_interval`]). Derivation: notes/render.md, "The aliasing estimator".

use crate::bench::clock::{children_cpu_seconds, CpuTimer};
use crate::report::{checks_table, Check};
use crate::tradeoff::{apply, Knobs};
use glam::Vec3;
use std::path::Path;
use xylem::math::luminance;
use xylem::picture::exr::read_exr_channels;
use xylem::render::{render, RunOptions};
use xylem::scene::LoadedScene;

/// The pixels of `mask` (row-major, `width` × `height`) whose 3 × 3 neighbourhood lies inside
/// the image and in the mask: where [`high_pass`] is judged.
pub fn judged_pixels(mask: &[bool], width: usize, height: usize) -> Vec<usize> {
    let mut out = Vec::new();
    for y in 1..height.saturating_sub(1) {
        for x in 1..width.saturating_sub(1) {
            let inside = (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| mask[yy * width + xx]));
            if inside {
                out.push(y * width + x);
            }
        }
    }
    out
}

/// The 3 × 3 high-pass d − box₃ₓ₃ d of `d` at each of `pixels` ([`judged_pixels`]). Aliasing is
/// signal above the pixel's Nyquist band folded back as structure a few pixels across; the
/// high-pass keeps it and drops slow shading. Linear in `d`.
pub fn high_pass(d: &[f64], pixels: &[usize], width: usize) -> Vec<f64> {
    pixels
        .iter()
        .map(|&i| {
            let mut sum = 0.0;
            for row in [i - width, i, i + width] {
                sum += d[row - 1] + d[row] + d[row + 1];
            }
            d[i] - sum / 9.0
        })
        .collect()
}

/// High-frequency power of `d` over the pixels of `mask` whose 3 × 3 neighbourhood lies in it:
/// Σ (d − box₃ₓ₃ d)², and the pixels counted.
pub fn high_pass_power(d: &[f64], mask: &[bool], width: usize, height: usize) -> (f64, usize) {
    let pixels = judged_pixels(mask, width, height);
    let hp = high_pass(d, &pixels, width);
    (dot(&hp, &hp), pixels.len())
}

/// The single-pair form of [`energies`]' bias part, kept for quick checks: P(x1 − r) −
/// P(x1 − x2)/2 − P(a − b)/4 with r = (a + b)/2, `x2` a render like `x1` of other seeds and
/// `a`, `b` the reference's independent halves (P = [`high_pass_power`], a quadratic form, so
/// for independent zero-mean noise E P(n₁ − n₂) = 2 E P(n) whatever the noise's correlation
/// between pixels). Unbiased for the bias energy but with one pair its scatter is of the order
/// of the noise's power itself; [`energies`] averages many renders and gives standard errors.
/// Returns (net power, the noise's share taken out, pixels).
pub fn aliasing_power(
    [x1, x2]: [&[f64]; 2],
    [a, b]: [&[f64]; 2],
    mask: &[bool],
    width: usize,
    height: usize,
) -> (f64, f64, usize) {
    let zip = |p: &[f64], q: &[f64], f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        p.iter().zip(q).map(|(u, v)| f(*u, *v)).collect()
    };
    let r = zip(a, b, &|u, v| 0.5 * (u + v));
    let (err, n) = high_pass_power(&zip(x1, &r, &|u, v| u - v), mask, width, height);
    let (x_noise, _) = high_pass_power(&zip(x1, x2, &|u, v| u - v), mask, width, height);
    let (r_noise, _) = high_pass_power(&zip(a, b, &|u, v| u - v), mask, width, height);
    let noise = x_noise / 2.0 + r_noise / 4.0;
    (err - noise, noise, n)
}

mod estimator;
#[cfg(test)]
mod tests;

pub use estimator::*;

/// One render's images: the beauty and the first hits' albedo AOV (the wood's colour averaged
/// over the pixel's samples: the texture alone, without the lighting's noise).
#[derive(Clone, Debug)]
pub struct Frame {
    pub beauty: Vec<Vec3>,
    pub albedo: Vec<Vec3>,
    /// The pixels whose first hits are wood (fibre AOV not zero); empty from another binary.
    pub wood: Vec<bool>,
    /// CPU seconds: of the render alone in this process, of the whole child process for
    /// another binary.
    pub cpu: f64,
}

/// The RGB layer `layer` (channels `layer.R`, `.G`, `.B`) of an EXR that `xylem render` wrote
/// (read by `picture::exr::read_exr_channels`).
fn read_exr_rgb_layer(path: &Path, layer: &str) -> Result<Vec<Vec3>, String> {
    let channels = read_exr_channels(path).map_err(|e| e.to_string())?;
    let channel = |name: &str| {
        let want = format!("{layer}.{name}");
        (channels.iter().find(|(n, _)| *n == want))
            .map(|(_, v)| v)
            .ok_or_else(|| format!("{}: no channel {want}", path.display()))
    };
    let (r, g, b) = (channel("R")?, channel("G")?, channel("B")?);
    Ok((0..r.len()).map(|i| Vec3::new(r[i], g[i], b[i])).collect())
}

/// Renders built-in scene `scene` (as `xylem render` takes it) with another `xylem` binary —
/// the default of another commit, e.g. the one issue 28 was filed against — at `size`, `spp`
/// and `seed`, the footprint filter on or off, into `dir`, and reads its beauty and albedo back.
pub fn render_with_binary(
    binary: &Path,
    scene: &str,
    size: (u32, u32),
    spp: u32,
    seed: u64,
    filter: bool,
    dir: &Path,
) -> Result<Frame, String> {
    let cpu0 = children_cpu_seconds();
    let out = std::process::Command::new(binary)
        .arg("render")
        .arg(format!("scenes/{scene}.toml"))
        .args(["--res", &format!("{}x{}", size.0, size.1)])
        .args(["--spp", &spp.to_string(), "--seed", &seed.to_string()])
        .args(["--footprint-filter", if filter { "on" } else { "off" }])
        .arg("--out")
        .arg(dir)
        .arg("--quiet")
        .output()
        .map_err(|e| format!("running {}: {e}", binary.display()))?;
    let cpu = match (cpu0, children_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => f64::NAN,
    };
    if !out.status.success() {
        return Err(format!(
            "{} render {scene} failed: {}",
            binary.display(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let path = dir.join(format!("{scene}.exr"));
    let img = xylem::picture::Image::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    if (img.width, img.height) != size {
        return Err(format!(
            "{}: {}×{}, not {:?}",
            path.display(),
            img.width,
            img.height,
            size
        ));
    }
    let albedo = read_exr_rgb_layer(&path, "albedo")?;
    if albedo.len() != img.pixels.len() {
        return Err(format!("{}: albedo of another size", path.display()));
    }
    Ok(Frame {
        beauty: img.pixels,
        albedo,
        wood: Vec::new(),
        cpu,
    })
}

/// Renders the scene `base` loads with `knobs` at seed `seed` in this process.
fn render_seeded(
    base: &dyn Fn() -> Result<LoadedScene, String>,
    knobs: &Knobs,
    seed: u64,
    run: &RunOptions,
) -> Result<Frame, String> {
    let mut loaded = base()?;
    loaded.settings.seed = seed;
    apply(&mut loaded, knobs).map_err(|e| e.to_string())?;
    let timer = CpuTimer::process();
    let out = render(&loaded.scene, &loaded.settings, run).map_err(|e| e.to_string())?;
    let cpu = timer.seconds();
    let aov = &out.image.aov;
    Ok(Frame {
        wood: aov.iter().map(|a| a.fiber != Vec3::ZERO).collect(),
        albedo: aov.iter().map(|a| a.albedo).collect(),
        beauty: out.image.beauty,
        cpu,
    })
}

/// How many renders of each setting and reference parts [`measure`] takes.
#[derive(Clone, Copy, Debug)]
pub struct Design {
    /// Renders of each setting at the scene's spp, seeds of their own (≥ 3).
    pub renders: u32,
    /// Independent parts of the reference (≥ 3).
    pub parts: u32,
    /// Samples per pixel of the whole reference (its parts share them).
    pub reference_spp: u32,
}

/// The settings compared.
pub const LABELS: [&str; 3] = [
    "today's default (filter on)",
    "today's samples, point-sampled",
    "issue-time default (other binary)",
];

/// One setting's figures in a scene.
#[derive(Clone, Copy, Debug)]
pub struct SettingRow {
    /// Energies over the reference's wood luminance power (standard errors likewise).
    pub energy: Energy,
    /// The same of the albedo AOV (the first hits' colour: the texture alone, no lighting).
    pub texture: Energy,
    /// Net relative MSE against the converged image (RGB), mean over the renders.
    pub mse: f64,
    /// CPU seconds of one render, median over the renders.
    pub cpu: f64,
}

/// One scene's figures.
#[derive(Clone, Debug)]
pub struct Row {
    /// Built-in scene name.
    pub scene: String,
    /// Resolution judged.
    pub size: (u32, u32),
    /// Samples per pixel of the compared renders.
    pub spp: u32,
    /// The renders and reference.
    pub design: Design,
    /// Wood pixels judged by the high-pass.
    pub pixels: usize,
    /// Degrees of freedom of the intervals.
    pub dof: usize,
    /// Today's default, today's samples point-sampled, and (with a baseline binary) the
    /// issue-time default.
    pub settings: Vec<SettingRow>,
    /// Total energy, today's default over today's samples point-sampled.
    pub vs_point: Ratio,
    /// Total energy, today's default over the issue-time default.
    pub vs_issue: Option<Ratio>,
    /// The same two ratios of the albedo AOV's energies (texture alone).
    pub texture_vs_point: Ratio,
    /// See `texture_vs_point`.
    pub texture_vs_issue: Option<Ratio>,
}

impl Row {
    /// Error at equal CPU time, today's default over point-sampled: MSE × CPU time, constant for
    /// error that is all Monte Carlo noise.
    pub fn equal_time_ratio(&self) -> f64 {
        (self.settings[0].mse * self.settings[0].cpu)
            / (self.settings[1].mse * self.settings[1].cpu)
    }

    /// The ratio the goal is judged on: against the issue-time default where it was rendered,
    /// else against point sampling.
    pub fn goal_ratio(&self) -> Ratio {
        self.vs_issue.unwrap_or(self.vs_point)
    }
}

/// The goal on the aliasing energy (issue 28): today's default ≤ 0.3× the issue-time one.
pub const GOAL: f64 = 0.3;

/// "met" when the whole 95 % interval is ≤ [`GOAL`], "missed" when it lies above, else
/// "undecided".
pub fn verdict(r: &Ratio) -> &'static str {
    match r.interval {
        Some((_, hi)) if hi <= GOAL => "met",
        Some((lo, _)) if lo > GOAL => "missed",
        _ => "undecided",
    }
}

/// The energies of one channel of every setting ([`energies`]) over the reference's wood power
/// in that channel, and the ratios of today's default's total to each other setting's.
fn channel(
    reference: &[Frame],
    settings: &[Vec<Frame>],
    pick: fn(&Frame) -> &[Vec3],
    mask: &[bool],
    pixels: &[usize],
    width: usize,
) -> (Vec<Energy>, Vec<Ratio>, usize) {
    let lum = |c: &[Vec3]| -> Vec<f64> { c.iter().map(|&v| luminance(v) as f64).collect() };
    let hp = |f: &Frame| high_pass(&lum(pick(f)), pixels, width);
    let parts: Vec<Vec<f64>> = reference.iter().map(hp).collect();
    let renders: Vec<Vec<Vec<f64>>> = settings
        .iter()
        .map(|s| s.iter().map(hp).collect())
        .collect();
    let n = reference.len() as f64;
    let power: f64 = (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| {
            (reference
                .iter()
                .map(|f| luminance(pick(f)[i]) as f64)
                .sum::<f64>()
                / n)
                .powi(2)
        })
        .sum::<f64>()
        .max(1e-30);
    let (energy, cov, dof) = energies(&parts, &renders);
    let t = t95(dof);
    let ratios = (1..settings.len())
        .map(|b| {
            let (nu, de) = (energy[0].total.value, energy[b].total.value);
            ratio_interval(nu, de, cov[0][0], cov[b][b], cov[0][b], t)
        })
        .collect();
    let scale = |e: Estimate| Estimate {
        value: e.value / power,
        se: e.se / power,
    };
    let scaled = (energy.iter())
        .map(|e| Energy {
            total: scale(e.total),
            bias: scale(e.bias),
            noise: scale(e.noise),
        })
        .collect();
    (scaled, ratios, dof)
}

/// Measures one scene: `base` loads it at `size` (the size judged); `baseline`, when given,
/// renders the issue-time default with that binary ([`render_with_binary`]; the scene's name
/// `name` is what it is given).
pub fn measure(
    name: &str,
    base: &dyn Fn() -> Result<LoadedScene, String>,
    size: (u32, u32),
    spp: u32,
    design: Design,
    baseline: Option<&Path>,
    run: &RunOptions,
) -> Result<Row, String> {
    let (w, h) = (size.0 as usize, size.1 as usize);
    let part = Knobs {
        footprint_filter: false,
        ..Knobs::full((design.reference_spp / design.parts).max(1))
    };
    let reference = (0..design.parts)
        .map(|k| render_seeded(base, &part, 1000 + u64::from(k), run))
        .collect::<Result<Vec<Frame>, String>>()?;
    let mask = reference[0].wood.clone();
    let pixels = judged_pixels(&mask, w, h);
    let mean_image: Vec<Vec3> = (0..w * h)
        .map(|i| reference.iter().map(|p| p.beauty[i]).sum::<Vec3>() / reference.len() as f32)
        .collect();
    // The reference mean's own noise, Σ|r_k − r̄|² / (R (R − 1)), comes off each MSE.
    let r = reference.len() as f64;
    let reference_noise = (reference.iter())
        .map(|p| {
            (p.beauty.iter().zip(&mean_image))
                .map(|(a, b)| (*a - *b).length_squared() as f64)
                .sum::<f64>()
        })
        .sum::<f64>()
        / (r * (r - 1.0));

    let scratch = tempfile::tempdir().map_err(|e| e.to_string())?;
    let count = if baseline.is_some() { 3 } else { 2 };
    let mut frames: Vec<Vec<Frame>> = Vec::new();
    for s in 0..count {
        let mut setting = Vec::new();
        for i in 0..design.renders {
            let seed = 100 * (s as u64 + 1) + u64::from(i);
            setting.push(match (s, baseline) {
                (2, Some(bin)) => {
                    render_with_binary(bin, name, size, spp, seed, false, scratch.path())?
                }
                _ => {
                    let knobs = Knobs {
                        footprint_filter: s == 0,
                        ..Knobs::full(spp)
                    };
                    render_seeded(base, &knobs, seed, run)?
                }
            });
        }
        frames.push(setting);
    }
    let (energy, ratios, dof) = channel(&reference, &frames, |f| &f.beauty, &mask, &pixels, w);
    let (texture, texture_ratios, _) =
        channel(&reference, &frames, |f| &f.albedo, &mask, &pixels, w);
    let settings = (frames.iter().enumerate())
        .map(|(s, f)| {
            let mses: Vec<f64> = (f.iter())
                .map(|x| crate::tradeoff::relative_mse_net(&x.beauty, &mean_image, reference_noise))
                .collect();
            let cpus: Vec<f64> = f.iter().map(|x| x.cpu).collect();
            SettingRow {
                energy: energy[s],
                texture: texture[s],
                mse: mses.iter().sum::<f64>() / mses.len() as f64,
                cpu: crate::tradeoff::median_range(&cpus).0,
            }
        })
        .collect();
    Ok(Row {
        scene: name.to_string(),
        size,
        spp,
        design,
        pixels: pixels.len(),
        dof,
        settings,
        vs_point: ratios[0],
        vs_issue: ratios.get(1).copied(),
        texture_vs_point: texture_ratios[0],
        texture_vs_issue: texture_ratios.get(1).copied(),
    })
}

/// "v ± se" in the report's style.
fn pm(e: Estimate) -> String {
    format!("{:.2e} ± {:.1e}", e.value, e.se)
}

/// "ρ [lo, hi]", or "ρ [unbounded]" when the denominator is not significant.
fn ratio_text(r: &Ratio) -> String {
    match r.interval {
        Some((lo, hi)) => format!("{:.2} [{:.2}, {:.2}]", r.value, lo, hi),
        None => format!("{:.2} [unbounded]", r.value),
    }
}

/// The report: the energies of every setting and the ratios with their 95 % intervals; the goal
/// (issue 28: aliasing energy ≤ 0.3× the issue-time default's, judged on the issue-time
/// binary where given, else on point sampling) met when the whole interval is ≤ 0.3. Returns
/// (markdown, every scene met).
pub fn report_md(rows: &[Row], command: &str) -> (String, Vec<Check>) {
    let design = rows.first().map(|r| r.design);
    let mut md = String::from(
        "# Aliasing energy: today's default against point sampling and the issue-time default (issue 28)\n\n\
         Written by `xylem validate aliasing` (crates/xylem-lab/src/aliasing/; derivation in \
         notes/render.md, \"The aliasing estimator\"). Each wood scene is rendered K times with \
         seeds of their own under each setting — today's default (wood band-limited by the pixel \
         footprint, Sobol-stratified samples spread adaptively, `render`'s default), today's samples with the wood point-sampled, and, \
         with `--baseline BIN`, the default issue 28 was filed against rendered by that binary \
         (`xylem` built from 5a8ffa9^ = 2934293: independent samples, point-sampled wood) — against a converged point-sampled reference \
         of R independent parts. **Energy**: the power of the 3 × 3 high-pass of a render's \
         luminance difference to the converged image over the wood, over the reference's wood \
         luminance power: *total* (one render's, the issue's aliasing energy, the reference's \
         own noise taken off), its *bias* part (what every render shares: the filter's \
         departure from the pixel average) and *noise* part (the spread between seeds: Monte \
         Carlo noise, including the sub-pixel texture that random point samples turn into \
         noise). Each ± is a delete-one jackknife standard error over the renders and \
         reference parts; ratios of totals carry Fieller's 95 % interval (Student's t). \
         **Texture only**: the same measured on the albedo AOV (the first hits' colour averaged \
         over the pixel's samples), which carries the wood's pattern and none of the lighting's \
         noise. Goal: \
         today's total ≤ 0.3× the issue-time default's — *met* when the whole interval is ≤ 0.3, \
         *missed* when it lies above, else *undecided*.\n\n",
    );
    md += &format!("Command: `{command}`\n\n");
    if let Some(d) = design {
        md += &format!(
            "Renders per setting K = {}, reference {} spp in R = {} parts.\n\n",
            d.renders, d.reference_spp, d.parts
        );
    }
    md += "| scene | size, spp | wood px | today / issue-time (total) [95 %] | goal ≤ 0.3 | today / point-sampled (total) [95 %] | texture only (albedo): today / issue-time | today / point | equal-time error, filtered / point |\n";
    md += "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    let mut checks = Vec::new();
    for r in rows {
        let issue = r.vs_issue.as_ref().map_or("—".to_string(), ratio_text);
        let v = verdict(&r.goal_ratio());
        checks.push(Check::new(
            format!("aliasing energy of `{}`", r.scene),
            format!(
                "today's total over the {} default's ≤ {GOAL} (the whole 95 % interval)",
                if r.vs_issue.is_some() {
                    "issue-time"
                } else {
                    "point-sampled"
                }
            ),
            r.goal_ratio().value,
            format!("{} ({v})", ratio_text(&r.goal_ratio())),
            v == "met",
        ));
        md += &format!(
            "| `{}` | {}×{}, {} | {} | {} | {}{} | {} | {} | {} | {:.2} |\n",
            r.scene,
            r.size.0,
            r.size.1,
            r.spp,
            r.pixels,
            issue,
            v,
            if r.vs_issue.is_none() {
                " (vs point)"
            } else {
                ""
            },
            ratio_text(&r.vs_point),
            r.texture_vs_issue
                .as_ref()
                .map_or("—".to_string(), ratio_text),
            ratio_text(&r.texture_vs_point),
            r.equal_time_ratio()
        );
    }
    md += "\n| scene | setting | total | bias | noise | albedo total | albedo bias | rel. MSE | CPU s |\n";
    md += "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for r in rows {
        for (label, s) in LABELS.iter().zip(&r.settings) {
            md += &format!(
                "| `{}` | {} | {} | {} | {} | {} | {} | {:.2e} | {:.2} |\n",
                r.scene,
                label,
                pm(s.energy.total),
                pm(s.energy.bias),
                pm(s.energy.noise),
                pm(s.texture.total),
                pm(s.texture.bias),
                s.mse,
                s.cpu
            );
        }
    }
    md += "\nThe bias part of a point-sampled setting is 0 in expectation (random point samples \
           are unbiased for the pixel average; the reference is that average), so its figure is \
           a check of the estimator. CPU seconds of the other binary are its whole process \
           (loading, BVH, EXR) and not comparable with the in-process renders'.\n";
    md += "\n";
    md += &checks_table(&checks);
    (md, checks)
}
