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
//!   mean) exceeds 0.05 after the pixels' own noise is taken out;
//! - growth rings are readable when the beauty's pixels on the light rings (by the albedo AOV)
//!   are brighter than those on the dark rings, relative to their neighbourhood, by the Weber
//!   threshold above;
//! - a curly figure is there when its bands along the fibre flip between bright and dark as the
//!   light moves to the other side along the fibre (chatoyance), with the Weber threshold's
//!   contrast: an albedo pattern (rings, scratches) stays put.
//!
//! Pixels are labelled by what the camera ray through their centre hits first (object, triangle,
//! face normal), independently of the shading.

use glam::{Vec2, Vec3};
use xylem::material::Material;
use xylem::math::{luminance, Frame};
use xylem::render::{
    light::nearest_light, render_frames, DistantLight, Light, LightFrames, PointLight, RenderError,
    RenderSettings, RenderedImage, RunOptions, Scene, SphereLight, SpotLight,
};

mod expect;
mod subject;
pub use expect::*;
pub use subject::*;

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
        /// Where the ray hits (world, mm).
        point: Vec3,
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
            if let Some((_, light)) = nearest_light(&scene.lights, &ray, t_hit) {
                if light.distance < t_hit {
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
                        point: ray.o + ray.d * hit.t,
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
pub fn firefly_ratio(img: &RenderedImage, keep: &[bool]) -> (f64, usize) {
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
pub fn contrast(img: &RenderedImage, a: &[bool], b: &[bool]) -> Contrast {
    let lum: Vec<f64> = img.beauty.iter().map(|c| luminance(*c) as f64).collect();
    contrast_of(&lum, a, b)
}

/// Mean of `values` over the set `a` against the set `b` (the statistics of [`contrast`]).
pub fn contrast_of(values: &[f64], a: &[bool], b: &[bool]) -> Contrast {
    let stats = |set: &[bool]| {
        let v: Vec<f64> = (values.iter().zip(set))
            .filter(|(_, &s)| s)
            .map(|(x, _)| *x)
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

/// Half-width of the window [`ring_contrast`] compares each pixel with (7×7 pixels).
const RING_WINDOW: usize = 3;

/// Growth-ring contrast of the beauty on the pixels of `set`: each pixel's luminance over the
/// mean of its 7×7 neighbourhood (in `set`), compared between the pixels whose albedo AOV is
/// lighter than its own neighbourhood's mean (earlywood, light rings) and those darker (latewood).
/// The labels come from the albedo, the numbers from the beauty, so this is the rings' contrast
/// as rendered; the lighting's slow change across a wall divides out, and Monte Carlo noise
/// (independent of the label) averages out of both means and only lowers `z`.
pub fn ring_contrast(img: &RenderedImage, set: &[bool]) -> Contrast {
    let (w, h) = (img.width as usize, img.height as usize);
    let lum: Vec<f64> = img.beauty.iter().map(|c| luminance(*c) as f64).collect();
    let alb: Vec<f64> = img.aov.iter().map(|a| luminance(a.albedo) as f64).collect();
    let k = RING_WINDOW;
    let mut rel = vec![0.0; w * h];
    let (mut light, mut dark) = (vec![false; w * h], vec![false; w * h]);
    for y in k..h.saturating_sub(k) {
        for x in k..w.saturating_sub(k) {
            let i = y * w + x;
            if !set[i] {
                continue;
            }
            let (mut sl, mut sa, mut n) = (0.0, 0.0, 0usize);
            for yy in y - k..=y + k {
                for xx in x - k..=x + k {
                    let j = yy * w + xx;
                    if set[j] {
                        sl += lum[j];
                        sa += alb[j];
                        n += 1;
                    }
                }
            }
            // At least half the window on the surface, so edges do not judge.
            if 2 * n < (2 * k + 1).pow(2) || sl <= 0.0 {
                continue;
            }
            rel[i] = lum[i] * n as f64 / sl;
            let a = alb[i] * n as f64 / sa.max(1e-12);
            light[i] = a > 1.0;
            dark[i] = a < 1.0;
        }
    }
    contrast_of(&rel, &light, &dark)
}

/// Local contrast of the pixels in `set` whose 5×5 neighbourhood lies in `set`: the RMS of each
/// pixel's luminance minus its 5×5 mean, with the pixels' own noise (their `std_error`²)
/// subtracted, over the mean luminance.
pub fn figure_contrast(img: &RenderedImage, set: &[bool]) -> f64 {
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

/// Half-angle (degrees) within which a surface's normal is taken to be the half vector between
/// the camera and a small light: there the finish mirrors the light, a highlight of the coat and
/// not of the wood (the sphere light's 2.5° plus the 0.05-roughness finish's spread, doubled).
const FINISH_GLINT_DEG: f32 = 8.0;

/// The pixels of `set` where the finish does not mirror one of `lights` (point, spot or sphere):
/// the half vector between the view and the light is more than `FINISH_GLINT_DEG` (8°) from the
/// geometric normal. Geometric, so the two renders of [`curl_flip`] are judged on one set.
pub fn without_glints(
    scene: &Scene,
    hits: &[PixelHit],
    set: &[bool],
    lights: &[Light],
) -> Vec<bool> {
    let cos_max = FINISH_GLINT_DEG.to_radians().cos();
    let centres: Vec<Vec3> = (lights.iter())
        .filter_map(|l| match l {
            Light::Point(PointLight { position, .. }) | Light::Spot(SpotLight { position, .. }) => {
                Some(*position)
            }
            Light::Sphere(s) => Some(s.center),
            Light::Distant(_) | Light::Rect(_) | Light::Environment(_) => None,
        })
        .collect();
    (hits.iter().zip(set))
        .map(|(h, &s)| match *h {
            PixelHit::Surface { normal, point, .. } if s => {
                let v = (scene.camera.eye - point).normalize();
                let n = if normal.dot(v) < 0.0 { -normal } else { normal };
                centres
                    .iter()
                    .all(|c| (v + (*c - point).normalize()).normalize().dot(n) < cos_max)
            }
            _ => false,
        })
        .collect()
}

/// A curly figure's bands as one render and its companion (the light mirrored along the fibre)
/// show them: the band contrast and the correlation of the two band patterns.
#[derive(Clone, Copy, Debug)]
pub struct CurlFlip {
    /// Weber contrast 2a / (1 + a) of a sinusoidal band of relative amplitude a = √2 · RMS of the
    /// flipping part (h₁ − h₂) / 2 of the two band patterns, Monte Carlo noise taken out.
    pub weber: f64,
    /// Correlation of the two band patterns h₁, h₂: near +1 for a pattern in the albedo (rings,
    /// scratches), negative for figure that swaps bright and dark with the light.
    pub correlation: f64,
    /// Pixels judged.
    pub pixels: usize,
}

/// The band pattern of the curl in `img` on the pixels of `set`: each pixel's luminance averaged
/// across the fibre over ± `across` pixels, over the mean of that along the fibre over ± `along`
/// pixels, minus 1 (a band-pass that keeps bands across the fibre and removes the shading's slow
/// change); with its Monte Carlo variance. The fibre's image direction is the fiber AOV projected
/// on the camera's film. NaN unless both windows lie wholly in `set`.
fn band_pattern(
    img: &RenderedImage,
    set: &[bool],
    film: &Frame,
    along: i32,
    across: i32,
) -> Vec<(f64, f64)> {
    let (w, h) = (img.width as i32, img.height as i32);
    let lum: Vec<f64> = img.beauty.iter().map(|c| luminance(*c) as f64).collect();
    let dir = |i: usize| {
        let f = img.aov[i].fiber;
        // Film x = camera s, film y (down) = −t.
        let d = Vec2::new(f.dot(film.s), -f.dot(film.t));
        (d.length() > 1e-3).then(|| d.normalize())
    };
    let at = |x: i32, y: i32, d: Vec2, k: i32| {
        let (qx, qy) = (
            (x as f32 + d.x * k as f32).round() as i32,
            (y as f32 + d.y * k as f32).round() as i32,
        );
        (qx >= 0 && qy >= 0 && qx < w && qy < h)
            .then(|| (qy * w + qx) as usize)
            .filter(|&j| set[j])
    };
    // Across the fibre: mean and its variance of the mean.
    let mut c = vec![(f64::NAN, 0.0); lum.len()];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let Some(d) = dir(i).filter(|_| set[i]) else {
                continue;
            };
            let p = Vec2::new(-d.y, d.x);
            let js: Vec<usize> = (-across..=across).filter_map(|k| at(x, y, p, k)).collect();
            if js.len() as i32 == 2 * across + 1 {
                let n = js.len() as f64;
                let m = js.iter().map(|&j| lum[j]).sum::<f64>() / n;
                let var = js
                    .iter()
                    .map(|&j| (img.std_error[j] as f64).powi(2))
                    .sum::<f64>()
                    / (n * n);
                c[i] = (m, var);
            }
        }
    }
    let mut out = vec![(f64::NAN, 0.0); lum.len()];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let Some(d) = dir(i).filter(|_| c[i].0.is_finite()) else {
                continue;
            };
            let js: Vec<usize> = (-along..=along)
                .filter_map(|k| at(x, y, d, k))
                .filter(|&j| c[j].0.is_finite())
                .collect();
            let mean = js.iter().map(|&j| c[j].0).sum::<f64>() / js.len().max(1) as f64;
            if js.len() as i32 == 2 * along + 1 && mean > 0.0 {
                out[i] = (c[i].0 / mean - 1.0, c[i].1 / (mean * mean));
            }
        }
    }
    out
}

/// The curl's chatoyance: `a` and `b` are one scene rendered with the light on either side
/// along the fibre; `band_mm` is the curl kernel's extent along the fibre (the tangential
/// distortion's z semi-axis S_z, tree mm = world mm). Windows: across the fibre ± S_z / 2 (the
/// bands are 25–60 mm long that way, so this only averages noise), along it ± S_z, i.e. one band
/// pair: one kernel's slope ∂m/∂z, which tilts the fibre, is one bright and one dark band over
/// its 2 S_z (Liu et al. 2016 §5.1, eq. 15), so the window is the shortest that keeps a whole
/// band pair, and removes what changes more slowly along the fibre: the shading, and the radial
/// distortion's wander, whose kernels are 12 mm along z (curly_maple), twice the curl's. Pixel pitch: the median world distance between horizontally
/// neighbouring pixels of `set`.
pub fn curl_flip(
    a: &RenderedImage,
    b: &RenderedImage,
    hits: &[PixelHit],
    set: &[bool],
    film: &Frame,
    band_mm: f64,
) -> CurlFlip {
    let w = a.width as usize;
    let point = |i: usize| match hits[i] {
        PixelHit::Surface { point, .. } => Some(point),
        _ => None,
    };
    let mut pitch: Vec<f32> = (0..hits.len().saturating_sub(1))
        .filter(|&i| (i + 1) % w != 0 && set[i] && set[i + 1])
        .filter_map(|i| Some(point(i)?.distance(point(i + 1)?)))
        .collect();
    pitch.sort_by(f32::total_cmp);
    let none = CurlFlip {
        weber: 0.0,
        correlation: f64::NAN,
        pixels: 0,
    };
    let Some(&mm) = pitch.get(pitch.len() / 2) else {
        return none;
    };
    let px = |mm_len: f64| ((mm_len / mm as f64).round() as i32).max(1);
    let (along, across) = (px(band_mm), px(0.5 * band_mm));
    let (ha, hb) = (
        band_pattern(a, set, film, along, across),
        band_pattern(b, set, film, along, across),
    );
    /// (h, its noise variance) in each render.
    type Pair = ((f64, f64), (f64, f64));
    let pairs: Vec<Pair> = (ha.into_iter().zip(hb))
        .filter(|(x, y)| x.0.is_finite() && y.0.is_finite())
        .collect();
    if pairs.len() < MIN_PIXELS {
        return none;
    }
    let n = pairs.len() as f64;
    let mean = |f: &dyn Fn(&Pair) -> f64| pairs.iter().map(f).sum::<f64>() / n;
    let (mx, my) = (mean(&|p| p.0 .0), mean(&|p| p.1 .0));
    let sxx = mean(&|p| (p.0 .0 - mx).powi(2));
    let syy = mean(&|p| (p.1 .0 - my).powi(2));
    let sxy = mean(&|p| (p.0 .0 - mx) * (p.1 .0 - my));
    // Var((h₁ − h₂)/2) = (sxx + syy − 2 sxy) / 4, less the noise (var₁ + var₂) / 4.
    let noise = mean(&|p| p.0 .1 + p.1 .1) / 4.0;
    let rms = ((sxx + syy - 2.0 * sxy) / 4.0 - noise).max(0.0).sqrt();
    let amp = std::f64::consts::SQRT_2 * rms;
    CurlFlip {
        weber: 2.0 * amp / (1.0 + amp),
        correlation: sxy / (sxx * syy).sqrt().max(1e-300),
        pixels: pairs.len(),
    }
}

/// The mirror image of `lights` through the plane x = 0 (world): the companion render of a scene
/// whose check compares the light on either side along a fibre that runs along x.
pub fn mirrored_x(lights: &[Light]) -> Vec<Light> {
    let m = |p: Vec3| Vec3::new(-p.x, p.y, p.z);
    (lights.iter())
        .map(|l| match l.clone() {
            Light::Point(p) => Light::Point(PointLight {
                position: m(p.position),
                ..p
            }),
            Light::Sphere(s) => Light::Sphere(SphereLight {
                center: m(s.center),
                ..s
            }),
            Light::Distant(d) => Light::Distant(DistantLight {
                direction: m(d.direction),
                ..d
            }),
            other @ (Light::Spot(_) | Light::Rect(_) | Light::Environment(_)) => other,
        })
        .collect()
}

/// [`measure`] with the companion render `expect` asks for (if any) made here at `settings`:
/// `turned_bowl` (the curl's chatoyance) has its key light mirrored along the fibre,
/// `grazing_oak` (the pore bump) its raking light mirrored across it, `cornell_bunny` (the
/// blue-background variant) the same lights without the background. Returns the measures and
/// the companion image.
pub fn measure_rendered(
    expect: &Expectations,
    scene: &Scene,
    settings: &RenderSettings,
    run: &RunOptions,
    names: &[Option<String>],
    img: &RenderedImage,
    exposure: f32,
) -> Result<(Vec<Measure>, Option<RenderedImage>), RenderError> {
    let companion = match expect.companion {
        Some(c) => {
            let lights = c.lights(scene);
            Some(render_frames(scene, &LightFrames::fixed(&lights), settings, run)?.image(0))
        }
        None => None,
    };
    let m = measure(expect, scene, names, img, companion.as_ref(), exposure);
    Ok((m, companion))
}

/// How much a solid-texture coordinate jumps across a face edge: the mean |Δ growth time|
/// between pixels 3 apart on two different faces of the object over the same between pixels on
/// one face (each pixel's 3×3 neighbourhood on one face, so no pixel mixes faces). About 1 where
/// the wood runs on around the edge (carved from a block), large where each face is its own
/// slice (veneer, Liu et al. 2016 Fig. 18).
pub fn edge_jump(img: &RenderedImage, hits: &[PixelHit], object: u32) -> f64 {
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
pub fn light_error(scene: &Scene, img: &RenderedImage, hits: &[PixelHit], expected: Vec3) -> f64 {
    let w = img.width as usize;
    let sees_light = |film: Vec2| {
        let ray = scene.camera.ray(film, Vec2::splat(0.5));
        let t_hit = scene
            .accel
            .intersect(&ray, f32::INFINITY)
            .map_or(f32::INFINITY, |h| h.t);
        nearest_light(&scene.lights, &ray, t_hit).is_some_and(|(_, hit)| hit.distance < t_hit)
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
pub fn bleed_ratio(img: &RenderedImage, set: &[bool], third: usize, a: usize, b: usize) -> f64 {
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
pub fn median_srgb(img: &RenderedImage, set: &[bool], exposure: f32) -> f64 {
    let k = 2f32.powf(exposure);
    let mut v: Vec<f32> = (img.beauty.iter().zip(set))
        .filter(|(_, &s)| s)
        .map(|(c, _)| xylem::picture::srgb::linear_to_srgb(luminance(*c) * k))
        .collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    v[v.len() / 2] as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, lum: impl Fn(u32, u32) -> f32) -> RenderedImage {
        let beauty = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| Vec3::splat(lum(x, y)))
            .collect::<Vec<_>>();
        RenderedImage {
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
        let (r, at) = firefly_ratio(&img, &[true; 63]);
        assert!((r - 20.0).abs() < 1e-4, "{r}");
        assert_eq!(at, 3 * 9 + 4);
        // Nothing to judge is not clean.
        assert!(firefly_ratio(&img, &[false; 63]).0.is_infinite());
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
        assert_eq!(contrast(&img, &left, &[false; 100]).weber, 0.0);
    }

    /// An image whose albedo AOV equals its beauty and whose fibre runs along +x.
    fn textured(w: u32, h: u32, lum: impl Fn(u32, u32) -> f32) -> RenderedImage {
        let mut img = image(w, h, lum);
        for (a, c) in img.aov.iter_mut().zip(&img.beauty) {
            a.albedo = *c;
            a.fiber = Vec3::X;
        }
        img
    }

    #[test]
    fn ring_contrast_of_a_checkerboard() {
        // One-pixel checkerboard of 0.6 and 0.4 in both beauty and albedo: a 7×7 window holds 25
        // of the centre's value and 24 of the other, so rel = 49 v / (25 v + 24 o) and the Weber
        // contrast is 1 − (0.4 · 24.6) / (0.6 · 24.4) = 0.327869 (by hand).
        let img = textured(20, 20, |x, y| if (x + y) % 2 == 0 { 0.6 } else { 0.4 });
        let c = ring_contrast(&img, &[true; 400]);
        assert!((c.weber - 0.327869).abs() < 1e-5, "{c:?}");
        // The same pattern in the lighting only (a flat albedo): no rings to find.
        let mut flat = img.clone();
        flat.aov
            .iter_mut()
            .for_each(|a| a.albedo = Vec3::splat(0.5));
        assert_eq!(ring_contrast(&flat, &[true; 400]).weber, 0.0);
    }

    #[test]
    fn curl_flip_of_swapping_bands() {
        // Bands across a fibre along x, period 7 px = 7 mm (pitch 1 mm): 1 ± 0.2 sin(2π x / 7).
        // band_mm 3 gives windows ±3 px along (7 = 1 period, so the mean is exactly 1) and ±2
        // across: h = ±0.2 sin, amplitude 0.2, Weber 2 · 0.2 / 1.2 = 1/3; correlation −1 when the
        // bands swap, +1 (and no flipping part) when they stay.
        // 48 columns: the judged ones (x = 3–44) are 6 whole periods, so their RMS is a/√2.
        let (w, h) = (48u32, 30u32);
        let band = |sign: f32| {
            move |x: u32, _| 1.0 + sign * 0.2 * (std::f32::consts::TAU * x as f32 / 7.0).sin()
        };
        let (a, b) = (textured(w, h, band(1.0)), textured(w, h, band(-1.0)));
        let hits: Vec<PixelHit> = (0..w * h)
            .map(|i| PixelHit::Surface {
                object: 0,
                triangle: 0,
                normal: Vec3::Z,
                point: Vec3::new((i % w) as f32, -((i / w) as f32), 0.0),
                delta: false,
            })
            .collect();
        let film = Frame {
            s: Vec3::X,
            t: Vec3::Y,
            n: -Vec3::Z,
        };
        let set = vec![true; (w * h) as usize];
        let f = curl_flip(&a, &b, &hits, &set, &film, 3.0);
        assert!((f.weber - 1.0 / 3.0).abs() < 1e-4, "{f:?}");
        assert!((f.correlation + 1.0).abs() < 1e-4, "{f:?}");
        let same = curl_flip(&a, &a, &hits, &set, &film, 3.0);
        assert!(
            same.weber < 1e-6 && (same.correlation - 1.0).abs() < 1e-6,
            "{same:?}"
        );
    }

    #[test]
    fn light_colour_of_a_uniform_light() {
        // Beauty = albedo × (1, 0.8, 0.5) on every pixel, the albedo varying: the light's blue
        // over red is 0.5 (by hand) in every group alike, so its random-group error is 0.
        let mut img = image(8, 8, |x, y| 0.2 + 0.05 * ((x + 2 * y) % 3) as f32);
        for (a, c) in img.aov.iter_mut().zip(img.beauty.iter_mut()) {
            a.albedo = *c;
            *c *= Vec3::new(1.0, 0.8, 0.5);
        }
        let all = vec![true; 64];
        assert!((light_blue_over_red(&img, &all) - 0.5).abs() < 1e-6);
        assert!(light_colour_error(&img, &all) < 1e-6);
        // One group's blue doubled: the 16 group figures are fifteen 0.5 and one 1.0, mean
        // 0.53125, sample variance (15 · 0.03125² + 0.46875²) / 15 = 0.015625, so the error is
        // √(0.015625 / 16) = 0.03125 (by hand).
        for i in [0usize, 4, 32, 36] {
            img.beauty[i].z *= 2.0;
        }
        assert!((light_colour_error(&img, &all) - 0.03125).abs() < 1e-6);
        // Nothing to judge: no figure, and no error bound.
        assert_eq!(light_blue_over_red(&img, &[false; 64]), 0.0);
        assert!(light_colour_error(&img, &[false; 64]).is_infinite());
    }

    #[test]
    fn figure_contrast_of_a_checkerboard() {
        // A one-pixel checkerboard of a = 1.2, b = 0.8: every 5×5 window holds 13 of the centre's
        // value and 12 of the other, so the residual is ±12(a − b)/25 and the local contrast
        // 12 (a − b) / 25 / ((a + b) / 2) = 0.192.
        let img = image(12, 12, |x, y| if (x + y) % 2 == 0 { 1.2 } else { 0.8 });
        let f = figure_contrast(&img, &[true; 144]);
        assert!((f - 0.192).abs() < 1e-4, "{f}");
        assert!(figure_contrast(&image(12, 12, |_, _| 0.7), &[true; 144]) < 1e-6);
    }
}
