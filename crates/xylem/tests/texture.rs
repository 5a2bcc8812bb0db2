//! The classic solid textures: construction by name with checked parameters, finite colours
//! everywhere, determinism, and properties of the constructions that can fail.

use std::collections::BTreeMap;
use xylem::math::{Pcg32, Vec3};
use xylem::texture::{self, by_name, first_non_finite, Plane, Slice, TextureError, NAMES};

fn defaults(name: &str) -> Box<dyn texture::SolidTexture> {
    by_name(name, &BTreeMap::new()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn with(name: &str, kv: &[(&str, f32)]) -> Box<dyn texture::SolidTexture> {
    let m = kv.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    by_name(name, &m).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_texture_is_finite_nonnegative_and_varies() {
    let mut r = Pcg32::new(1, 0);
    for name in NAMES {
        let t = defaults(name);
        let mut first = None;
        let mut varies = false;
        for k in 0..4000 {
            let scale = if k % 4 == 0 { 1e5 } else { 200.0 };
            let p = (Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) - 0.5) * scale;
            let c = t.eval(p);
            assert!(
                c.is_finite() && c.min_element() >= 0.0,
                "{name} at {p}: {c}"
            );
            varies |= first.is_some_and(|f: Vec3| (f - c).length() > 1e-3);
            first.get_or_insert(c);
        }
        for p in [Vec3::ZERO, Vec3::Z * 5.0, Vec3::splat(-1e5)] {
            assert!(t.eval(p).is_finite(), "{name} at {p}");
        }
        assert!(varies, "{name} is constant");
        // Deterministic: a second instance gives the same bits.
        let p = Vec3::new(12.5, -3.25, 40.0);
        assert_eq!(t.eval(p).to_array(), defaults(name).eval(p).to_array());
    }
}

#[test]
fn declared_defaults_are_in_range_and_seeds_matter() {
    for name in NAMES {
        let spec = texture::params(name).unwrap();
        assert!(!spec.is_empty());
        for s in spec {
            assert!(
                s.min <= s.default && s.default <= s.max,
                "{name}.{}",
                s.name
            );
            assert!(!s.doc.is_empty());
        }
        if spec.iter().any(|s| s.name == "seed") {
            let (a, b) = (with(name, &[("seed", 1.0)]), with(name, &[("seed", 2.0)]));
            let differ = (0..200)
                .filter(|&i| {
                    let p = Vec3::new(i as f32 * 3.7, i as f32 * 1.3, 5.0);
                    a.eval(p) != b.eval(p)
                })
                .count();
            // Some textures saturate (marble is mostly white), so only a fraction must change.
            assert!(
                differ > 20,
                "{name}: seed changes only {differ} of 200 points"
            );
        }
    }
}

#[test]
fn bad_names_and_parameters_are_reported() {
    let none = BTreeMap::new();
    let e = by_name("granite", &none).err().unwrap();
    assert!(matches!(e, TextureError::UnknownTexture { .. }));
    let msg = e.to_string();
    for n in NAMES {
        assert!(msg.contains(n), "{msg}");
    }
    let bogus: BTreeMap<String, f32> = [("bogus".to_string(), 1.0)].into();
    let msg = by_name("marble", &bogus).err().unwrap().to_string();
    assert!(
        msg.contains("bogus") && msg.contains("frequency") && msg.contains("seed"),
        "{msg}"
    );
    let neg: BTreeMap<String, f32> = [("scale".to_string(), -1.0)].into();
    let e = by_name("gradient", &neg).err().unwrap();
    assert!(
        matches!(e, TextureError::OutOfRange { min, .. } if min > 0.0),
        "{e}"
    );
    let nan: BTreeMap<String, f32> = [("octaves".to_string(), f32::NAN)].into();
    assert!(by_name("fbm", &nan).is_err());
    // Too many impulses per cell for the sparse convolution noise: the noise's own check.
    let dense: BTreeMap<String, f32> = [
        ("density".to_string(), 50.0),
        ("cell_scale".to_string(), 10.0),
    ]
    .into();
    let msg = by_name("sparse_convolution", &dense)
        .err()
        .unwrap()
        .to_string();
    assert!(msg.contains("impulses per cell"), "{msg}");
}

#[test]
fn ring_wood_depends_on_radius_only_without_wobble_and_tilt() {
    let t = with("ring_wood", &[("wobble", 0.0), ("tilt", 0.0)]);
    let mut r = Pcg32::new(2, 0);
    for _ in 0..1000 {
        let radius = 60.0 * r.next_f32();
        let (a, z) = (std::f32::consts::TAU * r.next_f32(), 100.0 * r.next_f32());
        let p = Vec3::new(radius * a.cos(), radius * a.sin(), z);
        let c = t.eval(p);
        assert!((c - t.eval(Vec3::new(radius, 0.0, 0.0))).length() < 1e-4);
    }
    // Rings repeat with the spacing: radius r and r + 4 mm have the same colour.
    let c = t.eval(Vec3::new(10.3, 0.0, 0.0));
    assert!((c - t.eval(Vec3::new(14.3, 0.0, 0.0))).length() < 1e-3);
}

#[test]
fn log_wood_rings_thin_with_taper() {
    // Without noise, ring boundaries sit where f (r + α r²) = 2π k + const: with α > 0 the k-th
    // ring is thinner than the first. Count light→dark transitions along x in two windows.
    let t = with(
        "log_wood",
        &[
            ("warp", 0.0),
            ("warp_fine", 0.0),
            ("grain", 0.0),
            ("tint", 0.0),
            ("taper", 0.02),
        ],
    );
    let count = |a: f32, b: f32| {
        let mut n = 0;
        let mut prev = t.eval(Vec3::new(a, 0.0, 0.0)).x;
        let mut x = a;
        while x < b {
            x += 0.01;
            let v = t.eval(Vec3::new(x, 0.0, 0.0)).x;
            n += (prev > 0.45 && v <= 0.45) as u32;
            prev = v;
        }
        n
    };
    let (inner, outer) = (count(0.0, 20.0), count(60.0, 80.0));
    // f = 2π/3: inner window ≈ (20 + 0.02·400)/3 ≈ 9 rings, outer ≈ (20 + 0.02·2800)/3 ≈ 25.
    assert!((8..=10).contains(&inner), "inner {inner}");
    assert!((24..=27).contains(&outer), "outer {outer}");
}

#[test]
fn slices_map_pixels_to_the_plane() {
    let s = Slice {
        plane: Plane::Xz,
        offset: 7.0,
        size: 10.0,
        res: 10,
        samples: 1,
    };
    assert_eq!(s.point(0, 0), Vec3::new(-4.5, 7.0, 4.5));
    assert_eq!(s.point(9, 9), Vec3::new(4.5, 7.0, -4.5));
    let px = s.render(&|p| p);
    assert_eq!(px.len(), 100);
    assert_eq!(px[10 * 3 + 2], s.point(2, 3));
    assert_eq!(first_non_finite(&px, 10), None);
    let mut bad = px.clone();
    bad[10 * 4 + 1] = Vec3::NAN;
    assert_eq!(first_non_finite(&bad, 10), Some((1, 4)));
    assert_eq!("YZ".parse::<Plane>(), Ok(Plane::Yz));
    assert!("zz".parse::<Plane>().unwrap_err().contains("xy, xz, yz"));
}

#[test]
fn batch_slices_equal_pointwise_slices() {
    // `render_rows` with `eval_many` (the batch noise calls in the gradient and fBm views) gives
    // the colours of `render` with `eval`, pixel for pixel; 37 px rows leave a scalar tail on
    // every SIMD width, and the fBm view is checked for all three kinds.
    let s = Slice {
        plane: Plane::Xy,
        offset: 3.3,
        size: 120.0,
        res: 37,
        samples: 1,
    };
    let mut cases: Vec<Box<dyn texture::SolidTexture>> =
        NAMES.iter().map(|n| defaults(n)).collect();
    cases.push(with("fbm", &[("kind", 1.0), ("octaves", 7.0)]));
    cases.push(with("fbm", &[("kind", 2.0), ("octaves", 3.0)]));
    cases.push(with("fbm", &[("basis", 1.0)]));
    for (k, t) in cases.iter().enumerate() {
        let one = s.render(&|p| t.eval(p));
        let many = s.render_rows(&|p, o| t.eval_many(p, o));
        assert_eq!(one, many, "case {k}");
    }
}

/// RMS difference of two images (every channel of every pixel).
fn rms(a: &[Vec3], b: &[Vec3]) -> f32 {
    let sum: f32 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).length_squared())
        .sum();
    (sum / (3 * a.len()) as f32).sqrt()
}

