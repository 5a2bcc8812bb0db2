//! `exp`, `sin`, `cos`, `asin` and `acos` as branch-free polynomials in plain f32 arithmetic. The libm functions
//! are calls the compiler cannot put in SIMD lanes; these inline into a loop over many points and
//! vectorise there, and give the same bits in a lane as in a scalar call (no fused or reordered
//! operations in Rust), so a batch evaluation equals the per-point one exactly.
//!
//! Both reduce the argument by Cody & Waite's two-constant method (W. J. Cody and W. Waite 1980,
//! "Software Manual for the Elementary Functions", ch. 6 and 8) and use the minimax polynomials of
//! S. L. Moshier's Cephes library (`expf.c`, `sinf.c`, `asinf.c`), accurate to about 1 ulp on the reduced
//! range; the tests bound the error against f64.

/// eˣ, relative error ≤ 1.5·10⁻⁷ for x ∈ [−87, 88] (measured 8·10⁻⁸); the argument is clamped to that range,
/// so the result is finite and positive for every finite x (≈ 1.6·10⁻³⁸ below, ≈ 1.65·10³⁸ above).
/// NaN gives NaN.
#[inline(always)]
#[allow(clippy::excessive_precision)] // the constants as published
pub fn exp(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    // ln 2 = C1 + C2 with C1 exact in few bits, so k·C1 is exact for |k| ≤ 2⁸ (Cody & Waite).
    const C1: f32 = 0.693_359_4;
    const C2: f32 = -2.121_944_4e-4;
    let x = x.clamp(-87.0, 88.0);
    // k = round(x / ln 2) by adding and removing 1.5·2²³ (exact for |x/ln 2| < 2²²).
    const ROUND: f32 = 12_582_912.0;
    let k = (x * LOG2E + ROUND) - ROUND;
    let r = (x - k * C1) - k * C2;
    // Cephes expf: e^r ≈ 1 + r + r² P(r) on |r| ≤ ln 2 / 2.
    let p = ((((1.987_569_1e-4 * r + 1.398_199_9e-3) * r + 8.333_452e-3) * r + 4.166_579_6e-2) * r
        + 1.666_666_5e-1)
        * r
        + 5.0e-1;
    let e = (p * r * r + r) + 1.0;
    // 2^k from the exponent bits (k ∈ [−126, 127] after the clamp).
    e * f32::from_bits(((k as i32 + 127) as u32) << 23)
}

/// (sin x, cos x), absolute error ≤ 1.5·10⁻⁷ for |x| ≤ 10⁴ (measured 7.6·10⁻⁸; the reduction
/// loses accuracy slowly beyond). The angle is reduced to r ∈ [−π/4, π/4] and a quadrant, whose swap and signs
/// are selected without branches.
#[inline(always)]
#[allow(clippy::excessive_precision)] // the constants as published
pub fn sin_cos(x: f32) -> (f32, f32) {
    const TWO_OVER_PI: f32 = std::f32::consts::FRAC_2_PI;
    // π/2 in three parts (Cephes sinf's DP1..DP3 doubled), each product with small k exact.
    const P1: f32 = 1.570_312_5;
    const P2: f32 = 4.837_512_97e-4;
    const P3: f32 = 7.549_789_9e-8;
    const ROUND: f32 = 12_582_912.0;
    let k = (x * TWO_OVER_PI + ROUND) - ROUND;
    let r = ((x - k * P1) - k * P2) - k * P3;
    let z = r * r;
    // Cephes sinf / cosf polynomials on [−π/4, π/4].
    let s = ((-1.951_529_6e-4 * z + 8.332_160_9e-3) * z - 1.666_665_5e-1) * z * r + r;
    let c = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    // Quadrant q = k mod 4: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s).
    let q = (k as i32) & 3;
    let (sin, cos) = if q & 1 == 0 { (s, c) } else { (c, s) };
    let sin = if q & 2 == 0 { sin } else { -sin };
    let cos = if (q + 1) & 2 == 0 { cos } else { -cos };
    (sin, cos)
}

