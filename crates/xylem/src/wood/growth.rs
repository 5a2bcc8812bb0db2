//! Seasonal growth (Liu et al. 2016 §6.1.3–6.1.4): the C¹ smoothed triangle wave that makes some
//! years grow faster than others (eq. 23), and the C² smoothed rectangle wave that turns growth
//! time into earlywood / latewood (the growth-ring volume g = w(t)).

use glam::Vec3;

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
    pub(crate) fn in_fast_range(&self, x: f32) -> bool {
        x.abs() < 2_097_152.0 * self.period
    }

    /// [`SmoothTriangleWave::eval`] where [`SmoothTriangleWave::in_fast_range`] holds (same bits),
    /// without the remainder's fallback call: a loop over many points vectorises.
    #[inline]
    pub(crate) fn eval_unchecked(&self, x: f32) -> (f32, f32) {
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
        self.level(self.normalized(t))
    }

    /// The wave's level for a normalised value `s` ∈ [0, 1] (0 at `min`, 1 at `max`), e.g. a
    /// filtered mean of the normalised wave.
    #[inline(always)]
    pub fn level(&self, s: f32) -> f32 {
        self.min + (self.max - self.min) * s
    }

    /// The normalised wave s(t) ∈ [0, 1].
    #[inline(always)]
    fn normalized(&self, t: f32) -> f32 {
        let u = t - floor_exact(t);
        let [e0, e1, e2] = self.ends;
        let rising = smootherstep((u - e0) / self.rise);
        let falling = 1.0 - smootherstep(((u - e2) / self.fall).min(1.0));
        let s = if u < e2 { 1.0 } else { falling };
        let s = if u < e1 { rising } else { s };
        if u < e0 {
            0.0
        } else {
            s
        }
    }

    /// Below this fraction of the shorter transition the box filters return the point value:
    /// the box mean and the point value differ by w² s″/24 + O(w⁴), and |s″| ≤ 5.78/L² on a
    /// transition of length L, so by at most 0.01 · 5.78 / 24 = 0.0024 (under half an 8-bit
    /// level) where they switch.
    pub(crate) const MIN_BOX_FRACTION: f32 = 0.1;

    /// The filter width (periods) below which the box filters return the point value.
    #[inline]
    pub fn min_box(&self) -> f32 {
        Self::MIN_BOX_FRACTION * self.rise.min(self.fall).max(1e-3)
    }

    /// The normalised wave s(t) ∈ [0, 1] box-filtered over [lo, hi] (w = hi − lo periods), in
    /// closed form: (S(hi) − S(lo)) / w with S the antiderivative of s, the classic way of
    /// antialiasing a procedural pulse train by integrating it (Ebert, Musgrave, Peachey, Perlin,
    /// Worley, "Texturing & Modeling", 3rd ed. 2003, ch. 2, "Antialiasing": the integral of the
    /// pulse train, `filteredpulsetrain`; Heckbert 1989 §3.3 on box prefiltering). Whole periods
    /// contribute their mean, the partial ones the antiderivative of the segments, where
    /// ∫₀ˣ (6y⁵ − 15y⁴ + 10y³) dy = x⁶ − 3x⁵ + 5x⁴/2 (derivation: notes/wood.md §3a). Below
    /// [`SmoothRectangleWave::min_box`] periods the point value (the two differ by at most
    /// 0.0024 there).
    pub fn box_mean(&self, lo: f32, hi: f32) -> f32 {
        self.box_moments(lo, hi).x
    }

    /// The box means of s, s² and s³ over [lo, hi] (as [`SmoothRectangleWave::box_mean`]; what a
    /// cubic of the ring value, such as ring-porous pore volume (1 − ρ s)³, averages to). The
    /// plateaus give 0 and 1; a transition's ∫₀ˣ Pⁿ is the polynomial `smootherstep_power_integral`.
    pub(crate) fn box_moments(&self, lo: f32, hi: f32) -> Vec3 {
        let w = hi - lo;
        if !(w >= self.min_box()) {
            let s = self.normalized(0.5 * (lo + hi));
            return Vec3::new(s, s * s, s * s * s);
        }
        let [e0, e1, e2] = self.ends;
        let high = e2 - e1;
        let q1 = smootherstep_power_integral(1.0);
        // ∫₀ᵘ sⁿ over one period; the fall's ∫₀ˣ (1 − P(y))ⁿ dy = Qₙ(1) − Qₙ(1 − x) since
        // 1 − P(y) = P(1 − y).
        let integral = |u: f32| -> Vec3 {
            if u < e0 {
                Vec3::ZERO
            } else if u < e1 {
                self.rise * smootherstep_power_integral((u - e0) / self.rise)
            } else if u < e2 {
                self.rise * q1 + Vec3::splat(u - e1)
            } else {
                let x = ((u - e2) / self.fall).min(1.0);
                let fall = q1 - smootherstep_power_integral(1.0 - x);
                self.rise * q1 + Vec3::splat(high) + self.fall * fall
            }
        };
        let period = (self.rise + self.fall) * q1 + Vec3::splat(high);
        let (whole, ua, ub) = window(lo, hi);
        (period * whole + integral(ub) - integral(ua)) * (1.0 / w)
    }

    /// E[exp(−k s)] over the box window [lo, hi] as [`SmoothRectangleWave::box_mean`], per channel
    /// of the table's k: what Beer's law makes of the filtered rings (c = exp(−a₀ − k s), so
    /// the mean colour is exp(−a₀) · E[exp(−k s)]; exp is convex, so exp(−k · mean s) would be
    /// too dark). The plateaus integrate in closed form (1 and e^(−k) times their length); a
    /// quintic transition's ∫ exp(−k P(y)) dy has none and comes from the table
    /// ([`RingExpTable`], built once per k). Below [`SmoothRectangleWave::min_box`] the point
    /// value exp(−k s(t)).
    pub(crate) fn box_exp_mean(&self, lo: f32, hi: f32, table: &RingExpTable) -> Vec3 {
        let w = hi - lo;
        if !(w >= self.min_box()) {
            return (-table.k * self.normalized(0.5 * (lo + hi))).exp();
        }
        let (whole, ua, ub) = window(lo, hi);
        (table.period * whole + table.cumulative(self, ub) - table.cumulative(self, ua)) * (1.0 / w)
    }

    /// The table [`SmoothRectangleWave::box_exp_mean`] reads for absorbance scale `k`.
    pub(crate) fn exp_table(&self, k: Vec3) -> RingExpTable {
        RingExpTable::new(self, k)
    }
}

