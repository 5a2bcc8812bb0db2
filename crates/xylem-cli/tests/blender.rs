//! Blender 5 (the PyPI `bpy` module, pinned in python/requirements-blender.txt, in its own venv
//! target/blender-venv because bpy pins numpy < 2) imports `xylem bake`'s .glb with the
//! anisotropy, and its Cycles render stretches the highlight across the fibres; the add-on
//! python/blender/xylem_import.py builds the same material from the baked maps
//! (notes/gltf.md, "Blender"). python/blender/check_gltf.py does the Blender side and writes
//! report.json, judged here.
//!
//! Where bpy cannot be installed (no PyPI, no wheel for this Python or platform) the test says
//! so loudly and passes, except on CI (`CI` set), where it fails.

use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// target/blender-venv with python/requirements-blender.txt, or why it cannot be made.
fn blender_venv() -> Result<PathBuf, String> {
    let venv = root().join("target/blender-venv");
    let python = venv.join("bin/python");
    let run = |cmd: &mut Command, what: &str| -> Result<(), String> {
        let out = cmd
            .output()
            .map_err(|e| format!("{what}: cannot run {cmd:?}: {e}"))?;
        if out.status.success() {
            Ok(())
        } else {
            Err(format!(
                "{what} failed ({}):\n{}",
                out.status,
                String::from_utf8_lossy(&out.stderr)
            ))
        }
    };
    if !python.exists() {
        let base = std::env::var("XYLEM_PYTHON").unwrap_or_else(|_| "python3".into());
        run(
            Command::new(&base).args(["-m", "venv"]).arg(&venv),
            "creating target/blender-venv (Python 3.11 with venv; bpy 5.0 needs CPython 3.11)",
        )?;
    }
    let req = root().join("python/requirements-blender.txt");
    let wanted = std::fs::read_to_string(&req).map_err(|e| format!("{}: {e}", req.display()))?;
    let stamp = venv.join("xylem-requirements.txt");
    if std::fs::read_to_string(&stamp).ok().as_deref() != Some(wanted.as_str()) {
        run(
            Command::new(&python)
                .args(["-m", "pip", "install", "--quiet"])
                .args(["--disable-pip-version-check", "-r"])
                .arg(&req),
            "pip install -r python/requirements-blender.txt (bpy 5.0.1, a 375 MB wheel from PyPI)",
        )?;
        std::fs::write(&stamp, wanted).map_err(|e| e.to_string())?;
    }
    Ok(venv)
}

fn xylem(args: &[&str], what: &str) {
    let out = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("report: no number {key} in {v}"))
}

/// Angle between two axes (degrees, modulo 180°).
fn axis_gap(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(180.0);
    d.min(180.0 - d)
}

fn linked(case: &Value, input: &str) -> bool {
    case["material"]["inputs"][input]["linked"] == Value::Bool(true)
}

/// Bakes the board, renders xylem's grazing view of it, and runs python/blender/check_gltf.py
/// in Blender on both; returns its report.json.
fn bake_render_and_check_in_blender(venv: &std::path::Path) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let bake = dir.path().join("bake");
    let out = root().join("target/blender-test");
    let _ = std::fs::remove_dir_all(&out);
    let scene = root().join("python/blender/grazing_board.toml");
    let started = std::time::Instant::now();
    xylem(
        &[
            "bake",
            "african_mahogany",
            "--board",
            "200x200x20",
            "--res",
            "64",
            "--seed",
            "1",
            "--out",
            bake.to_str().unwrap(),
        ],
        "xylem bake",
    );
    xylem(
        &[
            "render",
            scene.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        "xylem render",
    );
    let script = root().join("python/blender/check_gltf.py");
    let run = Command::new(venv.join("bin/python"))
        .arg(&script)
        .args(["--bake", bake.to_str().unwrap()])
        .args(["--scene", scene.to_str().unwrap()])
        .args([
            "--xylem-png",
            out.join("grazing_board.png").to_str().unwrap(),
        ])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&run.stdout);
    let summary: Vec<&str> = said
        .lines()
        .filter(|l| !l.contains("| INFO") && !l.contains("Saved:"))
        .collect();
    eprintln!("{}", summary.join("\n"));
    assert!(
        run.status.success(),
        "{} failed:\n{said}\n{}",
        script.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    eprintln!(
        "blender.rs: bake, xylem render and Blender took {:.1} s",
        started.elapsed().as_secs_f64()
    );
    serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap()
}

#[test]
fn blender_imports_the_anisotropy_and_renders_it_across_the_fibre() {
    let venv = match blender_venv() {
        Ok(v) => v,
        Err(why) if std::env::var_os("CI").is_none() => {
            eprintln!(
                "\n!!!!!!!! SKIPPED blender.rs: Blender (PyPI bpy) is not installable here !!!!!!!!\n\
                 {why}\n(on CI, with CI set, this fails instead)\n"
            );
            return;
        }
        Err(why) => panic!("Blender (PyPI bpy) is needed on CI: {why}"),
    };
    let report = bake_render_and_check_in_blender(&venv);
    let cases = &report["cases"];
    let check = |name: &str| -> (f64, f64) {
        let c = &cases[name];
        (num(c, "angle_deg"), num(c, "elongation"))
    };
    // The importer links strength, rotation and tangent (Blender 3.4's drops all three).
    for input in ["Anisotropic", "Anisotropic Rotation", "Tangent"] {
        assert!(
            linked(&cases["gltf"], input),
            "Blender's importer left {input} unlinked: {}",
            cases["gltf"]["material"]
        );
    }
    // Light and camera lie in the plane across the fibres (image y): the highlight must stretch
    // across the fibres, i.e. along image y (±90°), within 15°, at least 2:1.
    let across = |(angle, elong): (f64, f64)| axis_gap(angle, 90.0) <= 15.0 && elong >= 2.0;
    assert!(across(check("gltf")), "glTF import: {}", cases["gltf"]);
    // Negative controls: the anisotropy stripped (a round GGX lobe) and the board turned 90°.
    assert!(
        !across(check("stripped")),
        "stripped: {}",
        cases["stripped"]
    );
    assert!(!across(check("turned")), "turned: {}", cases["turned"]);
    // The add-on: its node tree and its render (the coat's mirror spot shortens the region).
    let addon = &cases["addon"];
    for input in [
        "Base Color",
        "Roughness",
        "Anisotropic",
        "Tangent",
        "Normal",
    ] {
        assert!(
            linked(addon, input),
            "add-on left {input} unlinked: {addon}"
        );
    }
    assert_eq!(addon["material"]["inputs"]["Coat Weight"]["value"], 1.0);
    let (a, e) = check("addon");
    assert!(
        axis_gap(a, 90.0) <= 15.0 && e >= 1.5,
        "add-on render: {addon}"
    );
}
