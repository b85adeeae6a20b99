//! Which vector instructions the skinning loops use: detected at run time, or chosen by
//! the caller (tests force every path the CPU has, including the portable one).

use crate::RuntimeError;

/// A family of skinning loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InstructionSet {
    /// Plain Rust (glam), on every CPU.
    Portable,
    /// x86-64 AVX2 and FMA: 256-bit registers.
    Avx2,
    /// x86-64 AVX-512 (F, VL and DQ) besides AVX2 and FMA: linear blend skinning of positions
    /// and normals with one 512-bit register per blended matrix and masked loads and
    /// stores; the other loops (dual quaternions, tangents) are the AVX2 ones.
    Avx512,
}

impl InstructionSet {
    /// Every family, narrowest first.
    pub const ALL: [InstructionSet; 3] = [Self::Portable, Self::Avx2, Self::Avx512];

    /// The widest family this CPU runs.
    pub fn best() -> Self {
        Self::ALL
            .into_iter()
            .rev()
            .find(|set| set.is_supported())
            .unwrap_or(Self::Portable)
    }

    /// True when this CPU runs the family's loops.
    pub fn is_supported(self) -> bool {
        match self {
            Self::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Self::Avx2 => crate::skinning_avx2::available(),
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => crate::skinning_avx512::available(),
            #[cfg(not(target_arch = "x86_64"))]
            Self::Avx2 | Self::Avx512 => false,
        }
    }

    /// The family's name: `portable`, `avx2`, `avx512`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Portable => "portable",
            Self::Avx2 => "avx2",
            Self::Avx512 => "avx512",
        }
    }

    /// The family named `name` ([`InstructionSet::name`]), if this CPU runs it.
    ///
    /// Errors: [`RuntimeError::UnsupportedInstructionSet`] for an unknown name or a family
    /// this CPU lacks.
    pub fn from_name(name: &str) -> Result<Self, RuntimeError> {
        Self::ALL
            .into_iter()
            .find(|set| set.name() == name && set.is_supported())
            .ok_or_else(|| RuntimeError::UnsupportedInstructionSet {
                name: name.to_string(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for set in InstructionSet::ALL.into_iter().filter(|s| s.is_supported()) {
            assert_eq!(InstructionSet::from_name(set.name()), Ok(set));
        }
        assert!(InstructionSet::best().is_supported());
        assert!(InstructionSet::from_name("sse9").is_err());
    }
}