/// ∫ exp(−k s) over the ring wave's segments for one k (per channel): the rise's
/// R(x) = ∫₀ˣ exp(−k P(y)) dy at [`RingExpTable::CELLS`] + 1 knots (each cell by 4-point
/// Gauss–Legendre, Abramowitz & Stegun 25.4.29) with its exact slope exp(−k P(x)), read by cubic
/// Hermite interpolation (error ≤ h⁴ max|R⁽⁴⁾| / 384 ≈ 10⁻¹⁰ for k ≤ 4, h = 1/64); the fall's
/// integrand exp(−k (1 − P(y))) is the rise's at 1 − y, since P(1 − y) = 1 − P(y).
#[derive(Clone, Debug, PartialEq)]
pub struct RingExpTable {
    k: Vec3,
    /// R at the knots and its slope there.
    value: Vec<Vec3>,
    slope: Vec<Vec3>,
    /// e^(−k), the latewood plateau.
    high: Vec3,
    /// ∫ exp(−k s) over one period.
    period: Vec3,
}

impl RingExpTable {
    /// Cells of the rise's table.
    pub const CELLS: usize = 64;

    fn new(wave: &SmoothRectangleWave, k: Vec3) -> Self {
        let f = |y: f32| (-k * smootherstep(y)).exp();
        let h = 1.0 / Self::CELLS as f32;
        let mut value = vec![Vec3::ZERO];
        let mut sum = Vec3::ZERO;
        for i in 0..Self::CELLS {
            sum += gauss_legendre_4(i as f32 * h, (i + 1) as f32 * h, f);
            value.push(sum);
        }
        let slope = (0..=Self::CELLS).map(|i| f(i as f32 * h)).collect();
        let [e0, e1, e2] = wave.ends;
        let high = (-k).exp();
        let period = e0 + (wave.rise + wave.fall) * sum + (e2 - e1) * high;
        RingExpTable {
            k,
            value,
            slope,
            high,
            period,
        }
    }

