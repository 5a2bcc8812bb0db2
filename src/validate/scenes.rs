//! Does each built-in scene show what it is for? One or two numbers per scene, measured on its
//! beauty image, with thresholds derived from what "visible" means (notes/scenes.md):
//!
//! - a luminance step is visible when its Weber contrast |a − b| / max(a, b) is at least 0.1
//!   (5× the ≈ 2 % threshold of luminance discrimination, Weber's law) and the difference of the
//!   two means is at least 5 standard errors (so it is not noise);
//! - an image is clean when no pixel is more than 10× the median of its 3×3 neighbourhood
//!   (issue 17's firefly criterion), on diffuse and glossy surfaces (a mirror's or glass's image
//!   of the light is a real feature, not a firefly);
//! - a figure (curl, rings) is visible when the beauty's local contrast (pixel against its 5×5
//!   mean) exceeds 0.05 after the pixels' own noise is taken out.
//!
//! Pixels are labelled by what the camera ray through their centre hits first (object, triangle,
//! face normal), independently of the shading.

use crate::math::luminance;
use crate::render::{integrator::nearest_light, Image, Scene};
use glam::{Vec2, Vec3};

/// What the ray through a pixel's centre meets first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelHit {
    /// The ray leaves the scene (background).
    Nothing,
    /// The ray meets a light before any surface.
    Light,
    /// The ray meets a surface.
    Surface {
        /// The instance index in the scene's acceleration structure.
        object: u32,
        /// The triangle index within that instance's mesh.
        triangle: u32,
        /// Geometric normal (world, unit, as the mesh winds it).
        normal: Vec3,
        /// True for a mirror or glass (every lobe a delta).
        delta: bool,
    },
}

/// The first hit of each pixel's centre ray (row-major, top row first).
pub fn pixel_hits(scene: &Scene) -> Vec<PixelHit> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let ray = scene
                .camera
                .ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
            let hit = scene.accel.intersect(&ray, f32::INFINITY);
            let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
            if let Some((_, t, _, _)) = nearest_light(&scene.lights, &ray, t_hit) {
                if t < t_hit {
                    out.push(PixelHit::Light);
                    continue;
                }
            }
            out.push(match hit {
                None => PixelHit::Nothing,
                Some(hit) => {
                    let s = scene.accel.surface(&ray, &hit);
                    let inst = &scene.accel.instances[hit.instance as usize];
                    let delta = scene.materials[inst.material as usize].is_delta();
                    PixelHit::Surface {
                        object: hit.instance,
                        triangle: hit.triangle,
                        normal: s.ng,
                        delta,
                    }
                }
            });
        }
    }
    out
}

/// The largest ratio of a pixel's luminance to the median of its 3×3 neighbourhood, over the
/// pixels whose whole neighbourhood is `keep`; with the pixel index where it occurs. Infinite
/// when no pixel qualifies (nothing to judge is not clean).
pub fn firefly_ratio(img: &Image, keep: &[bool]) -> (f64, usize) {
    let (w, h) = (img.width as usize, img.height as usize);
    let lum: Vec<f64> = img.beauty.iter().map(|c| luminance(*c) as f64).collect();
    let (mut worst, mut judged) = ((0.0, 0), 0usize);
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let mut n = [0.0f64; 9];
            let mut all = true;
            for (k, v) in n.iter_mut().enumerate() {
                let i = (y + k / 3 - 1) * w + x + k % 3 - 1;
                all &= keep[i];
                *v = lum[i];
            }
            if !all {
                continue;
            }
            n.sort_by(f64::total_cmp);
            judged += 1;
            let r = lum[y * w + x] / n[4].max(1e-12);
            if r > worst.0 {
                worst = (r, y * w + x);
            }
        }
    }
    if judged == 0 {
        return (f64::INFINITY, 0);
    }
    worst
}

/// Two pixel sets' mean luminances compared.
#[derive(Clone, Copy, Debug)]
pub struct Contrast {
    /// Mean luminance of set a.
    pub mean_a: f64,
    /// Mean luminance of set b.
    pub mean_b: f64,
    /// Pixels in set a.
    pub pixels_a: usize,
    /// Pixels in set b.
    pub pixels_b: usize,
    /// |a − b| / max(a, b).
    pub weber: f64,
    /// |a − b| over the standard error of the difference (from the pixels' spread).
    pub z: f64,
}

/// Fewer pixels than this in either set and [`contrast`] reports no contrast (0): a subject
/// that does not show cannot pass.
pub const MIN_PIXELS: usize = 20;

