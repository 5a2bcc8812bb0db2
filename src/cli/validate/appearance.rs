//! `xylem validate appearance`: presets against Marschner et al. 2005's measured boards and the
//! white-light ring-order check; writes validation/APPEARANCE.md with its plots and side-by-side
//! sweep frames. Exits non-zero when a stated criterion fails.

use crate::validate::appearance::{run_report, SweepSettings};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args, Debug, Default)]
pub struct Args {
    /// Report to write [default: validation/APPEARANCE.md]; plots go beside it in plots/.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Read the compared presets from DIR/NAME.toml instead of the built-in ones (calibration).
    #[arg(long, value_name = "DIR")]
    presets: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let report = args
        .report
        .unwrap_or_else(|| PathBuf::from("validation/APPEARANCE.md"));
    let dir = report.parent().map(Path::to_path_buf).unwrap_or_default();
    let bar = indicatif::ProgressBar::new(4).with_style(
        indicatif::ProgressStyle::with_template("validate appearance {bar:40} {pos}/{len} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let (md, ok) = run_report(
        Path::new("."),
        args.presets.as_deref(),
        &dir,
        SweepSettings::FULL,
        &|name| {
            bar.set_message(name.to_string());
            bar.inc(1);
        },
    )
    .map_err(anyhow::Error::msg)?;
    bar.finish_and_clear();
    super::finish_report(&report, &md, ok)
}
