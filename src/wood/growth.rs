//! Seasonal growth (Liu et al. 2016 §6.1.3–6.1.4): the C¹ smoothed triangle wave that makes some
//! years grow faster than others (eq. 23), and the C² smoothed rectangle wave that turns growth
//! time into earlywood / latewood (the growth-ring volume g = w(t)).

/// A periodic C¹ "triangle" wave: a rising line of slope `s_up`, a quadratic top, a falling line of
/// slope −`s_down`, a quadratic bottom (Liu et al. 2016 §6.1.3). Its derivative is continuous and
/// piecewise linear; the two slopes are tied so the wave has no drift over a period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothTriangleWave {
    /// Segment lengths: rise, top, fall, bottom (same unit as the argument).
    lengths: [f32; 4],
    period: f32,
    s_up: f32,
    s_down: f32,
    /// w at the start of the top, fall and bottom segments (w = 0 at the start of the rise).
    knots: [f32; 3],
}

impl SmoothTriangleWave {
    /// The wave with segment lengths `[rise, top, fall, bottom]` and peak-to-peak `amplitude`.
    /// Zero drift: ∫w' = s_up (L_rise + Q/2) − s_down (L_fall + Q/2) = 0 with Q = top + bottom, so
    /// s_down = k s_up, k = (L_rise + Q/2)/(L_fall + Q/2); the positive part of w' integrates to the
    /// amplitude: A = s_up (L_rise + Q / (2 (1 + k))) (derivation in notes/wood.md). Requires
    /// non-negative lengths with L_rise + Q/2 > 0 and L_fall + Q/2 > 0 (checked by the parameters).
    pub fn new(lengths: [f32; 4], amplitude: f32) -> Self {
        let [rise, top, fall, bottom] = lengths;
        let q = top + bottom;
        let k = (rise + 0.5 * q) / (fall + 0.5 * q);
        let s_up = amplitude / (rise + q / (2.0 * (1.0 + k)));
        let s_down = k * s_up;
        let w1 = s_up * rise;
        let w2 = w1 + 0.5 * top * (s_up - s_down);
        let w3 = w2 - s_down * fall;
        SmoothTriangleWave {
            lengths,
            period: rise + top + fall + bottom,
            s_up,
            s_down,
            knots: [w1, w2, w3],
        }
    }

    /// Steepest descent −min w' = s_down: the time volume r + w(r) is monotone iff s_down < 1.
    pub fn max_descent(&self) -> f32 {
        self.s_down
    }

    /// (w(x), w'(x)). Every segment's value is computed and the one `x` falls in is selected, so
    /// the evaluation has no data-dependent branch (random points would mispredict them).
    #[inline]
    pub fn eval(&self, x: f32) -> (f32, f32) {
        self.eval_with::<true>(x)
    }

    /// Whether [`SmoothTriangleWave::eval_unchecked`] holds at `x`: |x| below 2²¹ periods.
    #[inline]
    pub fn in_fast_range(&self, x: f32) -> bool {
        x.abs() < 2_097_152.0 * self.period
    }

    /// [`SmoothTriangleWave::eval`] where [`SmoothTriangleWave::in_fast_range`] holds (same bits),
    /// without the remainder's fallback call: a loop over many points vectorises.
    #[inline]
    pub fn eval_unchecked(&self, x: f32) -> (f32, f32) {
        self.eval_with::<false>(x)
    }

    #[inline(always)]
    fn eval_with<const CHECKED: bool>(&self, x: f32) -> (f32, f32) {
        let [rise, top, fall, bottom] = self.lengths;
        let [w1, w2, w3] = self.knots;
        let (a, b) = (self.s_up, -self.s_down);
        let u_rise = if CHECKED {
            rem_euclid_exact(x, self.period)
        } else {
            rem_euclid_small(x, self.period).0
        };
        let u_top = u_rise - rise;
        let u_fall = u_top - top;
        let u_bottom = u_fall - fall;
        // Over the top w' goes linearly from a to b, over the bottom back from b to a.
        let (top_slope, bottom_slope) = ((b - a) / top, (a - b) / bottom);
        let on_rise = (a * u_rise, a);
        let on_top = (
            w1 + a * u_top + 0.5 * top_slope * u_top * u_top,
            a + top_slope * u_top,
        );
        let on_fall = (w2 + b * u_fall, b);
        let on_bottom = (
            w3 + b * u_bottom + 0.5 * bottom_slope * u_bottom * u_bottom,
            b + bottom_slope * u_bottom,
        );
        let later = if u_fall < fall { on_fall } else { on_bottom };
        let later = if u_top < top { on_top } else { later };
        if u_rise < rise {
            on_rise
        } else {
            later
        }
    }
}

