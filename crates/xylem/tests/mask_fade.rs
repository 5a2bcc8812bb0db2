//! Pores and rays faded by the pixel footprint (issue 28, notes/wood.md §3b): where a footprint
//! cannot resolve them, the colour must be the footprint's mean colour — the supersampled
//! average of the point-evaluated wood — not Beer's law of the mean mask, which is darker (the
//! colour is convex in the mask). The negative control rebuilds that old colour and must fail
//! the same bound. Fixed seeds.

use xylem::math::{Pcg32, Vec3};
use xylem::wood::{preset, Footprint, WoodParams, WoodVolume};
#[path = "common/supersample.rs"]
mod supersample;
use supersample::{supersampled, COLOR};

/// Which mask a case fades.
#[derive(Clone, Copy, PartialEq)]
enum Mask {
    Pores,
    Rays,
}

/// Over `n` random footprints `width` mm wide on faces of normal `normal(c)`: the mean of
/// (faded − supersampled) colour, its standard error, and the same mean for the old colour of
/// the mean mask (the colour of the wood without the mask × exp(−c · faded mask), c the
/// absorbance of a full mask, −ln(latewood) × its path; eq. 25).
fn bias(
    params: WoodParams,
    mask: Mask,
    width: f32,
    normal: impl Fn(Vec3) -> Vec3,
    seed: u64,
) -> (Vec3, Vec3, Vec3) {
    let mut bare = params.clone();
    let late = -Vec3::from(params.color.latewood).ln();
    let scale = match mask {
        Mask::Pores => {
            bare.pores = None;
            late * params.color.pore_path
        }
        Mask::Rays => {
            bare.rays = None;
            late * params.color.ray_path
        }
    };
    let vol = WoodVolume::new(params, 3).unwrap();
    let without = WoodVolume::new(bare, 3).unwrap();
    let mut rng = Pcg32::new(seed, 28);
    let n = 1000;
    let (mut sum, mut sum2, mut old) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for _ in 0..n {
        let c = Vec3::new(
            30.0 + 90.0 * rng.next_f32(),
            20.0 * rng.next_f32() - 10.0,
            200.0 * rng.next_f32(),
        );
        let nrm = normal(c);
        let u = nrm.any_orthonormal_vector();
        let v = nrm.cross(u);
        let fp = Footprint { width, normal: nrm };
        let want = supersampled(&vol, c, (u, v), width, 24);
        let texel = vol.eval_footprint(c, COLOR, fp);
        let faded = texel.diffuse;
        let m = match mask {
            Mask::Pores => texel.pore_mask,
            Mask::Rays => texel.ray_mask,
        };
        let of_mean_mask = without.eval_footprint(c, COLOR, fp).diffuse * (-scale * m).exp();
        let d = faded - want;
        sum += d;
        sum2 += d * d;
        old += of_mean_mask - want;
    }
    let mean = sum / n as f32;
    let se = ((sum2 / n as f32 - mean * mean) / (n - 1) as f32)
        .max(Vec3::ZERO)
        .sqrt();
    (mean, se, old / n as f32)
}

/// Tolerance on the mean colour error per channel: a quarter of an 8-bit level (0.001) plus
/// three standard errors of the 1000-footprint mean.
fn check(name: &str, (mean, se, old): (Vec3, Vec3, Vec3)) {
    eprintln!("{name}: faded − supersampled {mean} ± {se}; mean-mask colour − supersampled {old}");
    let tol = Vec3::splat(0.001) + 3.0 * se;
    assert!(
        mean.abs().cmple(tol).all(),
        "{name}: faded colour off the footprint mean by {mean} (tolerance {tol})"
    );
    // Negative control: Beer's law of the mean mask misses the same bound.
    assert!(
        old.abs().cmpgt(tol).any(),
        "{name}: the mean-mask colour {old} passes the bound {tol}: no Jensen gap to find"
    );
}

#[test]
fn faded_pores_give_the_footprint_mean_colour() {
    // Red oak's open pores (0.3 mm) under footprints 2.5 pore diameters wide (fully faded),
    // ring-porous (the pores shrink to nothing in the latewood) and, as a second case, with
    // every pore at full size; rays and cell texture off so the pores alone set the gap.
    for ring_porosity in [None, Some(0.0)] {
        let mut p = preset("red_oak").unwrap();
        p.rays = None;
        p.texture = None;
        let pores = p.pores.as_mut().unwrap();
        if let Some(r) = ring_porosity {
            pores.ring_porosity = r;
        }
        let width = 2.5 * 2.0 * pores.radius;
        let random_face = |c: Vec3| {
            let h = c * 12.9898;
            Vec3::new(h.x.sin(), h.y.cos(), (h.z * 0.3).sin()).normalize()
        };
        let name = format!("red oak, ring porosity {ring_porosity:?}");
        check(&name, bias(p, Mask::Pores, width, random_face, 1));
    }
}

#[test]
fn faded_pores_at_half_weight_give_the_blend_of_colours() {
    // Footprints 1.5 pore diameters wide (weight ½): the colour is half the point colour and
    // half the mean colour, whose mean over footprints is again the footprint mean.
    let mut p = preset("red_oak").unwrap();
    p.rays = None;
    p.texture = None;
    p.pores.as_mut().unwrap().ring_porosity = 0.0;
    let width = 1.5 * 2.0 * p.pores.as_ref().unwrap().radius;
    let flat = |c: Vec3| Vec3::new(c.x, c.y, 0.0).normalize();
    check("red oak, half faded", bias(p, Mask::Pores, width, flat, 2));
}

#[test]
fn faded_rays_give_the_footprint_mean_colour() {
    // Rays on a flat-sawn face (normal r̂), where a footprint of 2.5 ray widths fades them fully;
    // pores and texture off: quartersawn white oak's broad rays, lighter than the fibres (a
    // negative path, Beer's law still convex), and red oak's made as dark as its pores (its own
    // path, 0.2, leaves a gap below the test's resolution).
    for name in ["quartersawn_white_oak", "red_oak"] {
        let mut p = preset(name).unwrap();
        p.pores = None;
        p.texture = None;
        if name == "red_oak" {
            p.color.ray_path = 1.0;
        }
        let width = 2.5 * p.rays.as_ref().unwrap().width;
        let flat = |c: Vec3| Vec3::new(c.x, c.y, 0.0).normalize();
        check(&format!("{name} rays"), bias(p, Mask::Rays, width, flat, 3));
    }
}
