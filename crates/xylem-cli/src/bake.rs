//! `xylem bake`: texture maps of a preset over a board's face, and the board as a glTF 2.0
//! binary (`DIR/PRESET.glb`), for other tools.

use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;
use xylem::bake::materialx::stage_materialx;
use xylem::bake::usd::stage_usda;
use xylem::bake::{bake, gltf::stage_glb, stage_maps, BakeCut, BoardCut};
use xylem::output::{commit_set, FolderLock, LockMode};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Species preset (see `xylem preset list`).
    pub preset: String,
    /// Board size W×H×T in mm (length, width, thickness), e.g. 300x120x20.
    #[arg(long, value_parser = parse_board)]
    pub board: [f32; 3],
    /// Which face of the log the board shows.
    #[arg(long, default_value = "tangential")]
    pub cut: BakeCut,
    /// Texels along the board's length, 1 to 16384.
    #[arg(long, default_value_t = 1024)]
    pub res: u32,
    /// Distance of the board's centre from the pith (mm).
    #[arg(long, default_value_t = 150.0)]
    pub radius: f32,
    /// Seed of the tree.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the material as an OpenPBR MaterialX document (`PRESET.mtlx`, with its
    /// specular roughness and anisotropy maps) and the board as a USD stage (`PRESET.usda`)
    /// that binds it (notes/gltf.md, "MaterialX / OpenPBR").
    #[arg(long)]
    pub materialx: bool,
}

/// Parses `W×H×T` (or `WxHxT`), each a positive finite length in mm up to 10 m.
fn parse_board(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<&str> = s.split(['x', 'X', '×']).collect();
    if parts.len() != 3 {
        return Err(format!("`{s}`: expected W×H×T in mm, e.g. 300x120x20"));
    }
    let mut out = [0.0; 3];
    for (o, p) in out.iter_mut().zip(&parts) {
        let v: f32 = p
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: `{p}` is not a number"))?;
        if !(v.is_finite() && v > 0.0 && v <= 10_000.0) {
            return Err(format!(
                "`{s}`: {v} mm is out of range (allowed 0 < size <= 10000)"
            ));
        }
        *o = v;
    }
    Ok(out)
}

/// The record of a bake's outputs, written last: the settings and every file's size and CRC-32.
const BAKE_RECORD: &str = "bake.json";

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        (1..=16384).contains(&args.res),
        "--res {}: allowed 1 to 16384 texels",
        args.res
    );
    anyhow::ensure!(
        args.radius.is_finite() && args.radius >= 0.0,
        "--radius {}: must be a distance >= 0 mm",
        args.radius
    );
    let params = xylem::wood::preset(&args.preset)?;
    let volume = xylem::wood::WoodVolume::new(params, args.seed)
        .with_context(|| format!("preset {}", args.preset))?;
    let board = BoardCut {
        size: args.board,
        cut: args.cut,
        radius: args.radius,
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let maps = bake(&volume, &board, args.res);
    // Every map and the .glb are staged first, then committed as one set whose record
    // `bake.json` comes last (`output::commit_set`): a full disk leaves the previous bake as it
    // was, a kill while committing leaves no `bake.json` and no file of the previous bake.
    let _lock = FolderLock::try_new(&args.out, LockMode::Exclusive)?;
    let mut staged = stage_maps(&args.out, &maps)?;
    let glb = args.out.join(format!("{}.glb", args.preset));
    staged.push(stage_glb(&glb, &board, &maps, &args.preset)?);
    if args.materialx {
        staged.extend(stage_materialx(&args.out, &maps, &args.preset)?);
        let usda = args.out.join(format!("{}.usda", args.preset));
        let mtlx = format!("{}.mtlx", args.preset);
        staged.push(
            stage_usda(&usda, &board, &maps, &args.preset, &mtlx)
                .with_context(|| format!("writing {}", usda.display()))?,
        );
    }
    let mut files: Vec<_> = staged.iter().map(|s| s.path().to_path_buf()).collect();
    let record = serde_json::json!({
        "preset": args.preset,
        "board_mm": args.board,
        "cut": args.cut.to_string(),
        "res": args.res,
        "radius_mm": args.radius,
        "seed": args.seed,
        "materialx": args.materialx,
    });
    let record = record.as_object().cloned().unwrap_or_default();
    files.push(
        commit_set(&args.out, staged, BAKE_RECORD, record)
            .with_context(|| format!("committing the bake in {}", args.out.display()))?,
    );
    println!(
        "baked {} ({} cut, {}x{} texels) into {}:",
        args.preset,
        args.cut,
        maps.width,
        maps.height,
        args.out.display()
    );
    for f in files {
        println!("  {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn board_sizes_parse_and_refuse_nonsense() {
        assert_eq!(parse_board("300x120x20"), Ok([300.0, 120.0, 20.0]));
        assert_eq!(parse_board("300×120×20.5"), Ok([300.0, 120.0, 20.5]));
        for bad in [
            "300x120", "0x1x1", "a x1x1", "1x1x-2", "1x1x1x1", "inf x1x1",
        ] {
            assert!(parse_board(bad).is_err(), "{bad}");
        }
    }
}
