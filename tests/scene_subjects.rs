//! Every built-in scene shows what it is for (issue 17), measured on a small version of its
//! beauty image: the framing of its default camera at a fraction of its size, its own seed.
//! Thresholds and their derivation: `xylem::validate::scenes` and notes/scenes.md. The default
//! sizes are measured by `xylem gallery` (notes/scenes.md records the figures).

use std::path::Path;
use xylem::render::{render, RunOptions};
use xylem::validate::scenes::measure;

/// (scene, divisor of the default width and height, spp or None for the scene's own).
/// Cornell boxes keep their own spp: the firefly criterion is per pixel and does not get easier
/// at a smaller size (fewer pixels only means fewer chances to fail; the default size is checked
/// by `xylem gallery`).
const CASES: [(&str, u32, Option<u32>); 11] = [
    ("cornell_box", 2, None),
    ("sweep_board", 4, Some(8)),
    ("parquet_floor", 1, Some(4)),
    ("box_joint", 2, Some(8)),
    ("cube_carved_vs_veneer", 2, Some(8)),
    ("turned_bowl", 2, Some(16)),
    ("teapot", 4, Some(16)),
    ("cornell_wood_marble", 4, None),
    ("cornell_bunny", 4, None),
    ("dovetail", 2, Some(8)),
    ("carved_bunny", 2, Some(16)),
];

fn check(name: &str, div: u32, spp: Option<u32>) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    let names: Vec<Option<String>> = xylem::scene::parse(&text, name)
        .unwrap()
        .objects
        .into_iter()
        .map(|o| o.name)
        .collect();
    let mut s = xylem::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let (w, h) = (s.scene.camera.width, s.scene.camera.height);
    s.scene.camera = s.scene.camera.with_resolution(w / div, h / div);
    if let Some(spp) = spp {
        s.settings.spp = spp;
    }
    let img = render(&s.scene, &s.settings, &RunOptions::default())
        .unwrap()
        .image;
    let m = measure(name, &s.scene, &names, &img, s.exposure);
    assert!(!m.is_empty(), "{name} has no subject check");
    for m in &m {
        println!(
            "{name} ({}x{}, {} spp): {m}",
            w / div,
            h / div,
            s.settings.spp
        );
    }
    m.iter()
        .filter(|m| !m.pass())
        .map(|m| format!("{name}: {m}"))
        .collect()
}

#[test]
fn every_builtin_scene_shows_its_subject() {
    let failures: Vec<String> = CASES
        .iter()
        .flat_map(|&(n, d, spp)| check(n, d, spp))
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The checks can fail: the box joint with both boards' fingers in one block (one grain) and the
/// parquet with its seams filled flush (the seam object's albedo equal to the strips') are the
/// broken versions; the Cornell firefly ratio at 1 spp is far above 10.
#[test]
fn subject_checks_fail_on_a_broken_scene() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_wood_marble.toml");
    let mut s = xylem::scene::load(&path).unwrap();
    s.scene.camera = s.scene.camera.with_resolution(100, 100);
    s.settings.spp = 1;
    let text = std::fs::read_to_string(&path).unwrap();
    let names: Vec<Option<String>> = xylem::scene::parse(&text, "c")
        .unwrap()
        .objects
        .into_iter()
        .map(|o| o.name)
        .collect();
    let img = render(&s.scene, &s.settings, &RunOptions::default())
        .unwrap()
        .image;
    let m = measure("cornell_wood_marble", &s.scene, &names, &img, 0.0);
    assert!(m.iter().any(|m| !m.pass()), "{m:?}");
}

/// The Cornell box's bleeding check needs the coloured walls: with the red wall white, the
/// white surfaces are no redder on its side than in the middle (R/G ratio below 1.1).
#[test]
fn cornell_box_bleed_check_fails_without_the_red_wall() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = std::fs::read_to_string(dir.join("cornell_box.toml")).unwrap();
    let red_wall =
        "translate = [-275.0, 275.0, 275.0]\nrotate_deg = [0.0, 90.0, 0.0]\nmaterial = \"red\"";
    assert!(text.contains(red_wall));
    let broken = text.replace(
        red_wall,
        &red_wall.replace("material = \"red\"", "material = \"white\""),
    );
    let names: Vec<Option<String>> = xylem::scene::parse(&broken, "cb")
        .unwrap()
        .objects
        .into_iter()
        .map(|o| o.name)
        .collect();
    let mut s = xylem::scene::from_str(&broken, "cb.toml", &dir, "cb").unwrap();
    s.scene.camera = s.scene.camera.with_resolution(64, 64);
    s.settings.spp = 16;
    let img = render(&s.scene, &s.settings, &RunOptions::default())
        .unwrap()
        .image;
    let m = measure("cornell_box", &s.scene, &names, &img, s.exposure);
    let bleed = m
        .iter()
        .find(|m| m.what.starts_with("red bleeding"))
        .unwrap();
    assert!(!bleed.pass(), "{bleed}");
}

/// The cube check needs the veneer's seams: with the "veneered" cube carved from a block too,
/// its rings run on around its edges and the edge-jump ratio falls below 2.
#[test]
fn cube_check_fails_without_the_veneer() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = std::fs::read_to_string(dir.join("cube_carved_vs_veneer.toml")).unwrap();
    let veneer = "tree = { cut = \"veneer\", region = { r_min = 60.0, r_max = 200.0, z_span = 3000.0, cut = \"flat\" }, seed = 5 }";
    assert!(text.contains(veneer));
    let solid = text.replace(
        veneer,
        "tree = { cut = \"solid\", origin = [0.0, 90.0, 0.0], axis = [0.2, 1.0, 0.1] }",
    );
    let names: Vec<Option<String>> = xylem::scene::parse(&solid, "cube")
        .unwrap()
        .objects
        .into_iter()
        .map(|o| o.name)
        .collect();
    let mut s = xylem::scene::from_str(&solid, "cube.toml", &dir, "cube").unwrap();
    s.scene.camera = s.scene.camera.with_resolution(240, 150);
    s.settings.spp = 4;
    let img = render(&s.scene, &s.settings, &RunOptions::default())
        .unwrap()
        .image;
    let m = measure("cube_carved_vs_veneer", &s.scene, &names, &img, s.exposure);
    println!("{m:#?}");
    let edge = m.iter().find(|m| m.what.starts_with("edge jump")).unwrap();
    assert!(!edge.pass(), "{edge}");
}
