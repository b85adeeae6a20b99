//! The decode budget of a glTF document: how many bytes its accessors and triangles may
//! take once decoded, checked before each allocation (docs/formats.md, "Memory").
//!
//! An accessor's data is bounded by its bufferView, but not the decoded total: accessors
//! without a bufferView are zeros of any count, many accessors (or many primitives and
//! samplers) can read the same bytes, and 1-byte components grow to 4 bytes. The budget is
//! `min(MAX_DECODED_BYTES, DECODED_FLOOR_BYTES + DECODED_PER_INPUT_BYTE × input bytes)`,
//! the input being the file, its buffers and its images.

use std::cell::Cell;

/// Largest number of bytes any document may decode.
pub const MAX_DECODED_BYTES: u64 = 1 << 30;
/// What every document may decode, however small.
pub const DECODED_FLOOR_BYTES: u64 = 64 << 20;
/// Decoded bytes allowed per byte of input.
pub const DECODED_PER_INPUT_BYTE: u64 = 16;

/// The bytes a document may still decode.
pub(crate) struct DecodeBudget {
    limit: u64,
    remaining: Cell<u64>,
}

impl DecodeBudget {
    /// The budget of a document whose file, buffers and images hold `input_bytes`.
    pub fn for_input(input_bytes: u64) -> Self {
        let limit = input_bytes
            .saturating_mul(DECODED_PER_INPUT_BYTE)
            .saturating_add(DECODED_FLOOR_BYTES)
            .min(MAX_DECODED_BYTES);
        Self {
            limit,
            remaining: Cell::new(limit),
        }
    }

    /// Takes `bytes` from the budget, or says (in an error message) that they exceed it.
    pub fn charge(&self, bytes: u64) -> Result<(), String> {
        let remaining = self.remaining.get();
        match remaining.checked_sub(bytes) {
            Some(left) => {
                self.remaining.set(left);
                Ok(())
            }
            None => Err(format!(
                "decoding {bytes} more bytes would pass the document's budget of {} bytes \
                 ({} left; docs/formats.md, \"Memory\")",
                self.limit, remaining
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_grows_with_the_input_up_to_the_cap() {
        let small = DecodeBudget::for_input(300);
        assert!(small.charge(DECODED_FLOOR_BYTES).is_ok());
        assert!(small.charge(300 * DECODED_PER_INPUT_BYTE).is_ok());
        assert!(small.charge(1).is_err());
        let huge = DecodeBudget::for_input(u64::MAX);
        assert!(huge.charge(MAX_DECODED_BYTES + 1).is_err());
        assert!(huge.charge(MAX_DECODED_BYTES).is_ok());
    }
}
