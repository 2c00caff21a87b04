//! What a receiver sees of a light sample ([`Contact`]), and the contact of a point emitter
//! (point, spot and projector lights), shared by resolving a stored sample and sampling a light.

use glam::Vec3;

/// A light sample seen from a receiver.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// Unit direction from the receiver towards the light (world space).
    pub wi: Vec3,
    /// The point on the light (shadow-ray end), for lights at a finite distance.
    pub p: Vec3,
    /// Distance to `p`; infinite for lights at infinity.
    pub dist: f32,
    /// Radiance arriving along `-wi` (for point lights intensity/distance²).
    pub le: Vec3,
    /// Converts a solid-angle density at the receiver into the sample's measure:
    /// `|cos θ_y|/d²` on area lights, 1 otherwise.
    pub measure: f32,
    /// Whether the light is a delta light (BSDF sampling cannot reach it).
    pub delta: bool,
    /// The light's geometric normal at `p` (area lights), for the light pdf.
    pub ng: Vec3,
    /// The power sampler's density of the sample per unit solid angle at the receiver (selection
    /// included), where it is known without a lookup (mesh lights, the environment).
    pub pdf_sa: Option<f32>,
    /// The area light whose surface `p` lies on and the primitive of its shape `p` lies on
    /// (for where a shadow ray toward it may end,
    /// [`LightSet::shadow_end`](crate::LightSet::shadow_end)); `None` for other lights.
    pub light: Option<(u32, u32)>,
}

/// A point emitter at `p` seen from `x`, sending `intensity(direction from p to x, unnormalised)`
/// toward it (`None` where it sends nothing, or where `x` is at `p`).
#[inline]
pub(crate) fn point_contact(
    p: Vec3,
    x: Vec3,
    intensity: impl FnOnce(Vec3) -> Option<Vec3>,
) -> Option<Contact> {
    let to = p - x;
    let d2 = to.length_squared();
    if d2.is_nan() || d2 <= 0.0 {
        return None;
    }
    let intensity = intensity(-to)?;
    let dist = d2.sqrt();
    Some(Contact {
        wi: to / dist,
        p,
        dist,
        le: intensity / d2,
        measure: 1.0,
        delta: true,
        ng: Vec3::ZERO,
        pdf_sa: None,
        light: None,
    })
}

/// `Some(v)` unless `v` is zero (a point emitter sending nothing that way has no contact).
#[inline]
pub(crate) fn nonzero(v: Vec3) -> Option<Vec3> {
    (v != Vec3::ZERO).then_some(v)
}