/// Mean luminance of the pixels in `a` against those in `b`.
pub fn contrast(img: &Image, a: &[bool], b: &[bool]) -> Contrast {
    let stats = |set: &[bool]| {
        let v: Vec<f64> = (img.beauty.iter().zip(set))
            .filter(|(_, &s)| s)
            .map(|(c, _)| luminance(*c) as f64)
            .collect();
        let n = v.len().max(1) as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0).max(1.0);
        (m, var / n, v.len())
    };
    let (ma, sa, na) = stats(a);
    let (mb, sb, nb) = stats(b);
    let d = if na < MIN_PIXELS || nb < MIN_PIXELS {
        0.0
    } else {
        (ma - mb).abs()
    };
    Contrast {
        mean_a: ma,
        mean_b: mb,
        pixels_a: na,
        pixels_b: nb,
        weber: d / ma.max(mb).max(1e-12),
        z: d / (sa + sb).sqrt().max(1e-300),
    }
}

/// Local contrast of the pixels in `set` whose 5×5 neighbourhood lies in `set`: the RMS of each
/// pixel's luminance minus its 5×5 mean, with the pixels' own noise (their `std_error`²)
/// subtracted, over the mean luminance.
pub fn figure_contrast(img: &Image, set: &[bool]) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let lum: Vec<f64> = img.beauty.iter().map(|c| luminance(*c) as f64).collect();
    let (mut r2, mut noise2, mut sum, mut n) = (0.0, 0.0, 0.0, 0usize);
    for y in 2..h.saturating_sub(2) {
        for x in 2..w.saturating_sub(2) {
            let mut local = 0.0;
            let mut all = true;
            for k in 0..25 {
                let i = (y + k / 5 - 2) * w + x + k % 5 - 2;
                all &= set[i];
                local += lum[i];
            }
            if !all {
                continue;
            }
            let i = y * w + x;
            let r = lum[i] - local / 25.0;
            r2 += r * r;
            noise2 += (img.std_error[i] as f64).powi(2);
            sum += lum[i];
            n += 1;
        }
    }
    if n == 0 {
        return 0.0;
    }
    ((r2 - noise2).max(0.0) / n as f64).sqrt() / (sum / n as f64).max(1e-12)
}

/// How much a solid-texture coordinate jumps across a face edge: the mean |Δ growth time|
/// between pixels 3 apart on two different faces of the object over the same between pixels on
/// one face (each pixel's 3×3 neighbourhood on one face, so no pixel mixes faces). About 1 where
/// the wood runs on around the edge (carved from a block), large where each face is its own
/// slice (veneer, Liu et al. 2016 Fig. 18).
pub fn edge_jump(img: &Image, hits: &[PixelHit], object: u32) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let face = |i: usize| match hits[i] {
        PixelHit::Surface {
            object: o, normal, ..
        } if o == object => Some((normal * 4.0).round().as_ivec3()),
        _ => None,
    };
    let interior = |x: usize, y: usize| {
        if x < 1 || y < 1 || x + 1 >= w || y + 1 >= h {
            return None;
        }
        let f = face(y * w + x)?;
        (0..9)
            .all(|k| face((y + k / 3 - 1) * w + x + k % 3 - 1) == Some(f))
            .then_some(f)
    };
    let gt = |x: usize, y: usize| img.aov[y * w + x].growth_time as f64;
    let (mut across, mut na, mut within, mut nw) = (0.0, 0usize, 0.0, 0usize);
    for y in 0..h {
        for x in 0..w {
            let Some(f) = interior(x, y) else { continue };
            for (qx, qy) in [(x + 3, y), (x, y + 3)] {
                let Some(g) = interior(qx, qy) else { continue };
                let d = (gt(x, y) - gt(qx, qy)).abs();
                if f == g {
                    within += d;
                    nw += 1;
                } else {
                    across += d;
                    na += 1;
                }
            }
        }
    }
    if na == 0 || nw == 0 {
        return f64::NAN;
    }
    (across / na as f64) / (within / nw as f64).max(1e-12)
}

