//! `xylem gallery`: the README's images in one command: every built-in scene at its default
//! settings with its subject check (`validate::scenes`), every preset on the README board
//! (`xylem preset gallery`), and a light-sweep close-up (APNG) of each figured preset.

use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use xylem::picture::png::{write_apng, write_png_rgb8};
use xylem::picture::srgb::to_srgb8;
use xylem::picture::Rgb8;
use xylem::render::{render, RunOptions};
use xylem::scene::quality::Quality;
use xylem::scene::Overrides;
use xylem::sweep::{render_sweep, SweepPath};
use xylem_lab::scenes::Expectations;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output folder [default: notes/gallery, where the README's images live]; a reduced run
    /// (`--frames` other than 12) must name it.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Only these parts: scenes, presets, sweeps (default: all three).
    #[arg(long, value_parser = ["scenes", "presets", "sweeps"])]
    only: Vec<String>,
    /// Only these built-in scenes (file stems; default: all but the measured-board sweeps).
    #[arg(long)]
    scene: Vec<String>,
    /// Frames of each sweep close-up, 1 to 1000.
    #[arg(long, default_value_t = FRAMES, value_parser = parse_frames)]
    frames: usize,
    /// Speed/accuracy preset for every render (draft, default, final: spp and wood-model knobs,
    /// validation/TRADEOFF.md) [default: each scene's own settings]; with it the images are
    /// not the README's, so `--out` must be named.
    #[arg(long)]
    quality: Option<Quality>,
}

/// Frames of each sweep close-up in the README's gallery.
const FRAMES: usize = 12;

fn parse_frames(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (1..=1000).contains(&n) => Ok(n),
        _ => Err(format!("`{s}`: allowed 1 to 1000 frames")),
    }
}

/// The built-in scenes the gallery shows (scenes/NAME.toml), hero renders first.
pub const SCENES: [&str; 12] = [
    "cornell_bunny",
    "carved_bunny",
    "dovetail",
    "parquet_floor",
    "cube_carved_vs_veneer",
    "turned_bowl",
    "box_joint",
    "teapot",
    "cornell_wood_marble",
    "cornell_bunny_black",
    "grazing_oak",
    "sweep_board",
];

/// The figured presets, whose figure moves with the light (chatoyance).
const FIGURED: [&str; 4] = [
    "african_mahogany",
    "curly_maple",
    "quilted_maple",
    "birdseye_maple",
];
/// The sweep close-up's camera: 45 mm across at the board's centre from 150 mm above.
const CLOSE_EYE: [f32; 3] = [0.0, -40.0, 150.0];
const CLOSE_FOV_DEG: f64 = 18.0;

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let part = |p: &str| args.only.is_empty() || args.only.iter().any(|o| o == p);
    let reduced = match (args.frames != FRAMES && part("sweeps"), args.quality) {
        (true, _) => Some(format!("--frames {}", args.frames)),
        (false, Some(q)) => Some(format!("--quality {q}")),
        _ => None,
    };
    let o = Overrides {
        quality: args.quality,
        ..Default::default()
    };
    let out = crate::output_path(args.out.clone(), "notes/gallery", "--out", reduced)?;
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let _lock = xylem::output::FolderLock::try_new(&out, xylem::output::LockMode::Exclusive)?;
    let start = Instant::now();
    let mut ok = true;
    if part("scenes") {
        ok &= scenes(&out.join("scenes"), &args.scene, &o)?;
    }
    if part("presets") {
        super::preset::gallery(
            &out.join("presets"),
            (480, 240),
            &o,
            &[-40.0, 0.0, 40.0],
            &[],
            None,
        )?;
    }
    if part("sweeps") {
        sweeps(&out.join("sweeps"), args.frames, &o)?;
    }
    println!("gallery done in {:.0} s", start.elapsed().as_secs_f64());
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// Renders each scene at its defaults to `out/NAME.png`, measures its subject, and writes
/// `out/checks.md` (time and numbers per scene). False when a check fails.
fn scenes(out: &Path, only: &[String], o: &Overrides) -> anyhow::Result<bool> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let names: Vec<&str> = if only.is_empty() {
        SCENES.to_vec()
    } else {
        only.iter().map(String::as_str).collect()
    };
    let mut rows: Vec<(String, String)> = Vec::new();
    let mut ok = true;
    let bar = super::progress::Bar::new(true);
    for name in names {
        let path = PathBuf::from(format!("scenes/{name}.toml"));
        // From disk, or the built-in copy (`xylem::builtin`).
        let (text, _) = xylem::scene::source_text(&path)?;
        let objects: Vec<Option<String>> = xylem::scene::parse(&text, &path.display().to_string())?
            .objects
            .into_iter()
            .map(|o| o.name)
            .collect();
        let mut s = xylem::scene::load(&path)?;
        let expect = Expectations::of(s.expect.as_ref(), &path.display().to_string())
            .map_err(anyhow::Error::msg)?;
        o.apply(&mut s)?;
        let (w, h) = (s.scene.camera.width, s.scene.camera.height);
        eprintln!("{name}: {w}x{h}, {} spp", s.settings.spp);
        let r = render(
            &s.scene,
            &s.settings,
            &RunOptions {
                threads: 0,
                progress: &bar,
            },
        )?;
        let png = out.join(format!("{name}.png"));
        write_png_rgb8(&png, w, h, &to_srgb8(&r.image.beauty, s.exposure))?;
        let run = RunOptions {
            threads: 0,
            progress: &bar,
        };
        let (measures, companion) = xylem_lab::scenes::measure_rendered(
            &expect,
            &s.scene,
            &s.settings,
            &run,
            &objects,
            &r.image,
            s.exposure,
        )?;
        if let (Some(c), Some(kind)) = (companion, expect.companion) {
            // The check's second render (turned_bowl: the key light mirrored along the fibre;
            // cornell_bunny: without its background).
            let label = kind.label();
            let png = out.join(format!("{name}_{label}.png"));
            write_png_rgb8(&png, w, h, &to_srgb8(&c.beauty, s.exposure))?;
        }
        let secs = r.elapsed.as_secs_f64();
        println!("{name}: {secs:.1} s");
        for m in &measures {
            println!("  {m}");
            ok &= m.pass();
        }
        let checks: Vec<String> = measures.iter().map(|m| m.to_string()).collect();
        rows.push((
            name.to_string(),
            format!(
                "| `{name}` | {w}×{h}, {} | {secs:.1} s | {} |",
                s.settings.spp,
                checks.join("; ")
            ),
        ));
    }
    let file = out.join("checks.md");
    // With --scene, the other scenes' rows of an earlier run stay.
    let old = if only.is_empty() {
        String::new()
    } else {
        // A table of a few rows (16 MiB bounds `/dev/zero` and the like).
        xylem::resources::read_text_bounded(&file, 16 << 20, "Markdown text").unwrap_or_default()
    };
    xylem::output::write_atomic(&file, merge_check_rows(&old, &rows).as_bytes())
        .with_context(|| format!("writing {}", file.display()))?;
    Ok(ok)
}

