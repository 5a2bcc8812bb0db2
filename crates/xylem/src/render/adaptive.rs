//! Adaptive sampling: a pilot pass of every pixel, then the rest of the image's budget spread
//! over the pixels by their neighbours' noise and cost (notes/render.md, "Adaptive sampling").
//!
//! Neyman allocation with costs (Neyman 1934, "On the two different aspects of the
//! representative method", J. R. Stat. Soc. 97(4); Cochran, *Sampling Techniques*, 3rd ed.,
//! §5.5): over strata of standard deviations σᵢ whose samples cost cᵢ, Σ σᵢ²/nᵢ for a fixed
//! total cost Σ nᵢcᵢ is least for nᵢ ∝ σᵢ/√cᵢ. A render's pixels are the strata, its summed
//! squared error Σ σᵢ²/nᵢ; on the wood scenes a few pixels (a glossy highlight's, a raking
//! light's pore walls) hold most of it. The cost of a sample is counted, not timed (rays plus
//! [`crate::material::Material::shading_cost`] of each surface shaded), so the image stays a
//! function of the seed; the budget is the cost of the uniform render's remaining samples, so
//! an adaptive render takes about the uniform one's time.
//!
//! **Unbiased.** Pixel i's count is a function of numbers independent of its own samples (the
//! pixels' samples are independent: scrambles and path numbers keyed by pixel), so the mean of
//! its samples stays unbiased:
//! - its σ̂ᵢ and ĉᵢ come from its eight neighbours' pilots, not its own;
//! - the image-wide normalisers are taken without pixel i's pilot (its neighbours' σ̂ and ĉ
//!   recomputed from their other seven);
//! - its share is rounded up or down by a hash of (seed, pixel), not by its neighbours' shares.
//!
//! (A count decided from the pixel's own pilot is biased: a pilot that caught a rare bright path
//! draws more samples, which dilute it.) The price is a total that is the budget only on
//! average: the leave-one-out normalisers and the rounding move it by a fraction of a percent.

/// Share of the extra samples spread evenly over the image whatever the pilot shows (defensive
/// mixing, Hesterberg 1995, "Weighted average importance sampling and defensive mixture
/// distributions", Technometrics 37(2)): a pixel whose neighbours all came out flat still gets
/// some, so a feature the pilot missed is not left at the pilot's count.
const DEFENSIVE: f64 = 0.1;

/// The most samples a pixel may take, in multiples of the nominal spp: bounds a tile's time
/// (and a firefly-ridden image's worst pixel) to a known multiple.
pub(crate) const MAX_FACTOR: u32 = 16;

/// The pilot's samples per pixel for a render of `spp`, or `None` where `spp` is too small to
/// estimate a variance from and leave samples to spread (adaptive sampling needs spp ≥ 8).
pub(crate) fn pilot_count(spp: u32) -> Option<u32> {
    (spp >= 8).then(|| (spp / 4).max(2))
}

/// What the pilot measured of one pixel: the sample variance of its samples' luminance and
/// their mean cost, in ray-equivalents a sample (rays traced plus
/// [`crate::material::Material::shading_cost`] of every surface shaded).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Pilot {
    pub var: f64,
    pub cost: f64,
}