/// The arcsine's core on [0, 1] (Cephes `asinf.c`): for a ≤ ½ the minimax polynomial in a²
/// directly, above ½ through asin a = π/2 − 2 asin √((1 − a)/2), whose argument is ≤ ½. Returns
/// (p, big) with p = asin a (a ≤ ½) or p = asin √((1 − a)/2) (a > ½), selected without branches.
#[inline(always)]
#[allow(clippy::excessive_precision)] // the constants as published
fn asin_core(a: f32) -> (f32, bool) {
    let big = a > 0.5;
    let z_big = 0.5 * (1.0 - a);
    let z = if big { z_big } else { a * a };
    let x = if big { z_big.sqrt() } else { a };
    let p = ((((4.216_319_9e-2 * z + 2.418_131_1e-2) * z + 4.547_002_6e-2) * z + 7.495_300_3e-2)
        * z
        + 1.666_675_2e-1)
        * z
        * x
        + x;
    (p, big)
}

/// asin x for x clamped to [−1, 1], absolute error ≤ 2·10⁻⁷ (tested against f64); NaN gives NaN.
#[inline(always)]
pub fn asin(x: f32) -> f32 {
    let x = x.clamp(-1.0, 1.0);
    let (p, big) = asin_core(x.abs());
    let r = if big {
        std::f32::consts::FRAC_PI_2 - 2.0 * p
    } else {
        p
    };
    r.copysign(x)
}

/// acos x for x clamped to [−1, 1], absolute error ≤ 3·10⁻⁷ (tested against f64), from the
/// arcsine's core as in Cephes `acosf.c`: 2 asin √((1 − x)/2) for x > ½, π − that for x < −½,
/// π/2 − asin x between; NaN gives NaN.
#[inline(always)]
pub fn acos(x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let x = x.clamp(-1.0, 1.0);
    let (p, big) = asin_core(x.abs());
    let outer = if x > 0.0 { 2.0 * p } else { PI - 2.0 * p };
    if big {
        outer
    } else {
        FRAC_PI_2 - p.copysign(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest `error(x)` over `n + 1` evenly spaced x in [lo, hi].
    fn worst(lo: f32, hi: f32, n: u32, error: impl Fn(f32) -> f64) -> f64 {
        (0..=n)
            .map(|i| error(lo + (hi - lo) * i as f32 / n as f32))
            .fold(0.0, f64::max)
    }

    #[test]
    fn exp_matches_f64_to_a_few_ulp() {
        let rel = worst(-87.0, 88.0, 200_000, |x| {
            let exact = (x as f64).exp();
            ((exp(x) as f64 - exact) / exact).abs()
        });
        assert!(rel < 1.5e-7, "worst relative error {rel:e}");
        assert_eq!(exp(0.0), 1.0);
        // Clamped, never infinite or zero; NaN stays NaN.
        assert!(exp(-1e30) > 0.0 && exp(1e30).is_finite());
        assert!(exp(f32::NAN).is_nan());
    }

    #[test]
    fn sin_cos_match_f64() {
        let error = |x: f32| {
            let ((s, c), (es, ec)) = (sin_cos(x), (x as f64).sin_cos());
            (s as f64 - es).abs().max((c as f64 - ec).abs())
        };
        let wide = worst(-1e4, 1e4, 400_000, error);
        assert!(wide < 1.5e-7, "worst absolute error {wide:e}");
        // Small angles (the interlock's): tighter, and exact at 0.
        let small = worst(-1.0, 1.0, 10_000, error);
        assert!(small < 1.2e-7, "worst absolute error {small:e}");
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    #[test]
    fn asin_acos_match_f64() {
        let err_asin = |x: f32| (asin(x) as f64 - (x as f64).asin()).abs();
        let err_acos = |x: f32| (acos(x) as f64 - (x as f64).acos()).abs();
        let a = worst(-1.0, 1.0, 400_000, err_asin);
        assert!(a < 2e-7, "asin: worst absolute error {a:e}");
        let c = worst(-1.0, 1.0, 400_000, err_acos);
        assert!(c < 3e-7, "acos: worst absolute error {c:e}");
        // Near ±1, where the half-angle branch takes over, and near the seam at ±½.
        assert!(worst(0.999, 1.0, 10_000, err_acos) < 3e-7);
        assert!(worst(0.4999, 0.5001, 10_000, err_asin) < 2e-7);
        assert_eq!((asin(0.0), acos(1.0)), (0.0, 0.0));
        assert_eq!(asin(2.0), std::f32::consts::FRAC_PI_2);
        assert_eq!(acos(-2.0), std::f32::consts::PI);
        assert!(asin(f32::NAN).is_nan() && acos(f32::NAN).is_nan());
        // Odd symmetry of asin, exactly.
        assert_eq!(asin(-0.3), -asin(0.3));
    }
}
