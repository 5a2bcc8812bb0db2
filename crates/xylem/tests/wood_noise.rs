//! The 1D noises of the wood model (xylem issue 11, item 2): the growth-time noise n(t_pre)
//! (Liu et al. 2016 eq. 24) and the interlocked-grain angle (§6.1.5) are 1D sparse convolution
//! noise (their App. A.3) and show no lattice: ring widths and interlock reversals differ from seed
//! to seed and have no period of their own (notes/wood.md §2 and §4).

use std::f64::consts::TAU;
use xylem::wood::{self, WoodParams, WoodVolume, PRESET_NAMES};

/// Rings per sequence: 960 = 2⁶ · 15, long enough for the statistics below.
const RINGS: usize = 960;

/// Presets with growth noise, with the triangle wave switched off (amplitude 0): the wave is by
/// design (eq. 23) the same function of r for every seed, so only without it do the ring widths
/// show the noise alone.
fn noise_only_growth() -> Vec<(&'static str, WoodParams)> {
    PRESET_NAMES
        .into_iter()
        .filter_map(|name| {
            let mut p = wood::preset(name).unwrap();
            let g = p.growth.as_mut()?;
            if g.noise_amplitude <= 0.0 {
                return None;
            }
            g.amplitude = 0.0;
            Some((name, p))
        })
        .collect()
}

/// The first `RINGS` ring widths (in mean ring widths) along a radius: the spacing of the radii
/// where the growth time crosses successive integers (linear interpolation between samples
/// 1/200 of a ring apart; dt/dr > 0, so each crossing is one ring boundary).
fn ring_widths(params: &WoodParams, seed: u64) -> Vec<f64> {
    let v = WoodVolume::new(params.clone(), seed).unwrap();
    let width = params.rings.width as f64;
    let step = width / 200.0;
    let (mut bounds, mut r0) = (Vec::new(), 0.0f64);
    let mut t0 = v.time(0.0).0 as f64;
    while bounds.len() <= RINGS {
        let r1 = r0 + step;
        let t1 = v.time(r1 as f32).0 as f64;
        let k = t1.floor();
        if k > t0.floor() {
            bounds.push(r0 + (k - t0) / (t1 - t0) * step);
        }
        (r0, t0) = (r1, t1);
    }
    bounds.windows(2).map(|b| (b[1] - b[0]) / width).collect()
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

fn std_dev(x: &[f64]) -> f64 {
    let m = mean(x);
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / x.len() as f64).sqrt()
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let (ma, mb) = (mean(a), mean(b));
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    cov / (std_dev(a) * std_dev(b) * a.len() as f64)
}

/// Periodogram |Σ (x_k − x̄) e^(−2πifk)|² / n at frequency `f` (cycles per sample).
fn periodogram(x: &[f64], f: f64) -> f64 {
    let m = mean(x);
    let (mut re, mut im) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let a = TAU * f * k as f64;
        re += (v - m) * a.cos();
        im -= (v - m) * a.sin();
    }
    (re * re + im * im) / x.len() as f64
}

#[test]
fn ring_widths_vary_and_differ_between_seeds() {
    // Independent noises give uncorrelated ring-width sequences: the correlation of two has mean 0
    // and standard error ≈ √(Σ ρ_a(k) ρ_b(k) / n) ≈ √(1.5 / 960) = 0.04 (ring widths are
    // differences of boundary shifts: lag-1 autocorrelation ≈ −½), so |r| < 0.2 is a 5σ bound.
    // Until 2026-12 the gradient noise was 0 at every multiple of noise_scale: with noise_scale
    // 1 year (curly maple) every ring boundary sat where the noise vanishes, all rings equal.
    let presets = noise_only_growth();
    assert!(presets.iter().any(|(n, _)| *n == "curly_maple") && presets.len() >= 2);
    for (name, p) in &presets {
        let seqs: Vec<Vec<f64>> = [1, 2, 5].iter().map(|&s| ring_widths(p, s)).collect();
        for (s, x) in seqs.iter().enumerate() {
            let cv = std_dev(x) / mean(x);
            assert!(
                cv >= 0.05,
                "{name} seed index {s}: ring widths vary by {cv}"
            );
        }
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            let r = correlation(&seqs[a], &seqs[b]);
            assert!(r.abs() < 0.2, "{name}: seeds {a}, {b} correlate {r}");
        }
    }
}

#[test]
fn ring_width_scatter_has_no_line_at_the_noise_lattice() {
    // A lattice shows as a period in the statistics: gradient noise vanished at every multiple ℓ
    // of noise_scale, so the scatter of ring boundaries, and with it the mean of the squared
    // ring-width deviations e_k = (x_k − x̄)², was periodic in the ring index with period ℓ years
    // (frequency 1/ℓ cycles per ring, folded into [0, ½]): a line in the periodogram of e. Without
    // a lattice (the cells of the sparse noise are ℓ long too, but its covariance is stationary)
    // the periodogram ordinate at that frequency over the mean of its 20 neighbours (1/n apart)
    // is ≈ F(2, 40)-distributed; F(2, 40) exceeds 8.25 with probability 10⁻³. Frequencies 0 (ℓ = 1
    // year: covered by `ring_widths_vary_and_differ_between_seeds`) have no line to test.
    let mut tested = 0;
    for (name, p) in noise_only_growth() {
        let scale = p.growth.as_ref().unwrap().noise_scale as f64;
        let f = (1.0 / scale).fract();
        let f = f.min(1.0 - f);
        if f < 20.0 / RINGS as f64 {
            continue;
        }
        for seed in [1, 2] {
            let x = ring_widths(&p, seed);
            let m = mean(&x);
            let e: Vec<f64> = x.iter().map(|v| (v - m) * (v - m)).collect();
            let line = periodogram(&e, f);
            let around = (1..=10)
                .flat_map(|j| [-1.0, 1.0].map(|s| f + s * j as f64 / RINGS as f64))
                .map(|g| periodogram(&e, g))
                .sum::<f64>()
                / 20.0;
            assert!(
                line < 8.25 * around,
                "{name} seed {seed}: line at {f:.4} cycles/ring {:.1}× its neighbours",
                line / around
            );
        }
        tested += 1;
    }
    assert!(
        tested >= 2,
        "only {tested} presets with a non-zero lattice frequency"
    );
}

