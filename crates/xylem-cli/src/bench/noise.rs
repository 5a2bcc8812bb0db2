//! `xylem bench noise`: evaluations per second (one thread) of each noise
//! ([`xylem_lab::bench::noise`]).

use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Points per pass (short passes fit between other jobs' time slices on a shared machine).
    #[arg(long, default_value_t = 256)]
    points: usize,
    /// Passes per function (the best one is reported).
    #[arg(long, default_value_t = 400)]
    passes: usize,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let rows = xylem_lab::bench::noise::rates(args.points, args.passes);
    println!("| function (one thread) | M evals/s |");
    println!("| --- | ---: |");
    for (name, r) in rows {
        println!("| {name} | {r:.2} |");
    }
    println!("\npeers (noise-rs, fastnoise-lite): cargo bench --bench noise");
    Ok(ExitCode::SUCCESS)
}
