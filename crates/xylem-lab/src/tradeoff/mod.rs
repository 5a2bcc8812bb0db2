//! Measuring the speed/accuracy trade (`xylem tradeoff`): render one frame of a scene with each
//! setting of each knob the renderer and the wood model expose, time it, and measure its error
//! against a high-quality reference (relative MSE and SSIM). The named `--quality` presets are
//! chosen from these measurements (validation/TRADEOFF.md): the measures here, the study in
//! [`study`], the report in [`report`].

pub mod report;
pub mod study;

pub use self::report::write_report;
pub use self::study::{check_options, run_study, StudyError, StudyOptions, StudyResult};
use crate::bench::clock::CpuTimer;
use serde::Serialize;
use xylem::bsdf::FinishModel;
use xylem::material::BakedFibers;
use xylem::math::luminance;
use xylem::picture::srgb::linear_to_srgb;
use xylem::render::{render, RunOptions};
pub use xylem::scene::quality::{apply, apply_to_params, top_face, Knobs, Quality, TradeoffError};
use xylem::scene::LoadedScene;

/// Relative mean squared error Σ|x − r|² / Σ|r|² over RGB.
pub fn relative_mse(x: &[glam::Vec3], r: &[glam::Vec3]) -> f64 {
    relative_mse_net(x, r, 0.0)
}

/// The reference as two independent halves `a` and `b` (same spp, other seeds): their mean,
/// the reference, and Σ Var(r), its own Monte Carlo noise summed over pixels and RGB. With a and
/// b independent and unbiased, E|a − b|² = Var(a) + Var(b) per channel and Var((a + b)/2) = that
/// over 4, so Σ|a − b|² / 4 estimates it without bias.
pub fn reference_from_halves(a: &[glam::Vec3], b: &[glam::Vec3]) -> (Vec<glam::Vec3>, f64) {
    let mean = a.iter().zip(b).map(|(x, y)| 0.5 * (*x + *y)).collect();
    let noise = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).length_squared() as f64)
        .sum::<f64>()
        / 4.0;
    (mean, noise)
}

/// [`relative_mse`] against the converged image rather than the reference: a render x
/// independent of the reference r has E Σ|x − r|² = Σ(|bias|² + Var x) + Σ Var r, so the
/// reference's own noise `reference_noise` ([`reference_from_halves`]) is taken off the sum
/// (floored at 0: a render as good as the reference can come out below it).
pub fn relative_mse_net(x: &[glam::Vec3], r: &[glam::Vec3], reference_noise: f64) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (a, b) in x.iter().zip(r) {
        num += (*a - *b).length_squared() as f64;
        den += b.length_squared() as f64;
    }
    ((num - reference_noise) / den.max(1e-30)).max(0.0)
}

/// Mean SSIM (Wang, Bovik, Sheikh, Simoncelli 2004, eq. 13, C1 = (0.01 L)², C2 = (0.03 L)², L = 1)
/// of the sRGB-encoded luminance of two images, over 8 × 8 windows with stride 4.
pub fn ssim(x: &[glam::Vec3], r: &[glam::Vec3], width: usize, height: usize, exposure: f32) -> f64 {
    let scale = exposure.exp2();
    let enc = |v: &[glam::Vec3]| -> Vec<f64> {
        v.iter()
            .map(|c| linear_to_srgb(luminance(*c) * scale) as f64)
            .collect()
    };
    let (a, b) = (enc(x), enc(r));
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let (win, stride) = (8usize.min(width), 4usize);
    let win_h = 8usize.min(height);
    let (mut total, mut count) = (0.0, 0usize);
    let mut y = 0;
    while y + win_h <= height {
        let mut x0 = 0;
        while x0 + win <= width {
            let n = (win * win_h) as f64;
            let (mut ma, mut mb) = (0.0, 0.0);
            for yy in y..y + win_h {
                for xx in x0..x0 + win {
                    ma += a[yy * width + xx];
                    mb += b[yy * width + xx];
                }
            }
            ma /= n;
            mb /= n;
            let (mut va, mut vb, mut cov) = (0.0, 0.0, 0.0);
            for yy in y..y + win_h {
                for xx in x0..x0 + win {
                    let (da, db) = (a[yy * width + xx] - ma, b[yy * width + xx] - mb);
                    va += da * da;
                    vb += db * db;
                    cov += da * db;
                }
            }
            let (va, vb, cov) = (va / (n - 1.0), vb / (n - 1.0), cov / (n - 1.0));
            total += ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            count += 1;
            x0 += stride;
        }
        y += stride;
    }
    if count == 0 {
        1.0
    } else {
        total / count as f64
    }
}

