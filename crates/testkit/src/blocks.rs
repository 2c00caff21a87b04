//! Block statistics for comparing estimators of the same image: the mean of each `block × block`
//! block of a render ([`block_means`]), the mean and standard error of every block over
//! independent renders ([`block_statistics`]), and the largest difference between two such sets
//! in standard errors ([`max_z`]).
//!
//! Images are passed as `(width, height, pixels)` with pixels row-major from the top left, so the
//! kit needs no renderer types.

use glam::Vec3;

/// Mean RGB-average of each `block`×`block` block of the `width × height` image `pixels`
/// (row-major blocks; a partial block at the right or bottom edge is left out).
pub fn block_means(width: u32, height: u32, pixels: &[Vec3], block: u32) -> Vec<f64> {
    let (bx, by) = (width / block, height / block);
    let mut out = vec![0.0; (bx * by) as usize];
    for y in 0..by * block {
        for x in 0..bx * block {
            let p = pixels[(y * width + x) as usize];
            out[((y / block) * bx + x / block) as usize] +=
                f64::from(p.x + p.y + p.z) / 3.0 / f64::from(block * block);
        }
    }
    out
}

/// Per block: mean and standard error of the mean over `seeds` independent renders with seeds
/// `seed_base`, `seed_base + 1`, …; `block_means_of(seed)` renders one and returns its
/// [`block_means`].
pub fn block_statistics(
    block_means_of: impl Fn(u64) -> Vec<f64>,
    seeds: u64,
    seed_base: u64,
) -> Vec<(f64, f64)> {
    let samples: Vec<Vec<f64>> = (0..seeds).map(|s| block_means_of(seed_base + s)).collect();
    let n = seeds as f64;
    (0..samples[0].len())
        .map(|b| {
            let mean = samples.iter().map(|v| v[b]).sum::<f64>() / n;
            let var = samples.iter().map(|v| (v[b] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, (var / n).sqrt())
        })
        .collect()
}

/// The largest |z| over blocks between two sets of block statistics.
pub fn max_z(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(&(ma, sa), &(mb, sb))| (ma - mb).abs() / (sa * sa + sb * sb).sqrt().max(1e-12))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn means_of_blocks() {
        // 5×2 image, blocks of 2: two full blocks, the last column left out.
        let pixels: Vec<Vec3> = (0..10).map(|i| Vec3::splat(i as f32)).collect();
        let m = block_means(5, 2, &pixels, 2);
        assert_eq!(
            m,
            vec![(0.0 + 1.0 + 5.0 + 6.0) / 4.0, (2.0 + 3.0 + 7.0 + 8.0) / 4.0]
        );
    }

    #[test]
    fn statistics_and_z() {
        let stats = block_statistics(|s| vec![s as f64, 1.0], 3, 10);
        assert_eq!(stats[0], (11.0, (1.0f64 / 3.0).sqrt()));
        assert_eq!(stats[1], (1.0, 0.0));
        let z = max_z(
            &stats,
            &[
                (11.0 + (2.0f64 / 3.0).sqrt(), (1.0f64 / 3.0).sqrt()),
                (1.0, 0.0),
            ],
        );
        assert!((z - 1.0).abs() < 1e-12);
    }
}
