//! Fractal sums of a lattice noise: fBm, turbulence and ridged multifractal (Musgrave, in Ebert et
//! al., *Texturing and Modeling* 3rd ed., ch. 16: `fBm`, `Turbulence`, `RidgedMultifractal`),
//! with analytic gradients. Octave i samples the basis at `lacunarity^i · p + shift_i` with its
//! own seed; the small irrational shift keeps lattice points of different octaves apart (gradient
//! noise vanishes on its lattice, so unshifted octaves with lacunarity 2 would all vanish at the
//! integer points).

#[cfg(target_arch = "x86_64")]
use super::gradient::kernel;
use super::gradient::{gradient3_grad_s, gradient3_s};
use super::hash::mix32;
#[cfg(target_arch = "x86_64")]
use super::lanes::Lanes;
use super::value::value3_grad_s;
use crate::simd::{simd_wide, Simd};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Which lattice noise the octaves sum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    /// Perlin's improved gradient noise (Perlin 2002).
    Gradient,
    /// Lattice value noise.
    Value,
}

/// How the octaves combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FractalKind {
    /// Σ gainⁱ n(λⁱ p): fractional Brownian motion.
    Fbm,
    /// Σ gainⁱ |n(λⁱ p)| (Perlin 1985's turbulence): creases where the noise crosses zero.
    Turbulence,
    /// Σ gainⁱ (1 − |n(λⁱ p)|)²: sharp ridges along the zero set (a simplified ridged
    /// multifractal without the inter-octave weighting, so every octave stays independent).
    Ridged,
}

/// A fractal sum of octaves of a basis noise.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fractal {
    /// How the octaves combine.
    pub kind: FractalKind,
    /// The noise each octave sums.
    pub basis: Basis,
    /// Number of octaves summed.
    pub octaves: u32,
    /// Frequency ratio between octaves (typically 2).
    pub lacunarity: f32,
    /// Amplitude ratio between octaves (typically ½; the Hurst exponent is −log₂ gain).
    pub gain: f32,
}

impl Default for Fractal {
    fn default() -> Self {
        Fractal {
            kind: FractalKind::Fbm,
            basis: Basis::Gradient,
            octaves: 5,
            lacunarity: 2.0,
            gain: 0.5,
        }
    }
}

/// Per-octave shifts (fractional parts of multiples of the plastic-number sequence, well spread).
/// Octave seeds: the scrambled seed plus i times the golden-ratio constant.
const OCTAVE_SEED_STEP: u32 = 0x9e37_79b9;

const SHIFT: Vec3 = Vec3::new(0.754_877_7, 0.569_840_3, 0.430_159_7);

impl Fractal {
    /// fBm with the default gradient basis, lacunarity 2 and gain ½.
    pub fn fbm(octaves: u32) -> Self {
        Fractal {
            octaves,
            ..Default::default()
        }
    }

    /// Σ of the amplitudes, Σ gainⁱ: a bound for |fBm| / max|basis| and the scale textures use
    /// to normalise.
    pub(crate) fn amplitude_sum(&self) -> f32 {
        (0..self.octaves).map(|i| self.gain.powi(i as i32)).sum()
    }

    /// The fractal sum at `p` for `seed`.
    #[inline]
    pub fn eval(&self, p: Vec3, seed: u32) -> f32 {
        match (self.basis, self.kind) {
            (Basis::Gradient, FractalKind::Fbm) => self.gradient_lanes(p, seed, |n| n),
            (Basis::Gradient, FractalKind::Turbulence) => self.gradient_lanes(p, seed, f32::abs),
            (Basis::Gradient, FractalKind::Ridged) => self.gradient_lanes(p, seed, ridge),
            (Basis::Value, _) => self.sum::<false, _>(p, seed, value3_grad_s).0,
        }
    }

