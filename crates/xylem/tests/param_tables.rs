//! The wood BSDF's parameter table (`bsdf::WOOD_BSDF_PARAMS`) is the one list its checks, the
//! scene format and the documentation follow: `WoodBsdf::new` accepts each scalar field at its
//! bounds and refuses it just beyond (naming the field), and scenes/README.md's `fiber` row names
//! every field with the table's range.

use glam::Vec3;
use xylem::bsdf::{ParamKind, WoodBsdf, WoodBsdfParams, WOOD_BSDF_PARAMS};

/// `params` with scalar field `name` set to `x`.
fn with(name: &str, x: f32) -> WoodBsdfParams {
    let mut p = WoodBsdfParams::default();
    match name {
        "ray_mask" => p.ray_mask = x,
        "highlight_width" => p.highlight_width = x,
        "eta" => p.eta = x,
        "roughness" => p.roughness = x,
        other => panic!("no scalar field `{other}`"),
    }
    p
}

#[test]
fn each_scalar_is_accepted_at_its_bounds_and_refused_beyond() {
    let mut scalars = 0;
    for spec in WOOD_BSDF_PARAMS {
        let ParamKind::Scalar { min, max } = spec.kind else {
            continue;
        };
        scalars += 1;
        for x in [min, max] {
            assert!(
                WoodBsdf::new(with(spec.name, x)).is_ok(),
                "{} = {x}",
                spec.name
            );
        }
        for x in [min - 1e-3 * (1.0 + min.abs()), max * 1.001 + 1e-6, f32::NAN] {
            let e = WoodBsdf::new(with(spec.name, x)).err();
            let msg = e.map(|e| e.to_string()).unwrap_or_default();
            assert!(
                msg.contains(spec.name) && msg.contains(spec.range),
                "{} = {x}: {msg:?}",
                spec.name
            );
        }
    }
    assert_eq!(scalars, 4);
    // Colours and directions: the control that a vector field is checked too.
    let long_fibre = WoodBsdfParams {
        fiber_dir: Vec3::new(2.0, 0.0, 0.0),
        ..Default::default()
    };
    let e = WoodBsdf::new(long_fibre).unwrap_err().to_string();
    assert!(e.contains("fiber_dir"), "{e}");
    let bright = WoodBsdfParams {
        diffuse: Vec3::new(1.5, 0.0, 0.0),
        ..Default::default()
    };
    let e = WoodBsdf::new(bright).unwrap_err().to_string();
    assert!(e.contains("diffuse"), "{e}");
}

#[test]
fn the_scene_documentation_lists_every_field_with_its_range() {
    let readme = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/README.md"
    ))
    .unwrap();
    let row = readme
        .lines()
        .find(|l| l.starts_with("| `fiber` |"))
        .expect("scenes/README.md has a `fiber` material row");
    for spec in WOOD_BSDF_PARAMS {
        // Scene files give the highlight width in degrees.
        let name = match spec.name {
            "highlight_width" => "highlight_width_deg",
            n => n,
        };
        assert!(
            row.contains(&format!("`{name}`")),
            "`{name}` missing: {row}"
        );
        if let (ParamKind::Scalar { min, max }, false) = (spec.kind, name.ends_with("_deg")) {
            let range = format!("{} {min}–{max}", spec.name);
            assert!(row.contains(&range), "{range:?} missing: {row}");
        }
    }
}
