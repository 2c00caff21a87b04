//! Where ReSTIR PT's brightest pixels come from: a diagnostic that, when the environment variable
//! `RESTIR_PT_DIAG` names a file, records for every pixel the pass whose shaded reservoir was
//! brightest and how that path got there, and rewrites the file as CSV after every pass.
//! Nothing is recorded, copied or checked per pixel when the variable is unset (the integrator
//! holds `None`).
//!
//! Per pixel: the passes, the mean and the largest luminance of the reservoir's shaded value
//! (`value · W`, the part of the pixel ReSTIR PT adds), in how many passes the camera ray saw
//! an emitter (a pixel that sees one in some passes only is on its silhouette) and the mean
//! luminance of what it saw, and for the brightest pass
//!
//! * the shift that moves the path (`reconnection` for `k = 2`, `hybrid` for `k ≥ 3`, `replay`
//!   for a path without a reconnection vertex), its kind, `k` and length;
//! * the pixel whose initial sampling found it (searched among this pass's initial reservoirs
//!   within the reach of the spatial rounds, by walk seed, kind and length): its offset, 0 0 for
//!   the pixel itself; and the Jacobian of the whole chain of shifts that brought it,
//!   `G_here / G_origin` (1 for point lights and directions);
//! * for `k = 2`, the reconnection distance over the scene radius and `|cos θ|` at `x2`;
//! * for paths that end at `x_k` on an area light, the lamp's size, `sqrt(area)` over the
//!   scene radius (0 for a point light, infinite for the environment);
//! * its unbiased contribution weight `W`, target `p̂` and the shaded luminance of the same
//!   path in the pixel that found it (`value · W` of its initial reservoir).
//!
//! `cargo run --release -p restir-evaluation --example pt_concentration` classifies the pixels
//! holding the top 1 % of the squared error from this file, the image and a reference.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Mutex;

use glam::Vec3;
use restir_lights::Light;
use restir_sampling::luminance;
use restir_scene::Scene;

use super::PtReservoir;
use super::sample::{Kind, PathSample, resolve_vertex};
use crate::reuse::gbuffer::GBuffer;

/// The environment variable naming the CSV file.
pub const DIAG_VAR: &str = "RESTIR_PT_DIAG";

/// How the brightest pass's path reached a pixel.
#[derive(Clone, Copy, Debug)]
struct Record {
    pass: u32,
    kind: Kind,
    rc: u8,
    length: u8,
    origin: Option<(i32, i32)>,
    jacobian: f32,
    distance: f32,
    cos: f32,
    lamp: f32,
    ucw: f32,
    target: f32,
    origin_value: f32,
}

#[derive(Clone, Copy, Debug, Default)]
struct PixelDiag {
    passes: u32,
    sum: f64,
    max: f32,
    seen_passes: u32,
    seen_sum: f64,
    record: Option<Record>,
}

/// The diagnostic's state: one record per pixel and the file it is written to.
#[derive(Debug)]
pub(super) struct Diag {
    path: PathBuf,
    state: Mutex<(u32, Vec<PixelDiag>)>,
}

impl Diag {
    /// The diagnostic when [`DIAG_VAR`] is set.
    pub(super) fn from_env() -> Option<Self> {
        let path = std::env::var_os(DIAG_VAR)?;
        Some(Self {
            path: path.into(),
            state: Mutex::new((0, Vec::new())),
        })
    }

