//! The toy GRIS domains shared by the integration tests (their generator and statistics come from
//! `restir_testkit`).
#![allow(dead_code)]

use restir_gris::{Reservoir, ShiftMap, Shifted, StreamingReservoir};

use restir_testkit::SplitMix64 as Rng;

// ---------------------------------------------------------------------------------------------
// The toy GRIS problem (our own construction; docs/GRIS.md §7).
//
// Every domain d lives on [0, support_max_d] ⊂ [0, 1] and carries an exponent s_d; the shift
// T_{a→b}(x) = x^{s_a/s_b} (canonical s = 1) with Jacobian (s_a/s_b)·x^{s_a/s_b − 1}. A shift fails
// iff its input lies outside the source support or its output outside the destination support,
// so forward and inverse shifts fail together. Each domain has its own target; one neighbour has
// partial support, which makes constant 1/M MIS biased.
// ---------------------------------------------------------------------------------------------

/// Target functions used by the toy domains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToyTarget {
    /// 0.25 + x (canonical).
    Linear,
    /// x² + 0.1.
    Quadratic,
    /// x.
    Ramp,
    /// 1 − 0.5·x.
    Falling,
}

#[derive(Clone, Copy, Debug)]
pub struct ToyDomain {
    pub exponent: f64,
    pub support_max: f64,
    pub target: ToyTarget,
    pub confidence: f32,
    /// RIS candidates used to build this domain's reservoir.
    pub candidates: usize,
}

impl ToyDomain {
    pub fn target_pdf(&self, x: f64) -> f64 {
        if !(0.0..=self.support_max).contains(&x) {
            return 0.0;
        }
        match self.target {
            ToyTarget::Linear => 0.25 + x,
            ToyTarget::Quadratic => x * x + 0.1,
            ToyTarget::Ramp => x,
            ToyTarget::Falling => 1.0 - 0.5 * x,
        }
    }

    /// RIS with uniform candidates on [0, support_max] (pdf 1/support_max).
    pub fn sample(&self, rng: &mut Rng) -> Reservoir<f64> {
        let n = self.candidates;
        let mut stream = StreamingReservoir::new();
        for _ in 0..n {
            let x = rng.next_f64() * self.support_max;
            let t = self.target_pdf(x);
            let w = t * self.support_max / n as f64;
            stream.add_candidate(x, t as f32, w as f32, 0.0, rng.next_f32());
        }
        let mut r = stream.finalize_recorded();
        r.confidence = self.confidence;
        r
    }
}

/// Integrand of the canonical domain: f(y) = 0.5 + 3y², ∫_0^1 f = 1.5.
pub fn toy_integrand(y: f64) -> f64 {
    0.5 + 3.0 * y * y
}

pub const TOY_INTEGRAL: f64 = 1.5;

/// ∫_{0.5}^{1} f: the part of the integral the partial-support neighbour cannot reach.
pub const TOY_UNCOVERED_INTEGRAL: f64 = 0.25 + 0.875;

#[derive(Clone, Copy, Debug)]
pub struct PowerShift;

impl ShiftMap<f64> for PowerShift {
    type Domain = ToyDomain;

    fn shift(&self, from: &ToyDomain, to: &ToyDomain, x: &f64) -> Option<Shifted<f64>> {
        let x = *x;
        if !(0.0..=from.support_max).contains(&x) {
            return None;
        }
        let a = from.exponent / to.exponent;
        let y = x.powf(a);
        if !(0.0..=to.support_max).contains(&y) {
            return None;
        }
        let jacobian = (a * x.powf(a - 1.0)) as f32;
        let s = Shifted {
            sample: y,
            jacobian,
            destination_target: to.target_pdf(y) as f32,
        };
        s.is_valid().then_some(s)
    }
}

/// Canonical domain and three neighbours: full support with a different target and exponent 2,
/// partial support [0, 0.5], and exponent 0.5 with a falling target.
pub fn toy_domains() -> (ToyDomain, [ToyDomain; 3]) {
    let canonical = ToyDomain {
        exponent: 1.0,
        support_max: 1.0,
        target: ToyTarget::Linear,
        confidence: 1.0,
        candidates: 4,
    };
    let neighbors = [
        ToyDomain {
            exponent: 2.0,
            support_max: 1.0,
            target: ToyTarget::Quadratic,
            confidence: 2.0,
            candidates: 3,
        },
        ToyDomain {
            exponent: 1.0,
            support_max: 0.5,
            target: ToyTarget::Ramp,
            confidence: 1.5,
            candidates: 3,
        },
        ToyDomain {
            exponent: 0.5,
            support_max: 1.0,
            target: ToyTarget::Falling,
            confidence: 0.5,
            candidates: 2,
        },
    ];
    (canonical, neighbors)
}
