//! Duplication-aware history confidence (`--duplication S`, off by default; biased).
//!
//! After a few spatial rounds many pixels of a neighbourhood can hold the same sample (one path
//! or light point shifted into each of them). Temporal reuse then carries that one sample
//! forward in all of them, with the full history confidence: the errors of neighbouring pixels
//! and of successive passes become correlated. NVIDIA's RTXDI (ReSTIR PT, "duplication map")
//! lowers the history's confidence cap the more the sample is duplicated: with `d` the share of
//! the neighbours holding the same sample (its "impoverishment") and strength `s`,
//!
//! ```text
//! t   = d^(0.1 · 2^(6(1 − s) − 3))
//! cap = max(1, mcap + (1 − mcap)·t)        (never above mcap)
//! ```
//!
//! so `s = 0` leaves `mcap` and larger `s` brings even a lightly duplicated history down to one
//! pass's confidence.
//!
//! **Biased.** The cap is a function of the history sample itself (whether its neighbours hold
//! the same one), so the MIS weight of the history depends on the sample it weighs, which the
//! unbiasedness argument of GRIS excludes (Lin et al. 2022, GRIS, §5). [`ReuseSettings::is_unbiased`]
//! says so, and the estimators' descriptions label it.
//!
//! [`ReuseSettings::is_unbiased`]: crate::settings::ReuseSettings::is_unbiased

use rayon::prelude::*;
use restir_gris::Reservoir;

/// The confidence cap of a history reservoir whose sample a share `impoverishment` (0 to 1) of
/// its neighbours also hold, at duplication `strength` (0 to 1) and absolute cap `mcap`.
#[inline]
pub fn cap(impoverishment: f32, strength: f32, mcap: f32) -> f32 {
    if !(impoverishment > 0.0 && strength > 0.0) {
        return mcap;
    }
    let d = impoverishment.min(1.0);
    let s = strength.min(1.0);
    let t = d.powf(0.1 * (6.0 * (1.0 - s) - 3.0).exp2());
    (mcap + (1.0 - mcap) * t).max(1.0).min(mcap)
}

/// Every pixel's history confidence cap ([`cap`]): the share of the other pixels with a sample
/// within `radius` pixels (a square window, clipped at the image's edges) whose sample is the
/// same as the pixel's (`same`). Pixels without a sample get `mcap`.
pub fn history_caps<S: Sync>(
    reservoirs: &[Reservoir<S>],
    width: usize,
    radius: usize,
    strength: f32,
    mcap: f32,
    same: impl Fn(&S, &S) -> bool + Sync,
) -> Vec<f32> {
    let height = reservoirs.len().checked_div(width).unwrap_or(0);
    (0..reservoirs.len())
        .into_par_iter()
        .map(|index| {
            let Some(sample) = reservoirs[index].sample() else {
                return mcap;
            };
            let (x, y) = (index % width, index / width);
            let (mut others, mut duplicates) = (0u32, 0u32);
            for ny in y.saturating_sub(radius)..(y + radius + 1).min(height) {
                let row = &reservoirs[ny * width..(ny + 1) * width];
                for (nx, r) in row
                    .iter()
                    .enumerate()
                    .take((x + radius + 1).min(width))
                    .skip(x.saturating_sub(radius))
                {
                    if (nx, ny) == (x, y) {
                        continue;
                    }
                    if let Some(other) = r.sample() {
                        others += 1;
                        duplicates += u32::from(same(sample, other));
                    }
                }
            }
            if others == 0 {
                return mcap;
            }
            cap(duplicates as f32 / others as f32, strength, mcap)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_follows_the_strength() {
        // No duplicates or no strength: the absolute cap.
        assert_eq!(cap(0.0, 0.8, 20.0), 20.0);
        assert_eq!(cap(0.5, 0.0, 20.0), 20.0);
        assert_eq!(cap(f32::NAN, 0.8, 20.0), 20.0);
        // Every neighbour the same: one pass's confidence.
        assert_eq!(cap(1.0, 0.8, 20.0), 1.0);
        // Strength 0.5: exponent 0.1·2^0 = 0.1; d = 0.01 gives t = 0.631.
        let t = 0.01f32.powf(0.1);
        assert!((cap(0.01, 0.5, 20.0) - (20.0 - 19.0 * t)).abs() < 1e-4);
        // Stronger duplication handling caps lower, more duplicates cap lower.
        assert!(cap(0.01, 0.9, 20.0) < cap(0.01, 0.5, 20.0));
        assert!(cap(0.1, 0.5, 20.0) < cap(0.01, 0.5, 20.0));
        // Never above the absolute cap, never below 1 (unless the cap is).
        assert_eq!(cap(0.5, 1.0, 0.5), 0.5);
    }

    #[test]
    fn counts_duplicates_in_the_window() {
        // 4×3 image: samples 7 in a 2×2 block at the top left, others distinct, one empty.
        let ids = [7, 7, 1, 2, 7, 7, 3, 4, 5, 6, 0, 8];
        let res: Vec<Reservoir<u32>> = ids
            .iter()
            .map(|&id| {
                if id == 0 {
                    Reservoir::empty()
                } else {
                    Reservoir::from_source_sample(id, 1.0, 1.0)
                }
            })
            .collect();
        let caps = history_caps(&res, 4, 1, 0.5, 20.0, |a, b| a == b);
        // Pixel 0: neighbours 1, 4, 5 all hold 7: share 1 → cap 1.
        assert_eq!(caps[0], 1.0);
        // Pixel 5: 8 neighbours (0,1,2,4,6,8,9; 10 empty): 7 others, 3 duplicates.
        assert!((caps[5] - cap(3.0 / 7.0, 0.5, 20.0)).abs() < 1e-6);
        // Distinct samples and the empty pixel keep the cap.
        assert_eq!(caps[3], 20.0);
        assert_eq!(caps[10], 20.0);
    }
}
