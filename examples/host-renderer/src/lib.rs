//! A renderer of its own kind (analytic spheres, a checkered floor, rectangle lights, brute-force
//! intersection: none of the workspace's scene, geometry or light crates) that gets ReSTIR DI
//! from `restir-reuse` by implementing two traits:
//!
//! * [`Surfaces`] for its G-buffer ([`GBuffer`]): which pixels see a surface, the similarity
//!   test, the previous pixel (the camera does not move: the same pixel);
//! * [`DirectLighting`] for its lights ([`Lights`]): a light sample (a light chosen by power, a
//!   uniform point on it, density in area measure), the target (the luminance of the unshadowed
//!   contribution), the contribution and a shadow ray.
//!
//! Its own direct-lighting estimator ([`render_reference`]: one light sample and one shadow ray
//! per pixel and pass) is the reference the tests compare ReSTIR DI against.

pub mod scene;

use glam::Vec3;
use rayon::prelude::*;
use restir_reuse::direct::{DirectLighting, DirectSettings, RestirDi};
use restir_reuse::{Pcg32, SeededStreams, Similarity, SimilarityKey, Streams, Surfaces};

pub use scene::Scene;

/// What the camera sees at a pixel.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// Position.
    pub p: Vec3,
    /// Unit normal, towards the camera.
    pub n: Vec3,
    /// Diffuse reflectance.
    pub albedo: Vec3,
}

/// One pass's primary hits.
#[derive(Clone, Debug)]
pub struct GBuffer {
    width: usize,
    height: usize,
    surfaces: Vec<Option<Surface>>,
    keys: Vec<SimilarityKey>,
}

impl GBuffer {
    /// Traces one jittered camera ray per pixel, jitter from stage 0 of `streams`.
    pub fn trace(scene: &Scene, width: usize, height: usize, streams: &impl Streams) -> Self {
        let surfaces: Vec<Option<Surface>> = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let mut rng = streams.pixel(i, 0);
                let (fx, fy) = ((i % width) as f32, (i / width) as f32);
                let (o, d) =
                    scene.camera_ray(fx + rng.next_f32(), fy + rng.next_f32(), width, height);
                scene.intersect(o, d, f32::INFINITY).map(|h| Surface {
                    p: h.p,
                    n: h.n,
                    albedo: h.albedo,
                })
            })
            .collect();
        let keys = surfaces
            .iter()
            .map(|s| match s {
                Some(s) => SimilarityKey {
                    n: s.n,
                    depth: (s.p - scene.eye).length(),
                },
                None => SimilarityKey {
                    n: Vec3::Z,
                    depth: SimilarityKey::NO_HIT,
                },
            })
            .collect();
        Self {
            width,
            height,
            surfaces,
            keys,
        }
    }

    /// The surface of pixel `index`.
    pub fn surface(&self, index: usize) -> Option<&Surface> {
        self.surfaces[index].as_ref()
    }
}

impl Surfaces for GBuffer {
    type Motion = ();

    fn width(&self) -> usize {
        self.width
    }

    fn height(&self) -> usize {
        self.height
    }

    fn has_surface(&self, index: usize) -> bool {
        self.surfaces[index].is_some()
    }

    fn similar(&self, a: usize, b: usize, rule: &Similarity) -> bool {
        let (ka, kb) = (&self.keys[a], &self.keys[b]);
        ka.hit() && kb.hit() && ka.is_similar(kb, rule)
    }

    fn previous_pixel(
        &self,
        index: usize,
        previous: &Self,
        _motion: Option<&()>,
        rule: &Similarity,
    ) -> Option<usize> {
        let (a, b) = (&self.keys[index], &previous.keys[index]);
        (a.hit() && b.hit() && a.is_similar(b, rule)).then_some(index)
    }
}

/// A point on a light: which light and where on its unit square.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    /// The light.
    pub light: u32,
    /// The point's coordinates on the light's rectangle.
    pub uv: [f32; 2],
}

/// The host's direct lighting, what ReSTIR DI asks of it.
#[derive(Clone, Copy, Debug)]
pub struct Lights<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Negative control: the sampler selects lights by power but reports the uniform
    /// selection's density (a wrong pdf, which biases the estimate).
    pub wrong_pdf: bool,
}

impl Lights<'_> {
    /// The density of drawing `x`, in area measure.
    fn pdf(&self, x: &LightPoint) -> f32 {
        let i = x.light as usize;
        let pmf = if self.wrong_pdf {
            1.0 / self.scene.lights.len() as f32
        } else {
            self.scene.light_pmf(i)
        };
        pmf / self.scene.lights[i].area()
    }

    /// Draws a light point from `rng` with its area density.
    pub fn sample(&self, rng: &mut Pcg32) -> (LightPoint, f32) {
        let light = self.scene.select_light(rng.next_f32()) as u32;
        let x = LightPoint {
            light,
            uv: [rng.next_f32(), rng.next_f32()],
        };
        (x, self.pdf(&x))
    }

    /// The unshadowed contribution of `x` to surface `s` in area measure: BSDF × radiance ×
    /// geometry term.
    pub fn unshadowed(&self, s: &Surface, x: &LightPoint) -> Vec3 {
        let light = &self.scene.lights[x.light as usize];
        let q = light.point(x.uv[0], x.uv[1]);
        let d = q - s.p;
        let dist2 = d.length_squared();
        let wi = d / dist2.sqrt();
        let (cos_s, cos_l) = (s.n.dot(wi), light.normal().dot(-wi));
        if cos_s <= 0.0 || cos_l <= 0.0 {
            return Vec3::ZERO;
        }
        s.albedo * std::f32::consts::FRAC_1_PI * light.radiance * (cos_s * cos_l / dist2)
    }

    /// Whether `x` is visible from surface `s`.
    pub fn visible_from(&self, s: &Surface, x: &LightPoint) -> bool {
        let light = &self.scene.lights[x.light as usize];
        self.scene
            .unoccluded(s.p, s.n, light.point(x.uv[0], x.uv[1]))
    }
}