/// The largest relative deviation, over the channels, of the mean beauty of the pixels that see
/// only the light (the rays through their centre and four corners all meet it first; the light
/// is a convex quad, so then the whole pixel does) from its radiance `expected`. Infinite when
/// no pixel sees only the light.
pub fn light_error(scene: &Scene, img: &Image, hits: &[PixelHit], expected: Vec3) -> f64 {
    let w = img.width as usize;
    let sees_light = |film: Vec2| {
        let ray = scene.camera.ray(film, Vec2::splat(0.5));
        let t_hit = scene
            .accel
            .intersect(&ray, f32::INFINITY)
            .map_or(f32::INFINITY, |h| h.t);
        nearest_light(&scene.lights, &ray, t_hit).is_some_and(|(_, t, _, _)| t < t_hit)
    };
    let (mut sum, mut n) = (glam::DVec3::ZERO, 0usize);
    for (i, h) in hits.iter().enumerate() {
        let p = Vec2::new((i % w) as f32, (i / w) as f32);
        let corners = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        if *h == PixelHit::Light && corners.iter().all(|&c| sees_light(p + c)) {
            sum += img.beauty[i].as_dvec3();
            n += 1;
        }
    }
    if n == 0 {
        return f64::INFINITY;
    }
    let ratio = sum / n as f64 / expected.as_dvec3();
    (ratio - glam::DVec3::ONE).abs().max_element()
}

/// Colour bleeding from one side wall: (channel `a` / channel `b` of the mean of the `set`
/// pixels in the image's `third`, 0 = left, 2 = right) over the same in the middle third. Above
/// 1 where the wall on that side tints the white surfaces near it. 0 when either third has
/// fewer than [`MIN_PIXELS`].
pub fn bleed_ratio(img: &Image, set: &[bool], third: usize, a: usize, b: usize) -> f64 {
    let w = img.width as usize;
    let ratio = |t: usize| {
        let (mut sum, mut n) = (glam::DVec3::ZERO, 0usize);
        for (i, c) in img.beauty.iter().enumerate() {
            if set[i] && 3 * (i % w) / w == t {
                sum += c.as_dvec3();
                n += 1;
            }
        }
        (n >= MIN_PIXELS).then(|| sum[a] / sum[b].max(1e-300))
    };
    match (ratio(third), ratio(1)) {
        (Some(side), Some(middle)) => side / middle.max(1e-300),
        _ => 0.0,
    }
}

/// Median of the sRGB-encoded luminance of a pixel set (0–1): how bright it looks in the PNG.
pub fn median_srgb(img: &Image, set: &[bool], exposure: f32) -> f64 {
    let k = 2f32.powf(exposure);
    let mut v: Vec<f32> = (img.beauty.iter().zip(set))
        .filter(|(_, &s)| s)
        .map(|(c, _)| crate::render::image_io::linear_to_srgb(luminance(*c) * k))
        .collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    v[v.len() / 2] as f64
}

/// One measured number of a scene, with its limit.
#[derive(Clone, Debug)]
pub struct Measure {
    /// What was measured, in words.
    pub what: String,
    /// The measured value.
    pub value: f64,
    /// Pass when `value >= min` (or `value <= max` for an upper limit).
    pub limit: Limit,
}

/// A measure's pass limit.
#[derive(Clone, Copy, Debug)]
pub enum Limit {
    /// Pass when the value is at least this.
    AtLeast(f64),
    /// Pass when the value is at most this.
    AtMost(f64),
}

impl Measure {
    /// True when `value` is within its limit.
    pub fn pass(&self) -> bool {
        match self.limit {
            Limit::AtLeast(m) => self.value >= m,
            Limit::AtMost(m) => self.value <= m,
        }
    }
}

impl std::fmt::Display for Measure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (op, m) = match self.limit {
            Limit::AtLeast(m) => ("≥", m),
            Limit::AtMost(m) => ("≤", m),
        };
        let verdict = if self.pass() { "pass" } else { "FAIL" };
        write!(f, "{}: {:.3} ({op} {m}) {verdict}", self.what, self.value)
    }
}

/// The minimum Weber contrast of a visible step (5× the ≈ 2 % discrimination threshold).
pub const VISIBLE_WEBER: f64 = 0.1;
/// The minimum separation of two means, in standard errors.
pub const VISIBLE_Z: f64 = 5.0;
/// Issue 17: no pixel above 10× its 3×3 median.
pub const MAX_FIREFLY_RATIO: f64 = 10.0;
/// Local contrast of a visible figure (2.5× the discrimination threshold; the figure is a
/// texture of many small steps, not one edge).
pub const VISIBLE_FIGURE: f64 = 0.05;
/// How much more the veneered cube's wood jumps across its edges than the carved cube's: an
/// order of magnitude (two carved cubes differ by up to 2×, since a 3-pixel step across an edge
/// spans more wood than one along a face; a seam jumps by whole growth rings).
pub const MIN_SEAM_RATIO: f64 = 10.0;
/// A light seen directly is its emitted radiance exactly (the camera ray's emission has MIS
/// weight 1); 1e-3 leaves room for f32 sums over the pixel's samples.
pub const MAX_LIGHT_ERROR: f64 = 1e-3;
/// Colour bleeding is visible when the white surfaces on a coloured wall's side are at least
/// 10 % redder (R/G; greener, G/R) than in the middle (the Weber step of [`VISIBLE_WEBER`], in
/// hue).
pub const MIN_BLEED_RATIO: f64 = 1.1;
/// Median sRGB level (0–1) of an object that is lit well enough to compare by eye.
pub const LIT_SRGB: f64 = 0.25;

