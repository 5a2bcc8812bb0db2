//! Rendering many frames at once must not change the picture: every frame of a sweep rendered in
//! one pass equals the render of that frame alone (its lights fixed), bit for bit, for direct
//! lighting and for path tracing, and for a slice of frames as for the whole sweep.

use std::path::Path;
use xylem::render::{render_frames, Integrator, LightFrames, RunOptions};
use xylem::scene::{from_str, LoadedScene};
use xylem::sweep::{render_sweep, SweepPath};

/// A grey box on a floor, lit by a point light that sweeps and a dim rectangle that stays.
const SCENE: &str = r#"
[render]
width = 20
height = 14
spp = 3
seed = 11

[camera]
eye = [0.0, -260.0, 180.0]
target = [0.0, 0.0, 10.0]
fov_deg = 45.0

[[lights]]
type = "point"
name = "key"
position = [0.0, 0.0, 300.0]
intensity = 40000.0

[[lights]]
type = "rect"
name = "fill"
corner = [-100.0, 150.0, 40.0]
edge_u = [200.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 120.0]
radiance = 0.4

[materials.grey]
type = "lambertian"
albedo = [0.6, 0.5, 0.4]

[[objects]]
shape = "quad"
size = [300.0, 300.0]
material = "grey"

[[objects]]
shape = "box"
size = [60.0, 40.0, 50.0]
translate = [0.0, 0.0, 25.0]
material = "grey"

[sweep]
frames = 7
arc_deg = [-70.0, 50.0]
light = "key"
radius = 300.0
"#;

/// A finished-wood board under a sphere light that sweeps between a rectangle before it and a
/// point light after it in the scene's list (so the next-event terms of the lights that stay are
/// summed around the moving one): the wood BSDF prepared per `wo`, the sphere's cone sampling,
/// a light seen directly by the camera and BSDF-sampled rays that meet it.
const WOOD_SCENE: &str = r#"
[render]
width = 24
height = 16
spp = 3
seed = 5

[camera]
eye = [0.0, -200.0, 150.0]
target = [0.0, 0.0, 10.0]
fov_deg = 70.0

[[lights]]
type = "rect"
name = "fill"
corner = [-100.0, 150.0, 40.0]
edge_u = [200.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 120.0]
radiance = 0.4

[[lights]]
type = "sphere"
name = "key"
center = [0.0, 0.0, 200.0]
radius = 30.0
radiance = 40.0

[[lights]]
type = "point"
name = "rim"
position = [-120.0, 80.0, 90.0]
intensity = 3000.0

[materials.finish]
type = "fiber"
diffuse = [0.5, 0.3, 0.15]
fiber_color = [0.6, 0.4, 0.25]
fiber_dir = [0.9, 0.0, -0.43589]
ray_mask = 0.3
highlight_width_deg = 6.0
eta = 1.5

[materials.grey]
type = "lambertian"
albedo = [0.3, 0.3, 0.3]

[[objects]]
shape = "quad"
size = [400.0, 400.0]
material = "grey"

[[objects]]
shape = "box"
size = [160.0, 90.0, 18.0]
translate = [0.0, 0.0, 9.0]
material = "finish"

[sweep]
frames = 9
arc_deg = [-60.0, 60.0]
light = "key"
radius = 200.0
"#;

fn load() -> LoadedScene {
    from_str(SCENE, "sweep_frames_test.toml", Path::new("."), "test").unwrap()
}

fn max_relative_difference(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((*x - *y).abs().max_element()) / y.max_element().max(1e-6))
        .fold(0.0, f32::max)
}

fn check(integrator: Integrator, frames: std::ops::Range<usize>) {
    check_scene(&load(), integrator, frames);
}

