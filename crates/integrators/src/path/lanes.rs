//! The path tracer over eight paths at once ([`trace_camera_paths`]): the estimator of
//! [`super::trace_path`], each lane one pixel's path with that pixel's numbers drawn in the same
//! order, so that lane `i` follows the path the scalar walk would (to within the rounding of
//! [`lanes::sample_cosine_hemisphere`]'s sine and cosine).
//!
//! What every lane does alike runs in lanes: the shading frame's changes of basis, the diffuse
//! model's value, density and cosine-weighted sampling, the power heuristic, the throughput and
//! Russian roulette. What differs per lane stays scalar, one lane after the other: traversal,
//! the surface data of a hit, light sampling, shadow rays, emission, and every material but a
//! plain diffuse one (its lanes call the general [`Bsdf`] methods and write their results
//! into the lanes).

use glam::Vec3;
use restir_geometry::{Ray, SurfaceInteraction, offset_ray_origin};
use restir_lights::LightSample;
use restir_materials::{Bsdf, BsdfKind};
use restir_sampling::Sampler;
use restir_sampling::lanes::{self, F8, LANES, M8, V3};
use restir_scene::Scene;

use super::{EmissionMis, PathSettings, PrevVertex, rr_survival};
use crate::shadow::{ShadowTarget, visible};

const FRAC_1_PI: f32 = core::f32::consts::FRAC_1_PI;

/// A lane's material at a vertex.
#[derive(Clone, Copy)]
enum Material {
    /// Mitsuba's `diffuse` with nothing around it (no mask, no normal map): computed in lanes.
    Diffuse { two_sided: bool },
    /// Anything else: the general methods, one lane at a time.
    General(Bsdf),
}

impl Material {
    #[inline(always)]
    fn of(bsdf: Bsdf) -> (Self, Vec3) {
        match bsdf.kind {
            BsdfKind::Diffuse { reflectance }
                if !bsdf.is_masked() && bsdf.normal_map.is_none() =>
            {
                (
                    Material::Diffuse {
                        two_sided: bsdf.two_sided,
                    },
                    reflectance,
                )
            }
            _ => (Material::General(bsdf), Vec3::ZERO),
        }
    }
}

/// Lanes where `pdf_a` wins by the power heuristic against `pdf_b`
/// ([`restir_sampling::warp::power_heuristic`] in every lane).
#[inline(always)]
fn power_heuristic(pdf_a: F8, pdf_b: F8) -> F8 {
    let (a2, b2) = (pdf_a * pdf_a, pdf_b * pdf_b);
    let w = a2 / (a2 + b2);
    let w = w.is_finite().select(w, F8::splat(0.0));
    pdf_a.is_infinite().select(F8::splat(1.0), w)
}

/// `v` in the frame `(s, t, n)` of every lane ([`restir_geometry::Frame::to_local`]).
#[inline(always)]
fn to_local(v: V3, s: V3, t: V3, n: V3) -> V3 {
    V3 {
        x: v.dot(s),
        y: v.dot(t),
        z: v.dot(n),
    }
}

