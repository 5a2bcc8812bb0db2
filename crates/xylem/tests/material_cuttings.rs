//! The wood material honours its placement's cutting (solid block, veneer per face, boards of a
//! floor), world-space placements, and bump-maps with the gradient of the height it looks up.

use glam::{Mat3, Vec3};
use std::sync::Arc;
use xylem::field::JacobianModel;
use xylem::material::{Cutting, MaterialHit, Placement, ShadingSwitches, WoodMaterial};
use xylem::math::Pcg32;
use xylem::wood::{self, BoardLayout, Cut, Needs, TreeRegion, WoodVolume};

fn material(preset: &str, bump: f32) -> WoodMaterial {
    WoodMaterial {
        volume: Arc::new(WoodVolume::new(wood::preset(preset).unwrap(), 3).unwrap()),
        finish: xylem::bsdf::Finish::new(1.5, 0.0),
        bump,
        switches: ShadingSwitches::default(),
    }
}

/// A hit on an object placed by `to_world` (a linear map) at object point `p` with object
/// normal `n`.
fn hit(p: Vec3, n: Vec3, to_world: Mat3, placement: Placement) -> MaterialHit {
    let normal_to_world = to_world.inverse().transpose();
    let ng = (normal_to_world * n).normalize();
    MaterialHit {
        p_object: p,
        p_world: to_world * p,
        n_object: n,
        ng,
        ns: ng,
        tangent: ng.any_orthonormal_vector(),
        object_to_world: to_world,
        normal_to_world,
        placement,
        footprint: 0.0,
    }
}

fn uniform(r: &mut Pcg32, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * r.next_f32()
}

/// A uniform point of the square [−half, half]² in the plane z = 0.
fn plane_point(r: &mut Pcg32, half: f32) -> Vec3 {
    Vec3::new(uniform(r, -half, half), uniform(r, -half, half), 0.0)
}

/// Mean |fibre · axis| of the shaded fibre AOV over random points of the plane z = 0.
fn mean_alignment(m: &WoodMaterial, placement: Placement, axis: Vec3) -> f32 {
    let mut r = Pcg32::new(11, 0);
    let n = 400;
    let mut sum = 0.0;
    for _ in 0..n {
        let p = plane_point(&mut r, 900.0);
        let s = m.shade(&hit(p, Vec3::Z, Mat3::IDENTITY, placement));
        assert!(s.aov.fiber.is_finite() && (s.aov.fiber.length() - 1.0).abs() < 1e-3);
        sum += s.aov.fiber.dot(axis).abs();
    }
    sum / n as f32
}

#[test]
fn planks_run_their_grain_along_the_boards() {
    let m = material("cherry", 0.0);
    let region = TreeRegion {
        r_min: 80.0,
        r_max: 250.0,
        z_span: 4000.0,
        cut: Cut::Flat,
    };
    let planks = Placement {
        cutting: Cutting::Boards {
            layout: BoardLayout::Planks {
                width: 120.0,
                length: 1500.0,
                stagger: 0.3,
            },
            region,
            seed: 5,
        },
        ..Default::default()
    };
    // Planks run along x: their fibres lie along x (within the figure's tilt), in the floor.
    let along = mean_alignment(&m, planks, Vec3::X);
    let up = mean_alignment(&m, planks, Vec3::Z);
    assert!(
        along > 0.9 && up < 0.2,
        "along x {along}, out of the floor {up}"
    );
    // A solid block with its pith along z shows end grain on the same floor.
    let solid = mean_alignment(&m, Placement::default(), Vec3::Z);
    assert!(solid > 0.9, "solid block's fibres along the pith: {solid}");
}

#[test]
fn parquet_strips_alternate_direction() {
    let m = material("cherry", 0.0);
    let parquet = Placement {
        cutting: Cutting::Boards {
            layout: BoardLayout::Parquet {
                tile: 480.0,
                strip: 60.0,
            },
            region: TreeRegion::default(),
            seed: 9,
        },
        ..Default::default()
    };
    let mut r = Pcg32::new(2, 0);
    let (mut along_x, mut along_y) = (0, 0);
    for _ in 0..400 {
        let p = plane_point(&mut r, 900.0);
        let f = m.shade(&hit(p, Vec3::Z, Mat3::IDENTITY, parquet)).aov.fiber;
        assert!(f.z.abs() < 0.5, "fibre leaves the floor: {f}");
        if f.x.abs() > 0.9 {
            along_x += 1;
        } else if f.y.abs() > 0.9 {
            along_y += 1;
        }
    }
    // The strips of each square frame run along its sides: both directions are common.
    assert!(
        along_x > 100 && along_y > 100,
        "{along_x} along x, {along_y} along y"
    );
}

