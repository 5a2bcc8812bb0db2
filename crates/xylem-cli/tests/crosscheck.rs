//! xylem's path tracer against Mitsuba 3 on the same scenes, small version: runs
//! `python -m validation.crosscheck --small` (validation/CROSSCHECK.md describes the method) in
//! the pinned virtual environment with the xylem binary this `cargo test` built. Every case
//! (Lambertian Cornell box, the box with a mirror and a glass sphere, a plane under a point
//! light, a plane under a rect light) must agree within noise (per-pixel and per-region Welch
//! tests, Šidák-corrected at 1 % per family), and both negative controls (xylem's image mirrored,
//! xylem's white walls 10 % darker) must be rejected.

mod common;

use common::python::{libllvm, venv};
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

#[test]
fn xylem_agrees_with_mitsuba_within_noise() {
    let root = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let venv = venv();
    let json = root.join("target/crosscheck/small.json");
    let _ = std::fs::remove_file(&json);
    let mut cmd = Command::new(venv.join("bin/python"));
    cmd.args(["-m", "validation.crosscheck", "--small", "--xylem"])
        .arg(env!("CARGO_BIN_EXE_xylem"))
        .arg("--json")
        .arg(&json)
        .current_dir(&root);
    if let Some(p) = libllvm() {
        cmd.env("DRJIT_LIBLLVM_PATH", p);
    }
    let started = std::time::Instant::now();
    let out = cmd
        .output()
        .expect("running python -m validation.crosscheck");
    println!("{}", String::from_utf8_lossy(&out.stdout));
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    eprintln!("cross-check ran {:.1} s", started.elapsed().as_secs_f64());
    let report: Value = serde_json::from_str(
        &std::fs::read_to_string(&json).expect("the cross-check wrote no results"),
    )
    .unwrap();
    let rows = report["rows"].as_array().unwrap();
    let cases: Vec<&str> = rows.iter().map(|r| r["case"].as_str().unwrap()).collect();
    for c in [
        "cornell_box",
        "cornell_spheres",
        "plane_point",
        "plane_rect",
    ] {
        assert!(cases.contains(&c), "case {c} was not run: {cases:?}");
    }
    for r in rows {
        assert_eq!(
            r["pass"], true,
            "xylem and Mitsuba differ beyond noise: {r:#}"
        );
    }
    let controls = report["controls"].as_array().unwrap();
    assert_eq!(controls.len(), 2);
    for c in controls {
        // Rejected far below any Šidák level: the smallest region p is ≈ 0.
        let p = c["tests"]["8x8 regions"]["min_p"].as_f64().unwrap();
        assert!(
            c["detected"] == true && p < 1e-6,
            "negative control not detected: {c:#}"
        );
    }
    assert!(
        out.status.success(),
        "the cross-check failed (output above)"
    );
}
