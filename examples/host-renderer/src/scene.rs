//! The host's own scene: analytic spheres over a checkered floor plane, lit by one-sided
//! rectangle lights facing down, seen by a pinhole camera. Intersection is brute force: a
//! renderer of a different kind from the workspace's (no meshes, no BVH, no light table).

use glam::Vec3;

/// A diffuse sphere.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre.
    pub centre: Vec3,
    /// Radius.
    pub radius: f32,
    /// Diffuse reflectance.
    pub albedo: Vec3,
}

/// A rectangle light `corner + u·edge_u + v·edge_v`, emitting `radiance` on the side of
/// `edge_u × edge_v`.
#[derive(Clone, Copy, Debug)]
pub struct RectLight {
    /// One corner.
    pub corner: Vec3,
    /// First edge.
    pub edge_u: Vec3,
    /// Second edge.
    pub edge_v: Vec3,
    /// Emitted radiance.
    pub radiance: Vec3,
}

impl RectLight {
    /// Unit normal of the emitting side.
    pub fn normal(&self) -> Vec3 {
        self.edge_u.cross(self.edge_v).normalize()
    }

    /// Area.
    pub fn area(&self) -> f32 {
        self.edge_u.cross(self.edge_v).length()
    }

    /// Emitted power (up to the constant π).
    pub fn power(&self) -> f32 {
        self.area() * (self.radiance.x + self.radiance.y + self.radiance.z) / 3.0
    }

    /// The point at `(u, v)` in the unit square.
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        self.corner + u * self.edge_u + v * self.edge_v
    }
}

/// What a camera ray or a shadow ray hits.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f32,
    /// Position.
    pub p: Vec3,
    /// Unit normal facing the ray's origin.
    pub n: Vec3,
    /// Diffuse reflectance there.
    pub albedo: Vec3,
}

/// The scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The spheres.
    pub spheres: Vec<Sphere>,
    /// Height of the floor plane `y = floor`.
    pub floor: f32,
    /// The lights.
    pub lights: Vec<RectLight>,
    /// Cumulative light powers, normalised (light selection proportional to power).
    pub light_cdf: Vec<f32>,
    /// Camera position.
    pub eye: Vec3,
    /// Camera target.
    pub look_at: Vec3,
    /// Vertical field of view in degrees.
    pub fov: f32,
}

impl Scene {
    /// The demonstration scene: `n` × `n` small spheres on a checkered floor under `lights` × 4
    /// rectangle lights of varied colour and power at two heights.
    pub fn demo(n: u32, lights: u32) -> Self {
        let mut spheres = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let x = (i as f32 - (n - 1) as f32 / 2.0) * 1.2;
                let z = (j as f32 - (n - 1) as f32 / 2.0) * 1.2;
                let r = 0.3 + 0.15 * (((i * 7 + j * 3) % 5) as f32 / 4.0);
                let hue = ((i + 2 * j) % 3) as usize;
                let mut albedo = Vec3::splat(0.25);
                albedo[hue] = 0.75;
                spheres.push(Sphere {
                    centre: Vec3::new(x, r, z),
                    radius: r,
                    albedo,
                });
            }
        }
        let mut rects = Vec::new();
        for k in 0..lights * 4 {
            let a = k as f32 * 2.399_963; // the golden angle spreads them
            let rad = 1.0 + 3.5 * ((k as f32 + 0.5) / (lights * 4) as f32).sqrt();
            let (x, z) = (rad * a.cos(), rad * a.sin());
            let y = if k % 2 == 0 { 2.2 } else { 3.4 };
            let size = 0.12 + 0.1 * ((k % 3) as f32);
            let strength = 4.0 + 36.0 * ((k * 13 % 7) as f32 / 6.0);
            let mut colour = Vec3::splat(0.4);
            colour[(k % 3) as usize] = 1.0;
            rects.push(RectLight {
                corner: Vec3::new(x - size / 2.0, y, z - size / 2.0),
                edge_u: Vec3::new(size, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, size),
                radiance: colour * strength,
            });
        }
        let mut scene = Self {
            spheres,
            floor: 0.0,
            lights: rects,
            light_cdf: Vec::new(),
            eye: Vec3::new(0.0, 3.0, 7.5),
            look_at: Vec3::new(0.0, 0.3, 0.0),
            fov: 45.0,
        };
        scene.update_light_cdf();
        scene
    }

    /// Recomputes the light selection's cumulative distribution.
    pub fn update_light_cdf(&mut self) {
        let total: f32 = self.lights.iter().map(RectLight::power).sum();
        let mut acc = 0.0;
        self.light_cdf = self
            .lights
            .iter()
            .map(|l| {
                acc += l.power() / total;
                acc
            })
            .collect();
    }

    /// The probability of selecting light `i`.
    pub fn light_pmf(&self, i: usize) -> f32 {
        self.light_cdf[i] - if i == 0 { 0.0 } else { self.light_cdf[i - 1] }
    }

    /// Selects a light proportionally to power with `u ∈ [0, 1)`.
    pub fn select_light(&self, u: f32) -> usize {
        self.light_cdf
            .partition_point(|&c| c <= u)
            .min(self.lights.len() - 1)
    }

    /// The nearest surface along `origin + t·dir` with `t` in `(0, t_max)` (lights are not
    /// surfaces here: they emit downwards and are seen by nothing in the demonstration).
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_best = t_max;
        for s in &self.spheres {
            let oc = origin - s.centre;
            let b = oc.dot(dir);
            let c = oc.length_squared() - s.radius * s.radius;
            let disc = b * b - c;
            if disc < 0.0 {
                continue;
            }
            let sq = disc.sqrt();
            for t in [-b - sq, -b + sq] {
                if t > 1e-4 && t < t_best {
                    let p = origin + t * dir;
                    let mut n = (p - s.centre) / s.radius;
                    if n.dot(dir) > 0.0 {
                        n = -n;
                    }
                    t_best = t;
                    best = Some(Hit {
                        t,
                        p,
                        n,
                        albedo: s.albedo,
                    });
                    break;
                }
            }
        }
        if dir.y.abs() > 1e-8 {
            let t = (self.floor - origin.y) / dir.y;
            if t > 1e-4 && t < t_best {
                let p = origin + t * dir;
                let checker = ((p.x.floor() + p.z.floor()) as i64).rem_euclid(2) == 0;
                let albedo = if checker {
                    Vec3::splat(0.7)
                } else {
                    Vec3::splat(0.2)
                };
                let n = if dir.y < 0.0 { Vec3::Y } else { -Vec3::Y };
                best = Some(Hit { t, p, n, albedo });
            }
        }
        best
    }

    /// Whether the segment from `p` (offset along `n`) to `q` is unoccluded.
    pub fn unoccluded(&self, p: Vec3, n: Vec3, q: Vec3) -> bool {
        let origin = p + n * 1e-3;
        let d = q - origin;
        let dist = d.length();
        self.intersect(origin, d / dist, dist * (1.0 - 1e-4))
            .is_none()
    }

    /// The camera ray through film position `(fx, fy)` (pixels from the top left) of a
    /// `width × height` image.
    pub fn camera_ray(&self, fx: f32, fy: f32, width: usize, height: usize) -> (Vec3, Vec3) {
        let forward = (self.look_at - self.eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let tan = (self.fov.to_radians() / 2.0).tan();
        let aspect = width as f32 / height as f32;
        let sx = (2.0 * fx / width as f32 - 1.0) * tan * aspect;
        let sy = (1.0 - 2.0 * fy / height as f32) * tan;
        (self.eye, (forward + sx * right + sy * up).normalize())
    }
}
