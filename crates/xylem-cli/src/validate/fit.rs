//! `xylem validate fit`: round trips of known boards through sweep and fit; writes
//! validation/FIT.md (or --report) with its plots and figure beside it. Exits non-zero when a goal is missed.

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem_lab::fit::{run_report, SweepSpec};

#[derive(clap::Args, Debug, Default)]
pub struct Args {
    /// Report to write [default: validation/FIT.md]; its plots and the README's figure
    /// (`fit_maple.png`) go beside it in plots/, nothing anywhere else. A reduced run
    /// (`--texels` other than 64) must name it.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Texels along each side of every board, 4 to 390 (default 64, the full validation).
    #[arg(long)]
    texels: Option<usize>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut spec = SweepSpec::full();
    if let Some(n) = args.texels {
        anyhow::ensure!((4..=390).contains(&n), "--texels {n}: allowed 4 to 390");
        spec.texels = n;
    }
    let reduced =
        (spec.texels != SweepSpec::full().texels).then(|| format!("--texels {}", spec.texels));
    let report = crate::output_path(args.report, "validation/FIT.md", "--report", reduced)?;
    let dir = report.parent().map(Path::to_path_buf).unwrap_or_default();
    let work = tempfile::tempdir().context("creating a temporary folder for the captures")?;
    let bar = crate::progress::Steps::new("validate fit", 4, "boards");
    let (md, checks) = run_report(Path::new("."), &dir, work.path(), &spec, &|name| {
        bar.step(name)
    })
    .map_err(anyhow::Error::msg)?;
    bar.finish();
    super::finish_report(&report, &md, &checks)
}
