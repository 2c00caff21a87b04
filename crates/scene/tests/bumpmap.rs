//! What Mitsuba's `bumpmap` reads besides the texture's value: the gradient of a bitmap's scalar
//! lookup (`eval_1_grad`) against finite differences of the lookup itself, and the surface's
//! `dp/du`, `dp/dv` of meshes and spheres against finite differences of their parametrisation.

use glam::{Vec2, Vec3};
use restir_geometry::{Shape, Sphere, TriangleMesh};
use restir_scene::texture::{FilterType, Texels, Texture, UvTransform, WrapMode};

fn bitmap(filter: FilterType, wrap: WrapMode, scale: Vec2) -> Texture {
    // A 5 × 4 grey ramp with a bump, values in [0, 1].
    let (w, h) = (5usize, 4usize);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            Vec3::splat(((0.3 * x + 0.7 * y * y + 0.2 * x * y) * 0.37).fract())
        })
        .collect();
    Texture::Bitmap {
        width: w,
        height: h,
        texels: Texels::new(texels, true),
        uv: UvTransform {
            scale,
            offset: Vec2::new(0.05, -0.1),
        },
        wrap,
        filter,
    }
}

/// Inside a texel cell the bilinear lookup is smooth: its gradient is the finite difference;
/// a nearest lookup's is zero; a checkerboard has none.
#[test]
fn gradient_is_the_derivative_of_the_lookup() {
    for (wrap, scale) in [
        (WrapMode::Repeat, Vec2::ONE),
        (WrapMode::Mirror, Vec2::new(2.0, 0.5)),
        (WrapMode::Clamp, Vec2::new(1.5, 3.0)),
    ] {
        let t = bitmap(FilterType::Bilinear, wrap, scale);
        let mut checked = 0;
        for i in 0..200 {
            let uv = Vec2::new(
                (i as f32 * 0.618_034).fract(),
                (i as f32 * 0.414_213_5).fract(),
            );
            let g = t.eval_1_grad(uv).unwrap();
            let e = 1e-3;
            let fd = Vec2::new(
                (t.eval_1(uv + Vec2::new(e, 0.0)) - t.eval_1(uv - Vec2::new(e, 0.0))) / (2.0 * e),
                (t.eval_1(uv + Vec2::new(0.0, e)) - t.eval_1(uv - Vec2::new(0.0, e))) / (2.0 * e),
            );
            // Skip points within the step of a texel-centre line (a kink of the lookup).
            let p = (uv * scale + Vec2::new(0.05, -0.1)) * Vec2::new(5.0, 4.0) - 0.5;
            let near = |x: f32, s: f32| {
                let f = x - x.floor();
                f.min(1.0 - f) < 2.0 * e * 5.0 * s
            };
            if near(p.x, scale.x) || near(p.y, scale.y) {
                continue;
            }
            checked += 1;
            assert!(
                (g - fd).length() < 2e-2 * (1.0 + fd.length()),
                "{wrap:?} at {uv}: {g} vs {fd}"
            );
        }
        assert!(checked > 100, "{checked}");
        // Negative control: the gradient without the uv transform's scale differs.
        if scale != Vec2::ONE {
            let uv = Vec2::new(0.33, 0.61);
            let g = t.eval_1_grad(uv).unwrap();
            assert!((g / scale - g).length() > 1e-3);
        }
    }
    let nearest = bitmap(FilterType::Nearest, WrapMode::Repeat, Vec2::ONE);
    assert_eq!(nearest.eval_1_grad(Vec2::new(0.3, 0.3)), Some(Vec2::ZERO));
    let checker = Texture::Checkerboard {
        color0: Vec3::ONE,
        color1: Vec3::ZERO,
        uv: UvTransform::default(),
    };
    assert_eq!(checker.eval_1_grad(Vec2::splat(0.3)), None);
}

/// A triangle whose positions are an affine function of its texture coordinates has that
/// function's columns as `dp/du` and `dp/dv`; without texture coordinates, its edges.
#[test]
fn mesh_derivatives_follow_the_texture_coordinates() {
    let (a, b, c) = (
        Vec3::new(0.7, -0.2, 0.1),
        Vec3::new(0.3, 1.1, -0.4),
        Vec3::new(1.0, 2.0, 3.0),
    );
    let p = |uv: Vec2| c + a * uv.x + b * uv.y;
    let uvs = vec![
        Vec2::new(0.1, 0.2),
        Vec2::new(0.9, 0.3),
        Vec2::new(0.4, 0.8),
    ];
    let positions = uvs.iter().map(|&uv| p(uv)).collect();
    let mesh =
        TriangleMesh::new(positions, None, Some(uvs.clone()), vec![[0, 1, 2]], false).unwrap();
    let (du, dv) = Shape::Mesh(mesh).uv_derivatives(0, Vec2::new(0.2, 0.3));
    assert!(
        (du - a).length() < 1e-5 && (dv - b).length() < 1e-5,
        "{du} {dv}"
    );
    let positions: Vec<Vec3> = uvs.iter().map(|&uv| p(uv)).collect();
    let bare = TriangleMesh::new(positions.clone(), None, None, vec![[0, 1, 2]], false).unwrap();
    let (du, dv) = bare.uv_derivatives(0);
    assert_eq!(
        (du, dv),
        (positions[1] - positions[0], positions[2] - positions[0])
    );
}

/// On a sphere the derivatives of `p(u, v) = c + r·(sin πv cos 2πu, sin πv sin 2πu, cos πv)`.
#[test]
fn sphere_derivatives_are_those_of_its_parametrisation() {
    let (c, r) = (Vec3::new(0.3, -0.2, 0.5), 1.7);
    let sphere = Shape::Sphere(Sphere::new(c, r, false));
    let p = |u: f64, v: f64| {
        let (phi, theta) = (2.0 * std::f64::consts::PI * u, std::f64::consts::PI * v);
        [
            f64::from(c.x) + f64::from(r) * theta.sin() * phi.cos(),
            f64::from(c.y) + f64::from(r) * theta.sin() * phi.sin(),
            f64::from(c.z) + f64::from(r) * theta.cos(),
        ]
    };
    for (u, v) in [(0.1, 0.3), (0.45, 0.7), (0.8, 0.52), (0.99, 0.1)] {
        let (phi, theta) = (
            2.0 * std::f32::consts::PI * u as f32,
            std::f32::consts::PI * v as f32,
        );
        let n = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        let (du, dv) = sphere.uv_derivatives(0, Sphere::param_of(n));
        let e = 1e-6;
        let d = |a: [f64; 3], b: [f64; 3]| {
            Vec3::new(
                ((a[0] - b[0]) / (2.0 * e)) as f32,
                ((a[1] - b[1]) / (2.0 * e)) as f32,
                ((a[2] - b[2]) / (2.0 * e)) as f32,
            )
        };
        let fu = d(p(u + e, v), p(u - e, v));
        let fv = d(p(u, v + e), p(u, v - e));
        assert!((du - fu).length() < 1e-3 * fu.length(), "{du} vs {fu}");
        assert!((dv - fv).length() < 1e-3 * fv.length(), "{dv} vs {fv}");
    }
}
