//! The garlands of the hall: the strands they hang on and their emissive meshes.

use glam::Vec3;
use restir_sampling::Pcg32;

use super::{GARLANDS, HALL_POWER, LOWEST, Layout};
use crate::garlands::{Strand, Style, garland, obj};
use crate::util::{hue_colour, round, uniform};
use crate::{Asset, AssetContents, DiOptions};
use restir_scene::{GeometryDesc, ShapeDesc};

/// The strands garlands hang on: along each colonnade between neighbouring pillars, across the
/// nave beside each row, and diagonally across each bay.
pub(super) fn strands(rng: &mut Pcg32, l: &Layout) -> Vec<Strand> {
    let mut strands = Vec::new();
    let hang = |rng: &mut Pcg32| uniform(rng, 0.6, 0.85) * l.h;
    let off = l.half * 1.2;
    // Sag 5–15 % of the span, 0.2–1 m, keeping the lowest point at least LOWEST up.
    let sag = |rng: &mut Pcg32, a: Vec3, b: Vec3| {
        (uniform(rng, 0.05, 0.15) * (b - a).length())
            .clamp(0.2, 1.0)
            .min((a.y.min(b.y) - LOWEST).max(0.1))
    };
    for pair in l.rows.windows(2) {
        for side in [-1.0, 1.0] {
            let a = Vec3::new(side * l.xc, hang(rng), pair[0] + off);
            let b = Vec3::new(side * l.xc, hang(rng), pair[1] - off);
            let s = sag(rng, a, b);
            strands.push(Strand { a, b, sag: s });
        }
        let flip = if rng.next_bounded(2) == 0 { -1.0 } else { 1.0 };
        let (a, b) = (
            Vec3::new(-flip * l.xc, hang(rng), pair[0]),
            Vec3::new(flip * l.xc, hang(rng), pair[1]),
        );
        let d = (b - a).with_y(0.0).normalize();
        let (a, b) = (a + off * 1.2 * d, b - off * 1.2 * d);
        let s = sag(rng, a, b);
        strands.push(Strand { a, b, sag: s });
    }
    for &z in &l.rows {
        let side = if rng.next_bounded(2) == 0 { -1.0 } else { 1.0 };
        let z = z + side * (l.half + 0.15);
        let a = Vec3::new(-l.xc + off, hang(rng), z);
        let b = Vec3::new(l.xc - off, hang(rng), z);
        let s = sag(rng, a, b);
        strands.push(Strand { a, b, sag: s });
    }
    strands
}

/// The garlands on `strands`: meshes, their OBJ assets, and how many.
pub(super) fn lights(
    seed: u64,
    options: &DiOptions,
    strands: &[Strand],
) -> (Vec<ShapeDesc>, Vec<Asset>, u32) {
    let mut rng = Pcg32::new(seed, 0x6761_726c); // "garl"
    let n = options.lights;
    let wanted = GARLANDS.0 + rng.next_bounded(GARLANDS.1 - GARLANDS.0 + 1);
    let garlands = wanted.min(n / 24).max(1);
    let mut levels: Vec<f32> = (0..garlands)
        .map(|i| {
            let t = i as f32 / (garlands - 1).max(1) as f32;
            options.power_ratio.powf(t.powf(2.5))
        })
        .collect();
    for i in (1..levels.len()).rev() {
        levels.swap(i, rng.next_bounded(i as u32 + 1) as usize);
    }
    let mut assets = Vec::new();
    let mut parts = Vec::new();
    for i in 0..garlands {
        let count = n / garlands + u32::from(i < n % garlands);
        let mut strand = strands[i as usize % strands.len()];
        // Further rounds on the same strands hang beside the first, 0.3 m apart.
        let round_no = i as usize / strands.len();
        if round_no > 0 {
            let along = (strand.b - strand.a).with_y(0.0).normalize_or(Vec3::X);
            let across = along.cross(Vec3::Y);
            let shift = 0.3
                * round_no as f32
                * if round_no.is_multiple_of(2) {
                    1.0
                } else {
                    -1.0
                };
            strand.a += shift * across;
            strand.b += shift * across;
        }
        let style =
            [Style::Bulbs, Style::Bulbs, Style::Rope, Style::Strip][rng.next_bounded(4) as usize];
        let (p, t, area) = garland(&mut rng, style, &strand, count as usize);
        let warm = rng.next_bounded(3) != 0;
        let tint = if warm {
            hue_colour(uniform(&mut rng, 0.05, 0.12), uniform(&mut rng, 0.1, 0.4))
        } else {
            hue_colour(rng.next_f32(), uniform(&mut rng, 0.4, 0.8))
        };
        let filename = format!("hall-s{seed}-n{n}-{i}-{}.obj", style.name());
        assets.push(Asset {
            filename: filename.clone(),
            contents: AssetContents::Text(obj(style.name(), &p, &t)),
        });
        parts.push((filename, levels[i as usize], tint, area));
    }
    let power: f64 = parts.iter().map(|p| p.1 as f64 * p.3 as f64).sum();
    let scale = (HALL_POWER as f64 / (core::f64::consts::PI * power.max(1e-30))) as f32;
    let shapes = parts
        .into_iter()
        .map(|(filename, level, tint, _)| {
            crate::util::emitter(
                GeometryDesc::Obj { filename },
                Vec::new(),
                tint.map(|c| round(c * level * scale, 4)),
            )
        })
        .collect();
    (shapes, assets, garlands)
}
