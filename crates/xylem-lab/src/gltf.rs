//! How well the exported glTF material approximates xylem's fibre highlight: a small reference
//! shader of KHR_materials_anisotropy (the extension's `BRDF_specularAnisotropicGGX` with glTF
//! 2.0's dielectric Fresnel mix, Appendix B) and xylem's `WoodBsdf::eval` shade the same flat
//! board under one point light seen by one camera, and the highlights' widths along and across
//! the fibre are compared (notes/gltf.md). Uses `bake::gltf` (the β → roughness map) and `bsdf`.

use glam::{Vec2, Vec3};
use xylem::bake::gltf::gltf_roughness;
use xylem::bsdf::{Bsdf, WoodBsdf, WoodBsdfParams};
use xylem::math::PI;
use xylem::picture::{Image, Rgb8};
use xylem::render::{Camera, Projection};

/// Schlick's Fresnel with f90 = 1 ([glTF] Appendix B.3.3).
fn f_schlick(f0: f32, v_dot_h: f32) -> f32 {
    f0 + (1.0 - f0) * (1.0 - v_dot_h.clamp(0.0, 1.0)).powi(5)
}

/// The anisotropic GGX specular F·V·D of KHR_materials_anisotropy ("Implementation": α_t along
/// the anisotropy direction `t`, α_b = α along b = n × t; D_GGX_anisotropic, V_GGX_anisotropic).
fn khr_specular(n: Vec3, t: Vec3, v: Vec3, l: Vec3, alpha: f32, strength: f32) -> f32 {
    let b = n.cross(t);
    let h = (v + l).normalize_or_zero();
    let (n_l, n_v) = (n.dot(l), n.dot(v));
    if n_l <= 0.0 || n_v <= 0.0 || h == Vec3::ZERO {
        return 0.0;
    }
    let at = alpha + (1.0 - alpha) * strength * strength;
    let ab = alpha;
    let a2 = at * ab;
    let f = Vec3::new(ab * t.dot(h), at * b.dot(h), a2 * n.dot(h));
    let w2 = a2 / f.dot(f);
    let d = a2 * w2 * w2 / PI;
    let gv = n_l * Vec3::new(at * t.dot(v), ab * b.dot(v), n_v).length();
    let gl = n_v * Vec3::new(at * t.dot(l), ab * b.dot(l), n_l).length();
    let vis = (0.5 / (gv + gl)).clamp(0.0, 1.0);
    f_schlick(0.04, v.dot(h)) * vis * d
}

/// The glTF 2.0 dielectric BRDF (metallic 0, ior 1.5): mix(diffuse, specular, F) (Appendix B.3.5),
/// grey, with base colour `base`.
pub fn khr_brdf(base: f32, n: Vec3, t: Vec3, v: Vec3, l: Vec3, alpha: f32, strength: f32) -> f32 {
    let h = (v + l).normalize_or_zero();
    let diffuse = (1.0 - f_schlick(0.04, v.dot(h))) * base / PI;
    diffuse + khr_specular(n, t, v, l, alpha, strength)
}

/// Full width at half maximum (pixels) of `row` around its largest value, crossings
/// interpolated linearly; the row's whole length where it never falls to half.
fn fwhm(row: &[f32]) -> f32 {
    let (peak_i, peak) = row
        .iter()
        .copied()
        .enumerate()
        .fold((0, f32::MIN), |a, (i, v)| if v > a.1 { (i, v) } else { a });
    let half = 0.5 * peak;
    let cross = |step: isize| -> f32 {
        let mut i = peak_i as isize;
        loop {
            let j = i + step;
            if j < 0 || j >= row.len() as isize {
                return (i - peak_i as isize).abs() as f32;
            }
            let (a, b) = (row[i as usize], row[j as usize]);
            if b < half {
                return (i - peak_i as isize).abs() as f32 + (a - half) / (a - b);
            }
            i = j;
        }
    };
    cross(-1) + cross(1)
}

/// The widths of one highlight image (pixels): along image x (the fibre) and along image y
/// (across it), through the brightest pixel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Widths {
    /// Full width at half maximum along image x (the fibre).
    pub along: f32,
    /// Full width at half maximum along image y (across the fibre).
    pub across: f32,
}

fn widths(img: &[f32], w: usize) -> Widths {
    let peak = (0..img.len()).fold(0, |a, i| if img[i] > img[a] { i } else { a });
    let (px, py) = (peak % w, peak / w);
    let row: Vec<f32> = img[py * w..(py + 1) * w].to_vec();
    let col: Vec<f32> = (0..img.len() / w).map(|y| img[y * w + px]).collect();
    Widths {
        along: fwhm(&row),
        across: fwhm(&col),
    }
}

