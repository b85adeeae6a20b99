//! Step 1 of the weights (Lu et al. 2008 §4): the regions related to every vertex and its
//! normalised depth λ_i in each (module documentation of [`crate::weights`]).

use crate::decomposition::Decomposition;
use crate::overlap::geodesic::BandDistances;
use crate::overlap::Overlaps;
use crate::rows::{Rows, PAR_CHUNK};

/// Per vertex, the (boundary, surface distance) of every cut band that reaches it.
pub fn vertex_bands(bands: &[BandDistances], vertex_count: usize) -> Rows<(u32, f64)> {
    let entries = bands.iter().enumerate().flat_map(|(k, band)| {
        band.vertices
            .iter()
            .zip(&band.distances)
            .map(move |(&v, &g)| (v as usize, (k as u32, g)))
    });
    Rows::group(vertex_count, entries)
}

/// Step 1: per vertex, the (region, λ) of its related regions that hold joints.
pub fn related_regions(
    decomposition: &Decomposition,
    overlaps: &Overlaps,
    bands: &Rows<(u32, f64)>,
) -> Rows<(u32, f64)> {
    let d = decomposition;
    Rows::par_build(d.surface.vertex_count(), PAR_CHUNK, |v, _: &mut (), out| {
        let start = out.len();
        for &f in d.topology.faces_of_vertex(v) {
            let region = d.face_region[f as usize];
            if !out[start..].iter().any(|&(r, _)| r == region) {
                out.push((region, f64::INFINITY));
            }
        }
        let inside = out.len();
        for &(k, g) in bands.row(v) {
            let boundary = &d.boundaries[k as usize];
            let w = overlaps.half_widths[k as usize].max(f64::MIN_POSITIVE);
            for region in [boundary.parent_region, boundary.child_region] {
                match out[start..].iter().position(|&(r, _)| r == region) {
                    Some(i) if start + i < inside => {
                        let depth = &mut out[start + i].1;
                        *depth = depth.min((w + g) / (2.0 * w));
                    }
                    Some(i) => {
                        let depth = &mut out[start + i].1;
                        *depth = depth.max((w - g) / (2.0 * w));
                    }
                    None => out.push((region, (w - g) / (2.0 * w))),
                }
            }
        }
        let mut keep = start;
        for i in start..out.len() {
            let (region, depth) = out[i];
            if depth > 0.0 && !d.regions[region as usize].joints.is_empty() {
                out[keep] = (region, depth);
                keep += 1;
            }
        }
        out.truncate(keep);
    })
}
