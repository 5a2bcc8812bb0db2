//! Adaptive sampling: a pilot pass of every pixel, then the rest of the image's sample budget
//! spread over the pixels in proportion to their neighbours' noise (notes/render.md, "Adaptive
//! sampling").
//!
//! Neyman allocation (Neyman 1934, "On the two different aspects of the representative method",
//! J. R. Stat. Soc. 97(4); Cochran, *Sampling Techniques*, 3rd ed., §5.5): with a fixed number
//! of samples N spread over strata of standard deviations σᵢ, Σ σᵢ²/nᵢ is least for nᵢ ∝ σᵢ, and
//! it is then (Σ σᵢ)²/N against Σ σᵢ² P/N for nᵢ = N/P. A render's pixels are the strata and the
//! summed squared error is Σ σᵢ²/nᵢ; on the wood scenes a few pixels (a glossy highlight's,
//! a raking light's pore walls) hold most of it.
//!
//! **Unbiased.** Pixel i's count is a function of numbers independent of its own samples (the
//! pixels' samples are independent: scrambles and path numbers keyed by pixel), so the mean of
//! its samples stays unbiased:
//! - its weight σ̂ᵢ comes from its eight neighbours' pilot variances, not its own;
//! - the image-wide normaliser Σⱼ σ̂ⱼ is taken without pixel i's variance (its neighbours'
//!   σ̂ recomputed from their other seven);
//! - its share is rounded up or down by a hash of (seed, pixel), not by its neighbours' shares.
//!
//! (A count decided from the pixel's own pilot is biased: a pilot that caught a rare bright path
//! draws more samples, which dilute it. A normaliser that held pixel i's variance left a bias
//! of about 0.02 % of the image sum on the carved bunny at 52 × 45 px.) The price is a total that
//! is the budget only on average: the leave-one-out normalisers and the rounding move it by a
//! fraction of a percent.

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

/// Extra samples of each pixel of a `width × height` image (row-major) after a pilot whose
/// per-pixel luminance variances are `pilot_var`: `budget` on average in all, pixel i's
/// B · (D / P + (1 − D) σ̂ᵢ / Σ₋ᵢ) (D = [`DEFENSIVE`], P pixels, σ̂ [`neighbour_sigma`], Σ₋ᵢ the sum
/// of σ̂ without pixel i's variance), at most `cap`, rounded up with the probability of its
/// fraction by a hash of (`seed`, pixel).
pub(crate) fn allocate(
    width: u32,
    height: u32,
    pilot_var: &[f64],
    budget: u64,
    cap: u32,
    seed: u64,
) -> Vec<u32> {
    assert_eq!(
        pilot_var.len(),
        (width * height) as usize,
        "a variance per pixel"
    );
    let (w, h) = (width as usize, height as usize);
    let n = pilot_var.len();
    let var: Vec<f64> = pilot_var
        .iter()
        .map(|&v| if v.is_finite() { v.max(0.0) } else { 0.0 })
        .collect();
    let sigma = neighbour_sigma(width, height, &var);
    let total: f64 = sigma.iter().sum();
    let even = budget as f64 / n as f64;
    (0..n)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            // Σ σ̂ with pixel i's variance left out of its neighbours' means.
            let mut without = total;
            for (nx, ny) in neighbours(x, y, w, h) {
                let j = ny * w + nx;
                let (sum, count) = neighbour_sum(&var, nx, ny, w, h);
                without -= sigma[j];
                if count > 1 {
                    without += ((sum - var[i]).max(0.0) / (count - 1) as f64).sqrt();
                }
            }
            let share = if without > 0.0 && without.is_finite() {
                DEFENSIVE * even + (1.0 - DEFENSIVE) * budget as f64 * sigma[i] / without
            } else {
                even
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

/// The sum of the variances of (x, y)'s neighbours and their count.
fn neighbour_sum(var: &[f64], x: usize, y: usize, w: usize, h: usize) -> (f64, u32) {
    neighbours(x, y, w, h).fold((0.0, 0), |(s, c), (nx, ny)| (s + var[ny * w + nx], c + 1))
}

/// σ̂ᵢ = √(mean of the variances of pixel i's neighbours, i itself left out): what pixel i's
/// count is proportional to. `var` is finite and ≥ 0.
fn neighbour_sigma(width: u32, height: u32, var: &[f64]) -> Vec<f64> {
    let (w, h) = (width as usize, height as usize);
    (0..w * h)
        .map(|i| {
            let (sum, count) = neighbour_sum(var, i % w, i / w, w, h);
            if count == 0 {
                0.0
            } else {
                (sum / count as f64).sqrt()
            }
        })
        .collect()
}

use super::sampler::splitmix64;

#[cfg(test)]
mod tests {
    use super::*;

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
        let budget = (w * h) as u64 * 12;
        let extra = allocate(w, h, &var, budget, 1000, 7);
        let spent = extra.iter().map(|&e| e as u64).sum::<u64>() as f64;
        assert!(
            (spent / budget as f64 - 1.0).abs() < 0.01,
            "{spent} of {budget}"
        );
        // The band's neighbours (x = 19..25) take more than the far pixels (x = 60), which
        // still get their defensive share.
        let col = |x: u32| (0..h).map(|y| extra[(y * w + x) as usize]).sum::<u32>();
        assert!(col(19) > 4 * col(60) && col(24) > 4 * col(60), "{extra:?}");
        assert!(col(60) > 0, "{extra:?}");
    }

    #[test]
    fn a_pixels_count_does_not_depend_on_its_own_pilot() {
        let (w, h) = (9u32, 7u32);
        let mut var: Vec<f64> = (0..63).map(|i| 1.0 + (i % 5) as f64).collect();
        let a = allocate(w, h, &var, 63 * 12, 1000, 3);
        for v in [0.0, 1e-3, 50.0, 1e6] {
            var[31] = v;
            let b = allocate(w, h, &var, 63 * 12, 1000, 3);
            assert_eq!(a[31], b[31], "variance {v}");
            // Control: its neighbours' counts move with it.
            if v == 1e6 {
                assert!(b[30] > 2 * a[30], "{} {}", a[30], b[30]);
            }
        }
    }

    #[test]
    fn a_pixels_weight_leaves_its_own_pilot_out() {
        let mut var: Vec<f64> = (0..25).map(|i| 1.0 + (i % 3) as f64).collect();
        let a = neighbour_sigma(5, 5, &var);
        var[12] = 1e6;
        let b = neighbour_sigma(5, 5, &var);
        assert_eq!(a[12], b[12]);
        // Control: its neighbours see it, a pixel two away does not.
        assert!(b[7] > 100.0 * a[7], "{} {}", a[7], b[7]);
        assert_eq!(a[2], b[2]);
        // A corner averages its three neighbours.
        assert_eq!(a[0], ((var[1] + var[5] + var[6]) / 3.0).sqrt());
    }

    #[test]
    fn caps_hold_and_flat_pilots_spread_evenly() {
        let var: Vec<f64> = (0..16).map(|i| if i == 5 { 1e9 } else { 1.0 }).collect();
        let extra = allocate(4, 4, &var, 16 * 10, 20, 1);
        assert!(extra.iter().all(|&e| e <= 20), "{extra:?}");
        let flat = allocate(4, 4, &[0.0; 16], 16 * 10, 20, 1);
        assert!(flat.iter().all(|&e| e == 10), "{flat:?}");
        let nan = allocate(4, 4, &[f64::NAN; 16], 16 * 10, 20, 1);
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