fn with_interlock() -> Vec<(&'static str, WoodParams)> {
    PRESET_NAMES
        .into_iter()
        .map(|n| (n, wood::preset(n).unwrap()))
        .filter(|(_, p)| p.interlock.is_some())
        .collect()
}

/// Radii (mm) where the interlock angle changes sign, sampled every period / 400 out to
/// 400 periods.
fn reversals(p: &WoodParams, seed: u64) -> Vec<f64> {
    let v = WoodVolume::new(p.clone(), seed).unwrap();
    let period = p.interlock.as_ref().unwrap().period as f64;
    let step = period / 400.0;
    let (mut out, mut last) = (Vec::new(), 0.0f32);
    for i in 1..=160_000 {
        let r = i as f64 * step;
        let a = v.interlock_angle(r as f32);
        if a != 0.0 {
            if last != 0.0 && a.signum() != last.signum() {
                out.push(r - 0.5 * step);
            }
            last = a;
        }
    }
    out
}

#[test]
fn interlock_reverses_irregularly_about_once_per_period() {
    // `period` is the mean distance between reversals (notes/wood.md §4). Over 400 periods ≈ 400
    // spacings, whose coefficient of variation is ≈ 0.7, so the sample mean has a standard error
    // of 3.5 %: the band [0.8, 1.25] × period is over 5σ. Reversals of two seeds are independent:
    // the fraction of one seed's reversals within period/20 of the other's is ≈ 0.1 (≈ 2/20 of a
    // period per reversal), standard error 0.015; gradient noise reversed at every multiple of its
    // period for every seed (a fraction ≥ ⅔).
    let presets = with_interlock();
    assert!(presets.len() >= 3);
    for (name, p) in presets {
        let period = p.interlock.as_ref().unwrap().period as f64;
        let (a, b) = (reversals(&p, 1), reversals(&p, 2));
        for x in [&a, &b] {
            let gaps: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
            let (m, cv) = (mean(&gaps), std_dev(&gaps) / mean(&gaps));
            assert!(
                (0.8..=1.25).contains(&(m / period)),
                "{name}: mean reversal spacing {m:.3} mm for period {period}"
            );
            assert!(cv >= 0.2, "{name}: reversal spacings vary by only {cv:.3}");
        }
        let near = a
            .iter()
            .filter(|&&r| b.iter().any(|&s| (r - s).abs() < period / 20.0))
            .count() as f64
            / a.len() as f64;
        assert!(
            near < 0.3,
            "{name}: {near:.2} of the reversals coincide for two seeds"
        );
    }
}

#[test]
fn interlock_angle_stays_within_its_bound_and_nears_it() {
    // |φ| < angle exactly (the pores' cells are sized for it); the bound is a supremum the noise
    // comes close to over 2000 periods.
    for (name, p) in with_interlock() {
        let i = p.interlock.as_ref().unwrap();
        let (bound, period) = (i.angle.to_radians(), i.period);
        let v = WoodVolume::new(p.clone(), 3).unwrap();
        let mut max = 0.0f32;
        for k in 0..400_000 {
            max = max.max(v.interlock_angle(k as f32 * period / 200.0).abs());
        }
        assert!(max <= bound, "{name}: |φ| reaches {max} > {bound}");
        assert!(
            max >= 0.9 * bound,
            "{name}: |φ| only reaches {max} of {bound}"
        );
    }
}

/// With the slow/fast growth wave on (eq. 23) the ring widths of different trees must differ too:
/// the wave's phase is warped by a seed's own noise (growth.phase_amplitude, notes/wood.md §2),
/// so the slow and fast periods fall at other radii. Without the warp every seed shares the wave
/// and correlates 0.74–0.87. Two independent quasi-periodic sequences of 960 rings whose phase
/// decorrelates within ≈ 12 years correlate with standard error ≈ √(Σρ_aρ_b/n) ≈ √(6/960) ≈ 0.08,
/// so the bound |r| < 0.2 holds at ≈ 2.5σ for each fixed pair of seeds.
#[test]
fn full_model_ring_widths_differ_between_seeds() {
    let mut tested = 0;
    for name in PRESET_NAMES {
        let p = wood::preset(name).unwrap();
        let Some(g) = p.growth.as_ref() else {
            continue;
        };
        if g.amplitude <= 0.0 {
            continue;
        }
        assert!(g.phase_amplitude > 0.0, "{name}: no phase warp");
        let seqs: Vec<Vec<f64>> = [1, 2, 5].iter().map(|&s| ring_widths(&p, s)).collect();
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            let r = correlation(&seqs[a], &seqs[b]);
            println!("{name}: seeds {a}, {b}: {r:.3}");
            assert!(r.abs() < 0.2, "{name}: seeds {a}, {b} correlate {r}");
        }
        tested += 1;
    }
    assert!(tested >= 8, "only {tested} presets have a growth wave");
}