/// Extra samples of each pixel of a `width × height` image (row-major) after a pilot
/// (`pilots`), `m` a pixel on average in cost: Neyman allocation with costs (Cochran §5.5,
/// nᵢ ∝ σᵢ/√cᵢ for a fixed total cost Σ nᵢcᵢ), pixel i taking
/// m · (D + (1 − D) · S₁ wᵢ / S₂), wᵢ = σ̂ᵢ/√ĉᵢ, σ̂ᵢ and ĉᵢ its neighbours' ([`around`]),
/// S₁ = Σ ĉⱼ, S₂ = Σ wⱼĉⱼ, both without pixel i's pilot; D = [`DEFENSIVE`]. So Σ nᵢĉᵢ ≈ m Σ ĉᵢ:
/// the cost of m more uniform samples. At most `cap`, rounded up with the probability of its
/// fraction by a hash of (`seed`, pixel).
pub(crate) fn allocate(
    width: u32,
    height: u32,
    pilots: &[Pilot],
    m: u32,
    cap: u32,
    seed: u64,
) -> Vec<u32> {
    let (w, h) = (width as usize, height as usize);
    assert_eq!(pilots.len(), w * h, "a pilot per pixel");
    let clean: Vec<Pilot> = pilots
        .iter()
        .map(|p| Pilot {
            var: if p.var.is_finite() {
                p.var.max(0.0)
            } else {
                0.0
            },
            cost: if p.cost.is_finite() {
                p.cost.max(0.0)
            } else {
                0.0
            },
        })
        .collect();
    let stats: Vec<(f64, f64)> = (0..w * h)
        .map(|i| around(&clean, i % w, i / w, w, h, None))
        .collect();
    let (s1, s2) = stats
        .iter()
        .fold((0.0, 0.0), |(a, b), &(wt, c)| (a + c, b + wt * c));
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            // S₁ and S₂ with pixel i's pilot left out of its neighbours' means.
            let (mut s1, mut s2) = (s1, s2);
            for (nx, ny) in neighbours(x, y, w, h) {
                let (wt, c) = stats[ny * w + nx];
                let (wt_, c_) = around(&clean, nx, ny, w, h, Some(i));
                s1 += c_ - c;
                s2 += wt_ * c_ - wt * c;
            }
            let share = if s2 > 0.0 && s1.is_finite() && s2.is_finite() {
                m as f64 * (DEFENSIVE + (1.0 - DEFENSIVE) * s1 * stats[i].0 / s2)
            } else {
                m as f64
            };
            let share = share.min(cap as f64);
            let whole = share.floor();
            let bits = splitmix64(seed ^ splitmix64(i as u64 ^ (1 << 61)));
            let u = (bits >> 11) as f64 / (1u64 << 53) as f64;
            (whole as u32 + u32::from(u < share - whole)).min(cap)
        })
        .collect()
}

/// The pixels next to (x, y) in a `w × h` image.
fn neighbours(x: usize, y: usize, w: usize, h: usize) -> impl Iterator<Item = (usize, usize)> {
    (y.saturating_sub(1)..(y + 2).min(h))
        .flat_map(move |ny| (x.saturating_sub(1)..(x + 2).min(w)).map(move |nx| (nx, ny)))
        .filter(move |&p| p != (x, y))
}

/// Pixel (x, y)'s weight w = σ̂/√ĉ and cost ĉ from its neighbours' pilots, pixel `leave` left
/// out as well (the pixel itself always is): σ̂ = √(mean variance), ĉ = mean cost (1 where the
/// neighbours cost nothing or there are none).
fn around(p: &[Pilot], x: usize, y: usize, w: usize, h: usize, leave: Option<usize>) -> (f64, f64) {
    let (mut var, mut cost, mut count) = (0.0, 0.0, 0u32);
    for (nx, ny) in neighbours(x, y, w, h) {
        let j = ny * w + nx;
        if Some(j) != leave {
            var += p[j].var;
            cost += p[j].cost;
            count += 1;
        }
    }
    if count == 0 {
        return (0.0, 1.0);
    }
    let (sigma, cost) = ((var / count as f64).sqrt(), cost / count as f64);
    let cost = if cost > 0.0 { cost } else { 1.0 };
    (sigma / cost.sqrt(), cost)
}

use super::sampler::splitmix64;

#[cfg(test)]
mod tests {
    use super::*;

    fn flat_cost(var: &[f64]) -> Vec<Pilot> {
        var.iter().map(|&var| Pilot { var, cost: 3.0 }).collect()
    }

    #[test]
    fn the_budget_is_spent_on_average_and_follows_the_neighbours_noise() {
        // 64 × 32 image: a noisy band at x = 20..24; flat elsewhere.
        let (w, h) = (64u32, 32u32);
        let var: Vec<f64> = (0..w * h)
            .map(|i| {
                if (20..24).contains(&(i % w)) {
                    4.0
                } else {
                    0.0
                }
            })
            .collect();
        let extra = allocate(w, h, &flat_cost(&var), 12, 1000, 7);
        let spent = extra.iter().map(|&e| e as u64).sum::<u64>() as f64;
        let budget = (w * h) as f64 * 12.0;
        assert!((spent / budget - 1.0).abs() < 0.01, "{spent} of {budget}");
        // The band's neighbours (x = 19..25) take more than the far pixels (x = 60), which
        // still get their defensive share.
        let col = |x: u32| (0..h).map(|y| extra[(y * w + x) as usize]).sum::<u32>();
        assert!(col(19) > 4 * col(60) && col(24) > 4 * col(60), "{extra:?}");
        assert!(col(60) > 0, "{extra:?}");
    }

