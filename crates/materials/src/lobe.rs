//! Lobe flags: what kind of scattering a BSDF lobe does (diffuse, glossy or delta; reflection or
//! transmission), and the combinations the models report.

/// Which kind of scattering a lobe does. ReSTIR PT decides where paths may reconnect from these.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct LobeFlags(u8);

impl LobeFlags {
    /// No lobe.
    pub const NONE: Self = Self(0);
    /// Lambertian-like, roughness 1.
    pub const DIFFUSE: Self = Self(1);
    /// Microfacet (rough) lobe.
    pub const GLOSSY: Self = Self(2);
    /// A Dirac delta lobe (perfect mirror or smooth refraction).
    pub const DELTA: Self = Self(4);
    /// Scatters to the side of `wo`.
    pub const REFLECTION: Self = Self(8);
    /// Scatters through the surface.
    pub const TRANSMISSION: Self = Self(16);

    /// Raw bits.
    pub const fn bits(self) -> u8 {
        self.0
    }
    /// Whether every flag of `other` is set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }
    /// Whether any flag of `other` is set.
    pub const fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }
    /// Union.
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
    /// Whether the lobe is a delta lobe.
    pub const fn is_delta(self) -> bool {
        self.contains(Self::DELTA)
    }
}

impl core::ops::BitOr for LobeFlags {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        self.union(rhs)
    }
}

impl core::ops::BitOrAssign for LobeFlags {
    fn bitor_assign(&mut self, rhs: Self) {
        *self = self.union(rhs);
    }
}

/// A Lambertian reflection lobe.
pub(crate) const REFLECT_DIFFUSE: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);
/// A microfacet reflection lobe.
pub(crate) const REFLECT_GLOSSY: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);
/// A mirror reflection.
pub(crate) const REFLECT_DELTA: LobeFlags = LobeFlags::DELTA.union(LobeFlags::REFLECTION);
/// A microfacet transmission lobe.
pub(crate) const TRANSMIT_GLOSSY: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::TRANSMISSION);
/// A smooth refraction (or the null surface's pass-through).
pub(crate) const TRANSMIT_DELTA: LobeFlags = LobeFlags::DELTA.union(LobeFlags::TRANSMISSION);
