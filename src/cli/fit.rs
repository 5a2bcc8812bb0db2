//! `xylem fit SWEEP_DIR --out DIR`: per-texel fibre-BSDF parameters fitted to a light sweep.

use crate::fit::{fit, write_maps, Capture, FitOptions};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Sweep folder: `manifest.json` and the frames it names (`xylem sweep` writes both).
    pub sweep: PathBuf,
    /// Output folder for the maps, residual map and report.
    #[arg(long)]
    pub out: PathBuf,
    /// Map size W×H in texels, each 1 to 8192 (default: the board's size in pixels); refused
    /// when the fit's memory estimate (12 bytes per texel per frame, and more) exceeds what is
    /// available.
    #[arg(long, value_parser = parse_texels)]
    pub texels: Option<(usize, usize)>,
    /// Worker threads (0 = all cores; at most 16 per core).
    #[arg(long, default_value_t = 0, value_parser = super::parse_threads)]
    pub threads: usize,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Parses `W×H` (or `WxH`, or one number for a square map), each 1 to 8192.
fn parse_texels(s: &str) -> Result<(usize, usize), String> {
    let parts: Vec<&str> = s.split(['x', 'X', '×']).collect();
    let num = |p: &str| -> Result<usize, String> {
        let v: usize = p
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: `{p}` is not a whole number"))?;
        if (1..=8192).contains(&v) {
            Ok(v)
        } else {
            Err(format!("`{s}`: {v} texels (allowed 1 to 8192)"))
        }
    };
    match parts.as_slice() {
        [a] => Ok((num(a)?, num(a)?)),
        [a, b] => Ok((num(a)?, num(b)?)),
        _ => Err(format!("`{s}`: expected W×H texels, e.g. 256x128")),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let capture = Capture::open(&args.sweep)?;
    let bar = super::progress::Bar::new(!args.quiet);
    let opts = FitOptions {
        texels: args.texels,
        threads: args.threads,
        progress: &bar,
    };
    let (maps, stats) = fit(&capture, &opts)?;
    let mut res: Vec<f32> = maps.residual.clone();
    res.sort_by(f32::total_cmp);
    let median = res[res.len() / 2];
    let report = serde_json::json!({
        "sweep": args.sweep.display().to_string(),
        "texels": [maps.width, maps.height],
        "frames": stats.frames,
        "arcs_azimuth_deg": capture.arc_azimuths(),
        "eta": capture.board.eta,
        "texels_not_fitted": stats.texels_failed,
        "samples": stats.samples.to_json(),
        "median_relative_residual": median,
        "read_seconds": stats.read_time.as_secs_f64(),
        "fit_seconds": stats.fit_time.as_secs_f64(),
    });
    write_maps(&args.out, &maps, &report)?;
    if 2 * stats.texels_failed > maps.width * maps.height {
        eprintln!(
            "warning: {} of {} texels not fitted (black in the maps, residual 1): {}",
            stats.texels_failed,
            maps.width * maps.height,
            stats.samples.describe(&capture)
        );
    }
    println!(
        "fitted {}x{} texels from {} frames in {:.2} s (+{:.2} s reading); median relative residual {:.4}; {} texels not fitted; maps in {}",
        maps.width,
        maps.height,
        stats.frames,
        stats.fit_time.as_secs_f64(),
        stats.read_time.as_secs_f64(),
        median,
        stats.texels_failed,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