    #[test]
    fn costlier_pixels_take_fewer_samples_for_the_same_noise() {
        // Equal noise everywhere; the right half costs 16 times the left: nᵢ ∝ 1/√cᵢ, so the
        // left takes about 4× the right's non-defensive share, and the total cost stays m Σ c.
        let (w, h) = (40u32, 20u32);
        let pilots: Vec<Pilot> = (0..w * h)
            .map(|i| Pilot {
                var: 1.0,
                cost: if i % w < 20 { 1.0 } else { 16.0 },
            })
            .collect();
        let extra = allocate(w, h, &pilots, 12, 1000, 5);
        let at = |x: u32| {
            (0..h)
                .map(|y| extra[(y * w + x) as usize] as f64)
                .sum::<f64>()
                / h as f64
        };
        let (cheap, dear) = (at(5), at(35));
        // Shares: m (D + (1 − D) S₁ w / S₂) with w = 1 and 1/4: 12 (0.1 + 0.9 · 8.5 / 2.5) and
        // 12 (0.1 + 0.9 · 8.5 / 10).
        assert!(
            (cheap - 37.9).abs() < 1.5 && (dear - 10.4).abs() < 1.0,
            "{cheap} {dear}"
        );
        let cost: f64 = extra
            .iter()
            .zip(&pilots)
            .map(|(&e, p)| e as f64 * p.cost)
            .sum();
        let budget = 12.0 * pilots.iter().map(|p| p.cost).sum::<f64>();
        assert!((cost / budget - 1.0).abs() < 0.03, "{cost} of {budget}");
    }

    #[test]
    fn a_pixels_count_does_not_depend_on_its_own_pilot() {
        let (w, h) = (9u32, 7u32);
        let mut pilots: Vec<Pilot> = (0..63)
            .map(|i| Pilot {
                var: 1.0 + (i % 5) as f64,
                cost: 1.0 + (i % 3) as f64,
            })
            .collect();
        let a = allocate(w, h, &pilots, 12, 1000, 3);
        for (var, cost) in [(0.0, 0.0), (1e-3, 50.0), (50.0, 1.0), (1e6, 1e3)] {
            pilots[31] = Pilot { var, cost };
            let b = allocate(w, h, &pilots, 12, 1000, 3);
            assert_eq!(a[31], b[31], "variance {var}, cost {cost}");
            // Control: its neighbours' counts move with it.
            if var == 1e6 {
                assert!(b[30] != a[30], "{} {}", a[30], b[30]);
            }
        }
    }

    #[test]
    fn a_pixels_weight_leaves_its_own_pilot_out() {
        let mut pilots = flat_cost(&(0..25).map(|i| 1.0 + (i % 3) as f64).collect::<Vec<_>>());
        let a = around(&pilots, 2, 2, 5, 5, None);
        pilots[12].var = 1e6;
        assert_eq!(a, around(&pilots, 2, 2, 5, 5, None));
        // Control: its neighbours see it, a pixel two away does not.
        assert!(around(&pilots, 2, 1, 5, 5, None).0 > 100.0);
        assert_eq!(around(&pilots, 2, 0, 5, 5, None).0, {
            let p = flat_cost(&(0..25).map(|i| 1.0 + (i % 3) as f64).collect::<Vec<_>>());
            around(&p, 2, 0, 5, 5, None).0
        });
        // A corner averages its three neighbours.
        let var = |i: usize| pilots[i].var;
        let corner = ((var(1) + var(5) + var(6)) / 3.0).sqrt() / 3f64.sqrt();
        assert_eq!(around(&pilots, 0, 0, 5, 5, None), (corner, 3.0));
    }

    #[test]
    fn caps_hold_and_flat_pilots_spread_evenly() {
        let var: Vec<f64> = (0..16).map(|i| if i == 5 { 1e9 } else { 1.0 }).collect();
        let extra = allocate(4, 4, &flat_cost(&var), 10, 20, 1);
        assert!(extra.iter().all(|&e| e <= 20), "{extra:?}");
        let flat = allocate(4, 4, &flat_cost(&[0.0; 16]), 10, 20, 1);
        assert!(flat.iter().all(|&e| e == 10), "{flat:?}");
        let nan = allocate(4, 4, &flat_cost(&[f64::NAN; 16]), 10, 20, 1);
        assert!(nan.iter().all(|&e| e == 10), "{nan:?}");
    }

    #[test]
    fn pilots_need_eight_samples() {
        assert_eq!(pilot_count(4), None);
        assert_eq!(pilot_count(8), Some(2));
        assert_eq!(pilot_count(16), Some(4));
        assert_eq!(pilot_count(64), Some(16));
    }
}
