//! The skinning data file that side-by-side runs hand to a peer's skinning job
//! (`../shared/perf/README.md`, read by `ozz-skinning-bench`), little-endian:
//!
//! ```text
//! int32 n, int32 j
//! n × 3 float32   rest positions
//! n × 3 float32   rest normals
//! n × 4 uint16    joint indices per vertex
//! n × 4 float32   weights per vertex (summing to 1)
//! j × 16 float32  skinning matrices (joint world × inverse bind), column-major
//! ```

use anyhow::{ensure, Context, Result};
use atlas_skin_io::OutputPlan;
use atlas_skin_runtime::CompactSkin;
use glam::{Mat4, Vec3};
use std::path::Path;

/// Influences per vertex of the format.
pub const DATA_INFLUENCES: usize = 4;

/// The file's bytes for `skin` (at most [`DATA_INFLUENCES`] influences; fewer are padded
/// with the vertex's first joint at weight 0, as [`CompactSkin`] pads), the rest streams
/// and one palette. The implicit last weight of the compact skin is written out as
/// `1 − Σ explicit`.
pub fn encode(
    skin: &CompactSkin,
    positions: &[Vec3],
    normals: &[Vec3],
    palette: &[Mat4],
) -> Result<Vec<u8>> {
    let k = skin.influences();
    ensure!(
        k <= DATA_INFLUENCES,
        "the skin has {k} influences per vertex; the data file holds {DATA_INFLUENCES}"
    );
    let n = skin.vertex_count();
    ensure!(
        positions.len() == n && normals.len() == n && palette.len() == skin.joint_count(),
        "streams of {} positions, {} normals and {} matrices for a skin of {n} vertices and {} joints",
        positions.len(),
        normals.len(),
        palette.len(),
        skin.joint_count()
    );
    let count =
        |c: usize| i32::try_from(c).context("too many vertices or joints for the data file");
    let mut bytes = Vec::with_capacity(8 + n * (24 + 8 + 16) + palette.len() * 64);
    bytes.extend(count(n)?.to_le_bytes());
    bytes.extend(count(palette.len())?.to_le_bytes());
    let floats = |bytes: &mut Vec<u8>, values: &[f32]| {
        bytes.extend(values.iter().flat_map(|x| x.to_le_bytes()));
    };
    for stream in [positions, normals] {
        for v in stream {
            floats(&mut bytes, &v.to_array());
        }
    }
    for v in 0..n {
        let joints = &skin.joints()[v * k..(v + 1) * k];
        for i in 0..DATA_INFLUENCES {
            let joint = joints.get(i).copied().unwrap_or(joints[0]);
            bytes.extend(joint.to_le_bytes());
        }
    }
    for v in 0..n {
        let mut weights = [0.0f32; DATA_INFLUENCES];
        for (w, explicit) in weights.iter_mut().zip(skin.explicit_weights(v)) {
            *w = explicit;
        }
        weights[k - 1] = 1.0 - weights[..k - 1].iter().sum::<f32>();
        floats(&mut bytes, &weights);
    }
    for m in palette {
        floats(&mut bytes, &m.to_cols_array());
    }
    Ok(bytes)
}

/// Writes [`encode`]'s bytes to the output `out` of `plan`.
pub fn write(
    plan: &OutputPlan,
    out: &Path,
    skin: &CompactSkin,
    positions: &[Vec3],
    normals: &[Vec3],
    palette: &[Mat4],
) -> Result<()> {
    let bytes = encode(skin, positions, normals, palette)?;
    plan.write(out, &bytes)
        .with_context(|| format!("cannot write the skinning data {}", out.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::VertexWeights;

    /// A two-vertex skin of 2 influences: the header, the padding to 4 and the implicit
    /// weight land where the format puts them.
    #[test]
    fn layout_follows_the_format() {
        let weights = VertexWeights::from_rows([vec![(1, 0.75), (0, 0.25)], vec![(2, 1.0)]]);
        let skin = CompactSkin::new(&weights, 3, 4).unwrap();
        let positions = [Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO];
        let normals = [Vec3::Z, Vec3::X];
        let palette = [
            Mat4::IDENTITY,
            Mat4::from_translation(Vec3::X),
            Mat4::IDENTITY,
        ];
        let bytes = encode(&skin, &positions, &normals, &palette).unwrap();
        assert_eq!(bytes.len(), 8 + 2 * 24 + 2 * 8 + 2 * 16 + 3 * 64);
        let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let float = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let short = |at: usize| u16::from_le_bytes(bytes[at..at + 2].try_into().unwrap());
        assert_eq!((int(0), int(4)), (2, 3));
        assert_eq!(float(8 + 8), 3.0);
        assert_eq!(float(8 + 24 + 8), 1.0);
        let joints = 8 + 48;
        let shorts: Vec<u16> = (0..8).map(|i| short(joints + 2 * i)).collect();
        assert_eq!(shorts, [1, 0, 1, 1, 2, 2, 2, 2]);
        let weights = joints + 16;
        let floats: Vec<f32> = (0..8).map(|i| float(weights + 4 * i)).collect();
        assert_eq!(floats, [0.75, 0.25, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        let second_matrix = weights + 32 + 64;
        assert_eq!(float(second_matrix + 4 * 12), 1.0, "translation x");
    }
}
