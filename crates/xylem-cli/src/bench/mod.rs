//! `xylem bench`: the project's benchmarks, one file per subject (each also a criterion bench in crates/xylem-lab/benches/).

use std::process::ExitCode;

mod bsdf;
mod noise;
mod render;
mod trace;
mod wood;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    what: What,
}

#[derive(clap::Subcommand, Debug)]
enum What {
    /// BVH build and closest-hit / any-hit rays per second.
    Trace(trace::Args),
    /// WoodBsdf eval / pdf / sample per call.
    Bsdf(bsdf::Args),
    /// Gradient noise, fBm and sparse convolution noise evaluations per second.
    Noise(noise::Args),
    /// Wood texels per second per preset.
    Wood(wood::Args),
    /// xylem against Mitsuba 3 on the Cornell box: samples/s and RMSE against one reference.
    Render(render::Args),
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.what {
        What::Trace(a) => trace::run(a),
        What::Bsdf(a) => bsdf::run(a),
        What::Noise(a) => noise::run(a),
        What::Wood(a) => wood::run(a),
        What::Render(a) => render::run(a),
    }
}
