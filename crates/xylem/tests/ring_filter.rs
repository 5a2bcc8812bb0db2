//! The growth rings band-limited by the pixel footprint (issue 28, notes/wood.md §3a): the
//! closed-form box filter of the ring wave and of the Beer's-law colour it drives, checked
//! against the unfiltered wood supersampled over the same footprint (fixed seeds), with
//! point-sampled rings as the negative control that must fail.

use xylem::math::{Pcg32, Vec3};
#[path = "common/bare.rs"]
mod bare;
#[path = "common/supersample.rs"]
mod supersample;

use bare::rings_only;
use supersample::{supersampled, COLOR};
use xylem::wood::{preset, Footprint, Needs, WoodVolume};

/// Root-mean-square colour error of the filtered and of the point-sampled colour against the
/// supersampled footprint, over random points, surface orientations and footprints of 0.3–4
/// mean ring widths (the footprint square's first side along the rings' gradient in its plane).
fn errors(name: &str, seed: u64) -> (f64, f64) {
    let vol = WoodVolume::new(rings_only(name), 3).unwrap();
    let ring = vol.params().rings.width;
    let mut rng = Pcg32::new(seed, 28);
    let (mut e_filtered, mut e_point, mut n) = (0.0f64, 0.0f64, 0);
    for _ in 0..120 {
        let c = Vec3::new(
            20.0 + 100.0 * rng.next_f32(),
            40.0 * rng.next_f32() - 20.0,
            200.0 * rng.next_f32(),
        );
        let normal = Vec3::new(
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
        )
        .normalize();
        let r_hat = Vec3::new(c.x, c.y, 0.0).normalize();
        let in_plane = r_hat - normal * r_hat.dot(normal);
        if in_plane.length() < 0.2 {
            continue; // a face almost tangent to the rings: no ring crosses the footprint
        }
        let u = in_plane.normalize();
        let v = normal.cross(u);
        let w = ring * 0.3 * (4.0f32 / 0.3).powf(rng.next_f32());
        let want = supersampled(&vol, c, (u, v), w, 32);
        let fp = Footprint { width: w, normal };
        let filtered = vol.eval_footprint(c, COLOR, fp).diffuse;
        let point = vol.eval(c, COLOR).diffuse;
        if std::env::var("RING_FILTER_DEBUG").is_ok() {
            let r = Vec3::new(c.x, c.y, 0.0).length();
            eprintln!(
                "r {r:6.1} w/W {:5.2} cos {:5.2} err filtered {:.4} point {:.4}",
                w / ring,
                in_plane.length(),
                (filtered - want).length(),
                (point - want).length()
            );
        }
        e_filtered += (filtered - want).length_squared() as f64;
        e_point += (point - want).length_squared() as f64;
        n += 1;
    }
    assert!(n > 60, "{n} usable footprints");
    ((e_filtered / n as f64).sqrt(), (e_point / n as f64).sqrt())
}

#[test]
fn filtered_rings_match_the_supersampled_footprint() {
    // Error budget: the growth time is linear across the footprint only to first order (the
    // growth wave bends it), 32² midpoints resolve a 4-ring footprint to ≈ 0.1 %; measured RMS
    // 1–3·10⁻³, an 8-bit level is 4·10⁻³.
    for (name, seed) in [("african_mahogany", 1), ("red_oak", 2), ("walnut", 3)] {
        let (filtered, point) = errors(name, seed);
        eprintln!("{name}: RMS filtered {filtered:.5}, point-sampled {point:.5}");
        assert!(filtered < 0.006, "{name}: filtered RMS {filtered}");
        // Negative control: point-sampled rings against the same reference fail the bound.
        assert!(
            point > 0.015,
            "{name}: point RMS {point}: no aliasing to remove"
        );
        assert!(point > 5.0 * filtered, "{name}: {point} vs {filtered}");
    }
}