/// A periodic C² "rectangle" wave of period 1: `min` for the `low` fraction of a period, a quintic
/// rise, `max` for the `high` fraction, a quintic fall (Liu et al. 2016 §6.1.4; they write cubic
/// segments, but C² continuity needs the quintic smootherstep 6x⁵ − 15x⁴ + 10x³, whose first and
/// second derivatives vanish at both ends).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothRectangleWave {
    /// End of low, rise, high (the fall ends at 1), as fractions of the period.
    ends: [f32; 3],
    rise: f32,
    fall: f32,
    /// Value over the low part of the period.
    pub min: f32,
    /// Value over the high part of the period.
    pub max: f32,
}

/// Quintic smootherstep on [0, 1] (C²).
#[inline]
fn smootherstep(x: f32) -> f32 {
    x * x * x * (x * (x * 6.0 - 15.0) + 10.0)
}

impl SmoothRectangleWave {
    /// Fractions `[low, rise, high, fall]` of a period (normalised to sum 1; the sum must be > 0).
    pub fn new(fractions: [f32; 4], min: f32, max: f32) -> Self {
        let sum: f32 = fractions.iter().sum();
        let [low, rise, high, fall] = fractions.map(|f| f / sum);
        SmoothRectangleWave {
            ends: [low, low + rise, low + rise + high],
            rise,
            fall,
            min,
            max,
        }
    }

    /// The wave at time `t` (period 1), every segment computed and the right one selected (no
    /// data-dependent branch).
    #[inline]
    pub fn eval(&self, t: f32) -> f32 {
        let u = t - floor_exact(t);
        let [e0, e1, e2] = self.ends;
        let rising = smootherstep((u - e0) / self.rise);
        let falling = 1.0 - smootherstep(((u - e2) / self.fall).min(1.0));
        let s = if u < e2 { 1.0 } else { falling };
        let s = if u < e1 { rising } else { s };
        let s = if u < e0 { 0.0 } else { s };
        self.min + (self.max - self.min) * s
    }
}

/// `x.rem_euclid(p)` for p > 0 without the libm `fmod` loop: the remainder x − n p is an f32
/// (fmod is exact), n p is exact in f64 (24 × 24 bits) and so is their difference; n = ⌊x / p⌋
/// from an f64 division, corrected by one where it rounded across an integer. Falls back to `%`
/// where the quotient is not small. Same bits as `rem_euclid` (tested).
#[inline]
fn rem_euclid_exact(x: f32, p: f32) -> f32 {
    match rem_euclid_small(x, p) {
        (r, true) => r,
        _ => x.rem_euclid(p),
    }
}

/// The fast case of [`rem_euclid_exact`] and whether it applies (|⌊x / p⌋| < 2²², p > 0).
#[inline(always)]
fn rem_euclid_small(x: f32, p: f32) -> (f32, bool) {
    let (xd, pd) = (x as f64, p as f64);
    let n = floor_f64(xd / pd);
    let ok = n.abs() < 4_194_304.0 && p > 0.0;
    let r = xd - n * pd;
    let r = if r < 0.0 {
        r + pd
    } else if r >= pd {
        r - pd
    } else {
        r
    };
    // A zero remainder keeps the sign of x, as fmod's does.
    let r = if r == 0.0 {
        0.0f32.copysign(x)
    } else {
        r as f32
    };
    (r, ok)
}

/// ⌊x⌋ up to the sign of a zero, by rounding to an integer with ±2⁵² (exact for |x| < 2⁵², and
/// beyond every f64 is an integer): plain arithmetic, no libm call on baseline x86-64, and it
/// vectorises. A zero quotient's sign does not change [`rem_euclid_small`]'s result.
#[inline(always)]
fn floor_f64(x: f64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    let m = TWO_52.copysign(x);
    let r = (x + m) - m;
    let r = if r > x { r - 1.0 } else { r };
    if x.abs() < TWO_52 {
        r
    } else {
        x
    }
}