/// The objects of the scene file whose names start with one of `prefixes`.
fn objects(names: &[Option<String>], prefixes: &[&str]) -> Vec<u32> {
    (names.iter().enumerate())
        .filter(|(_, n)| {
            n.as_deref()
                .is_some_and(|n| prefixes.iter().any(|p| n.starts_with(p)))
        })
        .map(|(i, _)| i as u32)
        .collect()
}

/// The mask of pixels hitting `objects`, on faces whose normal is within 25° of `face` if given.
fn mask(hits: &[PixelHit], objects: &[u32], face: Option<Vec3>) -> Vec<bool> {
    hits.iter()
        .map(|h| match *h {
            PixelHit::Surface { object, normal, .. } => {
                objects.contains(&object) && face.is_none_or(|f| normal.dot(f) > 0.906)
            }
            _ => false,
        })
        .collect()
}

/// Contrast of two object groups on one face direction, as two measures (Weber, z).
fn step(
    img: &Image,
    hits: &[PixelHit],
    names: &[Option<String>],
    what: &str,
    a: &[&str],
    b: &[&str],
    face: Option<Vec3>,
) -> Vec<Measure> {
    let c = contrast(
        img,
        &mask(hits, &objects(names, a), face),
        &mask(hits, &objects(names, b), face),
    );
    vec![
        Measure {
            what: format!("{what} Weber contrast"),
            value: c.weber,
            limit: Limit::AtLeast(VISIBLE_WEBER),
        },
        Measure {
            what: format!("{what} difference in standard errors"),
            value: c.z,
            limit: Limit::AtLeast(VISIBLE_Z),
        },
    ]
}

