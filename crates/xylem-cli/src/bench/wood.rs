//! `xylem bench wood`: wood texels per second per core for each preset, colour only and the full
//! model (the speed goal of issue 4; the criterion twin is crates/xylem-lab/benches/wood.rs).

use glam::Vec3;
use std::process::ExitCode;
use xylem::wood::{self, Needs, WoodVolume};
use xylem_lab::bench::clock::CpuTimer;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Points per pass (passes repeat until one CPU second is spent).
    #[arg(long, default_value_t = 20_000)]
    texels: usize,
    /// Only these presets (default: all).
    #[arg(long)]
    only: Vec<String>,
    /// Also time each preset with one feature switched off at a time (colour and full model).
    #[arg(long)]
    breakdown: bool,
    /// Run exactly this many passes per level of `needs` instead of timing (a fixed workload for
    /// instruction counts: `valgrind --tool=callgrind xylem bench wood --passes 1 ...`).
    #[arg(long)]
    passes: Option<usize>,
    /// With `--passes`: evaluate point by point (`eval`) instead of in batches (`eval_many`).
    #[arg(long)]
    per_point: bool,
    /// With `--passes`: only this level of `needs` (colour, fibres or all; default: the three).
    #[arg(long)]
    needs: Option<String>,
}

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

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let points = wood::sample_points(args.texels, 42);
    if let Some(passes) = args.passes {
        return fixed_passes(&args, &points, passes);
    }
    let names = selected(&args.only);
    println!(
        "| preset | colour (M texels/s) | colour, per point | colour + fibres | everything | \
         colour / everything |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    for name in names {
        let volume = WoodVolume::new(wood::preset(name)?, 1)?;
        // Warm-up, then measure each level of `needs`: colour in batches (`eval_many`, as
        // slices and bakes evaluate it) and point by point (`eval`, as a renderer's hit does).
        texels_per_second(&volume, &points[..points.len() / 10], Needs::COLOR, true);
        let c = texels_per_second(&volume, &points, Needs::COLOR, true);
        let c1 = texels_per_second(&volume, &points, Needs::COLOR, false);
        let cf = texels_per_second(&volume, &points, Needs::COLOR_FIBERS, false);
        let all = texels_per_second(&volume, &points, Needs::ALL, false);
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1}× |",
            c / 1e6,
            c1 / 1e6,
            cf / 1e6,
            all / 1e6,
            c / all
        );
        if name == "african_mahogany" {
            goal_line(all, c, c1);
        }
        if args.breakdown {
            breakdown(volume.params(), &points)?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Issue 4's speed goals for the mahogany preset: the full model at ≥ 1 M texels/s per core, colour
/// alone at ≥ 3× that (3 M); colour is timed in batches and point by point.
fn goal_line(all: f64, colour_batch: f64, colour_point: f64) {
    let verdict = |ok: bool| if ok { "met" } else { "not met" };
    println!(
        "|   goals: everything ≥ 1 M/s {}; colour ≥ 3 M/s {} in batches, {} point by point | | | | | |",
        verdict(all >= 1e6),
        verdict(colour_batch >= 3e6),
        verdict(colour_point >= 3e6),
    );
}

/// The presets named by `--only`, or all.
fn selected(only: &[String]) -> Vec<&str> {
    if only.is_empty() {
        wood::PRESET_NAMES.to_vec()
    } else {
        only.iter().map(String::as_str).collect()
    }
}

/// `passes` untimed passes of every level of `needs` (for instruction counting).
fn fixed_passes(args: &Args, points: &[Vec3], passes: usize) -> anyhow::Result<ExitCode> {
    let names = selected(&args.only);
    for name in names {
        let volume = WoodVolume::new(wood::preset(name)?, 1)?;
        let levels = [
            ("colour", "colour", Needs::COLOR),
            ("fibres", "colour + fibres", Needs::COLOR_FIBERS),
            ("all", "everything", Needs::ALL),
        ];
        if let Some(bad) = args
            .needs
            .as_deref()
            .filter(|n| !levels.iter().any(|l| l.0 == *n))
        {
            anyhow::bail!("--needs {bad}: expected colour, fibres or all");
        }
        let wanted = |key: &str| args.needs.as_deref().is_none_or(|n| n == key);
        for (_, label, needs) in levels.into_iter().filter(|l| wanted(l.0)) {
            let mut sink = 0.0f32;
            let mut bits = Fingerprint::default();
            let mut out = vec![wood::WoodTexel::default(); points.len()];
            for _ in 0..passes {
                if args.per_point {
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
            println!(
                "{name} {label}: {} texels, checksum {sink:.6e}, bits {:016x}",
                passes * points.len(),
                bits.0
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Colour-only and full-model speed with each feature switched off in turn: the saving is that
/// feature's cost.
fn breakdown(params: &wood::WoodParams, points: &[Vec3]) -> anyhow::Result<()> {
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
        println!("|   {label} | {:.2} | | | {:.2} | |", c / 1e6, all / 1e6);
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
