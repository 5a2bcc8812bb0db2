//! `xylem validate appearance`: presets against measured boards (Marschner et al. 2005's, built
//! in, or any board in the same encoding with `--board`), the white-light ring-order check and
//! the sheet of every preset on true cuts; writes a report with its plots and side-by-side sweep
//! frames. Exits non-zero when a stated criterion fails.

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem_lab::appearance::{builtin_pairs, detect_board, run_report, Pair, SweepSettings};

#[derive(clap::Args, Debug, Default)]
pub struct Args {
    /// Report to write [default: validation/APPEARANCE.md; with --board, ./appearance/APPEARANCE.md];
    /// plots go beside it in plots/.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Read the compared presets from DIR/NAME.toml instead of the built-in ones (calibration).
    #[arg(long, value_name = "DIR")]
    presets: Option<PathBuf>,
    /// A measured board to compare instead of the built-in pairs: a folder with diffuse.png,
    /// fiber_color.png and fiber_axis.png in the encoding of data/marschner2005/README.md.
    #[arg(long, value_name = "DIR", requires = "preset")]
    board: Option<PathBuf>,
    /// The preset to compare with --board: a built-in name or a preset file (.toml).
    #[arg(long, value_name = "NAME_OR_FILE", requires = "board")]
    preset: Option<String>,
    /// The board's grain direction in its images: x (columns) or y (rows) [default: detected
    /// from the fibre-axis map].
    #[arg(long, requires = "board")]
    grain: Option<Grain>,
    /// The board's cut: flat, quarter, rift, or the face's angle to the rings in degrees
    /// (0–90) [default: detected from the diffuse map's ring lines].
    #[arg(long, requires = "board", value_parser = parse_cut)]
    cut: Option<f32>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum Grain {
    X,
    Y,
}

/// `flat` 0°, `rift` 45°, `quarter` 90°, or a number of degrees in 0–90.
fn parse_cut(s: &str) -> Result<f32, String> {
    match s {
        "flat" => Ok(0.0),
        "rift" => Ok(45.0),
        "quarter" => Ok(90.0),
        _ => match s.parse::<f32>() {
            Ok(v) if (0.0..=90.0).contains(&v) => Ok(v),
            _ => Err(format!(
                "`{s}`: expected flat, rift, quarter or an angle to the rings in 0–90 degrees"
            )),
        },
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (pairs, builtin, default_report) = match (&args.board, &args.preset) {
        (Some(board), Some(preset)) => {
            let detected = detect_board(board)
                .map_err(anyhow::Error::msg)
                .with_context(|| format!("reading the board {}", board.display()))?;
            let pair = Pair {
                preset: preset.clone(),
                measured_dir: board.to_string_lossy().into_owned(),
                grain_along_x: args
                    .grain
                    .map_or(detected.grain_along_x, |g| matches!(g, Grain::X)),
                ring_angle_deg: args.cut.unwrap_or(detected.ring_angle_deg),
            };
            println!(
                "board {}: grain along {} ({}), {} ({})",
                board.display(),
                if pair.grain_along_x { "x" } else { "y" },
                if args.grain.is_some() {
                    "given"
                } else {
                    "detected"
                },
                if pair.ring_angle_deg < 45.0 {
                    "flat-sawn"
                } else {
                    "quartersawn"
                },
                if args.cut.is_some() {
                    "given".to_string()
                } else {
                    format!(
                        "detected: {:.0} % of the face has ring lines over 20° from the grain",
                        100.0 * detected.arch_fraction
                    )
                }
            );
            (vec![pair], false, "appearance/APPEARANCE.md")
        }
        _ => (builtin_pairs(), true, "validation/APPEARANCE.md"),
    };
    let report = args.report.unwrap_or_else(|| PathBuf::from(default_report));
    let dir = report.parent().map(Path::to_path_buf).unwrap_or_default();
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let steps = pairs.len() as u64 + if builtin { 3 } else { 0 };
    let bar = crate::progress::Steps::new("validate appearance", steps, "steps");
    let (md, checks) = run_report(
        Path::new("."),
        args.presets.as_deref(),
        &dir,
        SweepSettings::FULL,
        &pairs,
        builtin,
        &|name| bar.step(name),
    )
    .map_err(anyhow::Error::msg)?;
    bar.finish();
    super::finish_report(&report, &md, &checks)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuts_parse_by_name_and_angle_and_refuse_the_rest() {
        assert_eq!(parse_cut("flat"), Ok(0.0));
        assert_eq!(parse_cut("quarter"), Ok(90.0));
        assert_eq!(parse_cut("30"), Ok(30.0));
        for bad in ["91", "-1", "NaN", "sideways"] {
            assert!(parse_cut(bad).is_err(), "{bad}");
        }
    }
}