    /// R(x), x ∈ [0, 1], by cubic Hermite interpolation between the knots.
    #[inline]
    fn rise(&self, x: f32) -> Vec3 {
        let u = x.clamp(0.0, 1.0) * Self::CELLS as f32;
        let i = (u as usize).min(Self::CELLS - 1);
        let t = u - i as f32;
        let h = 1.0 / Self::CELLS as f32;
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        self.value[i] * h00
            + self.slope[i] * (h10 * h)
            + self.value[i + 1] * h01
            + self.slope[i + 1] * (h11 * h)
    }

    /// ∫₀ᵘ exp(−k s) over one period of `wave` (u ∈ [0, 1]).
    #[inline]
    fn cumulative(&self, wave: &SmoothRectangleWave, u: f32) -> Vec3 {
        let [e0, e1, e2] = wave.ends;
        let r1 = self.value[Self::CELLS];
        if u < e0 {
            Vec3::splat(u)
        } else if u < e1 {
            e0 + wave.rise * self.rise((u - e0) / wave.rise)
        } else if u < e2 {
            e0 + wave.rise * r1 + (u - e1) * self.high
        } else {
            let x = ((u - e2) / wave.fall).min(1.0);
            e0 + wave.rise * r1 + (e2 - e1) * self.high + wave.fall * (r1 - self.rise(1.0 - x))
        }
    }
}

/// The window [a, b] of a period-1 function as (whole periods between the ends' period
/// starts, phase of a, phase of b): ∫ₐᵇ f = whole · ∫₀¹ f + ∫₀^ub f − ∫₀^ua f.
#[inline]
fn window(a: f32, b: f32) -> (f32, f32, f32) {
    let (fa, fb) = (floor_exact(a), floor_exact(b));
    (fb - fa, a - fa, b - fb)
}

/// Qₙ(x) = ∫₀ˣ P(y)ⁿ dy for n = 1, 2, 3, P = 10y³ − 15y⁴ + 6y⁵ the quintic smootherstep:
/// Q₁ = x⁶ − 3x⁵ + 5x⁴/2, and Q₂, Q₃ from the expanded powers (exact rational coefficients,
/// Q₂(1) = 181/462, Q₃(1) = 26/77), in f64 since their terms cancel to 10⁻³ of their size.
#[inline]
fn smootherstep_power_integral(x: f32) -> Vec3 {
    let x = x as f64;
    let horner = |c: &[f64]| c.iter().rev().fold(0.0, |acc, &k| acc * x + k);
    let x4 = x * x * x * x;
    let q1 = x4 * x * x - 3.0 * x4 * x + 2.5 * x4;
    // Coefficients of x⁷ … x¹¹ and x¹⁰ … x¹⁶.
    let q2 = x4 * x * x * x * horner(&[100.0 / 7.0, -37.5, 115.0 / 3.0, -18.0, 36.0 / 11.0]);
    let x10 = x4 * x4 * x * x;
    let q3 = x10
        * horner(&[
            100.0,
            -4500.0 / 11.0,
            712.5,
            -675.0,
            2565.0 / 7.0,
            -108.0,
            13.5,
        ]);
    Vec3::new(q1 as f32, q2 as f32, q3 as f32)
}

