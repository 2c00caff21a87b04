//! Discrete and piecewise-constant distributions.

/// A piecewise-constant density on `[0, 1)` over `n` equal bins, also usable as a discrete
/// distribution over the bins. Built with an f64 prefix sum so that long tables stay accurate.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    /// Builds from non-negative bin values. Returns `None` when the input is empty, has a negative
    /// or non-finite value, or sums to zero: such a distribution cannot be sampled.
    pub fn new(func: &[f32]) -> Option<Self> {
        if func.is_empty() || func.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return None;
        }
        let n = func.len();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0f32);
        let mut running = 0.0f64;
        for v in func {
            running += *v as f64;
            cdf.push(running as f32);
        }
        if running <= 0.0 || !running.is_finite() {
            return None;
        }
        let sum = running;
        for c in cdf.iter_mut() {
            *c = (*c as f64 / sum) as f32;
        }
        cdf[n] = 1.0;
        Some(Self {
            func: func.to_vec(),
            cdf,
            integral: (sum / n as f64) as f32,
        })
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Always false: empty distributions cannot be built.
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// The average of the bin values (the integral of the step function over `[0, 1)`).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The bin values the distribution was built from.
    pub fn func(&self) -> &[f32] {
        &self.func
    }

    fn find_interval(&self, u: f32) -> usize {
        // Largest i with cdf[i] <= u, clamped to a valid bin; bins of zero mass are never chosen
        // because their cdf entries equal the next one.
        let idx = self.cdf.partition_point(|&c| c <= u);
        let mut i = idx.saturating_sub(1).min(self.func.len() - 1);
        while self.func[i] == 0.0 && i + 1 < self.func.len() && self.cdf[i + 1] <= u {
            i += 1;
        }
        while self.func[i] == 0.0 && i > 0 {
            i -= 1;
        }
        i
    }

    /// Samples a bin with probability proportional to its value. Returns `(index, pmf, u_remapped)`
    /// where `u_remapped` is `u` rescaled to `[0, 1)` within the chosen bin, reusable as a fresh
    /// random number.
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find_interval(u);
        let lo = self.cdf[i];
        let width = self.cdf[i + 1] - lo;
        let rem = if width > 0.0 {
            ((u - lo) / width).clamp(0.0, crate::ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, width, rem)
    }

    /// The probability [`Distribution1D::sample_discrete`] picks bin `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        if i >= self.func.len() {
            return 0.0;
        }
        self.cdf[i + 1] - self.cdf[i]
    }

    /// Samples `x ∈ [0, 1)` from the step density. Returns `(x, pdf, bin)`.
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, pmf, rem) = self.sample_discrete(u);
        let n = self.func.len() as f32;
        let x = ((i as f32 + rem) / n).min(crate::ONE_MINUS_EPSILON);
        (x, pmf * n, i)
    }

    /// The density of [`Distribution1D::sample_continuous`] at `x`.
    pub fn pdf(&self, x: f32) -> f32 {
        if !(0.0..1.0).contains(&x) {
            return 0.0;
        }
        let n = self.func.len();
        let i = ((x * n as f32) as usize).min(n - 1);
        self.pmf(i) * n as f32
    }

    /// Inverse of the continuous sampling map: the `u` that [`Distribution1D::sample_continuous`]
    /// maps to `x`.
    pub fn invert(&self, x: f32) -> f32 {
        let n = self.func.len();
        let xs = (x.clamp(0.0, 1.0) * n as f32).min(n as f32 - 1e-6);
        let i = (xs as usize).min(n - 1);
        let t = xs - i as f32;
        self.cdf[i] + t * (self.cdf[i + 1] - self.cdf[i])
    }
}

/// A piecewise-constant density on `[0, 1)²` given as a row-major `width × height` grid: a marginal
/// over rows and one conditional per row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    conditionals: Vec<Distribution1D>,
    marginal: Distribution1D,
    width: usize,
    height: usize,
}

impl Distribution2D {
    /// Builds from `values[y * width + x]`. `None` if the grid is malformed or sums to zero.
    pub fn new(values: &[f32], width: usize, height: usize) -> Option<Self> {
        if width == 0 || height == 0 || values.len() != width * height {
            return None;
        }
        let mut row_sums = Vec::with_capacity(height);
        let mut conditionals = Vec::with_capacity(height);
        for y in 0..height {
            let row = &values[y * width..(y + 1) * width];
            if row.iter().any(|v| !v.is_finite() || *v < 0.0) {
                return None;
            }
            let sum: f64 = row.iter().map(|&v| v as f64).sum();
            row_sums.push((sum / width as f64) as f32);
            // A row with no mass is never chosen by the marginal; give it a flat conditional.
            let cond = if sum > 0.0 {
                Distribution1D::new(row)?
            } else {
                Distribution1D::new(&vec![1.0; width])?
            };
            conditionals.push(cond);
        }
        let marginal = Distribution1D::new(&row_sums)?;
        Some(Self {
            conditionals,
            marginal,
            width,
            height,
        })
    }

    /// Grid size `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Samples `(x, y) ∈ [0, 1)²`; returns the point and its density per unit area of the square.
    pub fn sample(&self, u: glam::Vec2) -> (glam::Vec2, f32) {
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_x, _) = self.conditionals[row].sample_continuous(u.x);
        (glam::Vec2::new(x, y), pdf_x * pdf_y)
    }

    /// The density of [`Distribution2D::sample`] at `p`.
    pub fn pdf(&self, p: glam::Vec2) -> f32 {
        if !(0.0..1.0).contains(&p.x) || !(0.0..1.0).contains(&p.y) {
            return 0.0;
        }
        let row = ((p.y * self.height as f32) as usize).min(self.height - 1);
        self.marginal.pdf(p.y) * self.conditionals[row].pdf(p.x)
    }
}

