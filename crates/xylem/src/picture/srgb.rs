//! The sRGB transfer function (IEC 61966-2-1): the continuous curve both ways, and the exact 8-bit
//! encoding of linear values through a table of the 255 linear thresholds where the code changes.

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1]; non-finite
/// values give 0.
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x.is_finite() {
        x.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB transfer function (IEC 61966-2-1): the linear value of an encoded x in [0, 1].
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The linear value of an 8-bit sRGB code ([`srgb_to_linear`] of `v / 255`).
pub(crate) fn srgb8_to_linear(v: u8) -> f32 {
    srgb_to_linear(v as f32 / 255.0)
}

/// The sRGB transfer function (IEC 61966-2-1) in f64, for x in [0, 1].
fn encode_f64(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Its inverse (IEC 61966-2-1) in f64: the linear value of an encoded y in [0, 1].
fn decode_f64(y: f64) -> f64 {
    if y <= 0.040_45 {
        y / 12.92
    } else {
        ((y + 0.055) / 1.055).powf(2.4)
    }
}

/// The exact 8-bit code of a linear value: `round(255 · encode(x))` with the f64 formula
/// (halves round up), x clamped to [0, 1].
fn code_f64(x: f32) -> u8 {
    (255.0 * encode_f64((x as f64).clamp(0.0, 1.0))).round() as u8
}

/// Right shift of an f32's bits that leaves its exponent and the top [`MANTISSA_BITS`] bits of
/// its mantissa: the bucket of the encoder's table.
const BUCKET_SHIFT: u32 = 23 - MANTISSA_BITS;
/// Mantissa bits that pick a bucket: 2⁸ buckets an octave, each at most 2⁻⁸ ≈ 0.0039 of its
/// start wide, while neighbouring thresholds lie at least ≈ 1/112 ≈ 0.0089 of their value
/// apart (near x = 1, where d code/dx = 255 · 1.055/2.4 · x^(−1/2.4) ≈ 112; notes/picture.md),
/// so no bucket holds two thresholds.
const MANTISSA_BITS: u32 = 8;
/// The first bucket: everything below 2⁻¹⁴ (all code 0; the first threshold is ≈ 1.5·10⁻⁴ >
/// 2⁻¹³) falls into it.
const FIRST_BUCKET: usize = ((127 - 14) << 23 >> BUCKET_SHIFT) as usize;
/// Buckets from 2⁻¹⁴ up to and including 1.0's.
const BUCKETS: usize = (127 << 23 >> BUCKET_SHIFT) as usize - FIRST_BUCKET + 1;

/// An exact and fast 8-bit sRGB encoder. `thresholds[k]` is the smallest f32 whose code
/// (`round(255 · encode(x))`, IEC 61966-2-1 in f64) exceeds `k`, so the code of x is the number
/// of thresholds at or below x. The count is looked up, not searched: x's exponent and top
/// mantissa bits pick a bucket, `base` holds the code at the bucket's start, and since no bucket
/// holds two thresholds one comparison with `thresholds[base]` finishes it (no `powf`, no
/// branch). The 256th threshold is padding (+∞) for code 255.
///
/// Non-finite values encode as 0 and the rest are clamped to [0, 1], as [`linear_to_srgb`] does.
#[derive(Clone, Debug)]
pub struct Srgb8 {
    thresholds: [f32; 256],
    base: [u8; BUCKETS],
    /// The linear value of each code (`srgb8_to_linear`), for [`Srgb8::decode`].
    linear: [f32; 256],
}

impl Default for Srgb8 {
    fn default() -> Self {
        Self::new()
    }
}

/// The bucket of a value in [0, 1] (+0.0 for zeros of either sign).
#[inline]
fn bucket(x: f32) -> usize {
    (((x.to_bits() & 0x7fff_ffff) >> BUCKET_SHIFT) as usize)
        .saturating_sub(FIRST_BUCKET)
        .min(BUCKETS - 1)
}

impl Srgb8 {
    /// Computes the 255 thresholds from the exact formula — a first guess from the inverse curve
    /// at the code's lower half-step, `decode((k + ½) / 255)`, moved one f32 step at a time to
    /// the smallest value whose code exceeds `k` (a step or two at most) — and the code at each
    /// bucket's start.
    pub fn new() -> Self {
        let mut thresholds = [f32::INFINITY; 256];
        for (k, t) in thresholds.iter_mut().take(255).enumerate() {
            let above = |x: f32| code_f64(x) as usize > k;
            let mut x = decode_f64((k as f64 + 0.5) / 255.0) as f32;
            while !above(x) {
                x = x.next_up();
            }
            while above(x.next_down()) {
                x = x.next_down();
            }
            *t = x;
        }
        let mut base = [0u8; BUCKETS];
        for (i, b) in base.iter_mut().enumerate().skip(1) {
            let start = f32::from_bits(((FIRST_BUCKET + i) << BUCKET_SHIFT) as u32);
            *b = thresholds[..255].partition_point(|&t| t <= start) as u8;
        }
        Srgb8 {
            thresholds,
            base,
            linear: std::array::from_fn(|v| srgb8_to_linear(v as u8)),
        }
    }

    /// The linear value of an 8-bit sRGB code: [`srgb_to_linear`] of `v / 255`, by table (a
    /// `powf` a channel was 4 % of a README sweep's process, in the animation's and contact
    /// sheet's downsampling; notes/picture.md).
    #[inline]
    pub fn decode(&self, v: u8) -> f32 {
        self.linear[v as usize]
    }

    /// The linear value where the code first exceeds `k` (k < 255).
    pub fn threshold(&self, k: u8) -> f32 {
        self.thresholds[k as usize]
    }

    /// The 8-bit sRGB code of a linear value: equal to `round(255 · encode(x))` with the exact
    /// formula in f64, for every f32.
    #[inline]
    pub fn encode(&self, x: f32) -> u8 {
        // NaN and ±∞ give 0 (a select, not a branch).
        let x = if x.is_finite() {
            x.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let code = self.base[bucket(x)];
        code + u8::from(x >= self.thresholds[code as usize])
    }
}

/// 8-bit sRGB bytes (RGB, row-major, top row first) of a linear buffer scaled by `2^exposure`.
pub fn to_srgb8(pixels: &[glam::Vec3], exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    let enc = Srgb8::new();
    let mut out = Vec::with_capacity(pixels.len() * 3);
    for c in pixels {
        out.extend((*c * scale).to_array().map(|v| enc.encode(v)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// IEC 61966-2-1's encoding, written out again here as the test's own reference.
    fn reference(x: f32) -> u8 {
        let x = if x.is_finite() {
            (x as f64).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let e = if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (255.0 * e).round() as u8
    }

    /// The encoding before the threshold table: f32 `powf`, rounded by adding a half.
    fn previous(x: f32) -> u8 {
        (linear_to_srgb(x) * 255.0 + 0.5) as u8
    }

    #[test]
    fn srgb_curve_endpoints_and_continuity() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
        let a = 0.003_130_8_f32;
        assert!((12.92 * a - (1.055 * a.powf(1.0 / 2.4) - 0.055)).abs() < 1e-4);
    }

    #[test]
    fn every_threshold_and_both_its_neighbours_match_the_f64_formula() {
        let enc = Srgb8::new();
        for k in 0..255u8 {
            let t = enc.threshold(k);
            assert!(t > 0.0 && t <= 1.0, "threshold {k} = {t}");
            if k > 0 {
                assert!(
                    t > enc.threshold(k - 1),
                    "thresholds {} and {k} not increasing",
                    k - 1
                );
            }
            // The threshold is the first value of code k + 1; the f32 just below it still has k.
            assert_eq!(enc.encode(t), k + 1, "at threshold {k} = {t}");
            assert_eq!(reference(t), k + 1, "reference at threshold {k} = {t}");
            assert_eq!(enc.encode(t.next_down()), k, "below threshold {k}");
            assert_eq!(reference(t.next_down()), k, "reference below threshold {k}");
            assert_eq!(enc.encode(t.next_up()), reference(t.next_up()), "above {k}");
        }
        // Every code at its own centre, decode(k / 255).
        for k in 0..=255u8 {
            let x = decode_f64(k as f64 / 255.0) as f32;
            assert_eq!(enc.encode(x), k, "centre of code {k}");
            assert_eq!(reference(x), k, "reference centre of code {k}");
        }
        for x in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1.0,
            1.5,
            f32::MAX,
        ] {
            assert_eq!(enc.encode(x), reference(x), "{x}");
        }
    }

    #[test]
    fn no_bucket_holds_two_thresholds() {
        let enc = Srgb8::new();
        for k in 1..255u8 {
            let (lo, hi) = (enc.threshold(k - 1), enc.threshold(k));
            assert!(
                bucket(lo) < bucket(hi),
                "thresholds {} and {k} share bucket {}",
                k - 1,
                bucket(hi)
            );
        }
        assert!(enc.threshold(0) > f32::from_bits(((FIRST_BUCKET + 1) << BUCKET_SHIFT) as u32));
        assert_eq!(bucket(1.0), BUCKETS - 1);
    }

    #[test]
    fn random_values_match_the_f64_formula() {
        // A fixed-seed xorshift over [-0.1, 1.2): every value is checked, so no tolerance.
        let enc = Srgb8::new();
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..1_000_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let x = (s >> 40) as f32 / (1u64 << 24) as f32 * 1.3 - 0.1;
            assert_eq!(enc.encode(x), reference(x), "{x}");
        }
    }

    #[test]
    fn sample_images_give_the_same_bytes_as_before_but_where_f32_rounding_erred() {
        // A ramp over [0, 1.25] in 4096 steps and a noisy "render" (exponential radiance, seed
        // fixed), encoded with exposures of 0 and +1 stop, against the f32 `powf` encoding. A
        // byte may differ only where the f32 path missed the exact code (IEC 61966-2-1 in f64)
        // by one and the new one hits it.
        let ramp: Vec<glam::Vec3> = (0..4096)
            .map(|i| glam::Vec3::splat(i as f32 / 4095.0 * 1.25))
            .collect();
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32 + 0.5) / (1u64 << 24) as f32
        };
        let noisy: Vec<glam::Vec3> = (0..512 * 384)
            .map(|_| glam::Vec3::new(-next().ln(), -next().ln(), -next().ln()) * 0.2)
            .collect();
        for (name, img) in [("ramp", &ramp), ("noisy", &noisy)] {
            for exposure in [0.0f32, 1.0] {
                let scale = exposure.exp2();
                let values: Vec<f32> = img.iter().flat_map(|c| (*c * scale).to_array()).collect();
                let new = to_srgb8(img, exposure);
                let mut differ = 0;
                for (x, n) in values.iter().zip(&new) {
                    let o = previous(*x);
                    if o != *n {
                        differ += 1;
                        assert!(
                            *n == reference(*x) && o.abs_diff(*n) == 1,
                            "{name}, exposure {exposure}: x = {x:e}: old {o}, new {n}, exact {}",
                            reference(*x)
                        );
                    }
                }
                println!(
                    "{name}, exposure {exposure}: {differ} of {} bytes differ, each an f32 rounding error of the old encoding",
                    new.len()
                );
            }
        }
    }

    /// Every f32 in [0, 1] through the old and the new encoding, counting where they differ and
    /// where the old one disagreed with the exact formula (`cargo test --release --lib
    /// srgb_exhaustive -- --ignored --nocapture`; about a billion values).
    #[test]
    #[ignore]
    fn srgb_exhaustive() {
        let enc = Srgb8::new();
        let (mut differ, mut old_wrong, mut new_wrong) = (0u64, 0u64, 0u64);
        for bits in 0..=1.0f32.to_bits() {
            let x = f32::from_bits(bits);
            let (n, o) = (enc.encode(x), previous(x));
            differ += u64::from(n != o);
            let r = reference(x);
            old_wrong += u64::from(o != r);
            new_wrong += u64::from(n != r);
        }
        println!(
            "f32 values in [0, 1]: {}; old != new: {differ}; old != exact: {old_wrong}; new != exact: {new_wrong}",
            1.0f32.to_bits() as u64 + 1
        );
        assert_eq!(new_wrong, 0);
    }

    /// Time to encode a 512×384 frame of fixed-seed noise, old (`powf` per channel) against new
    /// (threshold table), median of 31 runs each (`cargo test --release --lib srgb_frame_speed
    /// -- --ignored --nocapture`; notes/picture.md records the figures).
    #[test]
    #[ignore]
    fn srgb_frame_speed() {
        use std::hint::black_box;
        use std::time::Instant;
        let mut s = 99u64;
        let px: Vec<glam::Vec3> = (0..512 * 384)
            .map(|_| {
                let mut v = [0.0f32; 3];
                for c in &mut v {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    *c = -(((s >> 40) as f32 + 0.5) / (1u64 << 24) as f32).ln() * 0.2;
                }
                glam::Vec3::from_array(v)
            })
            .collect();
        let old = |px: &[glam::Vec3]| -> Vec<u8> {
            px.iter().flat_map(|c| c.to_array()).map(previous).collect()
        };
        let median = |f: &dyn Fn() -> Vec<u8>| {
            let mut t: Vec<f64> = (0..31)
                .map(|_| {
                    let start = Instant::now();
                    black_box(f());
                    start.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[15]
        };
        let t_old = median(&|| old(black_box(&px)));
        let t_new = median(&|| to_srgb8(black_box(&px), 0.0));
        let t_table = median(&|| {
            black_box(Srgb8::new());
            Vec::new()
        });
        println!(
            "512x384 frame: powf {t_old:.3} ms, threshold table {t_new:.3} ms (table build {t_table:.4} ms included), speedup {:.1}x",
            t_old / t_new
        );
    }

    #[test]
    fn srgb8_decoding_inverts_encoding() {
        let enc = Srgb8::new();
        for v in 0..=255u8 {
            assert_eq!(enc.encode(srgb8_to_linear(v)), v, "{v}");
            // The table decodes as the formula does, bit for bit.
            assert_eq!(enc.decode(v).to_bits(), srgb8_to_linear(v).to_bits(), "{v}");
        }
    }
}
