//! The wood benchmark behind `xylem bench wood`: wood texels per second per core for each
//! preset, colour only and the full model (the speed goal of issue 4; the criterion twin is
//! crates/xylem-lab/benches/wood.rs).

use super::clock::CpuTimer;
use glam::Vec3;
use xylem::wood::{self, Needs, WoodError, WoodVolume};

/// Texels per CPU second of `volume` over `points` (one thread; wall clock where thread CPU time
/// is unavailable), evaluated by `eval_many` when `batch`, else point by point with `eval`.
/// Repeats the pass until at least a second of CPU time has been spent.
pub fn texels_per_second(volume: &WoodVolume, points: &[Vec3], needs: Needs, batch: bool) -> f64 {
    let timer = CpuTimer::thread();
    let mut sink = 0.0f32;
    let mut done = 0usize;
    let mut out = vec![wood::WoodTexel::default(); points.len()];
    loop {
        if batch {
            volume.eval_many(points, needs, &mut out);
        } else {
            for (o, &p) in out.iter_mut().zip(points) {
                *o = volume.eval(p, needs);
            }
        }
        for t in &out {
            sink += t.diffuse.x + t.fiber_dir.z + t.bump;
        }
        done += points.len();
        let spent = timer.seconds();
        if spent >= 1.0 {
            std::hint::black_box(sink);
            return done as f64 / spent;
        }
    }
}

/// One preset's texels per second at each level of `needs`.
#[derive(Clone, Copy, Debug)]
pub struct PresetSpeed {
    /// Colour only, in batches (`eval_many`, as slices and bakes evaluate it).
    pub colour_batch: f64,
    /// Colour only, point by point (`eval`, as a renderer's hit does).
    pub colour_point: f64,
    /// Colour and fibres, point by point.
    pub colour_fibres: f64,
    /// The full model, point by point.
    pub everything: f64,
}

/// [`PresetSpeed`] of `volume` over `points`, after a warm-up on a tenth of them.
pub fn preset_speed(volume: &WoodVolume, points: &[Vec3]) -> PresetSpeed {
    texels_per_second(volume, &points[..points.len() / 10], Needs::COLOR, true);
    PresetSpeed {
        colour_batch: texels_per_second(volume, points, Needs::COLOR, true),
        colour_point: texels_per_second(volume, points, Needs::COLOR, false),
        colour_fibres: texels_per_second(volume, points, Needs::COLOR_FIBERS, false),
        everything: texels_per_second(volume, points, Needs::ALL, false),
    }
}

/// The preset issue 4's speed goals are set on.
pub const GOAL_PRESET: &str = "african_mahogany";

/// Issue 4's speed goals for [`GOAL_PRESET`] as a table row: the full model at ≥ 1 M texels/s
/// per core, colour alone at ≥ 3× that (3 M); colour is timed in batches and point by point.
pub fn goal_line(s: &PresetSpeed) -> String {
    let verdict = |ok: bool| if ok { "met" } else { "not met" };
    format!(
        "|   goals: everything ≥ 1 M/s {}; colour ≥ 3 M/s {} in batches, {} point by point | | | | | |",
        verdict(s.everything >= 1e6),
        verdict(s.colour_batch >= 3e6),
        verdict(s.colour_point >= 3e6),
    )
}

/// The presets named by `only`, or all.
pub fn selected(only: &[String]) -> Vec<&str> {
    if only.is_empty() {
        wood::PRESET_NAMES.to_vec()
    } else {
        only.iter().map(String::as_str).collect()
    }
}

/// The levels of `needs` of [`fixed_passes`]: key (as `--needs` spells it), label, needs.
const LEVELS: [(&str, &str, Needs); 3] = [
    ("colour", "colour", Needs::COLOR),
    ("fibres", "colour + fibres", Needs::COLOR_FIBERS),
    ("all", "everything", Needs::ALL),
];

