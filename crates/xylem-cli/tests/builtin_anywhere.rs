//! Built-in scenes run by bare name from an empty folder, as from an installed binary: their
//! meshes and measured maps come from the copies compiled into the binary (`xylem::builtin`),
//! and `sweep` checksums the scene it loaded rather than reading the name from disk again.

use std::path::Path;
use std::process::{Command, Output};

fn xylem(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn every_builtin_scene_renders_by_bare_name_from_an_empty_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let names: Vec<&str> = xylem::builtin::scene_names().collect();
    assert!(names.len() >= 15, "{names:?}");
    for name in names {
        let args = [
            "render", name, "--res", "8x6", "--spp", "1", "--quiet", "--out", "o",
        ];
        ok(&xylem(&args, tmp.path()), name);
        assert!(tmp.path().join(format!("o/{name}.exr")).is_file(), "{name}");
    }
}

#[test]
fn builtin_sweeps_run_by_bare_name_from_an_empty_folder() {
    let tmp = tempfile::tempdir().unwrap();
    for name in ["sweep_board", "measured_maple_sweep"] {
        let out = format!("s/{name}");
        let args = [
            "sweep", name, "--frames", "2", "--spp", "1", "--quiet", "--out", &out,
        ];
        ok(&xylem(&args, tmp.path()), name);
        let csv = tmp.path().join(&out).join("sweep.csv");
        assert!(csv.is_file(), "{name}: no {}", csv.display());
    }
}