/// The luminance weights of linear sRGB.
fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

impl DirectLighting for Lights<'_> {
    type Sample = LightPoint;
    type Surfaces = GBuffer;

    fn sample_light(
        &self,
        surfaces: &GBuffer,
        _index: usize,
        rng: &mut Pcg32,
    ) -> Option<(LightPoint, f32)> {
        let _ = surfaces;
        Some(self.sample(rng))
    }

    fn target(&self, surfaces: &GBuffer, index: usize, x: &LightPoint) -> f32 {
        surfaces
            .surface(index)
            .map_or(0.0, |s| luminance(self.unshadowed(s, x)))
    }

    fn contribution(&self, surfaces: &GBuffer, index: usize, x: &LightPoint) -> [f32; 3] {
        surfaces
            .surface(index)
            .map_or([0.0; 3], |s| self.unshadowed(s, x).to_array())
    }

    /// The target is the contribution's luminance: one evaluation gives both.
    fn target_and_contribution(
        &self,
        surfaces: &GBuffer,
        index: usize,
        x: &LightPoint,
    ) -> (f32, [f32; 3]) {
        surfaces.surface(index).map_or((0.0, [0.0; 3]), |s| {
            let f = self.unshadowed(s, x);
            (luminance(f), f.to_array())
        })
    }

    fn visible(&self, surfaces: &GBuffer, index: usize, x: &LightPoint) -> bool {
        surfaces
            .surface(index)
            .is_some_and(|s| self.visible_from(s, x))
    }
}

/// A rendered image: linear RGB, row-major.
#[derive(Clone, Debug)]
pub struct Image {
    /// Width.
    pub width: usize,
    /// Height.
    pub height: usize,
    /// Pixels.
    pub pixels: Vec<Vec3>,
}

impl Image {
    /// Writes a PNG (sRGB, clamped).
    pub fn write_png(&self, path: &std::path::Path) -> Result<(), image::ImageError> {
        let mut out = image::RgbImage::new(self.width as u32, self.height as u32);
        for (i, p) in self.pixels.iter().enumerate() {
            let enc = |c: f32| {
                let c = c.clamp(0.0, 1.0);
                let s = if c <= 0.003_130_8 {
                    12.92 * c
                } else {
                    1.055 * c.powf(1.0 / 2.4) - 0.055
                };
                (s * 255.0 + 0.5) as u8
            };
            out.put_pixel(
                (i % self.width) as u32,
                (i / self.width) as u32,
                image::Rgb([enc(p.x), enc(p.y), enc(p.z)]),
            );
        }
        out.save(path)
    }
}

/// ReSTIR DI's direct light: the mean of `passes` passes of `width × height` with `settings`.
pub fn render_restir(
    lights: &Lights,
    width: usize,
    height: usize,
    passes: u32,
    seed: u64,
    settings: DirectSettings,
) -> Image {
    let di = RestirDi::new(settings);
    let mut sum = vec![Vec3::ZERO; width * height];
    for pass in 0..passes {
        let streams = SeededStreams { seed, pass };
        let gbuf = GBuffer::trace(lights.scene, width, height, &streams);
        let out = di.pass(lights, gbuf, &streams);
        for (s, l) in sum.iter_mut().zip(&out.radiance) {
            *s += Vec3::from_array(*l);
        }
    }
    average(sum, width, height, passes)
}

/// The host's own direct-lighting estimator: per pixel and pass, one jittered camera ray, one
/// light sample from the same sampler ([`Lights::sample`], with the true density) and one shadow
/// ray. The mean of `passes` passes.
pub fn render_reference(
    scene: &Scene,
    width: usize,
    height: usize,
    passes: u32,
    seed: u64,
) -> Image {
    let lights = Lights {
        scene,
        wrong_pdf: false,
    };
    let sum: Vec<Vec3> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let mut sum = Vec3::ZERO;
            for pass in 0..passes {
                let streams = SeededStreams { seed, pass };
                let mut rng = streams.pixel(i, 0);
                let (fx, fy) = ((i % width) as f32, (i / width) as f32);
                let (o, d) =
                    scene.camera_ray(fx + rng.next_f32(), fy + rng.next_f32(), width, height);
                let Some(h) = scene.intersect(o, d, f32::INFINITY) else {
                    continue;
                };
                let s = Surface {
                    p: h.p,
                    n: h.n,
                    albedo: h.albedo,
                };
                let mut rng = streams.pixel(i, 1);
                let (x, pdf) = lights.sample(&mut rng);
                let f = lights.unshadowed(&s, &x);
                if f != Vec3::ZERO && lights.visible_from(&s, &x) {
                    sum += f / pdf;
                }
            }
            sum
        })
        .collect();
    average(sum, width, height, passes)
}

fn average(sum: Vec<Vec3>, width: usize, height: usize, passes: u32) -> Image {
    let k = 1.0 / passes.max(1) as f32;
    Image {
        width,
        height,
        pixels: sum.into_iter().map(|s| s * k).collect(),
    }
}