/// The checks table: the rows of `old` (an earlier checks.md; its header and any row that is not
/// a scene's are dropped) with each scene of `rows` replacing its own row in place, and the
/// scenes `old` did not have appended in order.
fn merge_check_rows(old: &str, rows: &[(String, String)]) -> String {
    let mut table = String::from(
        "| scene | size, spp | render time | subject check |\n| --- | --- | --- | --- |\n",
    );
    let scene_of = |line: &str| {
        let rest = line.strip_prefix("| `")?;
        Some(rest[..rest.find('`')?].to_string())
    };
    let mut used = vec![false; rows.len()];
    for line in old.lines() {
        let Some(name) = scene_of(line) else { continue };
        let row = match rows.iter().position(|(n, _)| *n == name) {
            Some(k) => {
                used[k] = true;
                rows[k].1.as_str()
            }
            None => line,
        };
        let _ = writeln!(table, "{row}");
    }
    for ((_, row), used) in rows.iter().zip(used) {
        if !used {
            let _ = writeln!(table, "{row}");
        }
    }
    table
}

/// A light sweep over a close-up of each figured preset on the README board, as a looping APNG
/// (`out/NAME.png`, 12 frames/s), the light moving along the board's own arc (−60° to 60°).
fn sweeps(out: &Path, frames: usize, o: &Overrides) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let board = super::preset::board_table()?;
    let bar = super::progress::Bar::new(true);
    for name in FIGURED {
        let mut loaded =
            super::preset::preset_board(&board, name, (160, 120), 16, CLOSE_EYE, CLOSE_FOV_DEG)?;
        o.apply(&mut loaded)?;
        let (path, moving) = SweepPath::from_scene(&loaded, Some(frames), None)?;
        eprintln!("{name}: {frames} frames");
        let r = render_sweep(
            &loaded.scene,
            &loaded.settings,
            &path,
            moving,
            0..frames,
            &RunOptions {
                threads: 0,
                progress: &bar,
            },
        )?;
        let (w, h) = (loaded.scene.camera.width, loaded.scene.camera.height);
        let images: Vec<Rgb8> = (r.frames.iter())
            .map(|f| Rgb8 {
                width: w,
                height: h,
                data: to_srgb8(&f.beauty, loaded.exposure),
            })
            .collect();
        write_apng(&out.join(format!("{name}.png")), &images, 12)?;
        println!("{name}: sweep close-up written");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::merge_check_rows;

    #[test]
    fn merge_keeps_the_other_scenes_rows() {
        let old =
            "| scene | size, spp | render time | subject check |\n| --- | --- | --- | --- |\n\
                   | `a` | 1×1, 1 | 1.0 s | x |\n| `b` | 1×1, 1 | 2.0 s | y |\n";
        let rows = [
            ("b".to_string(), "| `b` | 2×2, 2 | 3.0 s | z |".to_string()),
            ("c".to_string(), "| `c` | 1×1, 1 | 4.0 s | w |".to_string()),
        ];
        let t = merge_check_rows(old, &rows);
        let body: Vec<&str> = t.lines().skip(2).collect();
        assert_eq!(
            body,
            [
                "| `a` | 1×1, 1 | 1.0 s | x |",
                "| `b` | 2×2, 2 | 3.0 s | z |",
                "| `c` | 1×1, 1 | 4.0 s | w |"
            ]
        );
        // No earlier table: the new rows alone, under the header.
        assert_eq!(merge_check_rows("", &rows).lines().count(), 4);
    }
}