/// One comparison at fibre width β.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Approximation {
    /// The fibre highlight width β (degrees).
    pub beta_deg: f32,
    /// xylem's fibre lobe (`WoodBsdf::eval`, k_f = 1, no diffuse; the finish's mirror
    /// reflection of the light, a delta, is not part of `eval`).
    pub xylem: Widths,
    /// The exported material: direction across the fibre, roughness from (G.1), strength 1.
    pub gltf: Widths,
    /// The same with the direction along the fibre (the map as baked before issue 16).
    pub gltf_along: Widths,
    /// RMS difference of the two highlight images, each divided by its peak, over the pixels
    /// where either exceeds 1 % of its peak (0 = the same shape).
    pub shape_rms: f32,
}

/// Image size of the comparison (pixels).
pub const RES: (u32, u32) = (256, 192);

/// The camera and light of the comparison: a flat board (z = 0, fibres along x) seen from
/// 300 mm up and 120 mm back, a point light as far on the other side, so the mirror point is the
/// image centre; image x runs along the fibres.
fn setup() -> (Camera, Vec3) {
    let camera = Camera::look_at(
        Vec3::new(0.0, -120.0, 300.0),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Perspective {
            fov_y: 50f32.to_radians(),
            lens_radius: 0.0,
            focus_distance: 1.0,
        },
        RES.0,
        RES.1,
    );
    (camera, Vec3::new(0.0, 120.0, 300.0))
}

/// Shades the plane z = 0 with `brdf(wo, wi)` (world = local frame: z normal, x the fibre) under
/// a unit point light: f cos θi / d², one ray through each pixel centre.
pub fn shade(brdf: &dyn Fn(Vec3, Vec3) -> f32) -> Vec<f32> {
    let (camera, light) = setup();
    let (w, h) = RES;
    (0..w * h)
        .map(|i| {
            let film = Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            let ray = camera.ray(film, Vec2::splat(0.5));
            if ray.d.z >= 0.0 {
                return 0.0;
            }
            let p = ray.o + ray.d * (-ray.o.z / ray.d.z);
            let to = light - p;
            let wi = to.normalize();
            brdf(-ray.d, wi) * wi.z / to.length_squared()
        })
        .collect()
}

/// Compares xylem's fibre highlight with the exported glTF material at fibre width `beta`.
pub fn compare(beta: f32) -> Approximation {
    let bsdf = WoodBsdf::new(WoodBsdfParams {
        diffuse: Vec3::ZERO,
        fiber_color: Vec3::ONE,
        highlight_width: beta,
        ..WoodBsdfParams::default()
    })
    .expect("valid parameters");
    let xylem = shade(&|wo, wi| bsdf.eval(wo, wi).x);
    let alpha = gltf_roughness(beta).powi(2);
    let gltf = shade(&|wo, wi| khr_brdf(0.0, Vec3::Z, Vec3::Y, wo, wi, alpha, 1.0));
    let along = shade(&|wo, wi| khr_brdf(0.0, Vec3::Z, Vec3::X, wo, wi, alpha, 1.0));
    let w = RES.0 as usize;
    let peak = |v: &[f32]| v.iter().copied().fold(0.0f32, f32::max);
    let (px, pg) = (peak(&xylem), peak(&gltf));
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (a, b) in xylem.iter().zip(&gltf) {
        let (a, b) = (a / px, b / pg);
        if a > 0.01 || b > 0.01 {
            sum += ((a - b) as f64).powi(2);
            n += 1;
        }
    }
    Approximation {
        beta_deg: beta.to_degrees(),
        xylem: widths(&xylem, w),
        gltf: widths(&gltf, w),
        gltf_along: widths(&along, w),
        shape_rms: (sum / n.max(1) as f64).sqrt() as f32,
    }
}

/// The images of a `.glb` by name, decoded to 8-bit RGB, and the board's size
/// (metres, from the POSITION accessor's bounds).
struct GlbBoard {
    images: Vec<(String, Rgb8)>,
    size: Vec3,
}

