//! `xylem bench bsdf`: nanoseconds per call of WoodBsdf construction, eval, pdf and sample on one
//! thread ([`xylem_lab::bench::bsdf`]).

use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Calls per timed run.
    #[arg(long, default_value_t = 2_000_000)]
    calls: u32,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    println!(
        "{:<10} {:>9} {:>9} {:>9} {:>9}   (ns per call, one thread)",
        "case", "new", "eval", "pdf", "sample"
    );
    xylem_lab::bench::bsdf::time_cases(args.calls, |t| {
        println!(
            "{:<10} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
            t.case, t.new, t.eval, t.pdf, t.sample
        );
    })?;
    Ok(ExitCode::SUCCESS)
}
