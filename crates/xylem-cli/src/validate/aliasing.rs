//! `xylem validate aliasing`: the wood scenes with and without the footprint filter, and with
//! `--baseline BIN` the default issue 28 was filed against, against a converged reference →
//! validation/ALIASING.md (aliasing energy with standard errors and ratio intervals; issue 28).
//! Exits non-zero when the goal is not met on every scene.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem_lab::aliasing::{measure, report_md, Design};

/// The built-in scenes with procedural wood, judged by default.
const SCENES: [&str; 9] = [
    "sweep_board",
    "parquet_floor",
    "box_joint",
    "dovetail",
    "cube_carved_vs_veneer",
    "carved_bunny",
    "turned_bowl",
    "teapot",
    "grazing_oak",
];
const DIVISOR: u32 = 4;
const REFERENCE_SPP: u32 = 256;
const RENDERS: u32 = 8;
const PARTS: u32 = 8;

#[derive(clap::Args, Debug, Default)]
pub struct Args {
    /// Report to write [default: validation/ALIASING.md]; a reduced run (other scenes, divisor,
    /// reference spp or renders) must name it.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Only these built-in scenes (file stems) [default: every scene with procedural wood].
    #[arg(long)]
    scene: Vec<String>,
    /// Render at 1/N of each scene's size, 1 to 16 [default: 4].
    #[arg(long)]
    div: Option<u32>,
    /// Samples per pixel of the reference (8 independent parts), at least 4× the scene's
    /// [default: 256].
    #[arg(long)]
    reference_spp: Option<u32>,
    /// Renders of each setting, seeds of their own, 3 to 64 [default: 8].
    #[arg(long)]
    renders: Option<u32>,
    /// Another `xylem` binary rendering the issue-time default, judged against: independent
    /// samples, point-sampled wood (the build of 5a8ffa9^ = 2934293, run with
    /// `--footprint-filter off`); without it the goal is judged against today's samples
    /// point-sampled.
    #[arg(long)]
    baseline: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let div = args.div.unwrap_or(DIVISOR);
    anyhow::ensure!((1..=16).contains(&div), "--div {div}: allowed 1 to 16");
    let reference_spp = args.reference_spp.unwrap_or(REFERENCE_SPP);
    let scenes: Vec<String> = if args.scene.is_empty() {
        SCENES.iter().map(|s| s.to_string()).collect()
    } else {
        args.scene.clone()
    };
    let renders = args.renders.unwrap_or(RENDERS);
    anyhow::ensure!(
        (3..=64).contains(&renders),
        "--renders {renders}: allowed 3 to 64"
    );
    let reduced = (div != DIVISOR
        || reference_spp != REFERENCE_SPP
        || renders != RENDERS
        || !args.scene.is_empty())
    .then(|| "a run with --scene, --div, --reference-spp or --renders".to_string());
    let design = Design {
        renders,
        parts: PARTS,
        reference_spp,
    };
    let report = crate::output_path(args.report, "validation/ALIASING.md", "--report", reduced)?;
    if let Some(dir) = report.parent().filter(|d| !d.as_os_str().is_empty()) {
        use anyhow::Context;
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let run = xylem::render::RunOptions::default();
    let bar = crate::progress::Steps::new("validate aliasing", scenes.len() as u64, "scenes");
    let mut rows = Vec::new();
    for name in &scenes {
        bar.step(name);
        let path = Path::new("scenes").join(format!("{name}.toml"));
        let probe = xylem::scene::load(&path)?;
        let spp = probe.settings.spp;
        anyhow::ensure!(
            reference_spp >= 4 * spp,
            "--reference-spp {reference_spp}: at least 4× {name}'s {spp} spp"
        );
        let (w, h) = (probe.scene.camera.width, probe.scene.camera.height);
        drop(probe);
        let size = ((w / div).max(8), (h / div).max(8));
        let base = || -> Result<xylem::scene::LoadedScene, String> {
            let mut l = xylem::scene::load(&path).map_err(|e| e.to_string())?;
            l.scene.camera = l.scene.camera.with_resolution(size.0, size.1);
            Ok(l)
        };
        let row = measure(
            name,
            &base,
            size,
            spp,
            design,
            args.baseline.as_deref(),
            &run,
        );
        rows.push(row.map_err(anyhow::Error::msg)?);
    }
    bar.finish();
    let command = report_command(std::env::args());
    let (md, checks) = report_md(&rows, &command);
    super::finish_report(&report, &md, &checks)
}

/// The command line as the report prints it: the program as `xylem` and the baseline binary as
/// `BIN`, so a report names no path of the machine it ran on.
fn report_command(args: impl Iterator<Item = String>) -> String {
    let mut out = Vec::new();
    let mut after_baseline = false;
    for (i, a) in args.enumerate() {
        out.push(match () {
            _ if i == 0 => "xylem".to_string(),
            _ if after_baseline => "BIN".to_string(),
            _ if a.starts_with("--baseline=") => "--baseline=BIN".to_string(),
            _ => a.clone(),
        });
        after_baseline = a == "--baseline";
    }
    out.join(" ")
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_report_names_no_machine_path() {
        let args = [
            "/opt/x/xylem",
            "validate",
            "aliasing",
            "--baseline",
            "/opt/base",
            "--div",
            "4",
        ];
        let line = super::report_command(args.iter().map(|s| s.to_string()));
        assert_eq!(line, "xylem validate aliasing --baseline BIN --div 4");
        let eq = super::report_command(["a", "--baseline=/x/y"].iter().map(|s| s.to_string()));
        assert_eq!(eq, "xylem --baseline=BIN");
    }
}
