//! `xylem sweep`: renders a light sweep (or a slice of one) and assembles its outputs.

use crate::sweep::sequence::{assemble, AssembleOptions};
use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene file (TOML); its `[sweep]` table sets the defaults of the options below.
    #[arg(required_unless_present = "assemble")]
    pub scene: Option<PathBuf>,
    /// Number of frames along the arc.
    #[arg(long)]
    pub frames: Option<usize>,
    /// The arc of light angles from the zenith, FROM..TO in degrees (e.g. -60..60).
    #[arg(long, allow_hyphen_values = true)]
    pub arc: Option<String>,
    /// Output folder (default: out/<scene name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Render only frames A..B (A to B-1) or A..=B, e.g. for a job array; assemble afterwards.
    #[arg(long)]
    pub frames_range: Option<String>,
    /// Assemble contact sheet, animated PNG, CSV and viewer from the frames already in DIR.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "frames", "arc", "frames_range"])]
    pub assemble: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let Some(dir) = &args.assemble {
        return assemble_dir(dir);
    }
    anyhow::bail!(
        "`xylem sweep SCENE` needs the renderer, which has not landed yet; `--assemble DIR` works"
    )
}

/// Assembles a folder of frames and reports what it wrote.
fn assemble_dir(dir: &std::path::Path) -> anyhow::Result<ExitCode> {
    let done = assemble(dir, &AssembleOptions::default())
        .with_context(|| format!("assembling the sweep in {}", dir.display()))?;
    println!("assembled {} frames:", done.frames);
    for f in &done.files {
        println!("  {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}