/// The numbers that say whether scene `name` (a file stem of scenes/) shows its subject in
/// `img`, rendered from `scene`; `names` are its objects' names in file order. Empty for a
/// scene without a check.
pub fn measure(
    name: &str,
    scene: &Scene,
    names: &[Option<String>],
    img: &Image,
    exposure: f32,
) -> Vec<Measure> {
    let hits = pixel_hits(scene);
    let fig = |what: &str, objs: &[&str]| Measure {
        what: format!("{what} local contrast"),
        value: figure_contrast(img, &mask(&hits, &objects(names, objs), None)),
        limit: Limit::AtLeast(VISIBLE_FIGURE),
    };
    let lit = |what: &str, objs: &[&str]| Measure {
        what: format!("{what} median sRGB"),
        value: median_srgb(img, &mask(&hits, &objects(names, objs), None), exposure),
        limit: Limit::AtLeast(LIT_SRGB),
    };
    match name {
        "cornell_box" => {
            let white = mask(
                &hits,
                &objects(
                    names,
                    &["floor", "ceiling", "back", "short_box", "tall_box"],
                ),
                None,
            );
            let expected = scene.lights.iter().find_map(|l| match l {
                crate::render::Light::Rect { radiance, .. } => Some(*radiance),
                _ => None,
            });
            vec![
                Measure {
                    what: "light seen directly, largest |mean / (radiance × color) − 1|".into(),
                    value: expected.map_or(f64::INFINITY, |e| light_error(scene, img, &hits, e)),
                    limit: Limit::AtMost(MAX_LIGHT_ERROR),
                },
                Measure {
                    what: "red bleeding: R/G of white surfaces, left third over middle".into(),
                    value: bleed_ratio(img, &white, 0, 0, 1),
                    limit: Limit::AtLeast(MIN_BLEED_RATIO),
                },
                Measure {
                    what: "green bleeding: G/R of white surfaces, right third over middle".into(),
                    value: bleed_ratio(img, &white, 2, 1, 0),
                    limit: Limit::AtLeast(MIN_BLEED_RATIO),
                },
            ]
        }
        n if n.starts_with("cornell") => {
            let keep: Vec<bool> = (hits.iter())
                .map(|h| matches!(h, PixelHit::Surface { delta: false, .. }))
                .collect();
            vec![Measure {
                what: "firefly ratio (pixel / 3×3 median)".into(),
                value: firefly_ratio(img, &keep).0,
                limit: Limit::AtMost(MAX_FIREFLY_RATIO),
            }]
        }
        "parquet_floor" => step(
            img,
            &hits,
            names,
            "strips against seams",
            &["floor"],
            &["seams"],
            None,
        ),
        "box_joint" => [
            step(
                img,
                &hits,
                names,
                "fingers on the front face",
                &["a_"],
                &["b_finger"],
                Some(-Vec3::Y),
            ),
            step(
                img,
                &hits,
                names,
                "fingers on the side face",
                &["b_"],
                &["a_finger"],
                Some(-Vec3::X),
            ),
        ]
        .concat(),
        "dovetail" => step(
            img,
            &hits,
            names,
            "tails against pins",
            &["tails"],
            &["pins"],
            Some(-Vec3::Y),
        ),
        "cube_carved_vs_veneer" => {
            let id = |n: &str| objects(names, &[n]).first().copied().unwrap_or(u32::MAX);
            let carved = edge_jump(img, &hits, id("carved"));
            let veneered = edge_jump(img, &hits, id("veneered"));
            vec![
                lit("carved cube", &["carved"]),
                lit("veneered cube", &["veneered"]),
                Measure {
                    what: "edge jump of the veneer over the carved cube's".into(),
                    value: veneered / carved,
                    limit: Limit::AtLeast(MIN_SEAM_RATIO),
                },
            ]
        }
        "turned_bowl" => vec![
            lit("bowl", &["bowl"]),
            fig("bowl grain and figure", &["bowl"]),
        ],
        "carved_bunny" => vec![lit("bunny", &["bunny"]), fig("bunny rings", &["bunny"])],
        // Walnut is dark by nature (median sRGB ≈ 0.16 here): only its grain is checked.
        "teapot" => vec![fig("teapot grain", &["teapot"])],
        "sweep_board" => vec![fig("board stripes", &["board"])],
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, lum: impl Fn(u32, u32) -> f32) -> Image {
        let beauty = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| Vec3::splat(lum(x, y)))
            .collect::<Vec<_>>();
        Image {
            width: w,
            height: h,
            std_error: vec![0.0; beauty.len()],
            aov: vec![Default::default(); beauty.len()],
            beauty,
            nonfinite: 0,
        }
    }

    #[test]
    fn firefly_ratio_finds_the_one_bright_pixel() {
        // Grey 0.5 with one pixel at 10: its 3×3 median is 0.5, so the ratio is 20 (by hand).
        let img = image(9, 7, |x, y| if (x, y) == (4, 3) { 10.0 } else { 0.5 });
        let (r, at) = firefly_ratio(&img, &vec![true; 63]);
        assert!((r - 20.0).abs() < 1e-4, "{r}");
        assert_eq!(at, 3 * 9 + 4);
        // Nothing to judge is not clean.
        assert!(firefly_ratio(&img, &vec![false; 63]).0.is_infinite());
    }

    #[test]
    fn contrast_of_two_flat_regions() {
        // Left half 1.0, right half 0.8 (white, so luminance = value): Weber 0.2 by hand; the
        // regions are flat, so the difference is infinitely many standard errors.
        let img = image(10, 10, |x, _| if x < 5 { 1.0 } else { 0.8 });
        let left: Vec<bool> = (0..100).map(|i| i % 10 < 5).collect();
        let right: Vec<bool> = left.iter().map(|l| !l).collect();
        let c = contrast(&img, &left, &right);
        assert!((c.weber - 0.2).abs() < 1e-6, "{c:?}");
        assert!(c.z > 1e6);
        // An empty set shows nothing.
        assert_eq!(contrast(&img, &left, &vec![false; 100]).weber, 0.0);
    }

    #[test]
    fn figure_contrast_of_a_checkerboard() {
        // A one-pixel checkerboard of a = 1.2, b = 0.8: every 5×5 window holds 13 of the centre's
        // value and 12 of the other, so the residual is ±12(a − b)/25 and the local contrast
        // 12 (a − b) / 25 / ((a + b) / 2) = 0.192.
        let img = image(12, 12, |x, y| if (x + y) % 2 == 0 { 1.2 } else { 0.8 });
        let f = figure_contrast(&img, &vec![true; 144]);
        assert!((f - 0.192).abs() < 1e-4, "{f}");
        assert!(figure_contrast(&image(12, 12, |_, _| 0.7), &vec![true; 144]) < 1e-6);
    }
}