    /// [`Fractal::eval`] at every point of `points`, written to `out` (same length). For the
    /// gradient basis the lanes are points — 16, 8 or 4 at once ([`Simd::best`]) — and the
    /// octaves a loop, so no lane idles whatever the octave count; the value basis and the last
    /// `len % lanes` points go one at a time. Values equal to `eval` (tested).
    ///
    /// # Panics
    /// If `points.len() != out.len()`.
    pub fn eval_many(&self, points: &[Vec3], seed: u32, out: &mut [f32]) {
        self.eval_many_with(Simd::best(), points, seed, out)
    }

    /// [`Fractal::eval_many`] on `simd`, or the best the CPU has if it lacks it.
    pub fn eval_many_with(&self, simd: Simd, points: &[Vec3], seed: u32, out: &mut [f32]) {
        assert_eq!(
            points.len(),
            out.len(),
            "Fractal::eval_many: {} points but {} outputs",
            points.len(),
            out.len()
        );
        let simd = match self.basis {
            Basis::Gradient => simd.min(Simd::best()),
            Basis::Value => Simd::Scalar,
        };
        // SAFETY: `simd` is no wider than `Simd::best()`.
        #[cfg(target_arch = "x86_64")]
        let done = match simd {
            Simd::Scalar => 0,
            Simd::Sse2 => unsafe { self.many::<std::arch::x86_64::__m128>(points, seed, out) },
            Simd::Avx2 => unsafe { many_avx2(self, points, seed, out) },
            Simd::Avx512 => unsafe { many_avx512(self, points, seed, out) },
        };
        #[cfg(not(target_arch = "x86_64"))]
        let done = 0;
        for (p, o) in points[done..].iter().zip(&mut out[done..]) {
            *o = self.eval(*p, seed);
        }
    }

