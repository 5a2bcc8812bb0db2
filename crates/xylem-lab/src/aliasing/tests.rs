//! The estimator against closed forms and controls (fixed seeds).
use super::*;
use xylem::math::Pcg32;

/// Gaussian noise of variance `v` by Box–Muller.
fn noise(rng: &mut Pcg32, v: f64) -> f64 {
    let (u1, u2) = (rng.next_f32().max(1e-7) as f64, rng.next_f32() as f64);
    v.sqrt() * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Pixel noise correlated with its neighbours, as a pixel filter wider than a pixel makes
/// it: white noise of variance `v` smoothed by [1, 2, 1]/4 along rows.
fn correlated_noise(rng: &mut Pcg32, v: f64, w: usize, h: usize) -> Vec<f64> {
    let white: Vec<f64> = (0..w * h).map(|_| noise(rng, v)).collect();
    (0..w * h)
        .map(|i| {
            let x = i % w;
            let l = white[if x > 0 { i - 1 } else { i }];
            let r = white[if x + 1 < w { i + 1 } else { i }];
            (l + 2.0 * white[i] + r) / 4.0
        })
        .collect()
}

#[test]
fn correlated_noise_leaves_no_aliasing_power_and_stripes_do() {
    let (w, h) = (128, 128);
    let mut rng = Pcg32::new(3, 28);
    let mask = vec![true; w * h];
    let truth = vec![0.5; w * h];
    let field = |rng: &mut Pcg32, v: f64, extra: &dyn Fn(usize) -> f64| -> Vec<f64> {
        (correlated_noise(rng, v, w, h).into_iter().enumerate())
            .map(|(i, n)| truth[i] + n + extra(i))
            .collect()
    };
    let none = |_: usize| 0.0;
    let (a, b) = (field(&mut rng, 0.01, &none), field(&mut rng, 0.01, &none));
    let (x1, x2) = (field(&mut rng, 0.04, &none), field(&mut rng, 0.04, &none));
    let (net, removed, n) = aliasing_power([&x1, &x2], [&a, &b], &mask, w, h);
    assert_eq!(n, (w - 2) * (h - 2));
    // The noise's share matches the error's power within 5 % (≈ 1.5 % standard error).
    assert!(net.abs() < 0.05 * removed, "net {net} of {removed}");
    // The control: subtracting independent-pixel noise, (8/9)² + 8/81 of each pixel's
    // variance, over-subtracts correlated noise by far.
    let var_x = 0.04 * 6.0 / 16.0;
    let var_r = 0.01 * 6.0 / 16.0 / 2.0;
    let independent = (n as f64) * (var_x + var_r) * (64.0 + 8.0) / 81.0;
    assert!(independent > 1.2 * removed, "{independent} vs {removed}");
    // Moiré-like stripes two pixels wide survive at their power: ±0.3 keeps ±0.2 after the
    // 3 × 3 mean, 0.04 a pixel.
    let stripes = |i: usize| {
        if ((i % w) / 2).is_multiple_of(2) {
            0.3
        } else {
            -0.3
        }
    };
    let (y1, y2) = (
        field(&mut rng, 0.04, &stripes),
        field(&mut rng, 0.04, &stripes),
    );
    let (net_s, _, _) = aliasing_power([&y1, &y2], [&a, &b], &mask, w, h);
    assert!(
        (net_s / n as f64 - 0.04).abs() < 0.004,
        "{}",
        net_s / n as f64
    );
}

/// A 1D pattern of `nu` cycles a pixel along x, amplitude 0.3 about 0.5, at film x.
fn pattern(nu: f64, x: f64) -> f64 {
    0.5 + 0.3 * (std::f64::consts::TAU * nu * x).sin()
}

/// Its exact average over pixel column `p` (the box pixel filter): the converged image.
fn pixel_average(nu: f64, p: f64) -> f64 {
    let k = std::f64::consts::TAU * nu;
    0.5 + 0.3 * ((k * p).cos() - (k * (p + 1.0)).cos()) / k
}

/// `k` images of `w` × `h` from `pixel(rng, x, y)`, high-passed over the whole interior.
fn high_passed(
    rng: &mut Pcg32,
    k: usize,
    (w, h): (usize, usize),
    pixel: &dyn Fn(&mut Pcg32, usize, usize) -> f64,
) -> Vec<Vec<f64>> {
    let pixels = judged_pixels(&vec![true; w * h], w, h);
    (0..k)
        .map(|_| {
            let img: Vec<f64> = (0..w * h).map(|i| pixel(rng, i % w, i / w)).collect();
            high_pass(&img, &pixels, w)
        })
        .collect()
}

/// The negative and positive controls of the estimator: a pattern of 0.7 cycles a pixel
/// (above the pixel's Nyquist 0.5) point-sampled at pixel centres aliases into a bias every
/// render shares, found significantly above 0 and at its exact value; sampled at random
/// points in the pixel it is unbiased (bias consistent with 0) and its aliasing is noise,
/// which the total counts.
#[test]
fn point_sampled_pattern_aliases_and_jitter_turns_it_into_noise() {
    let (w, h, nu) = (48, 32, 0.7);
    let mut rng = Pcg32::new(28, 5);
    let reference = high_passed(&mut rng, 8, (w, h), &|rng, x, _| {
        pixel_average(nu, x as f64) + noise(rng, 1e-4)
    });
    let centre = high_passed(&mut rng, 8, (w, h), &|rng, x, _| {
        pattern(nu, x as f64 + 0.5) + noise(rng, 1e-3)
    });
    let jitter = high_passed(&mut rng, 8, (w, h), &|rng, x, _| {
        let s: f64 = (0..4)
            .map(|_| pattern(nu, x as f64 + rng.next_f32() as f64))
            .sum();
        s / 4.0 + noise(rng, 1e-3)
    });
    let (e, cov, dof) = energies(&reference, &[centre, jitter]);
    let t = t95(dof);
    // The exact bias energy of centre sampling: ‖H(f(centre) − pixel average)‖².
    let pixels = judged_pixels(&vec![true; w * h], w, h);
    let beta: Vec<f64> = (0..w * h)
        .map(|i| pattern(nu, (i % w) as f64 + 0.5) - pixel_average(nu, (i % w) as f64))
        .collect();
    let truth = high_pass(&beta, &pixels, w)
        .iter()
        .map(|v| v * v)
        .sum::<f64>();
    let (lo, hi) = e[0].bias.interval(t);
    assert!(lo > 0.0, "centre sampling's bias {:?}", e[0].bias);
    assert!(lo < truth && truth < hi, "{truth} outside {lo}..{hi}");
    let (lo, hi) = e[1].bias.interval(t);
    assert!(lo < 0.0 && 0.0 < hi, "jitter's bias {:?}", e[1].bias);
    assert!(
        e[1].total.interval(t).0 > 0.0,
        "jitter's total {:?}",
        e[1].total
    );
    // The ratio of the two totals has a bounded interval holding its value.
    let r = ratio_interval(
        e[0].total.value,
        e[1].total.value,
        cov[0][0],
        cov[1][1],
        cov[0][1],
        t,
    );
    let (lo, hi) = r.interval.expect("jitter's total is significant");
    assert!(lo < r.value && r.value < hi, "{r:?}");
}

/// Noise alone (correlated between neighbouring pixels, as a wide pixel filter makes it)
/// leaves a bias energy consistent with 0. Over 200 independent trials: the bias's mean is
/// within 3 standard errors of 0 (unbiased), its 95 % interval holds 0 in ≥ 90 % of them
/// (the jackknife is conservative for a bias of 0, a degenerate U-statistic: its standard
/// error comes out ≈ 1.5× the trials' spread), and the total's jackknife standard error
/// matches the trials' spread within 0.8–1.4×.
#[test]
fn noise_only_gives_bias_consistent_with_zero() {
    let (w, h) = (24, 24);
    let mut rng = Pcg32::new(7, 28);
    let pixels = judged_pixels(&vec![true; w * h], w, h);
    let images = |rng: &mut Pcg32, k: usize, v: f64| -> Vec<Vec<f64>> {
        (0..k)
            .map(|_| {
                let n = correlated_noise(rng, v, w, h);
                let img: Vec<f64> = (0..w * h)
                    .map(|i| 0.5 + 0.1 * (i % w) as f64 / w as f64 + n[i])
                    .collect();
                high_pass(&img, &pixels, w)
            })
            .collect()
    };
    let trials = 200;
    let mut covered = 0;
    let (mut bias, mut total, mut total_se) = (vec![], vec![], vec![]);
    for _ in 0..trials {
        let reference = images(&mut rng, 8, 0.002);
        let renders = images(&mut rng, 8, 0.02);
        let (e, _, dof) = energies(&reference, &[renders]);
        let (lo, hi) = e[0].bias.interval(t95(dof));
        covered += usize::from(lo <= 0.0 && 0.0 <= hi);
        bias.push(e[0].bias.value);
        total.push(e[0].total.value);
        total_se.push(e[0].total.se);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let sd = |v: &[f64]| {
        let m = mean(v);
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
    };
    let n = trials as f64;
    assert!(
        mean(&bias).abs() < 3.0 * sd(&bias) / n.sqrt(),
        "{}",
        mean(&bias)
    );
    assert!(covered as f64 / n >= 0.9, "covered {covered} of {trials}");
    let se_ratio = mean(&total_se) / sd(&total);
    assert!(
        (0.8..1.4).contains(&se_ratio),
        "total's se / spread {se_ratio}"
    );
}

#[test]
fn fieller_interval_bounded_only_for_a_significant_denominator() {
    let r = ratio_interval(1.0, 4.0, 0.01, 0.04, 0.0, 2.0);
    let (lo, hi) = r.interval.unwrap();
    assert!((r.value - 0.25).abs() < 1e-12 && lo < 0.25 && 0.25 < hi && lo > 0.15 && hi < 0.4);
    // d = 0.1 ± 0.1: not significant, no bounded interval.
    assert!(ratio_interval(1.0, 0.1, 0.01, 0.01, 0.0, 2.0)
        .interval
        .is_none());
}

#[test]
fn the_mask_excludes_edges_and_outside_pixels() {
    let (w, h) = (8, 8);
    let d = vec![1.0; w * h];
    let mut mask = vec![true; w * h];
    mask[3 * w + 3] = false;
    let (p, n) = high_pass_power(&d, &mask, w, h);
    assert_eq!(p, 0.0);
    // 6 × 6 interior pixels less the 9 whose window holds (3, 3).
    assert_eq!(n, 36 - 9);
}
