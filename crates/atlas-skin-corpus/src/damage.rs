//! Damaged copies of a file for the readers' never-panic tests.

use atlas_skin_runtime::random_pose::SplitMix64;

/// About `truncations` prefixes of `original` (evenly spaced lengths from 1 byte) and
/// `flips` copies with 1 to 4 random bits flipped (seeded by `seed`).
pub fn damaged_copies(
    original: &[u8],
    truncations: usize,
    flips: usize,
    seed: u64,
) -> Vec<Vec<u8>> {
    let mut rng = SplitMix64::new(seed);
    let mut copies: Vec<Vec<u8>> = (1..original.len())
        .step_by(original.len() / truncations.max(1) + 1)
        .map(|n| original[..n].to_vec())
        .collect();
    for _ in 0..flips {
        let mut bytes = original.to_vec();
        for _ in 0..1 + rng.next_u64() % 4 {
            let at = (rng.next_u64() % bytes.len() as u64) as usize;
            bytes[at] ^= 1 << (rng.next_u64() % 8);
        }
        copies.push(bytes);
    }
    copies
}
