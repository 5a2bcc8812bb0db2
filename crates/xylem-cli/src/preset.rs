//! `xylem preset`: the built-in species presets.

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem::picture::png::write_png_linear;
use xylem::scene::Overrides;
use xylem::texture::{Plane, Slice, DEFAULT_SLICE_SAMPLES};
use xylem::wood;
use xylem::wood::{preview_color, Needs};

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    what: What,
}

#[derive(clap::Subcommand, Debug)]
enum What {
    /// List the built-in presets and the features each one switches on.
    List,
    /// Print a preset's TOML (a starting point for `--preset-file`).
    Show { name: String },
    /// Write each preset's three cuts (transverse xy, radial xz, tangential yz) as PNGs, plus a
    /// contact sheet of all of them.
    Cuts {
        /// Output folder.
        #[arg(long, default_value = "out/presets")]
        out: PathBuf,
        /// Image side in pixels.
        #[arg(long, default_value_t = 192)]
        res: u32,
        /// Side of each cut in mm.
        #[arg(long, default_value_t = 100.0)]
        size: f32,
        /// Only these presets (default: all).
        #[arg(long)]
        only: Vec<String>,
        /// Plain diffuse colour instead of shading by fibre direction.
        #[arg(long)]
        flat: bool,
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Render each preset on the README's board (scenes/sweep_board.toml: its camera, light and
    /// finish) at three light angles along the grain: `NAME.png` per preset and `gallery.png`.
    Gallery {
        /// Output folder.
        #[arg(long, default_value = "out/gallery")]
        out: PathBuf,
        /// Frame size WxH in pixels.
        #[arg(long, default_value = "480x240", value_parser = super::render::parse_res)]
        res: (u32, u32),
        /// Samples per pixel.
        #[arg(long, default_value_t = 16)]
        spp: u32,
        /// Light angles from the zenith along the grain, degrees (the sweep's arc).
        #[arg(long, num_args = 1.., default_values_t = [-40.0, 0.0, 40.0], allow_negative_numbers = true)]
        angles: Vec<f32>,
        /// Only these presets (default: all).
        #[arg(long)]
        only: Vec<String>,
        /// Read each preset from DIR/<name>.toml instead of the built-in one (iterate on a
        /// preset without recompiling).
        #[arg(long, value_name = "DIR")]
        presets: Option<PathBuf>,
    },
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.what {
        What::List => {
            for name in wood::PRESET_NAMES {
                let p = wood::preset(name).with_context(|| format!("preset {name}"))?;
                println!("{name:<24} {}", features(&p).join(", "));
            }
        }
        What::Show { name } => print!("{}", wood::preset_text(&name)?),
        What::Cuts {
            out,
            res,
            size,
            only,
            flat,
            seed,
        } => cuts(&out, res, size, &only, !flat, seed)?,
        What::Gallery {
            out,
            res,
            spp,
            angles,
            only,
            presets,
        } => {
            let o = Overrides {
                spp: Some(spp),
                ..Default::default()
            };
            gallery(&out, res, &o, &angles, &only, presets.as_deref())?
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The model features a preset switches on, in words.
fn features(p: &wood::WoodParams) -> Vec<&'static str> {
    let d = &p.distortion;
    [
        (p.growth.is_some(), "growth variation"),
        (p.interlock.is_some(), "interlocked grain"),
        (d.radial.is_some(), "r-distortion"),
        (d.tangential.is_some(), "θ-distortion"),
        (d.longitudinal.is_some(), "z-distortion"),
        (
            p.pores.as_ref().is_some_and(|x| x.ring_porosity >= 0.75),
            "ring-porous",
        ),
        (
            p.pores
                .as_ref()
                .is_some_and(|x| x.ring_porosity > 0.25 && x.ring_porosity < 0.75),
            "semi-ring-porous",
        ),
        (
            p.pores.as_ref().is_some_and(|x| x.ring_porosity <= 0.25),
            "diffuse-porous",
        ),
        (p.rays.is_some(), "rays"),
        (p.knots.is_some(), "knots"),
    ]
    .into_iter()
    .filter_map(|(on, name)| on.then_some(name))
    .collect()
}

/// The three cuts of each preset (transverse at z = 0, radial through the pith, tangential `size`
/// mm from the pith), one PNG per cut, and `sheet.png` (rows: presets; columns: xy, xz, yz).
fn cuts(
    out: &Path,
    res: u32,
    size: f32,
    only: &[String],
    shade: bool,
    seed: u64,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let names: Vec<&str> = if only.is_empty() {
        wood::PRESET_NAMES.to_vec()
    } else {
        only.iter().map(String::as_str).collect()
    };
    let bar = indicatif::ProgressBar::new(3 * names.len() as u64);
    let mut sheet = vec![glam::Vec3::ZERO; (3 * res * res) as usize * names.len()];
    for (row, name) in names.iter().enumerate() {
        let volume = wood::WoodVolume::new(wood::preset(name)?, seed)?;
        let cuts = [
            (Plane::Xy, "xy", 0.0, glam::Vec3::Z),
            (Plane::Xz, "xz", 0.0, glam::Vec3::Y),
            (Plane::Yz, "yz", size, glam::Vec3::X),
        ];
        for (col, (plane, tag, offset, view)) in cuts.into_iter().enumerate() {
            let slice = Slice {
                plane,
                offset,
                size,
                res,
                samples: DEFAULT_SLICE_SAMPLES,
            };
            let needs = if shade {
                Needs::COLOR_FIBERS
            } else {
                Needs::COLOR
            };
            let px = slice.render_rows(&|p, o| {
                let mut texels = vec![xylem::wood::WoodTexel::default(); p.len()];
                volume.eval_many(p, needs, &mut texels);
                for (o, t) in o.iter_mut().zip(&texels) {
                    *o = preview_color(t, view, shade);
                }
            });
            let path = out.join(format!("{name}_{tag}.png"));
            write_png_linear(&path, res, res, &px, 0.0)
                .with_context(|| format!("writing {}", path.display()))?;
            for j in 0..res {
                let dst = ((row as u32 * res + j) * 3 * res + col as u32 * res) as usize;
                let src = (j * res) as usize;
                sheet[dst..dst + res as usize].copy_from_slice(&px[src..src + res as usize]);
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let path = out.join("sheet.png");
    write_png_linear(&path, 3 * res, res * names.len() as u32, &sheet, 0.0)
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {} cuts and {}", 3 * names.len(), path.display());
    Ok(())
}

/// The README board scene, the gallery renders every preset on.
const GALLERY_SCENE: &str = "scenes/sweep_board.toml";
/// The gallery's camera: 65° above the board, 330 mm from it, the board filling a 2:1 frame.
const GALLERY_EYE: [f32; 3] = [0.0, -140.0, 300.0];
const GALLERY_FOV_DEG: f64 = 24.0;

/// Each preset on [`GALLERY_SCENE`] with only the board's preset, the frame size and the spp
/// changed; the light moves along the scene's own sweep arc to each of `angles`. One row of
/// frames per preset, one exposure for all, so the presets' brightness compares directly.
pub(super) fn gallery(
    out: &Path,
    (width, height): (u32, u32),
    o: &Overrides,
    angles: &[f32],
    only: &[String],
    presets: Option<&Path>,
) -> anyhow::Result<()> {
    use xylem::picture::contact::contact_sheet_rows;
    use xylem::picture::srgb::to_srgb8;
    use xylem::picture::Rgb8;
    use xylem::sweep::{render_sweep, SweepPath};
    let bar = super::progress::Bar::new(true);
    if angles.is_empty() || angles.iter().any(|a| !(-89.0..=89.0).contains(a)) {
        anyhow::bail!("--angles: each light angle must lie in [-89, 89] degrees");
    }
    let names: Vec<&str> = if only.is_empty() {
        wood::PRESET_NAMES.to_vec()
    } else {
        only.iter().map(String::as_str).collect()
    };
    for name in &names {
        wood::preset(name)?;
    }
    // The scene resolves a relative `preset_file` against its own folder: make DIR absolute.
    let presets = presets
        .map(std::path::absolute)
        .transpose()
        .context("--presets")?;
    let presets = presets.as_deref();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let board = board_table()?;
    let (mut thumbs, mut labels) = (Vec::new(), Vec::new());
    for name in &names {
        let mut loaded = preset_board_with(
            &board,
            name,
            presets,
            (width, height),
            xylem::scene::DEFAULT_SPP,
            GALLERY_EYE,
            GALLERY_FOV_DEG,
        )?;
        o.apply(&mut loaded)?;
        let mut row = Vec::new();
        for &angle in angles {
            let (path, moving) = SweepPath::from_scene(&loaded, Some(1), Some((angle, angle)))?;
            let r = render_sweep(
                &loaded.scene,
                &loaded.settings,
                &path,
                moving,
                0..1,
                &xylem::render::RunOptions {
                    threads: 0,
                    progress: &bar,
                },
            )?;
            let exposure = loaded.exposure;
            row.push(Rgb8 {
                width,
                height,
                data: to_srgb8(&r.frames[0].beauty, exposure),
            });
            labels.push(format!("{name} {angle:+.0}°"));
        }
        let sheet = contact_sheet_rows(&row, &labels[labels.len() - row.len()..], row.len(), 4);
        sheet.write_png(&out.join(format!("{name}.png")))?;
        thumbs.extend(row);
    }
    let sheet = contact_sheet_rows(&thumbs, &labels, angles.len(), 4);
    let path = out.join("gallery.png");
    sheet.write_png(&path)?;
    println!("wrote {} presets and {}", names.len(), path.display());
    Ok(())
}

/// The README board scene ([`GALLERY_SCENE`]) as a TOML table, without its sweep's measurement
/// regions (they are in pixels of the scene's own frame size).
pub(super) fn board_table() -> anyhow::Result<toml::Table> {
    // From disk, or the built-in copy (`xylem::builtin`).
    let (text, _) = xylem::scene::source_text(Path::new(GALLERY_SCENE))?;
    let mut scene: toml::Table = text
        .parse()
        .with_context(|| format!("parsing {GALLERY_SCENE}"))?;
    if let Some(sweep) = scene.get_mut("sweep").and_then(|s| s.as_table_mut()) {
        sweep.remove("regions");
    }
    Ok(scene)
}

/// Preset `name` on the board of `scene` ([`board_table`]), with only the board's preset and cut
/// (its showcase cut, `wood::showcase_ring_angle_deg`), the frame size, spp and camera changed.
pub(super) fn preset_board(
    scene: &toml::Table,
    name: &str,
    res: (u32, u32),
    spp: u32,
    eye: [f32; 3],
    fov_deg: f64,
) -> anyhow::Result<xylem::scene::LoadedScene> {
    preset_board_with(scene, name, None, res, spp, eye, fov_deg)
}

/// [`preset_board`] with the preset read from `presets`/`name`.toml when `presets` is given.
fn preset_board_with(
    scene: &toml::Table,
    name: &str,
    presets: Option<&Path>,
    (width, height): (u32, u32),
    spp: u32,
    eye: [f32; 3],
    fov_deg: f64,
) -> anyhow::Result<xylem::scene::LoadedScene> {
    let mut scene = scene.clone();
    let set = |t: &mut toml::Table, path: &[&str], v: toml::Value| {
        let (last, tables) = path.split_last().unwrap();
        let mut at = t;
        for k in tables {
            at = at.get_mut(*k).and_then(|v| v.as_table_mut()).unwrap();
        }
        at.insert(last.to_string(), v);
    };
    match presets {
        Some(dir) => {
            let file = dir.join(format!("{name}.toml"));
            let board = scene
                .get_mut("materials")
                .and_then(|m| m.get_mut("board"))
                .and_then(|b| b.as_table_mut())
                .context("the gallery scene has no material `board`")?;
            board.remove("preset");
            board.insert("preset_file".into(), file.display().to_string().into());
        }
        None => set(&mut scene, &["materials", "board", "preset"], name.into()),
    }
    set(&mut scene, &["render", "width"], i64::from(width).into());
    set(&mut scene, &["render", "height"], i64::from(height).into());
    set(&mut scene, &["render", "spp"], i64::from(spp).into());
    set(
        &mut scene,
        &["camera", "eye"],
        eye.map(f64::from).to_vec().into(),
    );
    set(&mut scene, &["camera", "fov_deg"], fov_deg.into());
    let board = scene["objects"]
        .as_array_mut()
        .and_then(|o| {
            o.iter_mut()
                .find(|o| o.get("name").and_then(|n| n.as_str()) == Some("board"))
        })
        .and_then(|o| o.as_table_mut())
        .context("the gallery scene has no object named `board`")?;
    // The face's true cut: flat- or quartersawn as the species shows its figure.
    let cut = xylem::material::SawnCut::showcase_board(wood::showcase_ring_angle_deg(name));
    let tree: toml::Table = format!("tree = {}", cut.tree_toml()).parse()?;
    let tree = tree["tree"].clone();
    board.insert("tree".into(), tree);
    Ok(xylem::scene::from_str(
        &toml::to_string(&scene)?,
        GALLERY_SCENE,
        Path::new("scenes"),
        name,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every gallery board's top face lies where its cut says: `SHOWCASE_PITH_DISTANCE_MM` (at
    /// least 100 mm) from the pith, tangential to the rings for the flat-sawn presets and radial
    /// for the quartersawn. The gallery once placed its "flat-sawn" boards on the pith axis,
    /// shifted along it (the face 9 mm from the pith).
    #[test]
    fn gallery_boards_are_cut_where_they_say() {
        let board = board_table().unwrap();
        for name in wood::PRESET_NAMES {
            let loaded =
                preset_board(&board, name, (64, 32), 1, GALLERY_EYE, GALLERY_FOV_DEG).unwrap();
            let inst = loaded
                .scene
                .accel
                .instances
                .iter()
                .find(|i| {
                    matches!(
                        loaded.scene.materials[i.material as usize],
                        xylem::material::Material::Wood(_)
                    )
                })
                .expect("the board");
            let at = inst
                .placement
                .cut_at(glam::Vec3::new(0.0, 0.0, 9.0), glam::Vec3::Z);
            assert!(at.pith_distance >= 100.0, "{name}: {at:?}");
            let want = wood::showcase_ring_angle_deg(name);
            assert!((at.ring_angle_deg - want).abs() < 1.0, "{name}: {at:?}");
        }
    }
}