fn check_scene(loaded: &LoadedScene, integrator: Integrator, frames: std::ops::Range<usize>) {
    let mut settings = loaded.settings;
    settings.integrator = integrator;
    let (path, moving) =
        SweepPath::from_scene(loaded, None, None).expect("the scene's [sweep] table");
    let run = RunOptions {
        threads: 1,
        ..Default::default()
    };
    let sweep = render_sweep(
        &loaded.scene,
        &settings,
        &path,
        moving,
        frames.clone(),
        &run,
    )
    .unwrap();
    assert_eq!(sweep.frames.len(), frames.len());
    let mut lit = 0;
    let all = path.light_frames(&loaded.scene.lights, moving, frames.clone());
    for (k, f) in frames.clone().enumerate() {
        // The frame rendered alone, its lights fixed: every value must be the same bits.
        let alone = LightFrames::fixed(all.frame(k));
        let naive = render_frames(&loaded.scene, &alone, &settings, &run).unwrap();
        let naive = naive.image(0);
        let swept = sweep.image(k);
        assert_eq!(swept.beauty, naive.beauty, "frame {f}: beauty");
        assert_eq!(swept.aov, naive.aov, "frame {f}: AOVs");
        assert_eq!(swept.std_error, naive.std_error, "frame {f}: std error");
        assert_eq!(swept.nonfinite, naive.nonfinite, "frame {f}");
        lit += swept
            .beauty
            .iter()
            .filter(|c| c.max_element() > 0.0)
            .count();
    }
    let cam = &loaded.scene.camera;
    assert!(
        lit > frames.len() * (cam.width * cam.height) as usize / 2,
        "frames are mostly lit: {lit}"
    );
}

#[test]
fn swept_direct_lighting_equals_frames_alone() {
    check(Integrator::Direct, 0..7);
}

#[test]
fn swept_path_tracing_equals_frames_alone_for_a_slice() {
    check(Integrator::Path { max_depth: 3 }, 2..5);
}

#[test]
fn swept_wood_under_a_sphere_light_between_fixed_lights_equals_frames_alone() {
    let loaded = from_str(WOOD_SCENE, "sweep_frames_wood.toml", Path::new("."), "test").unwrap();
    check_scene(&loaded, Integrator::Direct, 0..9);
    // The sphere is seen directly in some frames (the camera's view of it), which the check
    // above covers only if it happens: make sure it does.
    let (path, moving) = SweepPath::from_scene(&loaded, None, None).unwrap();
    let run = RunOptions {
        threads: 1,
        ..Default::default()
    };
    let s = render_sweep(&loaded.scene, &loaded.settings, &path, moving, 0..9, &run).unwrap();
    let brightest = s
        .frames
        .iter()
        .flat_map(|f| f.beauty.iter())
        .map(|c| c.max_element())
        .fold(0.0, f32::max);
    assert!(
        brightest > 30.0,
        "the sphere (radiance 40) is in view: {brightest}"
    );
}

#[test]
fn frames_differ_as_the_light_moves() {
    let loaded = load();
    let (path, moving) = SweepPath::from_scene(&loaded, None, None).unwrap();
    let run = RunOptions::default();
    let s = render_sweep(&loaded.scene, &loaded.settings, &path, moving, 0..7, &run).unwrap();
    // The light angle runs from −70° to 50°; the first and last frames are lit differently.
    assert!((path.light_deg(0) + 70.0).abs() < 1e-5);
    assert!((path.light_deg(6) - 50.0).abs() < 1e-5);
    assert!(max_relative_difference(&s.frames[0].beauty, &s.frames[6].beauty) > 0.1);
}

