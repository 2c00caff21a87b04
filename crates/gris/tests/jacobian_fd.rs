//! The analytic reconnection Jacobian `(cos θ_y / cos θ_x)·(d_x²/d_y²)` agrees with a
//! finite-difference measurement of the direction map ω_x ↦ ω_y (docs/GRIS.md §6.2).
//!
//! The map: a ray leaves `x_prev` in direction ω, hits the plane through the reconnection vertex
//! `v` with normal `n` at a point `p(ω)`, and ω_y = normalize(p(ω) − y_prev). Its Jacobian is the
//! ratio of the spherical patch areas spanned by two tangent perturbations of ω_x, measured with
//! central differences in f64.
// Uses `reconnection_jacobian_from_points`, which needs the `std` feature (square roots).
#![cfg(feature = "std")]

use restir_gris::jacobian::{reconnection_jacobian_from_points, reconnection_jacobian_solid_angle};
use restir_testkit::SplitMix64 as Rng;

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: V, s: f64) -> V {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn length(a: V) -> f64 {
    dot(a, a).sqrt()
}
fn normalize(a: V) -> V {
    scale(a, 1.0 / length(a))
}

/// A unit vector orthogonal to `a`, and a second one completing the frame.
fn tangent_frame(a: V) -> (V, V) {
    let helper = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let t1 = normalize(cross(a, helper));
    let t2 = cross(a, t1);
    (t1, t2)
}

/// ω ↦ ω_y through the plane (v, n).
fn direction_map(omega: V, x_prev: V, y_prev: V, v: V, n: V) -> V {
    let t = dot(n, sub(v, x_prev)) / dot(n, omega);
    let p = add(x_prev, scale(omega, t));
    normalize(sub(p, y_prev))
}

fn random_point(rng: &mut Rng, r: f64) -> V {
    [
        (rng.next_f64() * 2.0 - 1.0) * r,
        (rng.next_f64() * 2.0 - 1.0) * r,
        (rng.next_f64() * 2.0 - 1.0) * r,
    ]
}

#[test]
fn reconnection_jacobian_matches_finite_differences() {
    let mut rng = Rng::new(0xFD);
    let mut checked = 0;
    let mut max_rel = 0.0f64;
    while checked < 2000 {
        let v = random_point(&mut rng, 1.0);
        let n = normalize(random_point(&mut rng, 1.0));
        let x_prev = add(v, random_point(&mut rng, 3.0));
        let y_prev = add(v, random_point(&mut rng, 3.0));
        let (dx, dy) = (sub(x_prev, v), sub(y_prev, v));
        let cos_x = dot(n, dx) / length(dx);
        let cos_y = dot(n, dy) / length(dy);
        // Keep away from grazing angles and tiny distances, where finite differences break down.
        if cos_x.abs() < 0.1 || cos_y.abs() < 0.1 || length(dx) < 0.2 || length(dy) < 0.2 {
            continue;
        }
        let omega_x = normalize(sub(v, x_prev));
        let (t1, t2) = tangent_frame(omega_x);
        let eps = 1e-5;
        let at = |a: f64, b: f64| normalize(add(omega_x, add(scale(t1, a), scale(t2, b))));
        let fd = |f: &dyn Fn(V) -> V| -> f64 {
            let da = scale(sub(f(at(eps, 0.0)), f(at(-eps, 0.0))), 0.5 / eps);
            let db = scale(sub(f(at(0.0, eps)), f(at(0.0, -eps))), 0.5 / eps);
            length(cross(da, db))
        };
        let area_x = fd(&|w| w);
        let area_y = fd(&|w| direction_map(w, x_prev, y_prev, v, n));
        let measured = area_y / area_x;

        let to_f32 = |a: V| a.map(|c| c as f32);
        let analytic = f64::from(reconnection_jacobian_from_points(
            to_f32(x_prev),
            to_f32(y_prev),
            to_f32(v),
            to_f32(n),
        ));
        let from_cosines = f64::from(reconnection_jacobian_solid_angle(
            cos_y as f32,
            dot(dy, dy) as f32,
            cos_x as f32,
            dot(dx, dx) as f32,
        ));
        let rel = (analytic / measured - 1.0).abs();
        max_rel = max_rel.max(rel);
        assert!(
            rel < 1e-3,
            "analytic {analytic} vs finite difference {measured} (rel {rel})"
        );
        assert!((from_cosines / analytic - 1.0).abs() < 1e-5);
        checked += 1;
    }
    assert!(max_rel < 1e-3);
}