/// ∫ f(y) dy over [x0, x1] by 4-point Gauss–Legendre (Abramowitz & Stegun 25.4.29: nodes
/// ±0.3399810436, ±0.8611363116, weights 0.6521451549, 0.3478548451 on [−1, 1]).
#[inline]
fn gauss_legendre_4(x0: f32, x1: f32, f: impl Fn(f32) -> Vec3) -> Vec3 {
    const NODES: [f32; 4] = [-0.861_136_3, -0.339_981_04, 0.339_981_04, 0.861_136_3];
    const WEIGHTS: [f32; 4] = [0.347_854_84, 0.652_145_15, 0.652_145_15, 0.347_854_84];
    let (mid, half) = (0.5 * (x0 + x1), 0.5 * (x1 - x0));
    let mut sum = Vec3::ZERO;
    for (n, wt) in NODES.iter().zip(WEIGHTS) {
        sum += wt * f(mid + half * n);
    }
    sum * half
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

    /// The mean of f over [t − w/2, t + w/2] by a 20 000-point midpoint rule: the supersampled
    /// reference the closed forms are checked against.
    fn supersampled(t: f32, w: f32, f: impl Fn(f32) -> Vec3) -> Vec3 {
        let n = 20_000;
        let mut sum = glam::DVec3::ZERO;
        for i in 0..n {
            let x = t as f64 - 0.5 * w as f64 + (i as f64 + 0.5) / n as f64 * w as f64;
            sum += f(x as f32).as_dvec3();
        }
        (sum / n as f64).as_vec3()
    }

    /// Windows (t, w) from a tenth of a transition to several years, far from the pith too.
    fn windows() -> Vec<(f32, f32)> {
        let mut rng = crate::math::Pcg32::new(28, 1);
        (0..300)
            .map(|i| {
                let t = [0.0, 3.0, 40.0, 150.0][i % 4] + 3.0 * rng.next_f32();
                let w = 0.02 * 250f32.powf(rng.next_f32());
                (t, w)
            })
            .collect()
    }

    #[test]
    fn box_mean_matches_a_supersampled_window() {
        let g = SmoothRectangleWave::new([0.45, 0.15, 0.3, 0.1], 0.0, 1.0);
        let reference = |t, w| supersampled(t, w, |x| Vec3::splat(g.eval(x))).x;
        let mut worst = 0.0f32;
        for (t, w) in windows() {
            worst = worst.max((g.box_mean(t - 0.5 * w, t + 0.5 * w) - reference(t, w)).abs());
            // The second and third moments (ring-porous pore volume).
            let powers = |x: f32| {
                let s = g.eval(x);
                Vec3::new(s, s * s, s * s * s)
            };
            let m = g.box_moments(t - 0.5 * w, t + 0.5 * w) - supersampled(t, w, powers);
            worst = worst.max(m.abs().max_element());
        }
        // The midpoint rule's own error is ≤ w² max|s″| / (24 n²) ≈ 10⁻⁸; f32 phases ≈ 10⁻⁵.
        assert!(worst < 2e-4, "worst {worst}");
        // Negative control: the point value against the same reference is far off.
        let point = windows()
            .iter()
            .map(|&(t, w)| (g.eval(t) - reference(t, w)).abs())
            .fold(0.0f32, f32::max);
        assert!(
            point > 0.3,
            "point sampling came close ({point}): the test has no power"
        );
        // Whole periods average to the wave's mean, low·0 + rise/2 + high + fall/2.
        let mean = 0.15 / 2.0 + 0.3 + 0.1 / 2.0;
        assert!((g.box_mean(5.3, 9.3) - mean).abs() < 1e-5);
        // Below a tenth of the shorter transition: the point value.
        assert_eq!(g.box_mean(2.5, 2.509), g.eval(2.5045));
    }

    #[test]
    fn box_exp_mean_matches_fine_quadrature() {
        let g = SmoothRectangleWave::new([0.3, 0.25, 0.35, 0.1], 0.0, 1.0);
        let k = Vec3::new(0.3, 1.5, 4.0);
        let f = |x: f32| (-k * g.eval(x)).exp();
        let table = g.exp_table(k);
        let mut worst = 0.0f32;
        for (t, w) in windows() {
            let want = supersampled(t, w, f);
            let got = g.box_exp_mean(t - 0.5 * w, t + 0.5 * w, &table);
            worst = worst.max((got - want).abs().max_element());
        }
        assert!(worst < 2e-4, "worst {worst}");
        // Negative control: Beer's law of the mean ring value (too dark: exp is convex).
        let (t, w) = (5.2, 3.0);
        let want = supersampled(t, w, f);
        let of_mean = (-k * g.box_mean(t - 0.5 * w, t + 0.5 * w)).exp();
        assert!(
            (of_mean - want).min_element() < -0.02,
            "{of_mean} vs {want}"
        );
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
