//! `xylem bench bsdf`: nanoseconds per call of WoodBsdf construction, eval, pdf and sample on one
//! thread (the workload of crates/xylem-lab/benches/bsdf.rs, timed with a plain loop: median of 7 runs).

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;
use xylem::bsdf::{workload, Bsdf, WoodBsdf};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Calls per timed run.
    #[arg(long, default_value_t = 2_000_000)]
    calls: u32,
}

/// Median ns per call of `f` over 7 runs of `calls` calls.
fn time(calls: u32, mut f: impl FnMut(usize) -> f32) -> f64 {
    let mut runs: Vec<f64> = (0..7)
        .map(|_| {
            let t = Instant::now();
            let mut acc = 0.0f32;
            for k in 0..calls as usize {
                acc += f(k & 1023);
            }
            black_box(acc);
            t.elapsed().as_nanos() as f64 / calls as f64
        })
        .collect();
    runs.sort_by(f64::total_cmp);
    runs[3]
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (dirs, us) = workload::inputs();
    let configs = workload::cases();
    println!(
        "{:<10} {:>9} {:>9} {:>9} {:>9}   (ns per call, one thread)",
        "case", "new", "eval", "pdf", "sample"
    );
    for (name, p) in configs {
        let b = WoodBsdf::new(p)?;
        let n = args.calls.max(1000);
        let t_new = time(n / 4, |_| match WoodBsdf::new(black_box(p)) {
            Ok(b) => b.params().eta,
            Err(_) => 0.0,
        });
        let t_eval = time(n, |i| b.eval(black_box(dirs[i].0), black_box(dirs[i].1)).x);
        let t_pdf = time(n, |i| b.pdf(black_box(dirs[i].0), black_box(dirs[i].1)));
        let t_sample = time(n, |i| {
            b.sample(black_box(dirs[i].0), black_box(us[i].0), black_box(us[i].1))
                .map_or(0.0, |s| s.pdf)
        });
        println!("{name:<10} {t_new:>9.1} {t_eval:>9.1} {t_pdf:>9.1} {t_sample:>9.1}");
    }
    Ok(ExitCode::SUCCESS)
}
