//! `xylem bake`: texture maps of a preset over a board's faces, or over any mesh with a UV
//! layout (`--mesh`), and the board or mesh as a glTF 2.0 binary (`DIR/PRESET.glb`), for other
//! tools.

use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;
use xylem::bake::materialx::stage_materialx;
use xylem::bake::raster::{bake_mesh, Coverage, MeshBake};
use xylem::bake::usd::stage_usda;
use xylem::bake::uv_mesh::{UvMesh, BUILTIN_MESHES};
use xylem::bake::{bake, gltf::stage_glb, stage_maps, BakeCut, BoardCut, PAD_TEXELS};
use xylem::output::{commit_set, FolderLock, LockMode};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Species preset (see `xylem preset list`).
    pub preset: String,
    /// Board size W×H×T in mm (length, width, thickness), e.g. 300x120x20.
    #[arg(long, value_parser = parse_board, required_unless_present = "mesh", conflicts_with = "mesh")]
    pub board: Option<[f32; 3]>,
    /// Bake onto a mesh through its UV layout instead: an .obj with `vt` (mm, z up), or a
    /// built-in shape: `teapot` or `bowl` (the shapes of scenes/teapot.toml and
    /// scenes/turned_bowl.toml, placed in the tree as those scenes place them).
    #[arg(long)]
    pub mesh: Option<String>,
    /// With --mesh: the tree point (mm from the pith, pith along +z) of the mesh's origin, X,Y,Z
    /// (default: the built-in's scene placement, else 0,150,0).
    #[arg(long, value_parser = parse_vec3, requires = "mesh")]
    pub origin: Option<[f32; 3]>,
    /// With --mesh: the mesh direction the fibres run along, X,Y,Z (default: the built-in's
    /// scene placement, else 0,0,1).
    #[arg(long, value_parser = parse_vec3, requires = "mesh")]
    pub axis: Option<[f32; 3]>,
    /// With --mesh: texels of padding grown around every UV chart, 0 to 64.
    #[arg(long, default_value_t = PAD_TEXELS)]
    pub pad: u32,
    /// With --mesh: also write preview.png, the mesh drawn with its baked maps.
    #[arg(long, requires = "mesh")]
    pub preview: bool,
    /// Which face of the log the board shows.
    #[arg(long, default_value = "tangential")]
    pub cut: BakeCut,
    /// Texels along the board's length (with --mesh: along each side of the square texture),
    /// 1 to 16384.
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
    /// that binds it (notes/gltf.md, "MaterialX / OpenPBR"); with `--mesh`, the stage holds
    /// the mesh (`/Object/mesh`).
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

