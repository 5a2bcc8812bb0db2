//! `xylem bench trace`: BVH build time and closest-hit / any-hit rays per second per core on a
//! ~1M-triangle mesh, for coherent (camera) and incoherent (random) rays
//! ([`xylem_lab::bench::trace`]).

use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;
use xylem_lab::bench::trace::{run_presets, TraceFigures, TraceReport};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Triangles in the test mesh (a bumpy sphere).
    #[arg(long, default_value_t = 1_000_000)]
    triangles: usize,
    /// Rays in each ray set.
    #[arg(long, default_value_t = 1_000_000)]
    rays: usize,
    /// obvhs build preset(s), comma-separated: fastest, very_fast, fast, medium, slow, very_slow.
    #[arg(long, default_value = "medium")]
    build: String,
    /// Also write the figures as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let reports = run_presets(args.triangles, args.rays, &args.build, print)?;
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&reports)?;
        xylem::output::write_atomic(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// One preset's figures.
fn print(r: &TraceReport) {
    let row = |label: &str, f: &TraceFigures| {
        let pairs = f
            .closest_pair_mrays_per_s
            .map(|p| format!("  closest-hit in pairs {p:>7.2} Mrays/s"))
            .unwrap_or_default();
        println!(
            "  {label:<10} {:>9} rays  closest-hit {:>7.2} Mrays/s  any-hit {:>7.2} Mrays/s  ({} hits){pairs}",
            f.rays, f.closest_mrays_per_s, f.any_hit_mrays_per_s, f.closest_hits
        )
    };
    println!(
        "xylem wide BVH (obvhs BVH2 build `{}`): {} triangles, build {:.3} s core / {:.3} s total (all cores); tracing on 1 core:",
        r.build_params, r.triangles, r.build_core_s, r.build_total_s
    );
    row("coherent", &r.coherent);
    row("incoherent", &r.incoherent);
    println!(
        "obvhs CWBVH traversal (same build preset, build {:.3} s core); tracing on 1 core:",
        r.obvhs_cwbvh.build_core_s
    );
    row("coherent", &r.obvhs_cwbvh.coherent);
    row("incoherent", &r.obvhs_cwbvh.incoherent);
    match &r.embree {
        Some(e) => {
            println!(
                "Embree 3 (high-quality build {:.3} s, all cores); tracing on 1 core:",
                e.build_s
            );
            row("coherent", &e.coherent);
            row("incoherent", &e.incoherent);
            println!(
                "  xylem / Embree closest-hit: coherent {:.2}x, incoherent {:.2}x",
                e.closest_ratio_coherent, e.closest_ratio_incoherent
            );
            println!(
                "  xylem in pairs (as the renderer traces) / Embree one at a time: coherent {:.2}x, incoherent {:.2}x",
                e.pair_ratio[0], e.pair_ratio[1]
            );
        }
        None => println!("  (Embree comparison: build with --features embree-anchor)"),
    }
}
