//! `WoodVolume::eval_many` (the batch path slices and bakes use) gives `eval`'s texels bit for
//! bit, for every preset and level of `needs`, in whole blocks and the partial block at the end,
//! at the pith and far out where the growth wave leaves its fast range.

#[path = "common/texel.rs"]
mod texel;

use glam::Vec3;
use xylem::simd::Simd;
use xylem::wood::{self, Needs, WoodTexel, WoodVolume};

use texel::texel_bits as bits;

fn points() -> Vec<Vec3> {
    let mut p = wood::sample_points(3000, 17);
    // The pith, a point at r ≈ 0, and points past the growth wave's fast range (2²¹ periods).
    p.extend([
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(1e-7, -1e-7, 1.0),
        Vec3::new(3e9, 1.0, 2.0),
        Vec3::new(-1e12, 4e11, -7.0),
    ]);
    // Not a multiple of the block: the last points go one by one.
    p.extend(wood::sample_points(13, 3).iter().map(|q| *q * 0.1));
    p
}

#[test]
fn eval_many_is_eval_bit_for_bit() {
    let pts = points();
    for name in wood::PRESET_NAMES {
        let volume = WoodVolume::new(wood::preset(name).unwrap(), 7).unwrap();
        for needs in [Needs::COLOR, Needs::COLOR_FIBERS, Needs::ALL] {
            let one: Vec<WoodTexel> = pts.iter().map(|&p| volume.eval(p, needs)).collect();
            // Every instruction set this CPU has (the lane stages are compiled for each).
            for simd in Simd::ALL {
                if simd > Simd::best() {
                    continue;
                }
                let mut many = vec![WoodTexel::default(); pts.len()];
                volume.eval_many_on(simd, &pts, needs, &mut many);
                for (i, (t, one)) in many.iter().zip(&one).enumerate() {
                    assert_eq!(
                        bits(t),
                        bits(one),
                        "{name} {needs:?} {simd:?}: point {i} {}: {t:?} vs {one:?}",
                        pts[i]
                    );
                }
            }
        }
    }
}

#[test]
fn eval_many_far_points_stay_finite() {
    // Far points fall back to `eval`, whose results must be finite like everywhere else.
    let volume = WoodVolume::new(wood::preset("african_mahogany").unwrap(), 1).unwrap();
    let pts = vec![Vec3::new(3e9, 1.0, 2.0); 32];
    let mut out = vec![WoodTexel::default(); 32];
    volume.eval_many(&pts, Needs::COLOR, &mut out);
    assert!(out
        .iter()
        .all(|t| t.diffuse.is_finite() && t.growth_time.is_finite()));
}
