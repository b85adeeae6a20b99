//! What the decomposition reports: the JSON of `atlas-skin skin --report` (under its
//! `decomposition` key), the debug view (vertex colours by region, cut curves as lines) and
//! the warnings about what it made of the skeleton.

use crate::cuts::joint_roles::HELPER_REASON;
use crate::decomposition::{BoundaryKind, Decomposition, JointDecision, JointStatus};
use crate::skeleton::placement::listed;
use serde::Serialize;

/// The decomposition as the report shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DecompositionReport {
    pub cuts: usize,
    pub soft: usize,
    pub skipped: usize,
    pub joints: Vec<JointReport>,
    pub regions: Vec<RegionReport>,
    /// Regions the child sides of unrelated joints' cuts shared, divided among them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub shared_sides: Vec<SharedSideReport>,
}

/// A divided region: the head joint of each family of cuts that shared it and the region
/// each family's part became.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SharedSideReport {
    pub joints: Vec<String>,
    pub regions: Vec<u32>,
}

/// One joint: its status (`cut`, `soft` or `skipped`), the reason when not cut, and its
/// boundary's plane point, normal, perimeter and diameter when it has one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointReport {
    pub name: String,
    pub status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub perimeter: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diameter: Option<f64>,
    /// The region the joint lies in.
    pub region: Option<u32>,
}

/// One region: its bound joint, all its joints along the chain, its size.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionReport {
    pub joint: Option<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<String>,
    pub faces: usize,
    pub vertices: usize,
}

impl Decomposition {
    /// The report of this decomposition.
    pub fn report(&self) -> DecompositionReport {
        let count = |wanted: fn(&JointStatus) -> bool| {
            self.joints.iter().filter(|j| wanted(&j.status)).count()
        };
        let joints = self
            .joints
            .iter()
            .map(|decision| {
                let boundary = decision
                    .boundary
                    .and_then(|b| self.boundaries.get(b as usize));
                let (status, reason) = match &decision.status {
                    JointStatus::Cut => ("cut", None),
                    JointStatus::Soft(reason) => ("soft", Some(reason.clone())),
                    JointStatus::Skipped(reason) => ("skipped", Some(reason.clone())),
                };
                JointReport {
                    name: decision.name.clone(),
                    status,
                    reason,
                    point: boundary.map(|b| b.point.to_array()),
                    normal: boundary.map(|b| b.normal.to_array()),
                    perimeter: boundary.map(|b| b.perimeter),
                    diameter: boundary.map(|b| b.diameter),
                    region: decision.region,
                }
            })
            .collect();
        let name = |j: &u32| self.joints[*j as usize].name.clone();
        let regions = self
            .regions
            .iter()
            .map(|region| RegionReport {
                joint: region.joints.first().map(name),
                joints: if region.joints.len() > 1 {
                    region.joints.iter().map(name).collect()
                } else {
                    Vec::new()
                },
                faces: region.faces,
                vertices: region.vertices,
            })
            .collect();
        DecompositionReport {
            cuts: count(|s| matches!(s, JointStatus::Cut)),
            soft: count(|s| matches!(s, JointStatus::Soft(_))),
            skipped: count(|s| matches!(s, JointStatus::Skipped(_))),
            joints,
            regions,
            shared_sides: self
                .shared_sides
                .iter()
                .map(|shared| SharedSideReport {
                    joints: shared.joints.iter().map(name).collect(),
                    regions: shared.regions.clone(),
                })
                .collect(),
        }
    }
}

/// #V(surface) RGBA colour of every vertex of the split surface: the colour of the region
/// of its first face (hues spaced by the golden angle), grey for a vertex of no face.
pub fn debug_colors(decomposition: &Decomposition) -> Vec<[f32; 4]> {
    let mut colors = vec![[0.5, 0.5, 0.5, 1.0]; decomposition.surface.vertex_count()];
    for (f, t) in decomposition.surface.triangles.iter().enumerate().rev() {
        let color = region_color(decomposition.face_region[f]);
        for &v in t {
            colors[v as usize] = color;
        }
    }
    colors
}

/// Every cut curve as line segments between consecutive loop vertices of the surface, as
/// `[x, y, z]` pairs (for `atlas_skin_io::gltf::debug_glb`'s `lines`).
pub fn debug_lines(decomposition: &Decomposition) -> Vec<[[f32; 3]; 2]> {
    let at = |v: u32| {
        decomposition.surface.positions[v as usize]
            .as_vec3()
            .to_array()
    };
    decomposition
        .boundaries
        .iter()
        .filter_map(|b| match &b.kind {
            BoundaryKind::Cut { curve } => Some(curve),
            BoundaryKind::Soft => None,
        })
        .flat_map(|curve| {
            (0..curve.len()).map(move |k| [at(curve[k]), at(curve[(k + 1) % curve.len()])])
        })
        .collect()
}

/// A saturated colour for region `r`: hue r × 137.5°, HSV with s = 0.65, v = 0.95.
fn region_color(r: u32) -> [f32; 4] {
    let hue = (r as f32 * 137.507_77).rem_euclid(360.0) / 60.0;
    let (s, v) = (0.65f32, 0.95f32);
    let c = v * s;
    let x = c * (1.0 - (hue.rem_euclid(2.0) - 1.0).abs());
    let (r, g, b) = match hue as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r + m, g + m, b + m, 1.0]
}

/// Warnings about what the decomposition made of the skeleton: most joints outside the
/// surface owning nothing (`forbidden`: the joints the user or the input forbade, which
/// are not counted), or no boundary at all on a skeleton of several joints.
pub fn decomposition_warnings(decomposition: &Decomposition, forbidden: &[String]) -> Vec<String> {
    let joints = &decomposition.joints;
    let mut warnings = Vec::new();
    let is_helper =
        |j: &JointDecision| matches!(&j.status, JointStatus::Skipped(r) if r == HELPER_REASON);
    let helpers: Vec<String> = joints
        .iter()
        .filter(|j| is_helper(j))
        .map(|j| j.name.clone())
        .collect();
    if !helpers.is_empty() {
        warnings.push(format!(
            "{} joint(s) named as helpers that deform nothing (attachment slots, locators, IK \
             targets) move no skin; `--force JOINT` weights one: {}",
            helpers.len(),
            listed(helpers.into_iter())
        ));
    }
    let outside: Vec<String> = joints
        .iter()
        .filter(|j| !j.owns_skin && !forbidden.contains(&j.name) && !is_helper(j))
        .map(|j| j.name.clone())
        .collect();
    if joints.len() >= 2 && 2 * outside.len() >= joints.len() {
        warnings.push(format!(
            "{} of {} joints lie outside the surface and own none of it: the skeleton may not \
             sit in the body (moved, flipped or scaled against the mesh?): {}",
            outside.len(),
            joints.len(),
            listed(outside.into_iter())
        ));
    }
    for shared in &decomposition.shared_sides {
        warnings.push(format!(
            "the surface joins the sides of the cuts of {} (a higher genus: a hand fused to \
             the body, a part welded across a joint): their region was divided among them by \
             the bones behind each face",
            listed(
                shared
                    .joints
                    .iter()
                    .map(|&j| joints[j as usize].name.clone())
            )
        ));
    }
    if joints.len() >= 2 && decomposition.boundaries.is_empty() {
        warnings.push(format!(
            "no joint got a boundary: the whole mesh is {} region(s), with no transition \
             between joints (see each joint's reason in the decomposition)",
            decomposition.regions.len()
        ));
    }
    warnings
}
