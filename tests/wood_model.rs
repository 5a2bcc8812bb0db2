//! The solid-wood model (issue 4): finite values over a dense cube for every preset, at the pith
//! and under strong distortion; unit, orthonormal directions.

use glam::Vec3;
use xylem::wood::{self, Needs, WoodVolume, PRESET_NAMES};

fn volume(name: &str) -> WoodVolume {
    WoodVolume::new(wood::preset(name).unwrap(), 7).unwrap()
}

#[test]
fn every_preset_is_finite_over_a_dense_cube() {
    for name in PRESET_NAMES {
        let v = volume(name);
        let n = 24;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    // A cube around the pith (pith included: i = j = n/2 gives x = y = 0).
                    let p = Vec3::new(i as f32 - 12.0, j as f32 - 12.0, k as f32) * 5.0;
                    let t = v.eval(p, Needs::ALL);
                    let ok = t.diffuse.is_finite()
                        && t.fiber_color.is_finite()
                        && t.fiber_dir.is_finite()
                        && t.ray_dir.is_finite()
                        && t.bump_grad.is_finite()
                        && [
                            t.ray_mask,
                            t.pore_mask,
                            t.bump,
                            t.highlight_width,
                            t.growth_time,
                        ]
                        .iter()
                        .all(|x| x.is_finite());
                    assert!(ok, "{name} at {p}: {t:?}");
                    assert!((t.fiber_dir.length() - 1.0).abs() < 1e-4, "{name} at {p}");
                    assert!((t.ray_dir.length() - 1.0).abs() < 1e-4, "{name} at {p}");
                    assert!(t.diffuse.min_element() >= 0.0 && t.diffuse.max_element() <= 1.0);
                    assert!(
                        (0.0..=1.0).contains(&t.pore_mask) && (0.0..=1.0).contains(&t.ray_mask)
                    );
                }
            }
        }
    }
}

#[test]
fn volume_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<WoodVolume>();
}
