//! Instancing: objects placing one mesh file share one BVH (memory grows with distinct geometry,
//! not with copies), and render as the same objects given as separate copies.

use std::fmt::Write;
use std::path::Path;
use std::sync::Arc;
use xylem::render::resources::Resources;
use xylem::render::{Accel, Instance, RenderSettings, RunOptions, TriMesh};
use xylem::scene::shapes::make_sphere;

/// `mesh` as OBJ text with its vertex normals.
fn obj(mesh: &TriMesh) -> String {
    let mut s = String::new();
    for p in &mesh.positions {
        writeln!(s, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for n in mesh.normals.as_ref().unwrap() {
        writeln!(s, "vn {} {} {}", n.x, n.y, n.z).unwrap();
    }
    for t in &mesh.indices {
        let [a, b, c] = t.map(|i| i + 1);
        writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}").unwrap();
    }
    s
}

/// A scene of `n` objects placing `ball.obj` (rotated, non-uniformly scaled, one flat-shaded) on
/// a table under one sphere light.
fn scene(n: usize) -> String {
    let mut s = String::from(
        "[render]\nwidth = 48\nheight = 32\nspp = 2\nseed = 3\n\n\
         [camera]\neye = [0.0, -260.0, 160.0]\ntarget = [0.0, 0.0, 10.0]\nfov_deg = 45.0\n\n\
         [[lights]]\ntype = \"sphere\"\ncenter = [150.0, -100.0, 300.0]\nradius = 10.0\nradiance = 3000.0\n\n\
         [materials.grey]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
         [[objects]]\nshape = \"box\"\nsize = [600.0, 600.0, 10.0]\ntranslate = [0.0, 0.0, -5.0]\nmaterial = \"grey\"\n",
    );
    for i in 0..n {
        let x = -120.0 + 80.0 * i as f32;
        writeln!(
            s,
            "\n[[objects]]\nshape = \"mesh\"\nfile = \"ball.obj\"\nmaterial = \"grey\"\n\
             translate = [{x}, 0.0, 25.0]\nrotate_deg = [{}, 20.0, 0.0]\nscale = [1.0, 1.5, 0.8]\nsmooth = {}",
            15.0 * i as f32,
            i != 1
        )
        .unwrap();
    }
    s
}

fn load(dir: &Path, n: usize) -> xylem::scene::LoadedScene {
    xylem::scene::from_str(&scene(n), "inst.toml", dir, "inst").unwrap()
}

#[test]
fn instances_of_one_mesh_store_it_once_and_render_as_copies() {
    let dir = tempfile::tempdir().unwrap();
    let ball = make_sphere(30.0, 48);
    let ball_triangles = ball.indices.len();
    std::fs::write(dir.path().join("ball.obj"), obj(&ball)).unwrap();
    let mut four = load(dir.path(), 4);
    let one = load(dir.path(), 1);
    let accel = &four.scene.accel;
    // Objects 0, 2, 3 share the smooth mesh, object 1 (smooth = false) has its own: two distinct.
    assert_eq!(accel.triangle_count(), 12 + 4 * ball_triangles);
    assert_eq!(accel.stored_triangle_count(), 12 + 2 * ball_triangles);
    let flat_copies = |accel: &Accel| -> Vec<Instance> {
        (accel.instances.iter())
            .map(|i| Instance {
                mesh: Arc::new((*i.mesh).clone()),
                ..i.clone()
            })
            .collect()
    };
    let copies = Accel::new(flat_copies(accel));
    assert_eq!(copies.stored_triangle_count(), accel.triangle_count());
    // Memory: four placements cost about two meshes, not four (the copies do cost four).
    let (inst_mem, copy_mem, one_mem) = (
        accel.memory_bytes() as f64,
        copies.memory_bytes() as f64,
        one.scene.accel.memory_bytes() as f64,
    );
    assert!(inst_mem < 2.2 * one_mem, "{inst_mem} vs one {one_mem}");
    assert!(copy_mem > 3.5 * one_mem, "{copy_mem} vs one {one_mem}");
    // The up-front estimate counts distinct meshes too.
    let est = |i: &[Instance]| Resources::geometry(i).memory as f64;
    let shared_est = est(&accel.instances);
    assert!(shared_est < 0.6 * est(&flat_copies(accel)), "{shared_est}");

    // Same image as the copies within float noise (object-space vs world-space intersection).
    let settings = RenderSettings {
        spp: 2,
        ..four.settings
    };
    let run = RunOptions::default();
    let a = xylem::render::render(&four.scene, &settings, &run)
        .unwrap()
        .image;
    four.scene.accel = copies;
    let b = xylem::render::render(&four.scene, &settings, &run)
        .unwrap()
        .image;
    let (mut sum, mut differing) = (0.0f64, 0);
    for (p, q) in a.beauty.iter().zip(&b.beauty) {
        let d = (*p - *q).abs().max_element() / p.max_element().max(q.max_element()).max(1e-3);
        sum += d as f64;
        differing += (d > 1e-3) as usize;
    }
    let px = a.beauty.len();
    assert!(
        a.beauty.iter().any(|p| p.max_element() > 0.05),
        "image is dark"
    );
    // Rounding may move a sample across a silhouette in a pixel or two, nothing more.
    assert!(differing <= 2, "{differing} of {px} pixels differ");
    assert!(
        sum / (px as f64) < 2e-3,
        "mean relative difference {}",
        sum / px as f64
    );
    // Normals under the non-uniform scale agree too (the AOV normal of every pixel).
    let same_normals = (a.aov.iter().zip(&b.aov))
        .filter(|(p, q)| (p.normal - q.normal).length() < 1e-3)
        .count();
    assert!(same_normals >= px - px / 100, "{same_normals} of {px}");
}

#[test]
fn four_placements_of_a_large_mesh_are_estimated_as_one() {
    // 4 × 5 M triangles flattened would need ≥ 9 GB to build (issue 15); placed as instances the
    // estimate is that of one mesh.
    let mesh = Arc::new(TriMesh {
        positions: vec![glam::Vec3::ZERO; 3],
        normals: None,
        indices: vec![[0, 1, 2]; 5_000_000],
    });
    let inst: Vec<Instance> = (0..4)
        .map(|_| Instance {
            mesh: mesh.clone(),
            transform: xylem::render::Transform::identity(),
            material: 0,
            placement: Default::default(),
        })
        .collect();
    let shared = Resources::geometry(&inst).memory;
    let single = Resources::geometry(&inst[..1]).memory;
    assert!(shared < single + 4096, "{shared} vs {single}");
    assert!(single > 2 << 30, "{single}");
}