/// Reads a `.glb` the way a viewer would (glTF 2.0 §4.4 container; `gltf-json` for the document).
fn read_glb(bytes: &[u8]) -> Result<GlbBoard, String> {
    let word = |i: usize| -> Result<usize, String> {
        let b = bytes.get(i..i + 4).ok_or("truncated GLB")?;
        Ok(u32::from_le_bytes(b.try_into().unwrap()) as usize)
    };
    if bytes.get(..4) != Some(b"glTF") || word(4)? != 2 {
        return Err("not a glTF 2.0 binary".into());
    }
    let jlen = word(12)?;
    let json = bytes.get(20..20 + jlen).ok_or("truncated JSON chunk")?;
    let root = gltf_json::Root::from_slice(json).map_err(|e| e.to_string())?;
    let b = 20 + jlen;
    let bin = bytes
        .get(b + 8..b + 8 + word(b)?)
        .ok_or("truncated BIN chunk")?;
    let mut images = Vec::new();
    for img in &root.images {
        let view = &root.buffer_views[img.buffer_view.ok_or("image without a view")?.value()];
        let off = view.byte_offset.map_or(0, |o| o.0 as usize);
        let png = &bin[off..off + view.byte_length.0 as usize];
        let name = img.name.clone().unwrap_or_default();
        let img = xylem::picture::png::decode_png_rgb8(std::path::Path::new(&name), png)
            .map_err(|e| e.to_string())?;
        images.push((name, img));
    }
    let pos = root.meshes[0].primitives[0]
        .attributes
        .iter()
        .find(|(s, _)| {
            matches!(
                s,
                gltf_json::validation::Checked::Valid(gltf_json::mesh::Semantic::Positions)
            )
        })
        .map(|(_, a)| &root.accessors[a.value()])
        .ok_or("no positions")?;
    let v = |b: &Option<gltf_json::Value>| -> Vec3 {
        let a: Vec<f32> = serde_json::from_value(b.clone().unwrap_or_default()).unwrap_or_default();
        if a.len() == 3 {
            Vec3::new(a[0], a[1], a[2])
        } else {
            Vec3::ZERO
        }
    };
    let (lo, hi) = (v(&pos.min), v(&pos.max));
    Ok(GlbBoard {
        images,
        size: Vec3::new(hi.x - lo.x, hi.y, hi.z - lo.z),
    })
}

/// Renders the top face of a baked `.glb` with the KHR reference shader ([`khr_brdf`], per
/// colour channel, normal map applied) under one point light, seen from above and in front: a
/// preview of what a glTF viewer shows.
pub fn render_glb(bytes: &[u8], width: u32) -> Result<Image, String> {
    let board = read_glb(bytes)?;
    let map = |name: &str| {
        board
            .images
            .iter()
            .find(|i| i.0 == name)
            .map(|i| &i.1)
            .ok_or(format!("no image {name}"))
    };
    let (base, normal, rough, aniso) = (
        map("base_color")?,
        map("normal")?,
        map("metallic_roughness")?,
        map("anisotropy")?,
    );
    let (tw, th) = (base.width as usize, base.height as usize);
    let texel = |img: &Rgb8, u: f32, v: f32| -> Vec3 {
        let x = ((u * tw as f32) as usize).min(tw - 1);
        let y = ((v * th as f32) as usize).min(th - 1);
        let i = 3 * (y * tw + x);
        Vec3::new(
            img.data[i] as f32,
            img.data[i + 1] as f32,
            img.data[i + 2] as f32,
        ) / 255.0
    };
    let srgb = xylem::picture::srgb::srgb_to_linear;
    // glTF space (y up, metres): the face is y = top, x ∈ ±W/2 (u), z ∈ ±H/2 (v).
    let (w_m, top, h_m) = (board.size.x, board.size.y, board.size.z);
    let height = ((width as f32) * 0.6) as u32;
    let centre = Vec3::new(0.0, top, 0.0);
    let camera = Camera::look_at(
        centre + Vec3::new(0.0, 1.1 * w_m, 1.1 * w_m),
        centre,
        Vec3::Y,
        Projection::Perspective {
            fov_y: 30f32.to_radians(),
            lens_radius: 0.0,
            focus_distance: 1.0,
        },
        width,
        height,
    );
    let light = centre + Vec3::new(0.35 * w_m, 1.2 * w_m, -0.9 * w_m);
    let power = 1.2 * w_m * w_m * 4.0;
    let pixels = (0..width * height)
        .map(|i| {
            let film = Vec2::new((i % width) as f32 + 0.5, (i / width) as f32 + 0.5);
            let ray = camera.ray(film, Vec2::splat(0.5));
            let t = (top - ray.o.y) / ray.d.y;
            let p = ray.o + t * ray.d;
            let (u, v) = (p.x / w_m + 0.5, p.z / h_m + 0.5);
            if !(t > 0.0 && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)) {
                return Vec3::splat(0.02);
            }
            // Tangent frame of the face: t = +x (u), b = −z (the image's up), n = +y.
            let (tg, bt, ng) = (Vec3::X, -Vec3::Z, Vec3::Y);
            let nm = texel(normal, u, v) * 2.0 - Vec3::ONE;
            let n = (tg * nm.x + bt * nm.y + ng * nm.z).normalize();
            let a = texel(aniso, u, v);
            let d = Vec2::new(2.0 * a.x - 1.0, 2.0 * a.y - 1.0).normalize_or(Vec2::X);
            let dir = tg * d.x + bt * d.y;
            // The anisotropy direction made orthogonal to the mapped normal.
            let ta = (dir - n * n.dot(dir)).normalize_or(tg);
            let alpha = texel(rough, u, v).y.powi(2).max(1e-4);
            let to = light - p;
            let (wi, wo) = (to.normalize(), -ray.d);
            let e = power * n.dot(wi).max(0.0) / to.length_squared();
            let c = texel(base, u, v);
            Vec3::new(srgb(c.x), srgb(c.y), srgb(c.z))
                .to_array()
                .map(|b| khr_brdf(b, n, ta, wo, wi, alpha, a.z) * e)
                .into()
        })
        .collect();
    Ok(Image::new(width, height, pixels))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn khr_ggx_is_the_isotropic_ggx_at_zero_strength() {
        // Walter et al. 2007's isotropic GGX D at the normal: 1/(π α²); with h = n, v = l = n:
        // V = 0.5/(2 n·l n·v) = 1/4, F = 0.04.
        let a = 0.3;
        let s = khr_specular(Vec3::Z, Vec3::X, Vec3::Z, Vec3::Z, a, 0.0);
        assert!((s - 0.04 * 0.25 / (PI * a * a)).abs() < 1e-5, "{s}");
        // Rotating the anisotropy direction about n changes nothing at zero strength.
        let v = Vec3::new(0.3, 0.2, 1.0).normalize();
        let l = Vec3::new(-0.1, -0.4, 1.0).normalize();
        let (p, q) = (
            khr_specular(Vec3::Z, Vec3::X, v, l, a, 0.0),
            khr_specular(Vec3::Z, Vec3::Y, v, l, a, 0.0),
        );
        assert!((p - q).abs() < 1e-6 * p.max(1e-3));
    }

    #[test]
    fn fwhm_of_a_sampled_gaussian() {
        let row: Vec<f32> = (0..101)
            .map(|i| (-((i as f32 - 50.0) / 10.0).powi(2) / 2.0).exp())
            .collect();
        // 2 √(2 ln 2) σ = 23.55 for σ = 10 px.
        assert!((fwhm(&row) - 23.548).abs() < 0.1, "{}", fwhm(&row));
    }

    #[test]
    fn the_exported_highlight_stretches_across_the_fibre_as_xylems_does() {
        for beta_deg in [4.0f32, 8.0, 16.0] {
            let c = compare(beta_deg.to_radians());
            eprintln!("{c:?}");
            // xylem: short along the fibre, long across it.
            assert!(c.xylem.across > 1.5 * c.xylem.along, "{c:?}");
            // The export the same way round; the old map the wrong way round.
            assert!(c.gltf.across > 1.5 * c.gltf.along, "{c:?}");
            assert!(c.gltf_along.along > 1.5 * c.gltf_along.across, "{c:?}");
            // (G.1) matches the width along the fibre at half maximum.
            let r = c.gltf.along / c.xylem.along;
            assert!((0.75..1.33).contains(&r), "{c:?}");
        }
    }
}

