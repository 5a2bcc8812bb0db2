//! Every built-in scene parses and renders at a tiny resolution; bad scene files give errors that
//! name the file, the field and what is allowed.

use std::path::Path;
use xylem::render::{render, RunOptions};

#[test]
fn every_builtin_scene_renders_tiny() {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let mut s = xylem::scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
        s.scene.camera = s.scene.camera.with_resolution(24, 16);
        s.settings.spp = 2;
        let out = render(&s.scene, &s.settings, &RunOptions::default()).unwrap();
        let img = out.image;
        assert_eq!(img.nonfinite, 0, "{}", p.display());
        assert!(img
            .beauty
            .iter()
            .all(|c| c.is_finite() && c.min_element() >= 0.0));
        assert!(
            img.beauty.iter().any(|c| c.max_element() > 0.0),
            "{} renders black",
            p.display()
        );
        n += 1;
    }
    assert!(n >= 1);
}

fn err(text: &str) -> String {
    match xylem::scene::from_str(text, "test.toml", Path::new("."), "test") {
        Ok(_) => panic!("scene should be rejected"),
        Err(e) => e.to_string(),
    }
}

const CAMERA: &str = "[camera]\neye = [0.0, -10.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\n";

#[test]
fn scene_errors_name_file_field_and_allowed_values() {
    let e = err(&format!("{CAMERA}fov = 3\n"));
    assert!(e.contains("test.toml") && e.contains("fov"), "{e}");
    let e = err(&format!("{CAMERA}[render]\nspp = 0\n"));
    assert!(e.contains("render.spp") && e.contains("allowed 1"), "{e}");
    let e = err(&format!(
        "{CAMERA}[[lights]]\ntype = \"laser\"\nposition = [0.0, 0.0, 0.0]\n"
    ));
    assert!(e.contains("laser") && e.contains("point"), "{e}");
    let e = err(&format!(
        "{CAMERA}[materials.m]\ntype = \"lambertian\"\nalbedo = [1.5, 0.0, 0.0]\n"
    ));
    assert!(
        e.contains("materials.m.albedo") && e.contains("allowed 0 to 1"),
        "{e}"
    );
    let e = err(&format!(
        "{CAMERA}[materials.m]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n[[objects]]\nshape = \"box\"\nradius = 2.0\nsize = [1.0, 1.0, 1.0]\nmaterial = \"m\"\n"
    ));
    assert!(e.contains("objects[0].radius") && e.contains("size"), "{e}");
    let e = err(&format!(
        "{CAMERA}[materials.m]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n[[objects]]\nshape = \"mesh\"\nfile = \"missing.obj\"\nmaterial = \"m\"\n"
    ));
    assert!(
        e.contains("objects[0].file") && e.contains("missing.obj"),
        "{e}"
    );
    let e = err(&format!(
        "{CAMERA}[materials.m]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n[[objects]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nmaterial = \"wood\"\n"
    ));
    assert!(
        e.contains("objects[0].material") && e.contains("\"m\""),
        "{e}"
    );
}