#[test]
fn the_surface_normal_keeps_rings_that_the_face_shows_wide() {
    // A flat-sawn face 100–140 mm from the pith (normal r̂) shows rings as wide bands: a 0.5 mm
    // footprint on it spans almost no growth time, so the colour stays the point colour; the
    // same footprint of unknown orientation (the whole 3D gradient, ≈ 0.5 mm / ring width of
    // time) blurs it.
    let vol = WoodVolume::new(rings_only("red_oak"), 3).unwrap();
    let mut rng = Pcg32::new(5, 5);
    let (mut with_normal, mut isotropic) = (0.0f32, 0.0f32);
    for _ in 0..400 {
        let c = Vec3::new(
            100.0 + 40.0 * rng.next_f32(),
            4.0 * rng.next_f32() - 2.0,
            100.0 * rng.next_f32(),
        );
        let normal = Vec3::new(c.x, c.y, 0.0).normalize();
        let point = vol.eval(c, COLOR).diffuse;
        let a = vol.eval_footprint(c, COLOR, Footprint { width: 0.5, normal });
        let b = vol.eval_footprint(c, COLOR, Footprint::isotropic(0.5));
        with_normal = with_normal.max((a.diffuse - point).abs().max_element());
        isotropic = isotropic.max((b.diffuse - point).abs().max_element());
    }
    assert!(with_normal < 1e-3, "with the normal: {with_normal}");
    assert!(isotropic > 0.02, "isotropic: {isotropic}");
}

#[test]
fn wide_footprints_give_the_mean_ring_colour() {
    // Footprints of 200 rings average Beer's law over the year, not Beer's law of the mean ring
    // value (1–6 % darker for these colours). Reference: the unfiltered colour along the radius
    // (the face's normal is ẑ, so the rings vary along r only), 20 000 midpoints, 100 a ring.
    let vol = WoodVolume::new(rings_only("red_oak"), 3).unwrap();
    let ring = vol.params().rings.width;
    let (c, w) = (Vec3::new(400.0, 0.0, 10.0), 200.0 * ring);
    let n = 20_000;
    let mut want = Vec3::ZERO;
    for i in 0..n {
        let x = c.x + ((i as f32 + 0.5) / n as f32 - 0.5) * w;
        want += vol.eval(Vec3::new(x, c.y, c.z), COLOR).diffuse / n as f32;
    }
    let fp = Footprint {
        width: w,
        normal: Vec3::Z,
    };
    let wide = vol.eval_footprint(c, COLOR, fp).diffuse;
    let err = (wide - want).abs().max_element();
    assert!(err < 0.003, "wide footprint {wide} vs {want}");
}

#[test]
fn ray_fleck_stays_on_a_quartersawn_face_and_fades_on_a_flat_sawn_one() {
    // Quartersawn white oak's rays are sheets 0.4 mm thick with normal θ̂: a quartersawn face
    // (normal θ̂) lies in them and shows broad flecks, which a footprint of three ray widths
    // must keep; a flat-sawn face (normal r̂) cuts them in 0.4 mm lines, which it fades to the
    // mean (the negative control: the same footprint, the other face).
    let vol = WoodVolume::new(preset("quartersawn_white_oak").unwrap(), 3).unwrap();
    let width = vol.params().rays.as_ref().unwrap().width;
    let mut rng = Pcg32::new(9, 9);
    let spread = |normal_of: &dyn Fn(Vec3) -> Vec3, rng: &mut Pcg32| -> f32 {
        let masks: Vec<f32> = (0..2000)
            .map(|_| {
                let c = Vec3::new(
                    60.0 + 60.0 * rng.next_f32(),
                    2.0 * rng.next_f32(),
                    200.0 * rng.next_f32(),
                );
                let fp = Footprint {
                    width: 3.0 * width,
                    normal: normal_of(c),
                };
                vol.eval_footprint(c, Needs::ALL, fp).ray_mask
            })
            .collect();
        let mean = masks.iter().sum::<f32>() / masks.len() as f32;
        (masks.iter().map(|m| (m - mean).powi(2)).sum::<f32>() / masks.len() as f32).sqrt()
    };
    let theta = |c: Vec3| Vec3::new(-c.y, c.x, 0.0).normalize();
    let radial = |c: Vec3| Vec3::new(c.x, c.y, 0.0).normalize();
    let (quarter, flat) = (spread(&theta, &mut rng), spread(&radial, &mut rng));
    assert!(quarter > 0.05, "quartersawn fleck faded: std {quarter}");
    assert!(flat < 1e-4, "flat-sawn ray lines kept: std {flat}");
}