/// One measured setting.
#[derive(Clone, Debug, Serialize)]
pub struct Measurement {
    /// Which knob this row varies.
    pub knob: String,
    /// The setting, as the report prints it.
    pub setting: String,
    /// All knobs of the row.
    pub knobs: Knobs,
    /// Render time, wall clock: the median over the interleaved repeats.
    pub seconds: f64,
    /// Render time in CPU seconds of the process (all threads; what the machine's other jobs do
    /// not change, unlike wall clock): the median over the repeats, and its smallest and largest.
    pub cpu_seconds: f64,
    /// Smallest CPU seconds of the repeats.
    pub cpu_min: f64,
    /// Largest CPU seconds of the repeats.
    pub cpu_max: f64,
    /// Renders timed.
    pub repeats: u32,
    /// Time to prepare the scene for these knobs (rebuilding volumes, baking maps).
    pub prep_seconds: f64,
    /// [`relative_mse_net`] against the reference render ([`Knobs::reference`] at
    /// `--reference-spp`, other seeds than the rows'): the error against the converged image,
    /// the reference's own noise taken off.
    pub relative_mse: f64,
    /// [`ssim`] against the reference render.
    pub ssim: f64,
    /// Relative MSE against the reference model rendered at the same spp with the same seeds:
    /// the error the model knobs add, without the Monte Carlo noise both renders share.
    pub model_mse: f64,
    /// [`ssim`] against the reference model at the same spp with the same seeds.
    pub model_ssim: f64,
}

/// The settings measured, knob by knob (spp with the full model; each model knob at 16 spp).
pub fn settings() -> Vec<(String, String, Knobs)> {
    let mut v = Vec::new();
    for spp in [1, 4, 16, 64] {
        v.push((
            "samples per pixel".into(),
            format!("{spp} spp"),
            Knobs::full(spp),
        ));
    }
    for bands in [1, 2] {
        v.push((
            "noise bands".into(),
            format!("≤ {bands} band(s), 16 spp"),
            Knobs {
                max_bands: Some(bands),
                ..Knobs::full(16)
            },
        ));
    }
    for scale in [0.25, 0.5] {
        v.push((
            "impulse density".into(),
            format!("× {scale}, 16 spp"),
            Knobs {
                density_scale: scale,
                ..Knobs::full(16)
            },
        ));
    }
    v.push((
        "pores and rays".into(),
        "dropped, 16 spp".into(),
        Knobs {
            pores_and_rays: false,
            ..Knobs::full(16)
        },
    ));
    v.push((
        "distortion Jacobian".into(),
        "simplified (eq. 22), 16 spp".into(),
        Knobs::full(16),
    ));
    v.push((
        "distortion Jacobian".into(),
        "exact, 16 spp".into(),
        Knobs::reference(16),
    ));
    v.push((
        "finish".into(),
        "single bounce, 16 spp".into(),
        Knobs {
            finish: FinishModel::SingleBounce,
            ..Knobs::full(16)
        },
    ));
    for (fibers, label) in [
        (BakedFibers::Anisotropy, "glTF anisotropy map"),
        (BakedFibers::Direction, "fibre direction map"),
    ] {
        for res in [256, 512, 1024, 2048] {
            v.push((
                format!("baked texture ({label})"),
                format!("{res} texels, 16 spp"),
                Knobs {
                    baked_res: Some(res),
                    baked_fibers: fibers,
                    ..Knobs::full(16)
                },
            ));
        }
    }
    for spp in [1, 4, 16, 64] {
        v.push((
            "footprint band-limit".into(),
            format!("off, {spp} spp"),
            Knobs {
                footprint_filter: false,
                ..Knobs::full(spp)
            },
        ));
    }
    for q in [Quality::Draft, Quality::Default, Quality::Final] {
        v.push((
            "--quality".into(),
            format!("{q:?}").to_lowercase(),
            q.knobs(),
        ));
    }
    v
}