    /// Gradient-basis sums on whole groups of `L::N` points; returns how many points it wrote.
    /// Per octave and lane: `p · freq + shift`, the kernel, the fold, `total += amp · fold` —
    /// the scalar sum's operations in its order.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn many<L: Lanes>(&self, points: &[Vec3], seed: u32, out: &mut [f32]) -> usize {
        for (p, o) in points.chunks_exact(L::N).zip(out.chunks_exact_mut(L::N)) {
            let (x, y, z) = L::load_xyz(p);
            let mut oct = Octaves::new(self, seed);
            let mut total = L::splat(0.0);
            while oct.left > 0 {
                let f = L::splat(oct.freq);
                let n = kernel(
                    x.mul(f).add(L::splat(oct.shift.x)),
                    y.mul(f).add(L::splat(oct.shift.y)),
                    z.mul(f).add(L::splat(oct.shift.z)),
                    L::splat_i(oct.s),
                );
                let folded = match self.kind {
                    FractalKind::Fbm => n,
                    FractalKind::Turbulence => n.abs(),
                    FractalKind::Ridged => {
                        let r = L::splat(1.0).sub(n.abs());
                        r.mul(r)
                    }
                };
                total = total.add(L::splat(oct.amp).mul(folded));
                oct.step();
            }
            total.store(o);
        }
        points.len() / L::N * L::N
    }

    /// Value and analytic gradient (the chain rule through |·| uses sign(n); at n = 0 the
    /// turbulence and ridged sums have a crease where the gradient is one-sided).
    #[inline]
    pub fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        match self.basis {
            Basis::Gradient => self.sum::<true, _>(p, seed, gradient3_grad_s),
            Basis::Value => self.sum::<true, _>(p, seed, value3_grad_s),
        }
    }

    /// (fold(n), d fold / dn) of this sum's kind.
    #[inline(always)]
    fn fold(&self, n: f32) -> (f32, f32) {
        match self.kind {
            FractalKind::Fbm => (n, 1.0),
            FractalKind::Turbulence => (n.abs(), n.signum()),
            FractalKind::Ridged => {
                let r = 1.0 - n.abs();
                (r * r, -2.0 * r * n.signum())
            }
        }
    }

    /// The hot path: sums of gradient noise. Octaves are independent, so they go through the
    /// lane kernel together (lane k = octave i + k), each folded by `fold` (identity, |n|,
    /// ridge); octave seeds are one add apart on the scrambled seed. Eight lanes (AVX2, where
    /// the CPU has it) for more than four octaves, else four (SSE2); same points, seeds and
    /// summation order as the scalar path.
    #[inline(always)]
    fn gradient_lanes(&self, p: Vec3, seed: u32, fold: impl Fn(f32) -> f32) -> f32 {
        let simd = if self.octaves > 4 {
            Simd::Avx2
        } else {
            Simd::Sse2
        };
        self.gradient_lanes_with(simd.min(Simd::best()), p, seed, fold)
    }

    /// [`Self::gradient_lanes`] on `simd` (which the caller checked the CPU has).
    #[inline(always)]
    fn gradient_lanes_with(
        &self,
        simd: Simd,
        p: Vec3,
        seed: u32,
        fold: impl Fn(f32) -> f32,
    ) -> f32 {
        let mut o = Octaves::new(self, seed);
        // SAFETY: `simd` is no wider than `Simd::best()`.
        #[cfg(target_arch = "x86_64")]
        match simd {
            Simd::Scalar => {}
            Simd::Sse2 => unsafe { o.lanes::<std::arch::x86_64::__m128>(p, &fold) },
            Simd::Avx2 => unsafe { octaves_avx2(&mut o, p, &fold) },
            Simd::Avx512 => unsafe { octaves_avx512(&mut o, p, &fold) },
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = simd;
        while o.left > 0 {
            o.total += o.amp * fold(gradient3_s(p * o.freq + o.shift, o.s));
            o.step();
        }
        o.total
    }

    /// The general sum over a basis returning (value, gradient), with the fold of `kind`.
    #[inline]
    fn sum<const GRAD: bool, B: Fn(Vec3, u32) -> (f32, Vec3)>(
        &self,
        p: Vec3,
        seed: u32,
        basis: B,
    ) -> (f32, Vec3) {
        let mut s = mix32(seed);
        let (mut freq, mut amp) = (1.0f32, 1.0f32);
        let (mut total, mut grad) = (0.0f32, Vec3::ZERO);
        let mut shift = Vec3::ZERO;
        for _ in 0..self.octaves {
            let (n, g) = basis(p * freq + shift, s);
            let (v, dv) = self.fold(n);
            total += amp * v;
            if GRAD {
                // d/dp of fold(n(freq p + shift)) = fold'(n) freq ∇n.
                grad += (amp * freq * dv) * g;
            }
            freq *= self.lacunarity;
            amp *= self.gain;
            shift += SHIFT;
            s = s.wrapping_add(OCTAVE_SEED_STEP);
        }
        (total, grad)
    }
}

/// The ridged fold (1 − |n|)².
#[inline(always)]
fn ridge(n: f32) -> f32 {
    let r = 1.0 - n.abs();
    r * r
}

/// The running state of an octave sum: the next octave's frequency, amplitude, shift and
/// scrambled seed, how many octaves are left, and the total so far.
struct Octaves {
    freq: f32,
    amp: f32,
    shift: Vec3,
    s: u32,
    left: u32,
    total: f32,
    lacunarity: f32,
    gain: f32,
}

impl Octaves {
    fn new(f: &Fractal, seed: u32) -> Self {
        Octaves {
            freq: 1.0,
            amp: 1.0,
            shift: Vec3::ZERO,
            s: mix32(seed),
            left: f.octaves,
            total: 0.0,
            lacunarity: f.lacunarity,
            gain: f.gain,
        }
    }

    #[inline(always)]
    fn step(&mut self) {
        self.freq *= self.lacunarity;
        self.amp *= self.gain;
        self.shift += SHIFT;
        self.s = self.s.wrapping_add(OCTAVE_SEED_STEP);
        self.left = self.left.saturating_sub(1);
    }