/// Walker's alias method (Vose's construction): O(1) sampling of a discrete distribution.
#[derive(Clone, Debug)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
    sum: f64,
}

#[derive(Clone, Copy, Debug)]
struct AliasBin {
    /// Probability of keeping this bin (vs. its alias) given the bin was drawn.
    q: f32,
    alias: u32,
    pmf: f32,
}

impl AliasTable {
    /// Bytes the table keeps per weight.
    pub const BYTES_PER_BIN: usize = std::mem::size_of::<AliasBin>();

    /// Builds from non-negative weights. `None` if empty, any weight is negative or non-finite,
    /// or all are zero.
    pub fn new(weights: &[f32]) -> Option<Self> {
        if weights.is_empty()
            || weights.len() > u32::MAX as usize
            || weights.iter().any(|w| !w.is_finite() || *w < 0.0)
        {
            return None;
        }
        let sum: f64 = weights.iter().map(|&w| w as f64).sum();
        if sum <= 0.0 || !sum.is_finite() {
            return None;
        }
        let n = weights.len();
        let mut bins: Vec<AliasBin> = weights
            .iter()
            .map(|&w| AliasBin {
                q: 0.0,
                alias: 0,
                pmf: (w as f64 / sum) as f32,
            })
            .collect();
        let mut scaled: Vec<f64> = weights.iter().map(|&w| w as f64 / sum * n as f64).collect();
        let mut small = Vec::new();
        let mut large = Vec::new();
        for (i, &p) in scaled.iter().enumerate() {
            if p < 1.0 {
                small.push(i);
            } else {
                large.push(i);
            }
        }
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            large.pop();
            bins[s].q = scaled[s] as f32;
            bins[s].alias = l as u32;
            scaled[l] = (scaled[l] + scaled[s]) - 1.0;
            if scaled[l] < 1.0 {
                small.push(l);
            } else {
                large.push(l);
            }
        }
        // What remains has probability one up to rounding.
        for i in small.into_iter().chain(large) {
            bins[i].q = 1.0;
            bins[i].alias = i as u32;
        }
        Some(Self { bins, sum })
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Always false: empty tables cannot be built.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// The sum of the weights the table was built from.
    pub fn weight_sum(&self) -> f64 {
        self.sum
    }

    /// Picks an entry. Returns `(index, pmf, u_remapped)`; `u_remapped` is a fresh uniform number.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32, f32) {
        let n = self.bins.len();
        let scaled = u * n as f32;
        let i = (scaled as usize).min(n - 1);
        let up = (scaled - i as f32).clamp(0.0, crate::ONE_MINUS_EPSILON);
        let bin = self.bins[i];
        if up < bin.q {
            let rem = (up / bin.q).min(crate::ONE_MINUS_EPSILON);
            (i, bin.pmf, rem)
        } else {
            let j = bin.alias as usize;
            let rem = ((up - bin.q) / (1.0 - bin.q)).clamp(0.0, crate::ONE_MINUS_EPSILON);
            (j, self.bins[j].pmf, rem)
        }
    }

    /// The probability that [`AliasTable::sample`] returns `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.bins.get(i).map_or(0.0, |b| b.pmf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_input() {
        assert!(Distribution1D::new(&[]).is_none());
        assert!(Distribution1D::new(&[0.0, 0.0]).is_none());
        assert!(Distribution1D::new(&[1.0, f32::NAN]).is_none());
        assert!(Distribution1D::new(&[1.0, -1.0]).is_none());
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0]).is_none());
        assert!(AliasTable::new(&[f32::INFINITY]).is_none());
        assert!(Distribution2D::new(&[1.0; 5], 2, 2).is_none());
    }

    #[test]
    fn zero_bins_never_sampled() {
        let d = Distribution1D::new(&[0.0, 1.0, 0.0, 0.0, 3.0, 0.0]).unwrap();
        let a = AliasTable::new(&[0.0, 1.0, 0.0, 0.0, 3.0, 0.0]).unwrap();
        for k in 0..10_000 {
            let u = k as f32 / 10_000.0;
            let (i, pmf, _) = d.sample_discrete(u);
            assert!(i == 1 || i == 4, "u={u} picked {i}");
            assert_eq!(pmf, d.pmf(i));
            let (j, pmf_a, _) = a.sample(u);
            assert!(j == 1 || j == 4, "alias u={u} picked {j}");
            assert_eq!(pmf_a, a.pmf(j));
        }
    }

    #[test]
    fn continuous_invert_roundtrip() {
        let d = Distribution1D::new(&[1.0, 2.0, 0.5, 4.0]).unwrap();
        for k in 0..100 {
            let u = (k as f32 + 0.5) / 100.0;
            let (x, pdf, _) = d.sample_continuous(u);
            assert!((d.pdf(x) - pdf).abs() < 1e-5);
            assert!((d.invert(x) - u).abs() < 1e-4, "u={u} x={x}");
        }
    }

    #[test]
    fn pdf_2d_integrates_to_one() {
        let vals: Vec<f32> = (0..12).map(|i| (i % 5) as f32).collect();
        let d = Distribution2D::new(&vals, 4, 3).unwrap();
        let n = 200;
        let mut sum = 0.0f64;
        for y in 0..n {
            for x in 0..n {
                let p = glam::Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
                sum += d.pdf(p) as f64;
            }
        }
        assert!((sum / (n * n) as f64 - 1.0).abs() < 1e-3);
    }
}
