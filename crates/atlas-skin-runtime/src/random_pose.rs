//! Seeded random poses for testing and evaluation.

use glam::{Quat, Vec3};

/// SplitMix64 (Steele, Lea, Flood 2014): a small, fast, reproducible generator.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A unit vector uniform on the sphere (Marsaglia's cylinder projection).
    pub fn unit_vector(&mut self) -> Vec3 {
        let z = 2.0 * self.next_f64() - 1.0;
        let phi = std::f64::consts::TAU * self.next_f64();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
    }
}

/// One local rotation per joint: about a uniformly random axis by an angle uniform in
/// [0, `max_angle`] radians. The same `seed` gives the same pose on every machine. Applied
/// after each joint's rest rotation (see [`crate::pose::world_from_rotations`]), this is the
/// evaluation's random pose (BASELINES.md: up to 60°).
pub fn random_rotations(joint_count: usize, max_angle: f32, seed: u64) -> Vec<Quat> {
    let mut rng = SplitMix64::new(seed);
    (0..joint_count)
        .map(|_| {
            let axis = rng.unit_vector();
            let angle = max_angle * rng.next_f64() as f32;
            Quat::from_axis_angle(axis, angle)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_pose_and_angles_bounded() {
        let a = random_rotations(20, 1.0, 7);
        assert_eq!(a, random_rotations(20, 1.0, 7));
        assert_ne!(a, random_rotations(20, 1.0, 8));
        for q in a {
            assert!(q.is_normalized());
            assert!(q.to_axis_angle().1 <= 1.0 + 1e-5);
        }
    }
}
