//! `xylem bench wood`: wood texels per second per core for each preset, colour only and the full
//! model ([`xylem_lab::bench::wood`]; the speed goal of issue 4).

use std::process::ExitCode;
use xylem::wood::{self, WoodVolume};
use xylem_lab::bench::wood::{
    breakdown, fixed_passes, goal_line, preset_speed, selected, GOAL_PRESET,
};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Points per pass (passes repeat until one CPU second is spent).
    #[arg(long, default_value_t = 20_000)]
    texels: usize,
    /// Only these presets (default: all).
    #[arg(long)]
    only: Vec<String>,
    /// Also time each preset with one feature switched off at a time (colour and full model).
    #[arg(long)]
    breakdown: bool,
    /// Run exactly this many passes per level of `needs` instead of timing (a fixed workload for
    /// instruction counts: `valgrind --tool=callgrind xylem bench wood --passes 1 ...`).
    #[arg(long)]
    passes: Option<usize>,
    /// With `--passes`: evaluate point by point (`eval`) instead of in batches (`eval_many`).
    #[arg(long)]
    per_point: bool,
    /// With `--passes`: only this level of `needs` (colour, fibres or all; default: the three).
    #[arg(long)]
    needs: Option<String>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let points = wood::sample_points(args.texels, 42);
    if let Some(passes) = args.passes {
        for name in selected(&args.only) {
            let needs = args.needs.as_deref();
            for line in fixed_passes(name, &points, passes, needs, args.per_point)? {
                println!("{line}");
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    println!(
        "| preset | colour (M texels/s) | colour, per point | colour + fibres | everything | \
         colour / everything |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    for name in selected(&args.only) {
        let volume = WoodVolume::new(wood::preset(name)?, 1)?;
        let s = preset_speed(&volume, &points);
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1}× |",
            s.colour_batch / 1e6,
            s.colour_point / 1e6,
            s.colour_fibres / 1e6,
            s.everything / 1e6,
            s.colour_batch / s.everything
        );
        if name == GOAL_PRESET {
            println!("{}", goal_line(&s));
        }
        if args.breakdown {
            breakdown(volume.params(), &points, |label, c, all| {
                println!("|   {label} | {:.2} | | | {:.2} | |", c / 1e6, all / 1e6);
            })?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
