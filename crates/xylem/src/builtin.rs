//! Repository files compiled into the binary, so an installed `xylem` (`cargo install --path crates/xylem-cli`)
//! runs the built-in scenes, `validate` and the measured boards from any folder: the scene files
//! (`scenes/*.toml`), the meshes they place (`scenes/meshes/*.obj`), the BSDF validation cases
//! (`validation/bsdf_cases.toml`) and Marschner et al. 2005's measured maps
//! (`data/marschner2005/`). A file on disk always wins; the embedded copy is used only where the
//! path does not exist. A built-in scene loaded from its embedded copy resolves its relative
//! files against `scenes/` (its folder in the repository), so its meshes and maps are found
//! here too. (The species presets are embedded by `wood::preset` itself.)

use std::borrow::Cow;
use std::path::{Component, Path, PathBuf};

macro_rules! embed {
    ($($path:literal),* $(,)?) => {
        [$(($path, include_bytes!(concat!("../../../", $path)) as &[u8])),*]
    };
}

/// (path relative to the repository root, contents).
const FILES: [(&str, &[u8]); 30] = embed![
    "scenes/box_joint.toml",
    "scenes/carved_bunny.toml",
    "scenes/cornell_box.toml",
    "scenes/cornell_bunny.toml",
    "scenes/cornell_bunny_black.toml",
    "scenes/cornell_wood_marble.toml",
    "scenes/cube_carved_vs_veneer.toml",
    "scenes/dovetail.toml",
    "scenes/fit_maple_sweep.toml",
    "scenes/grazing_oak.toml",
    "scenes/measured_maple_sweep.toml",
    "scenes/measured_padauk_sweep.toml",
    "scenes/parquet_floor.toml",
    "scenes/sweep_board.toml",
    "scenes/teapot.toml",
    "scenes/turned_bowl.toml",
    "scenes/meshes/bunny.obj",
    "scenes/meshes/dovetail_pins.obj",
    "scenes/meshes/dovetail_tails.obj",
    "scenes/meshes/parquet.obj",
    "validation/bsdf_cases.toml",
    "data/marschner2005/maple/diffuse.png",
    "data/marschner2005/maple/fiber_axis.png",
    "data/marschner2005/maple/fiber_color.png",
    "data/marschner2005/padauk/diffuse.png",
    "data/marschner2005/padauk/fiber_axis.png",
    "data/marschner2005/padauk/fiber_color.png",
    "data/marschner2005/walnut1/diffuse.png",
    "data/marschner2005/walnut1/fiber_axis.png",
    "data/marschner2005/walnut1/fiber_color.png",
];

/// The built-in scenes' names (`sweep_board` for scenes/sweep_board.toml).
pub fn scene_names() -> impl Iterator<Item = &'static str> {
    FILES
        .iter()
        .filter_map(|(p, _)| p.strip_prefix("scenes/")?.strip_suffix(".toml"))
}

/// `path` with `.` dropped and `a/..` folded, lexically (no file system); `None` for an absolute
/// path or one that climbs above its start.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = Vec::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop()?;
            }
            Component::Normal(s) => out.push(s),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out.iter().collect())
}

/// The embedded file for `path` as (repository path, contents): its repository-relative form
/// (`scenes/sweep_board.toml`, `scenes/../data/…` folded), or a built-in scene's bare name
/// (`sweep_board`) or file name (`sweep_board.toml`).
fn entry(path: &Path) -> Option<(&'static str, &'static [u8])> {
    let rel = normalise(path)?;
    let scene = match rel.to_str() {
        Some(s) if !s.contains('/') => Some(format!(
            "scenes/{}.toml",
            s.strip_suffix(".toml").unwrap_or(s)
        )),
        _ => None,
    };
    FILES
        .iter()
        .find(|(p, _)| Path::new(p) == rel || scene.as_deref() == Some(*p))
        .copied()
}

/// The embedded contents for `path` (a repository-relative path, folded, or a built-in scene's bare name).
pub fn lookup(path: &Path) -> Option<&'static [u8]> {
    entry(path).map(|(_, bytes)| bytes)
}

/// The embedded file that stands in for `path` — (repository path, contents) — where `path`
/// does not exist on disk; None where the disk has it or nothing is embedded under that name.
pub(crate) fn stand_in(path: &Path) -> Option<(&'static str, &'static [u8])> {
    entry(path).filter(|_| !path.exists())
}

/// The bytes of `path` from disk — a regular file of at most `max` bytes
/// ([`read_bounded`](crate::resources::read_bounded)) — or the embedded copy where the
/// path does not exist.
pub fn read(path: &Path, max: u64) -> Result<Cow<'static, [u8]>, crate::resources::ResourceError> {
    match stand_in(path) {
        Some((_, bytes)) => Ok(Cow::Borrowed(bytes)),
        None => crate::resources::read_bounded(path, max).map(Cow::Owned),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_fold_relative_paths_and_bare_names() {
        // The repository root: the embedded paths are relative to it.
        let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
        let board = lookup(Path::new("scenes/sweep_board.toml")).unwrap();
        assert_eq!(
            board,
            std::fs::read(root.join("scenes/sweep_board.toml")).unwrap()
        );
        assert_eq!(lookup(Path::new("sweep_board")), Some(board));
        assert_eq!(lookup(Path::new("./sweep_board.toml")), Some(board));
        let png = lookup(Path::new("scenes/../data/marschner2005/maple/diffuse.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        for missing in [
            "/scenes/sweep_board.toml",
            "../scenes/sweep_board.toml",
            "nope",
        ] {
            assert!(lookup(Path::new(missing)).is_none(), "{missing}");
        }
        // Every scene file in the repository is embedded.
        let mut on_disk: Vec<String> = std::fs::read_dir(root.join("scenes"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension() == Some("toml".as_ref()))
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        on_disk.sort();
        let mut embedded: Vec<String> = scene_names().map(String::from).collect();
        embedded.sort();
        assert_eq!(embedded, on_disk);
    }
}