/// Radiance along the camera rays `rays` (one a lane, at most [`LANES`]), each estimated with one
/// path drawing its numbers from the same lane of `rngs`: [`super::trace_path`] from depth 0, lane
/// by lane. Writes the estimates to `out` and returns the number of rays traced.
#[inline(always)]
pub(crate) fn trace_camera_paths<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    rays: &[Ray],
    rngs: &mut [S],
    out: &mut [Vec3],
) -> u64 {
    let n = rays.len();
    debug_assert!(n <= LANES && rngs.len() == n && out.len() == n);
    let mut traced = 0u64;
    let max_depth = settings.max_segments();
    if max_depth == 0 {
        out.fill(Vec3::ZERO);
        return 0;
    }
    let lights = &scene.lights;
    let has_env = scene.features.has_environment;
    let mut ray: [Ray; LANES] = core::array::from_fn(|i| rays[i.min(n - 1)]);
    let mut active = M8(core::array::from_fn(|i| i < n));
    let mut beta = V3::splat(Vec3::ONE);
    let mut radiance = V3::ZERO;
    let mut eta_scale = F8::splat(1.0);
    let mut prev: [Option<PrevVertex>; LANES] = [None; LANES];
    let mut si: [Option<SurfaceInteraction>; LANES] = [None; LANES];
    let mut depth = 0u32;
    loop {
        // The hits and what they emit, lane by lane.
        let hide = depth == 0 && settings.hide_emitters;
        for i in 0..n {
            si[i] = None;
            if !active.0[i] {
                continue;
            }
            let r = &ray[i];
            let (hit, k) = scene.camera_intersect(r, hide);
            traced += k;
            let mut add = Vec3::ZERO;
            match hit {
                None => {
                    active.0[i] = false;
                    if has_env && !hide {
                        let le = lights.environment_radiance(r.d);
                        let w = match prev[i] {
                            Some(pv) if !pv.delta => {
                                let env = lights
                                    .environment()
                                    .expect("feature summary says there is one");
                                let em_pdf =
                                    pv.light_pdf(lights, settings.nee, (env, 0), pv.p + r.d, -r.d);
                                pv.emission_weight(em_pdf)
                            }
                            _ => 1.0,
                        };
                        add = beta.get(i) * le * w;
                    }
                }
                Some(s) => {
                    if let Some(light) = lights.light_on_shape(s.shape)
                        && !hide
                    {
                        let le = lights.area_radiance(light, &s, -r.d);
                        if le != Vec3::ZERO {
                            let w = match prev[i] {
                                Some(pv) if !pv.delta => {
                                    let em_pdf = pv.light_pdf(
                                        lights,
                                        settings.nee,
                                        (light, s.prim),
                                        s.p,
                                        s.ng,
                                    );
                                    pv.emission_weight(em_pdf)
                                }
                                _ => 1.0,
                            };
                            add = beta.get(i) * le * w;
                        }
                    }
                    si[i] = Some(s);
                }
            }
            if add != Vec3::ZERO {
                radiance.set(i, radiance.get(i) + add);
            }
        }
        if !active.any() || depth + 1 >= max_depth {
            break;
        }

        // The fixed per-bounce budget of numbers, the surfaces and their materials.
        let mut u = [[0.0f32; 7]; LANES];
        let mut mat = [Material::Diffuse { two_sided: false }; LANES];
        let (mut p, mut ng) = (V3::ZERO, V3::ZERO);
        let (mut fs, mut ft, mut fn_) = (V3::ZERO, V3::ZERO, V3::ZERO);
        let mut albedo = V3::ZERO;
        let mut d = V3::ZERO;
        for i in 0..n {
            let Some(s) = &si[i] else { continue };
            let rng = &mut rngs[i];
            let u_select = rng.next_1d();
            let u_light = rng.next_2d();
            let u_lobe = rng.next_1d();
            let u_bsdf = rng.next_2d();
            let u_rr = rng.next_1d();
            u[i] = [
                u_select, u_light.x, u_light.y, u_lobe, u_bsdf.x, u_bsdf.y, u_rr,
            ];
            let (m, a) = Material::of(scene.bsdf(s));
            mat[i] = m;
            albedo.set(i, a);
            p.set(i, s.p);
            ng.set(i, s.ng);
            fs.set(i, s.shading.s);
            ft.set(i, s.shading.t);
            fn_.set(i, s.shading.n);
            d.set(i, ray[i].d);
        }
        let lane = |k: usize| F8::from_fn(|i| u[i][k]);
        let wo = to_local(-d, fs, ft, fn_);
        // Two-sided diffuse seen from behind: mirrored to the front.
        let flip = M8(core::array::from_fn(|i| {
            matches!(mat[i], Material::Diffuse { two_sided: true })
        })) & wo.z.lt(F8::splat(0.0));
        let vz = flip.select(-wo.z, wo.z);
        let zero = F8::splat(0.0);
        let front = vz.gt(zero);

        // Next-event estimation: the light sample lane by lane, the material's value and
        // density in lanes for the diffuse lanes.
        let mut ls: [Option<LightSample>; LANES] = [None; LANES];
        let (mut l_wi, mut l_le) = (V3::ZERO, V3::ZERO);
        let (mut l_pdf, mut l_delta) = (F8::splat(1.0), M8::default());
        let (mut g_f, mut g_pdf) = (V3::ZERO, zero);
        for i in 0..n {
            let Some(s) = &si[i] else { continue };
            let smooth = match &mat[i] {
                Material::Diffuse { .. } => true,
                Material::General(b) => b.has_smooth_lobe(),
            };
            if !smooth {
                continue;
            }
            let Some(l) = lights.sample_nee(
                settings.nee,
                s.p,
                s.shading.n,
                (u[i][0], u[i][6]),
                glam::Vec2::new(u[i][1], u[i][2]),
            ) else {
                continue;
            };
            l_wi.set(i, l.wi);
            l_le.set(i, l.le);
            l_pdf.0[i] = l.pdf_sa;
            l_delta.0[i] = l.delta;
            ls[i] = Some(l);
            if let Material::General(b) = &mat[i] {
                let (wo_i, wi_i) = (s.shading.to_local(-ray[i].d), s.shading.to_local(l.wi));
                g_f.set(i, b.eval(wo_i, wi_i));
                g_pdf.0[i] = b.pdf_sa(wo_i, wi_i);
            }
        }
        let wi = to_local(l_wi, fs, ft, fn_);
        let lz = flip.select(-wi.z, wi.z);
        let reach = front & lz.gt(zero);
        let diffuse = M8(core::array::from_fn(|i| {
            matches!(mat[i], Material::Diffuse { .. })
        }));
        let f = diffuse.select3(
            reach.select3(albedo.scale(F8::splat(FRAC_1_PI) * lz), V3::ZERO),
            g_f,
        );
        let b_pdf = diffuse.select(reach.select(lz * FRAC_1_PI, zero), g_pdf);
        let w = l_delta.select(F8::splat(1.0), power_heuristic(l_pdf, b_pdf));
        let direct = (beta * f * l_le).scale(w / l_pdf);
        for i in 0..n {
            let (Some(l), Some(s)) = (&ls[i], &si[i]) else {
                continue;
            };
            if f.get(i) == Vec3::ZERO {
                continue;
            }
            traced += 1;
            if visible(scene, s.p, s.ng, ShadowTarget::of_sample(l)) {
                radiance.set(i, radiance.get(i) + direct.get(i));
            }
        }

        // The continuation: cosine-weighted in lanes for the diffuse lanes.
        let cos = lanes::sample_cosine_hemisphere(lane(4), lane(5));
        let pdf_c = cos.z.gt(zero).select(cos.z * FRAC_1_PI, zero);
        let f_c = albedo.scale(F8::splat(FRAC_1_PI) * cos.z);
        let valid_c = front
            & pdf_c.gt(zero)
            & pdf_c.is_finite()
            & f_c.is_finite()
            & cos.is_finite();
        let mut b_wi = V3 {
            x: cos.x,
            y: cos.y,
            z: flip.select(-cos.z, cos.z),
        };
        let mut b_weight = f_c / pdf_c;
        let mut b_pdf = pdf_c;
        let mut b_eta = F8::splat(1.0);
        let mut ok = valid_c;
        let mut delta = M8::default();
        for i in 0..n {
            if si[i].is_none() {
                ok.0[i] = false;
                continue;
            }
            let Material::General(b) = &mat[i] else {
                continue;
            };
            let s = si[i].as_ref().expect("checked above");
            let wo_i = s.shading.to_local(-ray[i].d);
            match b.sample(wo_i, u[i][3], glam::Vec2::new(u[i][4], u[i][5])) {
                None => ok.0[i] = false,
                Some(bs) => {
                    ok.0[i] = true;
                    b_wi.set(i, bs.wi);
                    b_weight.set(i, bs.f / bs.pdf_sa);
                    b_pdf.0[i] = bs.pdf_sa;
                    b_eta.0[i] = bs.eta;
                    delta.0[i] = bs.lobe.is_delta();
                }
            }
        }
        active = active & ok;
        beta = beta * b_weight;
        eta_scale = eta_scale * b_eta;
        let dir = fs.scale(b_wi.x) + ft.scale(b_wi.y) + fn_.scale(b_wi.z);
        for i in 0..n {
            if !active.0[i] {
                continue;
            }
            let (pi, ngi, di) = (p.get(i), ng.get(i), dir.get(i));
            prev[i] = Some(PrevVertex {
                p: pi,
                n: fn_.get(i),
                pdf_sa: b_pdf.0[i],
                delta: delta.0[i],
                mis: EmissionMis::Power,
            });
            ray[i] = Ray::new(offset_ray_origin(pi, ngi, di), di);
        }
        depth += 1;

        // Russian roulette.
        let bmax = beta.max_element();
        active = active & bmax.gt(zero) & beta.is_finite();
        if depth >= settings.rr_depth {
            let q = F8::from_fn(|i| rr_survival(bmax.0[i], eta_scale.0[i]));
            active = active & lane(6).lt(q);
            beta = beta / q;
        }
        if !active.any() {
            break;
        }
    }
    for (i, o) in out.iter_mut().enumerate() {
        *o = radiance.get(i);
    }
    traced
}

