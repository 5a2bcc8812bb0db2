//! `xylem validate [bsdf|sweep|appearance|fit|aliasing]`: runs the validation suite; exits non-zero when a check fails.

use std::process::ExitCode;

mod aliasing;
mod appearance;
mod bsdf;
mod fit;
mod sweep;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    what: Option<What>,
}

#[derive(clap::Subcommand, Debug)]
enum What {
    /// The BSDF checks: white furnace, reciprocity, chi-square, pdf normalisation, extremes.
    Bsdf(bsdf::Args),
    /// The light-sweep checks: highlight tracking, renderer against the BSDF, figure signatures.
    Sweep(sweep::Args),
    /// Presets against Marschner 2005's measured boards → validation/APPEARANCE.md.
    Appearance(appearance::Args),
    /// `xylem fit` by round trip on known boards → validation/FIT.md.
    Fit(fit::Args),
    /// The wood scenes with and without the footprint filter, and with `--baseline` against
    /// another binary's default: aliasing energy with standard errors, ratio intervals and error
    /// at equal time → validation/ALIASING.md.
    Aliasing(aliasing::Args),
}

/// Writes a report (staged under a unique temporary name, `output::write_atomic`), prints it
/// and the suite's verdict table, and turns the verdict into the exit code.
fn finish_report(
    report: &std::path::Path,
    md: &str,
    checks: &[xylem_lab::report::Check],
) -> anyhow::Result<ExitCode> {
    use anyhow::Context;
    xylem::output::write_atomic(report, md.as_bytes())
        .with_context(|| format!("writing {}", report.display()))?;
    println!("{md}");
    print!("{}", xylem_lab::report::checks_text(checks));
    println!("report: {}", report.display());
    Ok(if xylem_lab::report::all_passed(checks) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.what {
        Some(What::Bsdf(a)) => bsdf::run(a),
        Some(What::Sweep(a)) => sweep::run(a),
        Some(What::Appearance(a)) => appearance::run(a),
        Some(What::Fit(a)) => fit::run(a),
        Some(What::Aliasing(a)) => aliasing::run(a),
        None => {
            let b = bsdf::run(bsdf::Args::default())?;
            let s = sweep::run(sweep::Args::default())?;
            Ok(if b == ExitCode::SUCCESS && s == ExitCode::SUCCESS {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
    }
}