/// Parses `X,Y,Z`, three finite numbers within ±1e6.
fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let mut out = [0.0; 3];
    if parts.len() != 3 {
        return Err(format!("`{s}`: expected X,Y,Z, e.g. 0,150,0"));
    }
    for (o, p) in out.iter_mut().zip(&parts) {
        let v: f32 = (p.trim().parse()).map_err(|_| format!("`{s}`: `{p}` is not a number"))?;
        if !(v.is_finite() && v.abs() <= 1e6) {
            return Err(format!("`{s}`: {v} is out of range (allowed -1e6 to 1e6)"));
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
    anyhow::ensure!(args.pad <= 64, "--pad {}: allowed 0 to 64 texels", args.pad);
    let params = xylem::wood::preset(&args.preset)?;
    let volume = xylem::wood::WoodVolume::new(params, args.seed)
        .with_context(|| format!("preset {}", args.preset))?;
    let (Some(size), None) = (args.board, &args.mesh) else {
        return run_mesh(&args, &volume);
    };
    let board = BoardCut {
        size,
        cut: args.cut,
        radius: args.radius,
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let maps = bake(&volume, &board, args.res);
    let sides = board.bake_sides(&volume, args.res);
    // Every map and the .glb are staged first, then committed as one set whose record
    // `bake.json` comes last (`output::commit_set`): a full disk leaves the previous bake as it
    // was, a kill while committing leaves no `bake.json` and no file of the previous bake.
    let _lock = FolderLock::try_new(&args.out, LockMode::Exclusive)?;
    let mut staged = stage_maps(&args.out, &maps)?;
    let glb = args.out.join(format!("{}.glb", args.preset));
    staged.push(stage_glb(&glb, &board, &maps, &sides.maps, &args.preset)?);
    if args.materialx {
        staged.extend(stage_materialx(&args.out, &maps, &args.preset)?);
        let usda = args.out.join(format!("{}.usda", args.preset));
        let mtlx = format!("{}.mtlx", args.preset);
        staged.push(
            stage_usda(&usda, &board, &maps, &args.preset, &mtlx)
                .with_context(|| format!("writing {}", usda.display()))?,
        );
    }
    let record = serde_json::json!({
        "preset": args.preset,
        "board_mm": size,
        "cut": args.cut.to_string(),
        "res": args.res,
        "radius_mm": args.radius,
        "seed": args.seed,
        "materialx": args.materialx,
        "sides_atlas_texels": [sides.maps.width, sides.maps.height],
    });
    let files = commit(&args.out, staged, record)?;
    println!(
        "baked {} ({} cut, {}x{} texels, the other faces {}x{}) into {}:",
        args.preset,
        args.cut,
        maps.width,
        maps.height,
        sides.maps.width,
        sides.maps.height,
        args.out.display()
    );
    for f in files {
        println!("  {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// Commits `staged` with the record `bake.json` last; the files written.
fn commit(
    dir: &std::path::Path,
    staged: Vec<xylem::output::Staged>,
    record: serde_json::Value,
) -> anyhow::Result<Vec<PathBuf>> {
    let mut files: Vec<_> = staged.iter().map(|s| s.path().to_path_buf()).collect();
    let record = record.as_object().cloned().unwrap_or_default();
    files.push(
        commit_set(dir, staged, BAKE_RECORD, record)
            .with_context(|| format!("committing the bake in {}", dir.display()))?,
    );
    Ok(files)
}

/// The mesh of `--mesh` and its default (origin, axis) in the tree: a built-in's scene
/// placement, else 150 mm out along +y with the fibres along z.
fn mesh_of(spec: &str) -> anyhow::Result<(UvMesh, [f32; 3], [f32; 3])> {
    Ok(match spec {
        "teapot" => (UvMesh::builtin(spec), [0.0, 110.0, 0.0], [0.0, 0.0, 1.0]),
        "bowl" => (UvMesh::builtin(spec), [0.0, 250.0, 300.0], [1.0, 0.0, 0.0]),
        path => (
            Some(UvMesh::load(std::path::Path::new(path)).with_context(|| {
                let names: Vec<_> = BUILTIN_MESHES.iter().map(|b| b.0).collect();
                format!("--mesh {path}: not a built-in shape ({})", names.join(", "))
            })?),
            [0.0, 150.0, 0.0],
            [0.0, 0.0, 1.0],
        ),
    })
    .and_then(|(m, o, a)| {
        let m = m.ok_or_else(|| anyhow::anyhow!("built-in mesh {spec} failed to build"))?;
        Ok((m, o, a))
    })
}

/// Warns about texels under more than one UV triangle and triangles reaching outside UV [0, 1]².
fn warn_about_layout(spec: &str, bake: &MeshBake) {
    if bake.overlapping > 0 {
        eprintln!(
            "warning: --mesh {spec}: {} texels lie under more than one UV triangle \
             (overlapping or mirrored charts); each keeps the first triangle's wood",
            bake.overlapping
        );
    }
    if bake.outside > 0 {
        eprintln!(
            "warning: --mesh {spec}: {} triangles reach outside UV [0, 1]²; only their part \
             inside is baked",
            bake.outside
        );
    }
}

/// The optional outputs of a mesh bake, staged: the preview picture (--preview), and the
/// MaterialX document with a USD stage binding it (--materialx).
fn stage_mesh_extras(
    args: &Args,
    mesh: &xylem::bake::uv_mesh::UvMesh,
    maps: &xylem::bake::BakedMaps,
) -> anyhow::Result<Vec<xylem::output::Staged>> {
    let (name, mut staged) = (&args.preset, Vec::new());
    if args.preview {
        let (w, h) = (480, 360);
        let px = xylem::bake::preview::preview(mesh, maps, w, h);
        staged.push(xylem::picture::png::stage_png_rgb8(
            &args.out.join("preview.png"),
            w,
            h,
            &xylem::picture::srgb::to_srgb8(&px, 0.0),
        )?);
    }
    if args.materialx {
        staged.extend(stage_materialx(&args.out, maps, name)?);
        let usda = args.out.join(format!("{name}.usda"));
        let text = xylem::bake::usd::usda_mesh_stage(mesh, name, &format!("{name}.mtlx"));
        staged.push(
            xylem::output::stage_bytes(&usda, text.as_bytes())
                .with_context(|| format!("writing {}", usda.display()))?,
        );
    }
    Ok(staged)
}

/// `xylem bake PRESET --mesh …`: the maps over the mesh's UV layout, its coverage mask, the
/// mesh as a `.glb` and as an `.obj` (for Mitsuba), and (with --preview) a picture of it.
fn run_mesh(args: &Args, volume: &xylem::wood::WoodVolume) -> anyhow::Result<ExitCode> {
    let spec = args.mesh.as_deref().unwrap_or_default();
    let (mesh, origin, axis) = mesh_of(spec)?;
    let (origin, axis) = (args.origin.unwrap_or(origin), args.axis.unwrap_or(axis));
    let axis_v = glam::Vec3::from(axis);
    anyhow::ensure!(
        axis_v.length() > 1e-6,
        "--axis {axis:?}: the fibre direction must not be zero"
    );
    let placement = xylem::material::Placement {
        origin: origin.into(),
        axis: axis_v.normalize(),
        ..Default::default()
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let start = std::time::Instant::now();
    let bake: MeshBake = bake_mesh(
        volume,
        &mesh,
        placement.object_to_tree(),
        args.res,
        args.res,
        args.pad,
    );
    let seconds = start.elapsed().as_secs_f64();
    let count = |c: Coverage| bake.coverage.iter().filter(|&&x| x == c).count();
    warn_about_layout(spec, &bake);
    let maps = &bake.maps;
    let _lock = FolderLock::try_new(&args.out, LockMode::Exclusive)?;
    let mut staged = stage_maps(&args.out, maps)?;
    staged.push(bake.stage_coverage(&args.out)?);
    let name = &args.preset;
    let glb = args.out.join(format!("{name}.glb"));
    staged.push(xylem::bake::gltf::stage_mesh_glb(&glb, &mesh, maps, name)?);
    // The mesh as baked, for renderers that load OBJ (Mitsuba with xylem_wood_baked).
    let obj = args.out.join(format!("{name}.obj"));
    staged.push(
        xylem::output::stage_bytes(&obj, mesh.to_obj().as_bytes())
            .with_context(|| format!("writing {}", obj.display()))?,
    );
    staged.extend(stage_mesh_extras(args, &mesh, maps)?);
    let record = serde_json::json!({
        "preset": name,
        "mesh": spec,
        "materialx": args.materialx,
        "triangles": mesh.indices.len(),
        "tree_origin_mm": origin,
        "tree_axis": axis,
        "res": args.res,
        "pad": args.pad,
        "seed": args.seed,
        "texels_covered": count(Coverage::Covered),
        "texels_padding": count(Coverage::Padding),
        "texels_empty": count(Coverage::Empty),
        "texels_overlapping": bake.overlapping,
        "triangles_outside_unit_uv": bake.outside,
    });
    let files = commit(&args.out, staged, record)?;
    println!(
        "baked {name} onto {spec} ({} triangles, {}x{} texels, {:.1} % covered, {seconds:.2} s) into {}:",
        mesh.indices.len(),
        maps.width,
        maps.height,
        100.0 * count(Coverage::Covered) as f64 / bake.coverage.len().max(1) as f64,
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
