//! Wood reached after a bounce is band-limited too (issue 28): by the camera's footprint at the
//! hit's depth (pbrt-v4's `Approximate_dp_dxy`, `CameraRays::depth_footprint`), a lower bound on
//! the true one. A red-oak wall seen only in a mirror, at 6.25 mm a pixel: its rings (about 4 mm), pores (0.3 mm) and
//! cell texture alias into pixel noise when point-sampled; band-limited they fade to their mean.
//! Measured by what band-limiting does to a pixel's samples: they agree, so the pixels' standard
//! error over the wall falls, while the mean stays. Before this change hits after a bounce had
//! no footprint, so filter on and off were the same: the negative control is that state, the
//! ratio 1. (The aliasing power against the converged image is printed too; since the pixel
//! samples are stratified, 2026-12-04, point sampling no longer aliases measurably here.)

use xylem::math::luminance;
use xylem::render::{render, RunOptions};
use xylem_lab::aliasing::aliasing_power;

const SCENE: &str = r#"
[render]
width = 64
height = 64
spp = 16
integrator = "path"
max_depth = 2
seed = 3
footprint_filter = FILTER

[camera]
projection = "orthographic"
eye = [0.0, 0.0, 500.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
width = 400.0

[[lights]]
type = "distant"
direction = [0.0, 0.98, 0.2]
irradiance = 2.0

[materials.mirror]
type = "mirror"
reflectance = [0.95, 0.95, 0.95]

[materials.oak]
type = "wood"
preset = "red_oak"
seed = 1

[[objects]]
name = "mirror"
shape = "quad"
size = [1000.0, 1000.0]
material = "mirror"
# Normal (0, -1, 1)/sqrt 2: the camera's downward rays leave along -y.
rotate_deg = [45.0, 0.0, 0.0]

[[objects]]
name = "wall"
shape = "box"
size = [2000.0, 20.0, 2000.0]
translate = [0.0, -900.0, 0.0]
material = "oak"
tree = { axis = [0.0, 0.0, 1.0], origin = [120.0, 0.0, 0.0] }
"#;

/// The image's luminance at `spp` with the filter on or off and seed `seed`, and the pixels'
/// standard errors.
fn luminance_image(filter: bool, spp: u32, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let text = SCENE.replace("FILTER", if filter { "true" } else { "false" });
    let dir = std::env::temp_dir();
    let mut s = xylem::scene::from_str(&text, "bounce.toml", &dir, "bounce").unwrap();
    (s.settings.spp, s.settings.seed) = (spp, seed);
    let img = render(&s.scene, &s.settings, &RunOptions::default())
        .unwrap()
        .image;
    let lum = img.beauty.iter().map(|c| luminance(*c) as f64).collect();
    (lum, img.std_error.iter().map(|&e| e as f64).collect())
}

#[test]
fn wood_seen_in_a_mirror_is_band_limited() {
    // The converged point-sampled image (the supersampled one) in two halves, and two renders of
    // each kind at the scene's 16 spp: aliasing is the high-pass power of the error with the
    // noise's share measured from them (`aliasing_power`).
    let (a, b) = (
        luminance_image(false, 128, 11).0,
        luminance_image(false, 128, 12).0,
    );
    let mask = vec![true; a.len()];
    let aliasing = |filter: bool| {
        let ((x1, e1), (x2, _)) = (
            luminance_image(filter, 16, 1),
            luminance_image(filter, 16, 2),
        );
        let (p, _, n) = aliasing_power([&x1, &x2], [&a, &b], &mask, 64, 64);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        (p / n as f64, mean(&x1), mean(&e1))
    };
    let (filtered, mean_f, error_f) = aliasing(true);
    let (point, mean_p, error_p) = aliasing(false);
    println!(
        "aliasing power: filtered {filtered:.3e}, point-sampled {point:.3e}; means {mean_f:.4} \
         {mean_p:.4}; pixel standard errors {error_f:.3e} {error_p:.3e}"
    );
    assert!(
        mean_f > 0.01,
        "the wall is lit and seen in the mirror: {mean_f}"
    );
    // Band-limiting keeps the mean (the features fade to it) ...
    assert!((mean_f / mean_p - 1.0).abs() < 0.1, "{mean_f} vs {mean_p}");
    // ... and a pixel's samples see the same faded wood: its standard error falls.
    assert!(error_f < 0.5 * error_p, "{error_f:.3e} vs {error_p:.3e}");
}