/// The least reference sample count, as a multiple of the highest measured one, that `xylem
/// tradeoff` accepts without `--allow-weak-reference`: the reference's own noise variance is
/// then ≤ ¼ of the noisiest row's lowest, so a row cannot score better than it is by matching the
/// reference's noise (with a 16-spp reference the 16-spp row scored SSIM 1.0000, same seeds).
pub const MIN_REFERENCE_FACTOR: u32 = 4;

/// Why a reference of `reference_spp` is too weak to score rows of up to `max_spp` samples
/// (below [`MIN_REFERENCE_FACTOR`] × `max_spp`), or `None`.
pub fn weak_reference(reference_spp: u32, max_spp: u32) -> Option<String> {
    let need = MIN_REFERENCE_FACTOR.saturating_mul(max_spp);
    (reference_spp < need).then(|| {
        format!(
            "--reference-spp {reference_spp} is under {MIN_REFERENCE_FACTOR}× the highest \
             measured {max_spp} spp: rows near it are scored against a reference about as noisy \
             as they are (its noise, taken off each row's error, is then estimated from two \
             halves as noisy as the rows); use \
             --reference-spp {need} or more"
        )
    })
}

/// One render of [`render_with`].
pub struct Rendered {
    /// The beauty image.
    pub image: Vec<glam::Vec3>,
    /// The pixels whose first hits are wood (their fibre AOV is not zero).
    pub wood: Vec<bool>,
    /// Render time, wall clock.
    pub seconds: f64,
    /// Render time in CPU seconds of the process ([`CpuTimer::process`]; the wall clock where
    /// that is unavailable).
    pub cpu_seconds: f64,
    /// Wall-clock time spent applying the knobs.
    pub prep_seconds: f64,
}

/// Renders the scene (its own lights, as built) with `knobs`.
pub fn render_with(
    base: &dyn Fn() -> Result<LoadedScene, String>,
    knobs: &Knobs,
    run: &RunOptions,
) -> Result<Rendered, String> {
    let mut loaded = base()?;
    let prep = std::time::Instant::now();
    apply(&mut loaded, knobs).map_err(|e| e.to_string())?;
    let prep = prep.elapsed().as_secs_f64();
    let timer = CpuTimer::process();
    let out = render(&loaded.scene, &loaded.settings, run).map_err(|e| e.to_string())?;
    let (seconds, cpu_seconds) = (out.elapsed.as_secs_f64(), timer.seconds());
    Ok(Rendered {
        wood: (out.image.aov.iter())
            .map(|a| a.fiber != glam::Vec3::ZERO)
            .collect(),
        image: out.image.beauty,
        seconds,
        cpu_seconds,
        prep_seconds: prep,
    })
}