    /// Notes what the G-buffer's camera rays saw directly this pass (`seen`, before anything
    /// else is added and before the silhouettes' extra camera rays).
    pub(super) fn seen(&self, seen: &[Vec3]) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        let pixels = &mut state.1;
        if pixels.len() != seen.len() {
            *pixels = vec![PixelDiag::default(); seen.len()];
        }
        for (px, l) in pixels.iter_mut().zip(seen) {
            let l = luminance(*l);
            if l > 0.0 && l.is_finite() {
                px.seen_passes += 1;
                px.seen_sum += f64::from(l);
            }
        }
    }

    /// Records one pass: `initial` the reservoirs after initial sampling, `last` after reuse,
    /// `reach` the farthest (Chebyshev) distance in pixels a path can have moved.
    pub(super) fn record(
        &self,
        scene: &Scene,
        gbuf: &GBuffer,
        initial: &[PtReservoir],
        last: &[PtReservoir],
        reach: i32,
    ) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        let (pass, pixels) = &mut *state;
        if pixels.len() != last.len() {
            *pixels = vec![PixelDiag::default(); last.len()];
        }
        let (w, h) = (gbuf.width as i32, (last.len() / gbuf.width.max(1)) as i32);
        let radius = scene.lights.scene_radius();
        for (i, (px, res)) in pixels.iter_mut().zip(last).enumerate() {
            px.passes += 1;
            let Some(s) = res.sample.as_ref() else {
                continue;
            };
            let c = luminance(s.value * res.ucw);
            if !c.is_finite() {
                continue;
            }
            px.sum += f64::from(c);
            if c <= px.max {
                continue;
            }
            px.max = c;
            let (x, y) = ((i as i32) % w, (i as i32) / w);
            let origin = find_origin(initial, s, x, y, w, h, reach);
            let origin_sample = origin.and_then(|(dx, dy)| {
                let j = ((y + dy) * w + x + dx) as usize;
                initial[j].sample.as_ref().map(|o| (o, initial[j].ucw))
            });
            let jacobian = match origin_sample {
                Some((o, _)) if s.geometry > 0.0 && o.geometry > 0.0 => s.geometry / o.geometry,
                Some(_) if s.kind != Kind::Frozen && s.geometry == 0.0 => 1.0,
                Some(_) if s.kind == Kind::Frozen => 1.0,
                _ => f32::NAN,
            };
            let (distance, cos) = match (s.rc, gbuf.receiver(i)) {
                (2, Some(r)) if s.kind != Kind::Frozen => {
                    match resolve_vertex(scene, s).area_point() {
                        Some((p, n)) => {
                            let to = p - r.p;
                            let d = to.length();
                            (d / radius, (n.dot(to) / d).abs())
                        }
                        None => (f32::INFINITY, 1.0),
                    }
                }
                _ => (f32::NAN, f32::NAN),
            };
            px.record = Some(Record {
                pass: *pass,
                kind: s.kind,
                rc: s.rc,
                length: s.length,
                origin,
                jacobian,
                distance,
                cos,
                lamp: lamp_size(scene, s, radius),
                ucw: res.ucw,
                target: luminance(s.value),
                origin_value: origin_sample.map_or(f32::NAN, |(o, ucw)| luminance(o.value * ucw)),
            });
        }
        *pass += 1;
        let text = csv(pixels, w);
        if let Err(e) = std::fs::write(&self.path, text) {
            eprintln!("{DIAG_VAR}: cannot write {}: {e}", self.path.display());
        }
    }
}

/// The nearest pixel within `reach` of `(x, y)` whose initial reservoir holds the path of `s`.
fn find_origin(
    initial: &[PtReservoir],
    s: &PathSample,
    x: i32,
    y: i32,
    w: i32,
    h: i32,
    reach: i32,
) -> Option<(i32, i32)> {
    let mut best: Option<(i32, i32)> = None;
    for dy in -reach..=reach {
        for dx in -reach..=reach {
            let (qx, qy) = (x + dx, y + dy);
            if qx < 0 || qy < 0 || qx >= w || qy >= h {
                continue;
            }
            let Some(o) = initial[(qy * w + qx) as usize].sample.as_ref() else {
                continue;
            };
            if o.seed == s.seed
                && o.kind == s.kind
                && o.length == s.length
                && best.is_none_or(|(bx, by)| dx * dx + dy * dy < bx * bx + by * by)
            {
                best = Some((dx, dy));
            }
        }
    }
    best
}

/// `sqrt(area) / radius` of the light a direct path ends on (0 for a point light, infinite for
/// lights at infinity), NaN when the path continues past `x_k`.
fn lamp_size(scene: &Scene, s: &PathSample, radius: f32) -> f32 {
    if !s.is_direct() {
        return f32::NAN;
    }
    match scene.lights.lights().get(s.id as usize) {
        Some(Light::Area { shape, .. }) => scene
            .shapes
            .get(*shape as usize)
            .map_or(f32::NAN, |sh| sh.area().sqrt() / radius),
        Some(Light::Point { .. } | Light::Spot(_) | Light::Projector(_)) => 0.0,
        Some(_) => f32::INFINITY,
        None => f32::NAN,
    }
}

fn shift_name(r: &Record) -> &'static str {
    match (r.kind, r.rc) {
        (Kind::Frozen, _) => "replay",
        (_, 2) => "reconnection",
        _ => "hybrid",
    }
}

/// The CSV text.
fn csv(pixels: &[PixelDiag], w: i32) -> String {
    let mut s = String::from(
        "x,y,passes,seen_passes,seen_mean,mean,max,pass,shift,kind,rc,length,origin_dx,origin_dy,jacobian,distance,cos,lamp,ucw,target,origin_value\n",
    );
    for (i, p) in pixels.iter().enumerate() {
        let (x, y) = ((i as i32) % w, (i as i32) / w);
        let mean = p.sum / f64::from(p.passes.max(1));
        let seen = p.seen_sum / f64::from(p.passes.max(1));
        let _ = write!(
            s,
            "{x},{y},{},{},{seen:e},{mean:e},{:e},",
            p.passes, p.seen_passes, p.max
        );
        match &p.record {
            Some(r) => {
                let (dx, dy) = r.origin.map_or((String::new(), String::new()), |(a, b)| {
                    (a.to_string(), b.to_string())
                });
                let _ = writeln!(
                    s,
                    "{},{},{:?},{},{},{dx},{dy},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                    r.pass,
                    shift_name(r),
                    r.kind,
                    r.rc,
                    r.length,
                    r.jacobian,
                    r.distance,
                    r.cos,
                    r.lamp,
                    r.ucw,
                    r.target,
                    r.origin_value
                );
            }
            None => s.push_str(",,,,,,,,,,,,,\n"),
        }
    }
    s
}
