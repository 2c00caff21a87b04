//! The shift-map contract that renderers implement.
//!
//! A shift map `T_{i→j}` moves a sample of domain `i` (e.g. a light sample or path of one pixel)
//! into domain `j` (another pixel, or the same pixel in another frame). GRIS needs, for each
//! shifted sample, three things: the shifted sample, the Jacobian determinant `|∂T_{i→j}/∂x|`
//! and the target function of domain `j` at the shifted sample. A shift either delivers all three
//! or fails explicitly (`None`); it never returns partially-filled state
//! (`docs/GRIS.md` §6.1).
//!
//! # Measures
//!
//! The Jacobian converts densities between the measures in which the two domains' targets are
//! expressed: a density `q` on domain `j` pulled back to domain `i` is `q(T(x))·J(x)`. Whatever
//! measure a renderer chooses (solid angle at the primary hit, area on the light, primary sample
//! space), it must be the same one in which its reservoirs' `ucw` are unbiased contribution
//! weights and in which the targets are evaluated. The standard Jacobians, with their measures in
//! their names, are in [`crate::jacobian`].
//!
//! # What the caller must guarantee
//!
//! * **Bijectivity:** `T_{j→i}` is the true inverse of `T_{i→j}` on its domain of definition,
//!   with `J_{j→i}(T_{i→j}(x)) = 1 / J_{i→j}(x)`.
//! * **Symmetric failure:** the forward shift of `x` succeeds iff the inverse shift of its result
//!   succeeds (every acceptance test — roughness, distance, Jacobian bound, visibility — must be
//!   symmetric; see [`crate::jacobian::reject_jacobian`]).
//! * **Consistent targets:** the target returned for domain `j` ([`Shifted::destination_target`])
//!   is the same function that domain `j` uses for its own reservoirs
//!   ([`Reservoir::own_target`](crate::Reservoir::own_target)), evaluated with domain `j`'s data.

/// A successfully shifted sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shifted<S> {
    /// The shifted sample `y = T(x)`, expressed in the destination domain.
    pub sample: S,
    /// Jacobian determinant `|∂T/∂x|` of this shift at `x` (destination measure per source
    /// measure). Must be finite and positive.
    pub jacobian: f32,
    /// Target function of the **destination** domain at `y`, `p̂_dst(y) ≥ 0`, evaluated with the
    /// destination's data (in the destination's measure). Not the source domain's target.
    pub destination_target: f32,
}

impl<S> Shifted<S> {
    /// The identity shift (a domain's own sample): `J = 1`.
    pub fn identity(sample: S, destination_target: f32) -> Self {
        Self {
            sample,
            jacobian: 1.0,
            destination_target,
        }
    }

    /// `true` when the Jacobian is finite and positive and the target finite and non-negative.
    /// The drivers in [`crate::resampling`] treat an invalid result like a failed shift.
    pub fn is_valid(&self) -> bool {
        self.jacobian > 0.0
            && self.jacobian.is_finite()
            && self.destination_target >= 0.0
            && self.destination_target.is_finite()
    }

    /// For a shift **from the receiving domain `c` into domain `j`**, the pulled-back target
    /// `p̂_{←j}(y) = p̂_j(T_{c→j}(y)) · J_{c→j}(y)` used by the MIS weights in [`crate::mis`]
    /// (0 for an invalid result).
    pub fn pulled_back_target_pdf(&self) -> f32 {
        if !self.is_valid() {
            return 0.0;
        }
        let p = (f64::from(self.destination_target) * f64::from(self.jacobian)) as f32;
        if p.is_finite() { p } else { 0.0 }
    }

    /// For a shift **from domain `i` into the receiving domain**, the source-domain target
    /// `p̂_i(x)` re-expressed in the receiver's measure: `p̂_i(x) / J_{i→c}(x)`
    /// (= `p̂_{←i}(y)` at `y = T_{i→c}(x)`). 0 for an invalid result.
    pub fn source_target_pdf_at_receiver(&self, source_target_pdf: f32) -> f32 {
        if !self.is_valid() || !(source_target_pdf > 0.0) {
            return 0.0;
        }
        let p = (f64::from(source_target_pdf) / f64::from(self.jacobian)) as f32;
        if p.is_finite() { p } else { 0.0 }
    }
}

/// A shift map between the domains of one renderer, over sample payload `S`.
///
/// Implementations must honour the contract in the [module docs](self): true inverses,
/// symmetric failure, and the destination domain's own target.
///
/// # Example
///
/// A toy 1-D shift `T_{i→j}(x) = x^{s_i/s_j}` between domains that each carry an exponent:
///
/// ```
/// use restir_gris::{ShiftMap, Shifted};
///
/// struct Domain { exponent: f64 }
/// struct PowerShift;
///
/// impl ShiftMap<f64> for PowerShift {
///     type Domain = Domain;
///     fn shift(&self, from: &Domain, to: &Domain, x: &f64) -> Option<Shifted<f64>> {
///         let a = from.exponent / to.exponent;
///         let y = x.powf(a);
///         let jacobian = (a * x.powf(a - 1.0)) as f32;
///         let destination_target = y as f32; // this toy's target is p̂_j(y) = y in every domain
///         let s = Shifted { sample: y, jacobian, destination_target };
///         s.is_valid().then_some(s)
///     }
/// }
///
/// let (a, b) = (Domain { exponent: 1.0 }, Domain { exponent: 2.0 });
/// let fwd = PowerShift.shift(&a, &b, &0.25).unwrap();
/// let back = PowerShift.shift(&b, &a, &fwd.sample).unwrap();
/// assert!((back.sample - 0.25).abs() < 1e-12);
/// assert!((fwd.jacobian * back.jacobian - 1.0).abs() < 1e-6);
/// ```
pub trait ShiftMap<S> {
    /// Everything a domain needs for shifting and evaluating its target (a pixel's G-buffer
    /// entry and camera, a frame index, ...).
    type Domain: ?Sized;

    /// Shifts `sample` from domain `from` into domain `to`. Returns `None` if the shift fails.
    fn shift(&self, from: &Self::Domain, to: &Self::Domain, sample: &S) -> Option<Shifted<S>>;

    /// `p̂_{←j}(y)`: the target of domain `source` pulled back into domain `receiver` at the
    /// receiver's sample `y`, computed by the inverse shift `T_{receiver→source}`; 0 if it fails.
    fn pulled_back_target_pdf(
        &self,
        receiver: &Self::Domain,
        source: &Self::Domain,
        sample_at_receiver: &S,
    ) -> f32 {
        self.shift(receiver, source, sample_at_receiver)
            .map_or(0.0, |s| s.pulled_back_target_pdf())
    }
}
