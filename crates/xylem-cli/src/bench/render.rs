//! `xylem bench render`: xylem against Mitsuba 3 on a Cornell box (Lambertian, or with a mirror
//! and a glass sphere) or a wood board, renders timed interleaved, both scored against one
//! Mitsuba reference ([`xylem_lab::bench::render`]).

use std::path::PathBuf;
use std::process::ExitCode;
use xylem_lab::bench::render::{run as bench, RenderBench, CASES};
use xylem_lab::tradeoff::median_range;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene both render: `cornell_box` (Lambertian), `cornell_spheres` (a mirror and a
    /// glass sphere in the box) or `wood_board` (sweep_board's board under a rect light;
    /// Mitsuba through the `xylem_wood` plugin), written as a xylem scene file by Mitsuba's
    /// timing process.
    #[arg(long, default_value = "cornell_box", value_parser = CASES)]
    case: String,
    /// Time xylem alone (with --no-mitsuba) on this scene (a file, or a built-in scene's name).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Samples per pixel of each timed render (both renderers).
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Render threads (xylem) and Dr.Jit worker threads (Mitsuba).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Samples per pixel of the Mitsuba reference (made once, cached in target/crosscheck/timing).
    #[arg(long, default_value_t = 2048)]
    reference_spp: u32,
    /// Python with Mitsuba 3 (default: $XYLEM_PYTHON, else the test suite's
    /// target/python-venv/bin/python).
    #[arg(long)]
    python: Option<PathBuf>,
    /// Only time xylem.
    #[arg(long)]
    no_mitsuba: bool,
    /// Timed renders of each renderer, 1 to 100, interleaved.
    #[arg(long, default_value_t = 5)]
    repeats: u32,
    /// Mitsuba's sampler for the timed renders: `independent` (its default) or one of its
    /// stratified ones (`multijitter`, `orthogonal`, `ldsampler`, `stratified`), to compare
    /// with xylem's Owen-scrambled Sobol samples like with like.
    #[arg(long, default_value = "independent", value_parser = ["independent", "multijitter", "orthogonal", "ldsampler", "stratified"])]
    mitsuba_sampler: String,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let t = bench(&RenderBench {
        case: args.case,
        scene: args.scene,
        spp: args.spp,
        threads: args.threads,
        reference_spp: args.reference_spp,
        python: args.python,
        no_mitsuba: args.no_mitsuba,
        repeats: args.repeats,
        mitsuba_sampler: args.mitsuba_sampler,
    })?;
    if let Some(why) = &t.mitsuba_skipped {
        println!("Mitsuba skipped: {why}");
    }
    let samples = t.width as f64 * t.height as f64 * args.spp as f64;
    let (median, lo, hi) = median_range(&t.xylem_s);
    println!(
        "xylem {}: {}x{}, {} spp, {}, {} threads: {:.3} s (median of {}, {:.3}-{:.3}), {:.3} M samples/s",
        t.name,
        t.width,
        t.height,
        args.spp,
        t.integrator,
        args.threads,
        median,
        args.repeats,
        lo,
        hi,
        samples / median / 1e6
    );
    let Some(table) = &t.mitsuba_table else {
        return Ok(ExitCode::SUCCESS);
    };
    let (m_median, m_lo, m_hi) = median_range(&t.mitsuba_s);
    println!(
        "Mitsuba: {m_median:.3} s (median of {}, {m_lo:.3}-{m_hi:.3}), interleaved with xylem's",
        args.repeats
    );
    print!("{table}");
    Ok(ExitCode::SUCCESS)
}
