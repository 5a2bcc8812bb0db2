//! Frame fields and distortion Jacobians (issue 4): orthonormal frames everywhere (pith included),
//! the exact Jacobian of f(p) = p + Σ mᵢ aᵢ against finite differences of an independent f64
//! implementation, and the transport identities of Liu et al. 2016 eq. 17–18.

use glam::{DVec3, Mat3, Vec3};
use xylem::field::{cylinder_frame, exact_jacobian, rotate_about_radial, Displacement, Distortion};
use xylem::math::{Frame, Pcg32};

fn assert_orthonormal(f: &Frame, tol: f32, at: Vec3) {
    for (a, b) in [(f.s, f.t), (f.t, f.n), (f.s, f.n)] {
        assert!(a.dot(b).abs() < tol, "not orthogonal at {at}");
    }
    for v in [f.s, f.t, f.n] {
        assert!((v.length() - 1.0).abs() < tol, "not unit at {at}");
    }
    assert!(
        (f.s.cross(f.t) - f.n).length() < tol,
        "not right-handed at {at}"
    );
}

#[test]
fn cylinder_frame_is_orthonormal_everywhere_including_the_pith() {
    let mut rng = Pcg32::new(11, 0);
    let mut points = vec![
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -5.0),
        Vec3::new(1e-9, -1e-9, 3.0),
    ];
    for _ in 0..20_000 {
        let scale = [1e-7, 1e-3, 1.0, 100.0, 1e4][(rng.next_u32() % 5) as usize];
        points.push((Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * scale);
    }
    for p in points {
        let f = cylinder_frame(p);
        assert_orthonormal(&f, 1e-5, p);
        // Interlock keeps it orthonormal for any angle.
        let angle = (rng.next_f32() - 0.5) * 3.0;
        assert_orthonormal(&rotate_about_radial(&f, angle), 1e-5, p);
    }
}

/// m(p) = A sin(k·p + φ) in f64, with gradient.
#[derive(Clone, Copy)]
struct Wave {
    amp: f64,
    k: DVec3,
    phase: f64,
}

impl Wave {
    fn m(&self, p: DVec3) -> f64 {
        self.amp * (self.k.dot(p) + self.phase).sin()
    }
    fn grad(&self, p: DVec3) -> DVec3 {
        self.k * self.amp * (self.k.dot(p) + self.phase).cos()
    }
}

/// f(p) = p + Σ mᵢ(p) aᵢ(p), aᵢ = (r̂, θ̂, ẑ), written independently in f64.
fn f64_distort(p: DVec3, waves: &[Wave; 3]) -> DVec3 {
    let r = (p.x * p.x + p.y * p.y).sqrt();
    let rh = DVec3::new(p.x / r, p.y / r, 0.0);
    let th = DVec3::new(-p.y / r, p.x / r, 0.0);
    p + waves[0].m(p) * rh + waves[1].m(p) * th + waves[2].m(p) * DVec3::Z
}

#[test]
fn exact_jacobian_matches_finite_differences() {
    let mut rng = Pcg32::new(5, 1);
    let mut checked = 0;
    for _ in 0..2000 {
        let mut rnd = |s: f64| (rng.next_f64() - 0.5) * 2.0 * s;
        let waves = [(); 3].map(|_| Wave {
            amp: rnd(3.0),
            k: DVec3::new(rnd(0.3), rnd(0.3), rnd(0.3)),
            phase: rnd(3.0),
        });
        let p = DVec3::new(rnd(80.0), rnd(80.0), rnd(200.0));
        let r = (p.x * p.x + p.y * p.y).sqrt();
        if r < 5.0 {
            continue;
        }
        let grads: Vec<DVec3> = waves.iter().map(|w| w.grad(p)).collect();
        if grads.iter().any(|g| g.length() >= 0.5) {
            continue;
        }
        let pf = p.as_vec3();
        let terms = [0, 1, 2].map(|i| (waves[i].m(p) as f32, grads[i].as_vec3()));
        let j = exact_jacobian(pf, &cylinder_frame(pf), terms);
        let h = 1e-4;
        let cols = [DVec3::X, DVec3::Y, DVec3::Z]
            .map(|e| (f64_distort(p + e * h, &waves) - f64_distort(p - e * h, &waves)) / (2.0 * h));
        let fd = Mat3::from_cols(cols[0].as_vec3(), cols[1].as_vec3(), cols[2].as_vec3());
        let diff = (j - fd).to_cols_array();
        let err = diff.iter().map(|d| d * d).sum::<f32>().sqrt();
        let norm = fd.to_cols_array().iter().map(|d| d * d).sum::<f32>().sqrt();
        assert!(err / norm <= 1e-3, "relative error {} at {p}", err / norm);
        checked += 1;
    }
    assert!(checked > 500, "only {checked} points checked");
}

#[test]
fn safe_jacobian_is_invertible_and_transport_keeps_tangency() {
    // Strong distortion: steep gradients along all three directions. The safe Jacobian (eq. 22)
    // stays invertible, and a vector tangent to a level set of s at f(p) stays tangent to the
    // level set of s∘f at p: (Jᵀ g)·(J⁻¹ v) = g·v (eq. 17–18).
    let mut rng = Pcg32::new(9, 2);
    for _ in 0..5000 {
        let mut rnd = |s: f32| (rng.next_f32() - 0.5) * 2.0 * s;
        let p = Vec3::new(rnd(50.0), rnd(50.0), rnd(50.0));
        let frame = cylinder_frame(p);
        let mut d = Distortion::identity(p);
        for dir in [frame.s, frame.t, frame.n] {
            let g = Vec3::new(rnd(1.0), rnd(1.0), rnd(1.0)) * 10f32.powf(rnd(2.0));
            d.add(Displacement {
                dir,
                m: rnd(5.0),
                grad_m: g,
            });
        }
        assert!(d.jacobian.determinant().is_finite());
        let g = Vec3::new(rnd(1.0), rnd(1.0), rnd(1.0)).normalize();
        let v = g.any_orthonormal_vector();
        let tv = d.vector(v);
        let tg = d.gradient(g);
        assert!(tv.is_finite() && tg.is_finite());
        if d.jacobian.determinant().abs() > 1e-2 {
            assert!(
                tg.dot(tv).abs() < 1e-3 * tg.length() * tv.length().max(1.0),
                "at {p}"
            );
        }
    }
}

#[test]
fn one_term_safe_jacobian_never_folds() {
    // det(I + a ⊗ g/(1+‖g‖)) = 1 + a·g/(1+‖g‖) > 0 for unit a, whatever g.
    let mut rng = Pcg32::new(3, 3);
    for _ in 0..10_000 {
        let a = xylem::math::uniform_sphere(rng.next_vec2());
        let g =
            xylem::math::uniform_sphere(rng.next_vec2()) * 10f32.powf(rng.next_f32() * 8.0 - 2.0);
        let mut d = Distortion::identity(Vec3::ZERO);
        d.add(Displacement {
            dir: a,
            m: 1.0,
            grad_m: g,
        });
        assert!(d.jacobian.determinant() > 0.0, "a = {a}, g = {g}");
    }
}
