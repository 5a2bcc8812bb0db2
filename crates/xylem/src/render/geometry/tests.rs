//! The acceleration structure and hit reconstruction against closed forms.
use super::accel::triangle_frame;
use super::*;

fn unit_quad() -> TriMesh {
    TriMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        normals: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[test]
fn hit_point_matches_ray_equation_and_barycentrics() {
    let inst = Instance {
        mesh: Arc::new(unit_quad()),
        transform: Transform::new(Affine3A::from_translation(Vec3::new(0.0, 0.0, 2.0))),
        material: 0,
        placement: Placement::default(),
    };
    let accel = Accel::new(vec![inst]);
    let ray = Ray {
        o: Vec3::new(0.3, 0.6, 5.0),
        d: -Vec3::Z,
    };
    let hit = accel.intersect(&ray, f32::INFINITY).unwrap();
    assert!((hit.t - 3.0).abs() < 1e-5);
    let s = accel.surface(&ray, &hit);
    // Object-space point from barycentrics must equal the ray point moved back to object space.
    assert!(
        (s.p_object - Vec3::new(0.3, 0.6, 0.0)).length() < 1e-5,
        "{s:?}"
    );
    assert!((s.ng - Vec3::Z).length() < 1e-6);
    assert!(!accel.unoccluded(&ray, 10.0));
    assert!(accel.unoccluded(&ray, 2.9));
}

/// A hit's surface is the same whether its triangle's frame comes from the table (a mesh
/// placed once, flattened) or is worked out per hit (the same mesh placed twice, shared),
/// under a transform that shears and scales, so that every normalisation matters.
#[test]
fn tabled_triangle_frames_equal_per_hit_frames() {
    let mesh = Arc::new(unit_quad());
    let to_world = Affine3A::from_cols_array(&[
        1.3, 0.2, 0.1, -0.4, 0.9, 0.3, 0.2, -0.1, 1.7, 0.5, -0.25, 2.0,
    ]);
    let inst = |mesh: &Arc<TriMesh>| Instance {
        mesh: mesh.clone(),
        transform: Transform::new(to_world),
        material: 0,
        placement: Placement::default(),
    };
    let other = Arc::new(unit_quad());
    let once = Accel::new(vec![inst(&mesh)]);
    // The first two share one mesh (traced in object space, frames per hit).
    let twice = Accel::new(vec![inst(&other), inst(&other)]);
    assert!(!once.is_instanced(0) && twice.is_instanced(0));
    for (u, v) in [(0.3, 0.6), (0.7, 0.2), (0.5, 0.5)] {
        let hit = Hit {
            t: 4.0,
            instance: 0,
            triangle: (u > v) as u32,
            uv: Vec2::new(u, v),
        };
        let ray = Ray {
            o: Vec3::new(0.2, 0.4, 6.0),
            d: -Vec3::Z,
        };
        let (a, b) = (once.surface(&ray, &hit), twice.surface(&ray, &hit));
        for (x, y) in [(a.n_object, b.n_object), (a.ng, b.ng), (a.ns, b.ns)] {
            assert_eq!(x.to_array(), y.to_array());
        }
        assert_eq!(a.tangent.to_array(), b.tangent.to_array());
        let f = triangle_frame(&twice.instances[0], hit.triangle as usize);
        assert_eq!(a.tangent.to_array(), f.tangent.to_array());
    }
}

#[test]
fn degenerate_triangles_are_dropped() {
    let mut m = unit_quad();
    m.indices.push([0, 0, 1]);
    m.indices.push([0, 1, 9]);
    assert_eq!(m.drop_degenerate(), 2);
    assert_eq!(m.indices.len(), 2);
}