/// `t.floor()` without the libm call (baseline x86-64 has no rounding instruction): through i32
/// below 2²³, where floats have a fraction; the sign of a zero kept.
#[inline]
fn floor_exact(t: f32) -> f32 {
    let small = t.abs() < 8_388_608.0;
    // The truncation unchecked on an argument replaced by 0 where it is large or NaN (a plain
    // `as` saturates, which compiles to scalar code even in a loop the compiler vectorises).
    // SAFETY: the argument is finite and below 2²³ in magnitude.
    let i = unsafe { (if small { t } else { 0.0 }).to_int_unchecked::<i32>() } as f32;
    let f = if i > t { i - 1.0 } else { i.copysign(t) };
    if small {
        f
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rem_euclid_exact_is_rem_euclid() {
        let mut rng = crate::math::Pcg32::new(3, 0);
        for i in 0..400_000 {
            let p = [8.0f32, 6.0, 0.37, 12.5, 1.0][i % 5] * (1.0 + rng.next_f32());
            let scale = [1.0f32, 10.0, 1e3, 1e5][(i / 5) % 4];
            let x = (rng.next_f32() * 2.0 - 1.0) * scale;
            for x in [x, (x / p).round() * p, x.next_up(), x.next_down()] {
                let (fast, slow) = (rem_euclid_exact(x, p), x.rem_euclid(p));
                assert_eq!(
                    fast.to_bits(),
                    slow.to_bits(),
                    "{x} mod {p}: {fast} vs {slow}"
                );
            }
        }
    }

    #[test]
    fn floor_f64_is_floor_up_to_the_sign_of_zero() {
        let mut rng = crate::math::Pcg32::new(8, 0);
        for i in 0..200_000 {
            let x = (rng.next_f32() as f64 * 2.0 - 1.0) * 10f64.powi(i % 18);
            for x in [x, x.round(), x + 0.5, x.round() - 0.5] {
                assert_eq!(floor_f64(x), x.floor(), "{x}");
            }
        }
        for x in [4.5e15, -4.5e15, 1e300, -1e300, f64::INFINITY, 0.0, -0.0] {
            assert_eq!(floor_f64(x), x.floor(), "{x}");
        }
        assert!(floor_f64(f64::NAN).is_nan());
    }

    #[test]
    fn floor_exact_is_floor() {
        let mut x = 1.0e-3f32;
        while x < 3.0e7 {
            for t in [x, -x, x + 0.5, -x - 0.5, x.round(), -x.round()] {
                assert_eq!(floor_exact(t).to_bits(), t.floor().to_bits(), "{t}");
            }
            x *= 1.013;
        }
        for t in [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
        ] {
            assert_eq!(floor_exact(t).to_bits(), t.floor().to_bits(), "{t}");
        }
        assert!(floor_exact(f32::NAN).is_nan());
    }

    #[test]
    fn triangle_wave_is_periodic_c1_with_the_requested_amplitude() {
        let w = SmoothTriangleWave::new([3.0, 1.0, 1.5, 0.5], 0.8);
        let period = 6.0;
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        let n = 60_000;
        let mut prev = w.eval(0.0);
        for i in 1..=n {
            let x = i as f32 * period / n as f32;
            let (v, d) = w.eval(x);
            lo = lo.min(v);
            hi = hi.max(v);
            // C¹: value and slope change by O(h) between neighbouring samples.
            assert!(
                (v - prev.0).abs() < 1e-3 && (d - prev.1).abs() < 1e-2,
                "jump at {x}"
            );
            prev = (v, d);
        }
        assert!((hi - lo - 0.8).abs() < 1e-3, "peak-to-peak {}", hi - lo);
        assert!((w.eval(period).0 - w.eval(0.0).0).abs() < 1e-5, "no drift");
        assert!(w.eval(0.1).1 > 0.0 && w.eval(4.5).1 < 0.0);
    }

    #[test]
    fn rectangle_wave_is_c2_and_reaches_its_levels() {
        let g = SmoothRectangleWave::new([0.5, 0.2, 0.2, 0.1], 0.2, 0.9);
        assert!((g.eval(0.25) - 0.2).abs() < 1e-6 && (g.eval(0.8) - 0.9).abs() < 1e-6);
        // Second differences stay O(h²) everywhere (no kink), also across the year boundary.
        let h = 1e-3_f32;
        for i in 0..2000 {
            let t = i as f32 / 1000.0 + 0.0005;
            let d2 = g.eval(t + h) - 2.0 * g.eval(t) + g.eval(t - h);
            // |g''| ≤ (max − min) · 5.77 / fall² for the quintic; times h².
            assert!(
                d2.abs() < 0.7 * 5.8 / 0.01 * h * h + 1e-5,
                "kink at {t}: {d2}"
            );
        }
    }
}