/// (median, smallest, largest) of `xs` (the median of an even count is the mean of the middle
/// two); (NaN, NaN, NaN) when empty.
pub fn median_range(xs: &[f64]) -> (f64, f64, f64) {
    if xs.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let median = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (median, v[0], v[n - 1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn median_range_of_odd_and_even_counts() {
        assert_eq!(median_range(&[3.0, 1.0, 2.0]), (2.0, 1.0, 3.0));
        assert_eq!(median_range(&[4.0, 1.0, 2.0, 10.0]), (3.0, 1.0, 10.0));
        assert!(median_range(&[]).0.is_nan());
    }

    #[test]
    fn identical_images_have_no_error_and_unit_ssim() {
        let img: Vec<Vec3> = (0..64 * 32)
            .map(|i| Vec3::splat(0.1 + 0.4 * (i % 64) as f32 / 64.0))
            .collect();
        assert_eq!(relative_mse(&img, &img), 0.0);
        assert!((ssim(&img, &img, 64, 32, 0.0) - 1.0).abs() < 1e-12);
        // Noise lowers SSIM and raises the error.
        let mut rng = xylem::math::Pcg32::new(1, 1);
        let noisy: Vec<Vec3> = img
            .iter()
            .map(|c| *c + Vec3::splat(0.2 * (rng.next_f32() - 0.5)))
            .collect();
        assert!(ssim(&noisy, &img, 64, 32, 0.0) < 0.9);
        let e = relative_mse(&noisy, &img);
        assert!(e > 0.0 && e < 0.1, "{e}");
    }

    /// A synthetic truth t; a render x = t + bias + noise of variance σx²; a reference in two
    /// independent halves of noise σh² each (so Var r = σh²/2). The net relative MSE must
    /// recover Σ(bias² + σx²) / Σ|r|² (the error against t), where the raw one (the control)
    /// also counts the reference's σh²/2 and misses by it. Uniform noise of half-width w has
    /// variance w²/3; 64k pixels, fixed seed, so the estimates sit within 2 % of their means.
    #[test]
    fn the_reference_noise_comes_off_the_error() {
        let n = 256 * 256;
        let mut rng = xylem::math::Pcg32::new(7, 3);
        let mut noise = |w: f32| Vec3::splat(w * (2.0 * rng.next_f32() - 1.0));
        let truth: Vec<Vec3> = (0..n)
            .map(|i| Vec3::splat(0.2 + 0.3 * (i % 97) as f32 / 97.0))
            .collect();
        let (wx, wh, bias) = (0.05f32, 0.08f32, 0.01f32);
        let x: Vec<Vec3> = truth
            .iter()
            .map(|t| *t + Vec3::splat(bias) + noise(wx))
            .collect();
        let a: Vec<Vec3> = truth.iter().map(|t| *t + noise(wh)).collect();
        let b: Vec<Vec3> = truth.iter().map(|t| *t + noise(wh)).collect();
        let (r, ref_noise) = reference_from_halves(&a, &b);
        let den: f64 = r.iter().map(|c| c.length_squared() as f64).sum();
        // Per pixel and channel: var of uniform(−w, w) is w²/3; the reference's is half a half's.
        let per = |w: f32| (w as f64).powi(2) / 3.0;
        let want_noise = 3.0 * n as f64 * per(wh) / 2.0;
        assert!(
            (ref_noise / want_noise - 1.0).abs() < 0.02,
            "{ref_noise} vs {want_noise}"
        );
        let want = 3.0 * n as f64 * ((bias as f64).powi(2) + per(wx)) / den;
        let net = relative_mse_net(&x, &r, ref_noise);
        let raw = relative_mse(&x, &r);
        assert!((net / want - 1.0).abs() < 0.02, "net {net} vs {want}");
        assert!(
            raw / want > 1.5,
            "the raw error counts the reference's noise: {raw} vs {want}"
        );
        // Floored at zero: the reference against itself.
        assert_eq!(relative_mse_net(&r, &r, ref_noise), 0.0);
    }

    #[test]
    fn ssim_of_flat_images_is_the_luminance_term() {
        // Flat windows have no variance or covariance, so SSIM reduces to
        // (2 a b + C1) / (a² + b² + C1) of the encoded values a, b.
        let (la, lb) = (0.2f32, 0.5f32);
        let a = vec![Vec3::splat(la); 16 * 16];
        let b = vec![Vec3::splat(lb); 16 * 16];
        let (ea, eb) = (linear_to_srgb(la) as f64, linear_to_srgb(lb) as f64);
        let c1 = 1e-4;
        let want = (2.0 * ea * eb + c1) / (ea * ea + eb * eb + c1);
        assert!((ssim(&a, &b, 16, 16, 0.0) - want).abs() < 1e-5);
    }
}