/// Why [`fixed_passes`] could not run.
#[derive(Debug, thiserror::Error)]
pub enum FixedPassError {
    /// The preset could not be built.
    #[error(transparent)]
    Wood(#[from] WoodError),
    /// `needs` is none of the levels.
    #[error("--needs {0}: expected colour, fibres or all")]
    Needs(String),
}

/// `passes` untimed passes of each level of `needs` (one level when `needs` names it: colour,
/// fibres or all) of the preset `name` (for instruction counting), point by point when
/// `per_point`: one line per level with the texel count, a checksum and the bits' fingerprint.
pub fn fixed_passes(
    name: &str,
    points: &[Vec3],
    passes: usize,
    needs: Option<&str>,
    per_point: bool,
) -> Result<Vec<String>, FixedPassError> {
    let volume = WoodVolume::new(wood::preset(name)?, 1)?;
    if let Some(bad) = needs.filter(|n| !LEVELS.iter().any(|l| l.0 == *n)) {
        return Err(FixedPassError::Needs(bad.to_string()));
    }
    let wanted = |key: &str| needs.is_none_or(|n| n == key);
    let mut lines = Vec::new();
    for (_, label, needs) in LEVELS.into_iter().filter(|l| wanted(l.0)) {
        let mut sink = 0.0f32;
        let mut bits = Fingerprint::default();
        let mut out = vec![wood::WoodTexel::default(); points.len()];
        for _ in 0..passes {
            if per_point {
                for (o, &p) in out.iter_mut().zip(points) {
                    *o = volume.eval(p, needs);
                }
            } else {
                volume.eval_many(points, needs, &mut out);
            }
            for t in &out {
                sink += t.diffuse.x + t.fiber_dir.z + t.bump;
                bits.add_texel(t);
            }
        }
        lines.push(format!(
            "{name} {label}: {} texels, checksum {sink:.6e}, bits {:016x}",
            passes * points.len(),
            bits.0
        ));
    }
    Ok(lines)
}

/// Colour-only (batches) and full-model (point by point) texels per second with each feature
/// switched off in turn, handed to `each` as (label, colour, everything): the saving is that
/// feature's cost.
pub fn breakdown(
    params: &wood::WoodParams,
    points: &[Vec3],
    mut each: impl FnMut(&str, f64, f64),
) -> Result<(), WoodError> {
    type SwitchOff = fn(&mut wood::WoodParams);
    let variants: [(&str, SwitchOff); 8] = [
        ("no growth noise", |p| p.growth = None),
        ("no interlock", |p| p.interlock = None),
        ("no distortion", |p| p.distortion = Default::default()),
        ("no pores", |p| p.pores = None),
        ("no rays", |p| p.rays = None),
        ("no knots", |p| p.knots = None),
        ("no fibre wander", |p| p.fibre_wander = None),
        ("rings + colour only", |p| {
            *p = wood::WoodParams {
                growth: None,
                interlock: None,
                distortion: Default::default(),
                pores: None,
                rays: None,
                knots: None,
                fibre_wander: None,
                ..p.clone()
            }
        }),
    ];
    for (label, edit) in variants {
        let mut p = params.clone();
        edit(&mut p);
        let v = WoodVolume::new(p, 1)?;
        let c = texels_per_second(&v, points, Needs::COLOR, true);
        let all = texels_per_second(&v, points, Needs::ALL, false);
        each(label, c, all);
    }
    Ok(())
}

/// FNV-1a over the bits of every field of every texel: equal only if the outputs are bit for bit
/// equal (the check that a speed change left the model alone).
#[derive(Debug)]
struct Fingerprint(u64);

impl Default for Fingerprint {
    fn default() -> Self {
        Fingerprint(0xcbf2_9ce4_8422_2325)
    }
}

impl Fingerprint {
    fn add(&mut self, x: f32) {
        for byte in x.to_bits().to_le_bytes() {
            self.0 = (self.0 ^ byte as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn add_texel(&mut self, t: &wood::WoodTexel) {
        for v in [
            t.diffuse,
            t.fiber_color,
            t.fiber_dir,
            t.ray_dir,
            t.bump_grad,
        ] {
            v.to_array().into_iter().for_each(|x| self.add(x));
        }
        let scalars = [
            t.ray_mask,
            t.pore_mask,
            t.bump,
            t.highlight_width,
            t.growth_time,
        ];
        scalars.into_iter().for_each(|x| self.add(x));
    }
}