    /// Sums octaves `L::N` at a time while at least two are left (lanes past the last octave get
    /// amplitude 0); leaves a last single octave to the scalar kernel.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn lanes<L: Lanes>(&mut self, p: Vec3, fold: &impl Fn(f32) -> f32) {
        const MAX: usize = 16;
        while self.left >= 2 {
            let (mut f, mut sh, mut seeds, mut amps) = (
                [0.0f32; MAX],
                [[0.0f32; MAX]; 3],
                [0u32; MAX],
                [0.0f32; MAX],
            );
            let live = self.left;
            for k in 0..L::N {
                (f[k], sh[0][k], sh[1][k], sh[2][k], seeds[k]) =
                    (self.freq, self.shift.x, self.shift.y, self.shift.z, self.s);
                amps[k] = if (k as u32) < live { self.amp } else { 0.0 };
                self.step();
            }
            // Lane k's point p · f[k] + shift[k], formed in the scalar `p * freq + shift` order.
            let f = L::load(&f);
            let axis = |c: f32, sh: &[f32]| L::splat(c).mul(f).add(L::load(sh));
            let n = kernel(
                axis(p.x, &sh[0]),
                axis(p.y, &sh[1]),
                axis(p.z, &sh[2]),
                L::load_i(&seeds),
            );
            let mut out = [0.0f32; MAX];
            n.store(&mut out);
            for k in 0..L::N {
                self.total += amps[k] * fold(out[k]);
            }
        }
    }
}

simd_wide! {
    unsafe fn octaves_avx2 / octaves_avx512(o: &mut Octaves, p: Vec3, fold: &impl Fn(f32) -> f32)
    where lanes = L
    {
        o.lanes::<L>(p, fold)
    }
}

simd_wide! {
    unsafe fn many_avx2 / many_avx512(f: &Fractal, points: &[Vec3], seed: u32, out: &mut [f32]) -> usize
    where lanes = L
    {
        f.many::<L>(points, seed, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    #[test]
    fn every_simd_batch_path_equals_eval() {
        // Same operations in the same order per point, so equal values; 37 points leave a
        // scalar tail on every lane width, both bases and all kinds.
        let mut r = Pcg32::new(12, 0);
        let pts: Vec<Vec3> = (0..37)
            .map(|_| {
                Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 400.0 - Vec3::splat(200.0)
            })
            .collect();
        for basis in [Basis::Gradient, Basis::Value] {
            for kind in [
                FractalKind::Fbm,
                FractalKind::Turbulence,
                FractalKind::Ridged,
            ] {
                for octaves in [1, 5, 9] {
                    let fr = Fractal {
                        kind,
                        basis,
                        octaves,
                        lacunarity: 2.1,
                        gain: 0.45,
                    };
                    for simd in Simd::ALL {
                        let mut out = vec![f32::NAN; pts.len()];
                        fr.eval_many_with(simd, &pts, 77, &mut out);
                        for (p, v) in pts.iter().zip(out) {
                            assert_eq!(v, fr.eval(*p, 77), "{simd:?} {basis:?} {kind:?} {octaves}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn every_simd_octave_path_equals_scalar_sum() {
        // The lane paths and the scalar `sum` over the scalar kernel evaluate the same octaves
        // (points, seeds) with the same operations in the same order, so equal values; 1–17 octaves cover partial and several lane groups.
        let mut r = Pcg32::new(11, 0);
        for octaves in 1..=17 {
            for kind in [
                FractalKind::Fbm,
                FractalKind::Turbulence,
                FractalKind::Ridged,
            ] {
                let fr = Fractal {
                    kind,
                    octaves,
                    ..Fractal::default()
                };
                let fold = |n: f32| fr.fold(n).0;
                for _ in 0..200 {
                    let p = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 200.0
                        - Vec3::splat(100.0);
                    let seed = r.next_u32();
                    let want = fr
                        .sum::<false, _>(p, seed, |q, s| (gradient3_s(q, s), Vec3::ZERO))
                        .0;
                    for simd in Simd::ALL {
                        if simd <= Simd::best() {
                            let got = fr.gradient_lanes_with(simd, p, seed, fold);
                            assert_eq!(got, want, "{simd:?} {kind:?} {octaves} octaves at {p}");
                        }
                    }
                }
            }
        }
    }
}
