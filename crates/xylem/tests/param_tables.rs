//! The wood BSDF's parameter table (`bsdf::WOOD_BSDF_PARAMS`) is the one list its checks follow:
//! `WoodBsdf::new` accepts each scalar field at its bounds and refuses it just beyond (naming the
//! field). The scene's `fiber` fields take their ranges from it (`scene::fields`, tested in
//! scene_fields.rs).

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
