//! `xylem validate sweep`: the light-sweep checks; rewrites the sweep section of
//! validation/REPORT.md (with plots) and optionally writes every number as JSON. Exits non-zero
//! when a check fails.

use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;
use xylem_lab::sweep::{run_checks, to_markdown};

#[derive(clap::Args, Debug, Default)]
pub struct Args {
    /// Report to update (only its sweep section) [default: validation/REPORT.md].
    #[arg(long)]
    report: Option<PathBuf>,
    /// Also write every measured number as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Do not touch the report or write plots.
    #[arg(long)]
    no_report: bool,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let report = args
        .report
        .unwrap_or_else(|| PathBuf::from("validation/REPORT.md"));
    let dir = report.parent().map(|p| p.to_path_buf()).unwrap_or_default();
    let run = xylem::render::RunOptions::default();
    let bar = crate::progress::Steps::new("validate sweep", 6, "checks");
    let plots = (!args.no_report).then_some(dir.as_path());
    let checks = run_checks(plots, &run, &|name| bar.step(name))?;
    bar.finish();
    let verdicts: Vec<_> = checks.iter().map(|c| c.verdict.clone()).collect();
    print!("{}", xylem_lab::report::checks_text(&verdicts));
    for c in &checks {
        println!("{}: {}", c.verdict.check, c.figure);
    }
    if !args.no_report {
        xylem_lab::update_report_section(&report, "sweep", &to_markdown(&checks))
            .with_context(|| format!("writing {}", report.display()))?;
        println!("report: {}", report.display());
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&checks)?;
        xylem::output::write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(if xylem_lab::report::all_passed(&verdicts) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