/// Slices of every texture at the README's scale (100 mm over 192 px; rust 200 mm, fabric 20 mm),
/// 48 px of it, against the same slice supersampled 16 × 16 per pixel (the box filter a pixel
/// shows): the default 4 × 4 grid stays within `BOUND` RMS (linear RGB 0–1) of it where
/// point-sampling the pixel centre (the control) is farther off on the textures with detail below
/// a pixel. Figures in notes/picture.md.
#[test]
fn default_slices_match_a_supersampled_reference() {
    const BOUND: f32 = 0.02;
    let mut aliased = Vec::new();
    for name in NAMES {
        let width = match name {
            "rust" => 200.0,
            "fabric" => 20.0,
            _ => 100.0,
        };
        let t = defaults(name);
        let slice = |samples| Slice {
            plane: Plane::Xy,
            offset: 0.0,
            size: width * 48.0 / 192.0,
            res: 48,
            samples,
        };
        let render = |samples| slice(samples).render_rows(&|p, o| t.eval_many(p, o));
        let reference = render(texture::MAX_SLICE_SAMPLES);
        let (default, point) = (
            rms(&render(texture::DEFAULT_SLICE_SAMPLES), &reference),
            rms(&render(1), &reference),
        );
        println!("{name}: default {default:.4}, point-sampled {point:.4}");
        assert!(default <= BOUND, "{name}: {default} from the reference");
        if point > BOUND {
            aliased.push(name);
        }
    }
    println!("point-sampled beyond {BOUND}: {aliased:?}");
    for name in ["rust", "ring_wood", "log_wood"] {
        assert!(aliased.contains(&name), "{name} should alias point-sampled");
    }
}