#[test]
fn culled_shadow_test_answers_as_the_bvh() {
    // Segments from points just off the surfaces (offset as the renderer offsets shadow rays)
    // and from anywhere, in random directions and lengths: the box-culled query must give the
    // BVH's answer every time, blocked and unblocked cases both occurring.
    use xylem::math::{uniform_sphere, Pcg32};
    use xylem::render::shadow::ShadowTest;
    use xylem::render::Ray;
    let loaded = from_str(WOOD_SCENE, "sweep_frames_wood.toml", Path::new("."), "test").unwrap();
    let accel = &loaded.scene.accel;
    let (culled, bvh) = (ShadowTest::culled(accel), ShadowTest::bvh(accel));
    let eps = 2e-5 * accel.scale();
    let mut rng = Pcg32::new(17, 4);
    let (mut blocked, mut free) = (0, 0);
    for i in 0..20_000 {
        let o = glam::Vec3::new(300.0, 300.0, 120.0)
            * (2.0 * rng.next_vec2().extend(rng.next_f32()) - 1.0);
        let probe = Ray {
            o,
            d: uniform_sphere(rng.next_vec2()),
        };
        let origin = match (i % 2 == 0)
            .then(|| accel.intersect(&probe, f32::INFINITY))
            .flatten()
        {
            Some(h) => {
                let s = accel.surface(&probe, &h);
                let n = if s.ng.dot(probe.d) < 0.0 { s.ng } else { -s.ng };
                s.p + n * eps
            }
            None => o,
        };
        let ray = Ray {
            o: origin,
            d: uniform_sphere(rng.next_vec2()),
        };
        let t_max = if i % 7 == 0 {
            f32::INFINITY
        } else {
            400.0 * rng.next_f32()
        };
        let want = bvh.unoccluded(&ray, t_max);
        assert_eq!(culled.unoccluded(&ray, t_max), want, "{ray:?} {t_max}");
        if want {
            free += 1;
        } else {
            blocked += 1;
        }
    }
    assert!(blocked > 1000 && free > 1000, "{blocked} {free}");
}

#[test]
fn batch_culled_shadow_segments_are_unoccluded() {
    // `culled_many` (a sweep's shadow segments box-tested all frames at once) may only cull
    // segments the BVH finds unoccluded: from the camera's first hits towards sphere lights at
    // random places, above and below the board's top, both culled and kept segments occurring.
    use xylem::math::Pcg32;
    use xylem::render::light::{LightSamples, LightU};
    use xylem::render::shadow::{Segments, ShadowTest};
    use xylem::render::{primary_sample, Ray};
    let loaded = from_str(WOOD_SCENE, "sweep_frames_wood.toml", Path::new("."), "test").unwrap();
    let scene = &loaded.scene;
    let (culled_test, bvh) = (
        ShadowTest::culled(&scene.accel),
        ShadowTest::bvh(&scene.accel),
    );
    let mut rng = Pcg32::new(23, 1);
    let (mut samples, mut seg, mut culled) = (LightSamples::default(), Segments::default(), vec![]);
    let (mut n_culled, mut n_kept) = (0, 0);
    for y in 0..scene.camera.height {
        for x in 0..scene.camera.width {
            let Some(sp) = primary_sample(scene, glam::UVec2::new(x, y), 0, 3, 1.0).point else {
                continue;
            };
            let centers: [Vec<f32>; 3] = [
                (0..24).map(|_| 400.0 * rng.next_f32() - 200.0).collect(),
                (0..24).map(|_| 400.0 * rng.next_f32() - 200.0).collect(),
                (0..24).map(|_| 300.0 * rng.next_f32() - 20.0).collect(),
            ];
            let u = LightU::new(rng.next_vec2());
            samples.sample_sphere(sp.p, &centers, 5.0, glam::Vec3::ONE, &u);
            culled_test.culled_many(&sp, &samples, &mut seg, &mut culled);
            for (k, &is_culled) in culled.iter().enumerate().take(samples.len()) {
                let Some(ls) = samples.get(k) else { continue };
                let side = if sp.ng.dot(ls.wi) >= 0.0 { 1.0 } else { -1.0 };
                let ray = Ray {
                    o: sp.p + sp.ng * (side * sp.eps),
                    d: ls.wi,
                };
                let t_max = ls.dist * (1.0 - 1e-4);
                if is_culled {
                    assert!(bvh.unoccluded(&ray, t_max), "{ray:?} {t_max}");
                    n_culled += 1;
                } else {
                    n_kept += 1;
                }
            }
        }
    }
    assert!(n_culled > 2000 && n_kept > 300, "{n_culled} {n_kept}");
}
