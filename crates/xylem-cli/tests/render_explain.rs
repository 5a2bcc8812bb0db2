//! Level of detail from the scene (issue 28): `xylem::render::lod::plan` bounds every camera
//! hit's footprint from below, finds the parquet floor's pores skipped once the floor is seen
//! from far enough, and `xylem render --explain` prints it. Fails before issue 28's `lod` module
//! and `--explain` option.

use std::path::Path;
use xylem::math::{Vec2, Vec3};
use xylem::render::integrator::footprint_scale;
use xylem::render::lod::{plan, Detail};
use xylem::scene::{load, LoadedScene};

fn parquet(width: u32, height: u32) -> LoadedScene {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/parquet_floor.toml"
    ));
    let mut l = load(path).unwrap();
    l.scene.camera = l.scene.camera.with_resolution(width, height);
    l
}

fn pores(l: &LoadedScene, spp: u32) -> (f32, Detail) {
    let plans = plan(&l.scene, spp);
    assert_eq!(plans.len(), 1, "one wood material: {plans:?}");
    let p = &plans[0];
    let f = p.features.iter().find(|f| f.name == "pores").unwrap();
    (p.footprint, f.detail)
}

#[test]
fn the_plan_is_a_tight_lower_bound_of_the_camera_footprints() {
    let l = parquet(180, 120);
    let spp = 16;
    let (floor, _) = pores(&l, spp);
    assert!(floor.is_finite() && floor > 0.0, "{floor}");
    // Every first hit on the floor over a grid of pixels, its footprint as the integrator and
    // `WoodMaterial::shade` take it, in tree mm.
    let s = &l.scene;
    let cam = &s.camera;
    let mut smallest = f32::INFINITY;
    for y in 0..cam.height {
        for x in (0..cam.width).step_by(4) {
            let ray = cam.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
            let Some(hit) = s.accel.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let inst = &s.accel.instances[hit.instance as usize];
            if inst.material as usize != 0 {
                continue;
            }
            let sf = s.accel.surface(&ray, &hit);
            let world = footprint_scale(spp) * cam.pixel_footprint(&ray, hit.t)
                / sf.ng.dot(ray.d).abs().max(0.05).sqrt();
            let unit = if inst.placement.world_space {
                1.0
            } else {
                inst.transform.to_world.matrix3.determinant().abs().cbrt()
            };
            smallest = smallest.min(world / unit * inst.placement.scale);
        }
    }
    assert!(
        floor <= smallest * 1.0001,
        "plan {floor} > a hit's {smallest}"
    );
    // Tight: the oblique floor's nearest visible strip is at the image's bottom edge, whose
    // footprint the plan undercuts only by the 1/√cos stretch (the floor seen at ≈ 56° there).
    assert!(floor >= 0.6 * smallest, "plan {floor} far under {smallest}");
}

#[test]
fn a_distant_parquet_floor_skips_its_pores() {
    // As shipped (720×480, 16 spp) the pores (0.26 mm) are still shown near the camera.
    let (fp, d) = pores(&parquet(720, 480), 16);
    assert_ne!(d, Detail::Skipped, "footprint {fp}");
    // Seen from 4× as far (one pixel for 4×4 of the shipped image) every pixel fades them out.
    let (fp, d) = pores(&parquet(180, 120), 16);
    assert_eq!(d, Detail::Skipped, "footprint {fp}");
    // The broad quartersawn rays (flecks up to 30 mm across) are kept at both.
    let l = parquet(180, 120);
    let p = &plan(&l.scene, 16)[0];
    let rays = p.features.iter().find(|f| f.name == "rays").unwrap();
    assert_eq!(rays.detail, Detail::Kept);
}

#[test]
fn nothing_out_of_view_is_planned_as_shown() {
    let mut l = parquet(180, 120);
    // Turn the camera to look straight up, away from the floor.
    let c = &l.scene.camera;
    l.scene.camera = xylem::render::camera::Camera::look_at(
        c.eye,
        c.eye + Vec3::Z,
        Vec3::Y,
        c.projection,
        c.width,
        c.height,
    );
    let p = &plan(&l.scene, 16)[0];
    assert!(p.footprint.is_infinite(), "{p:?}");
    assert!(p.features.iter().all(|f| f.detail == Detail::Skipped));
}

#[test]
fn render_explain_prints_what_is_skipped() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/parquet_floor.toml"
    ));
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_xylem"))
        .arg("render")
        .arg(scene)
        .args([
            "--explain",
            "--res",
            "180x120",
            "--spp",
            "16",
            "--quiet",
            "--out",
        ])
        .arg(tmp.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("pores"))
        .unwrap_or_else(|| panic!("no pores line: {err}"));
    assert!(line.contains("skipped"), "{line}");
    assert!(err.contains("smallest pixel footprint"), "{err}");
}
