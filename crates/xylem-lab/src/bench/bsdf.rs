//! The BSDF benchmark behind `xylem bench bsdf`: nanoseconds per call of WoodBsdf construction,
//! eval, pdf and sample on one thread (the workload of crates/xylem-lab/benches/bsdf.rs, timed
//! with a plain loop: median of 7 runs).

use std::hint::black_box;
use std::time::Instant;
use xylem::bsdf::{workload, Bsdf, BsdfError, WoodBsdf};

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

/// One workload case's median nanoseconds per call.
#[derive(Clone, Debug)]
pub struct BsdfTimes {
    /// The case's name ([`workload::cases`]).
    pub case: &'static str,
    /// `WoodBsdf::new`.
    pub new: f64,
    /// `eval`.
    pub eval: f64,
    /// `pdf`.
    pub pdf: f64,
    /// `sample`.
    pub sample: f64,
}

/// Times every workload case with `calls` calls per run (at least 1000; construction a quarter
/// of that), handing each case's times to `each` as soon as they are measured.
pub fn time_cases(calls: u32, mut each: impl FnMut(&BsdfTimes)) -> Result<(), BsdfError> {
    let (dirs, us) = workload::inputs();
    for (name, p) in workload::cases() {
        let b = WoodBsdf::new(p)?;
        let n = calls.max(1000);
        let times = BsdfTimes {
            case: name,
            new: time(n / 4, |_| match WoodBsdf::new(black_box(p)) {
                Ok(b) => b.params().eta,
                Err(_) => 0.0,
            }),
            eval: time(n, |i| b.eval(black_box(dirs[i].0), black_box(dirs[i].1)).x),
            pdf: time(n, |i| b.pdf(black_box(dirs[i].0), black_box(dirs[i].1))),
            sample: time(n, |i| {
                b.sample(black_box(dirs[i].0), black_box(us[i].0), black_box(us[i].1))
                    .map_or(0.0, |s| s.pdf)
            }),
        };
        each(&times);
    }
    Ok(())
}