#[test]
fn veneer_faces_show_fibres_in_their_plane() {
    let m = material("walnut", 0.0);
    let veneer = Placement {
        cutting: Cutting::Veneer {
            region: TreeRegion::default(),
            seed: 5,
        },
        ..Default::default()
    };
    let mut r = Pcg32::new(4, 0);
    for n in [Vec3::X, Vec3::NEG_Y, Vec3::Z] {
        let mut sum = 0.0;
        for _ in 0..100 {
            let t = plane_point(&mut r, 50.0);
            let p = Mat3::from_cols(
                n.any_orthonormal_vector(),
                n.cross(n.any_orthonormal_vector()),
                n,
            ) * t
                + 50.0 * n;
            sum += m
                .shade(&hit(p, n, Mat3::IDENTITY, veneer))
                .aov
                .fiber
                .dot(n)
                .abs();
        }
        // A flat-sawn slice shows long grain: fibres in the face, whatever face it is.
        assert!(
            sum / 100.0 < 0.2,
            "face {n}: mean |fibre·n| = {}",
            sum / 100.0
        );
    }
}

#[test]
fn world_space_placement_ignores_the_instance_transform() {
    let m = material("african_mahogany", 0.0);
    let world = Placement {
        origin: Vec3::new(0.0, 120.0, 0.0),
        axis: Vec3::X,
        world_space: true,
        ..Default::default()
    };
    // The same world point on two instances with different object → world maps.
    let a = Mat3::from_rotation_z(0.7) * Mat3::from_diagonal(Vec3::new(2.0, 2.0, 2.0));
    let b = Mat3::from_rotation_x(-0.4);
    let pw = Vec3::new(31.0, -12.0, 7.0);
    let nw = Vec3::Z;
    let at = |to_world: Mat3| {
        let p = to_world.inverse() * pw;
        let n = (to_world.transpose() * nw).normalize();
        m.shade(&hit(p, n, to_world, world))
    };
    let (sa, sb) = (at(a), at(b));
    assert!((sa.aov.albedo - sb.aov.albedo).abs().max_element() < 1e-5);
    assert!(
        (sa.aov.fiber - sb.aov.fiber).length() < 1e-4,
        "{} vs {}",
        sa.aov.fiber,
        sb.aov.fiber
    );
    // Placed in object space instead, the two instances see different wood.
    let object = Placement {
        world_space: false,
        ..world
    };
    let p = |to_world: Mat3| to_world.inverse() * pw;
    let fa = m.shade(&hit(p(a), Vec3::Z, a, object)).aov.fiber;
    let fb = m.shade(&hit(p(b), Vec3::Z, b, object)).aov.fiber;
    assert!((fa - fb).length() > 0.1);
}

/// The bump-mapped normal is n − ∇ₛh (Blinn 1978) with the surface gradient of the height the
/// material looks up through a rotated, scaled placement on a rotated instance: exactly for the
/// texel's analytic gradient carried by the chain rule written out here, and in direction for
/// central differences of the height (the analytic gradient holds the fibre frame fixed, so the
/// two differ by the frame's rotation across a pore).
#[test]
fn bump_tilts_the_normal_against_the_height_gradient() {
    let k = 0.5;
    // Mahogany's pores are diffuse (no ring-porous resizing) with smooth bump kernels; the
    // exact distortion Jacobian makes the texel's gradient transport exact.
    let mut m = material("african_mahogany", k);
    m.volume = Arc::new(
        WoodVolume::new(wood::preset("african_mahogany").unwrap(), 3)
            .unwrap()
            .with_jacobian(JacobianModel::Exact),
    );
    let placement = Placement {
        origin: Vec3::new(0.0, 90.0, 0.0),
        axis: Vec3::new(1.0, 0.0, 0.3),
        rotation: 0.4,
        scale: 1.7,
        ..Default::default()
    };
    let to_world = Mat3::from_rotation_y(0.3);
    let texel = |p: Vec3| {
        let q = placement.object_to_tree().transform_point3(p);
        m.volume.eval(q, Needs::ALL)
    };
    let mut r = Pcg32::new(8, 0);
    let (mut checked, mut cos_sum) = (0, 0.0);
    for _ in 0..4000 {
        let p = plane_point(&mut r, 40.0);
        let h = hit(p, Vec3::Z, to_world, placement);
        let n = m.shade(&h).frame.n;
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-4);
        let surface = |g: Vec3| g - h.ng * g.dot(h.ng);
        // h(p) = bump(origin + s R p): ∇ₚh = s Rᵀ ∇h; to world by the normal matrix.
        let grad_tree = texel(p).bump_grad;
        let g = surface(
            h.normal_to_world * (placement.rotation_matrix().transpose() * grad_tree) * 1.7 * k,
        );
        let want = (h.ng - g).normalize();
        assert!(
            (n - want).length() < 1e-4,
            "at {p}: normal {n}, expected {want}"
        );
        // Central differences of the height along the object's x and y.
        let e = 2e-3;
        // Where overlapping kernels saturate the mask (a kink), differences do not apply.
        let around = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::ZERO];
        if g.length() < 0.05 || around.iter().any(|d| texel(p + *d * e).pore_mask >= 0.999) {
            continue;
        }
        let d = |a: Vec3| (texel(p + a * e).bump - texel(p - a * e).bump) / (2.0 * e);
        let g_fd = surface(h.normal_to_world * Vec3::new(d(Vec3::X), d(Vec3::Y), 0.0) * k);
        checked += 1;
        cos_sum += (h.ng - n).normalize().dot(g_fd.normalize());
    }
    let mean_cos = cos_sum / checked as f32;
    assert!(
        checked > 50 && mean_cos > 0.9,
        "{checked} checked, mean cosine {mean_cos}"
    );
}