/// The path tracer's estimates for the pixels `first..first + out.len()` of a film `width`
/// pixels wide, added to `out`, eight pixels at a time: `start` gives a pixel's numbers and its
/// film position (the caller's pixel sampler). Returns the rays traced. Runs with AVX2 and FMA
/// where the CPU has them (the same bits as without).
pub(crate) fn render_pixels<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    width: usize,
    first: usize,
    out: &mut [glam::DVec3],
    start: impl Fn(usize, (u32, u32)) -> (S, glam::Vec2),
) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU reported AVX2 and FMA, the features the function is compiled with.
        #[allow(unsafe_code)]
        return unsafe { render_pixels_avx2(scene, settings, width, first, out, start) };
    }
    render_pixels_with(scene, settings, width, first, out, start)
}

/// [`render_pixels`] compiled for AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[allow(unsafe_code)]
unsafe fn render_pixels_avx2<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    width: usize,
    first: usize,
    out: &mut [glam::DVec3],
    start: impl Fn(usize, (u32, u32)) -> (S, glam::Vec2),
) -> u64 {
    render_pixels_with(scene, settings, width, first, out, start)
}

#[inline(always)]
fn render_pixels_with<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    width: usize,
    first: usize,
    out: &mut [glam::DVec3],
    start: impl Fn(usize, (u32, u32)) -> (S, glam::Vec2),
) -> u64 {
    let mut traced = 0;
    for (g, group) in out.chunks_mut(LANES).enumerate() {
        let base = first + g * LANES;
        let n = group.len();
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); LANES];
        // Lanes past the end of a short group repeat its last pixel and are not traced.
        let mut rngs: [S; LANES] = core::array::from_fn(|i| {
            let index = base + i.min(n - 1);
            let (mut rng, film) = start(index, ((index % width) as u32, (index / width) as u32));
            // The lens sample comes first, as in `trace_camera_path`.
            let u_lens = rng.next_2d();
            rays[i] = scene.camera.generate_ray(film, u_lens);
            rng
        });
        let mut est = [Vec3::ZERO; LANES];
        traced += trace_camera_paths(scene, settings, &rays[..n], &mut rngs[..n], &mut est[..n]);
        for (o, e) in group.iter_mut().zip(est) {
            *o += e.as_dvec3();
        }
    }
    traced
}