#[cfg(test)]
mod glb_tests {
    use super::*;

    /// The `.glb` of `preset` baked over a 20 mm thick board's face.
    fn baked(preset: &str, size: [f32; 3], cut: xylem::bake::BakeCut, res: u32) -> Vec<u8> {
        let volume = xylem::wood::WoodVolume::new(xylem::wood::preset(preset).unwrap(), 1).unwrap();
        let board = xylem::bake::BoardCut {
            size,
            cut,
            radius: 150.0,
        };
        let maps = xylem::bake::bake(&volume, &board, res);
        let sides = board.bake_sides(&volume, res).maps;
        xylem::bake::gltf::glb_bytes(&board, &maps, &sides, preset).unwrap()
    }

    /// Regenerates the README's image of a baked `.glb`:
    /// `cargo test --release --lib regenerate_readme_glb_image -- --ignored`.
    #[test]
    #[ignore]
    fn regenerate_readme_glb_image() {
        let glb = baked(
            "african_mahogany",
            [300.0, 120.0, 20.0],
            xylem::bake::BakeCut::Radial,
            512,
        );
        let img = render_glb(&glb, 480).unwrap();
        let out = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("notes/images/gltf_board.png");
        img.write(&out).unwrap();
    }

    #[test]
    fn a_baked_glb_renders_finite_and_fills_the_view() {
        let glb = baked(
            "walnut",
            [200.0, 80.0, 20.0],
            xylem::bake::BakeCut::Tangential,
            48,
        );
        let Image {
            width: w,
            height: h,
            pixels: px,
        } = render_glb(&glb, 64).unwrap();
        assert_eq!(px.len(), (w * h) as usize);
        assert!(px.iter().all(|c| c.is_finite() && c.min_element() >= 0.0));
        let board_px = px.iter().filter(|c| c.x != 0.02).count();
        assert!(
            board_px > px.len() / 8,
            "the board fills the view: {board_px}"
        );
        assert!(read_glb(b"glTF\x01\0\0\0").is_err());
    }
}
