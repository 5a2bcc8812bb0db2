//! `xylem validate bsdf`: runs the BSDF validation suite over validation/bsdf_cases.toml, prints
//! the table, rewrites the bsdf section of validation/REPORT.md (with polar plots) and optionally
//! writes the full results as JSON. Exits non-zero when a check fails.

use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;
use xylem_lab::bsdf::{load_suite, run_suite, to_markdown, write_polar_plot, BsdfValidation};

#[derive(clap::Args, Debug, Default)]
pub struct Args {
    /// Case file [default: validation/bsdf_cases.toml].
    #[arg(long)]
    cases: Option<PathBuf>,
    /// Report to update (only its bsdf section) [default: validation/REPORT.md].
    #[arg(long)]
    report: Option<PathBuf>,
    /// Also write every measured number as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Divide every sample count by this factor (a quick look; the defaults are the real
    /// check): 1 up to where the chi-square test keeps 10 samples per histogram cell on average
    /// (24 for the committed cases). A reduced run must name its --report (or give --no-report).
    #[arg(long)]
    reduce: Option<u32>,
    /// Do not touch the report or write plots.
    #[arg(long)]
    no_report: bool,
    /// Rebuild the table, report and plots from a JSON file of an earlier run instead of measuring.
    #[arg(long)]
    from_json: Option<PathBuf>,
}

/// The largest `--reduce` at which the chi-square test keeps 10 samples per histogram cell on
/// average (Pearson's statistic is chi-square distributed only with enough per cell; pooling
/// cells under `chi2_min_expected` is not enough below that: measured, a correct sampler failed
/// at 50 with the committed cases and passed at 10 and 20).
fn max_reduce(s: &xylem_lab::bsdf::Settings) -> u32 {
    let cells = 10 * s.chi2_theta_bins as u64 * s.chi2_phi_bins as u64;
    (s.chi2_samples as u64 / cells.max(1)).clamp(1, u32::MAX as u64) as u32
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let cases = args
        .cases
        .unwrap_or_else(|| PathBuf::from("validation/bsdf_cases.toml"));
    let mut suite = load_suite(&cases).context("loading the BSDF validation cases")?;
    let reduce = args.reduce.unwrap_or(1);
    let most = max_reduce(&suite.settings);
    anyhow::ensure!(
        (1..=most).contains(&reduce),
        "--reduce {reduce}: allowed 1 to {most} for {}: the chi-square test needs 10 samples per histogram cell on average (chi2_samples {} / reduce ≥ 10 × {}×{} cells); with fewer its statistic is no longer chi-square distributed and a correct sampler fails (at 50: p = 1.1e-5)",
        cases.display(),
        suite.settings.chi2_samples,
        suite.settings.chi2_theta_bins,
        suite.settings.chi2_phi_bins,
    );
    let reduced = (reduce > 1 && !args.no_report).then(|| format!("--reduce {reduce}"));
    let report = crate::output_path(args.report, "validation/REPORT.md", "--report", reduced)?;
    if let Some(k) = Some(reduce).filter(|&k| k > 1) {
        let s = &mut suite.settings;
        s.furnace_samples = (s.furnace_samples / k).max(1000);
        s.chi2_samples = (s.chi2_samples / k).max(10_000);
        s.reciprocity_pairs = (s.reciprocity_pairs / k).max(100);
        s.extreme_samples = (s.extreme_samples / k).max(100);
        if let Some(r) = &mut suite.rough {
            r.paths = (r.paths / k).max(2000);
        }
    }
    let result: BsdfValidation = if let Some(path) = &args.from_json {
        // A results file: text well under 16 MiB (bounds `/dev/zero` and the like).
        let text = xylem::resources::read_text_bounded(path, 16 << 20, "JSON text")?;
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?
    } else {
        let n = suite.cases.len() as u64;
        let bar = crate::progress::Steps::new("validate bsdf", n, "cases");
        let r = run_suite(&suite, &|| bar.step(""));
        bar.finish();
        r
    };

    print!("{}", xylem_lab::report::checks_text(&result.checks));
    if let Some((a, case)) = &result.published_max_albedo {
        println!("(published lobe, not normalised: max albedo {a:.3} at {case})");
    }

    if !args.no_report {
        let dir = report.parent().map(|p| p.to_path_buf()).unwrap_or_default();
        let mut plots = Vec::new();
        for (k, spec) in suite.cases.iter().filter(|c| c.plot).enumerate() {
            let rel = format!("plots/bsdf_polar_{k}.png");
            write_polar_plot(spec, &dir.join(&rel))
                .with_context(|| format!("writing the polar plot of `{}`", spec.name))?;
            plots.push((spec.name.clone(), rel));
        }
        xylem_lab::update_report_section(&report, "bsdf", &to_markdown(&result, &plots))
            .with_context(|| format!("writing {}", report.display()))?;
        println!("report: {}", report.display());
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&result)?;
        xylem::output::write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(if result.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
