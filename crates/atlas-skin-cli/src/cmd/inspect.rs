//! `atlas-skin inspect`: what was read from a character — mesh facts on the welded surface,
//! the joint tree with an inside/outside flag per joint, weights, clips and warnings.

use crate::input::{InputArgs, Prepared};
use anyhow::Result;
use atlas_skin::mesh::winding::is_inside;
use atlas_skin_io::gltf::{Binding, PrimitiveSource};
use atlas_skin_io::PartBinding;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeSet;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let prepared = Prepared::new(args.input.load()?);
    let report = Report::new(&prepared);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.to_text());
    }
    Ok(())
}

/// What `inspect` prints. The JSON keys are a stable interface: `vertices`,
/// `welded_vertices`, `triangles`, `components`, `closed`, `euler_characteristic`, `genus`
/// (null when open) and `joints` (name, parent, position, inside) are relied on by tests and
/// scripts.
/// Deepest level of the joint tree that `inspect` indents.
pub const MAX_TREE_INDENT: usize = 16;

#[derive(Debug, Serialize)]
pub struct Report {
    pub input: String,
    /// How units and axes were converted on reading (FBX), if they were.
    pub space: Option<String>,
    /// The meshes of a multi-mesh input (FBX), empty for other formats.
    pub parts: Vec<PartReport>,
    /// Stored vertices some triangle references.
    pub vertices: usize,
    pub welded_vertices: usize,
    pub triangles: usize,
    pub components: usize,
    pub closed: bool,
    pub euler_characteristic: i64,
    pub genus: Option<i64>,
    pub degenerate_triangles: usize,
    pub boundary_edges: usize,
    pub boundary_loops: usize,
    pub nonmanifold_edges: usize,
    pub inconsistently_oriented_edges: usize,
    pub joints: Vec<JointReport>,
    /// For glTF input with a skin: the meshes read.
    pub gltf_meshes: Option<GltfMeshes>,
    /// Whether the input came with weights (artist or precomputed).
    pub reference_weights: bool,
    pub clips: Vec<ClipReport>,
    pub warnings: Vec<String>,
}

/// One joint: bind position in the mesh's space, and whether the generalized winding number
/// of the welded surface there exceeds 0.5.
#[derive(Debug, Serialize)]
pub struct JointReport {
    pub name: String,
    pub parent: Option<String>,
    #[serde(skip)]
    pub parent_index: Option<usize>,
    pub position: [f32; 3],
    pub inside: bool,
    /// Where the joint's bone ends, when the file says (MakeHuman tails, BVH End Sites).
    pub tail: Option<[f32; 3]>,
}

/// One mesh of a multi-mesh input: its name, counts and how it follows the skeleton
/// (`skinned`, `rigid` with its joint, or `unbound`).
#[derive(Debug, Serialize)]
pub struct PartReport {
    pub name: String,
    pub vertices: usize,
    pub triangles: usize,
    pub binding: String,
}

/// The meshes of a skinned glTF read into the character: skinned meshes, the skins they
/// use (all over the same joints), rigid meshes under joint nodes (one per node).
#[derive(Debug, Serialize, PartialEq, Eq)]
pub struct GltfMeshes {
    pub skinned_meshes: usize,
    pub skins: usize,
    pub rigid_meshes: usize,
}

impl GltfMeshes {
    fn of(source: &atlas_skin_io::gltf::GltfSource) -> Option<Self> {
        source.skin?;
        let distinct = |key: &dyn Fn(&PrimitiveSource) -> Option<usize>| {
            source
                .primitives
                .iter()
                .filter_map(key)
                .collect::<BTreeSet<_>>()
                .len()
        };
        Some(Self {
            skinned_meshes: distinct(&|p| matches!(p.binding, Binding::Skin(_)).then_some(p.mesh)),
            skins: distinct(&|p| match p.binding {
                Binding::Skin(skin) => Some(skin),
                _ => None,
            }),
            rigid_meshes: distinct(&|p| matches!(p.binding, Binding::Rigid(_)).then_some(p.node)),
        })
    }
}

#[derive(Debug, Serialize)]
pub struct ClipReport {
    pub name: String,
    pub duration: f32,
    pub tracks: usize,
}

impl Report {
    /// Measures a prepared character (the mesh facts come from its welded surface).
    pub fn new(prepared: &Prepared) -> Self {
        let character = &prepared.character;
        let stats = &prepared.stats;
        let joints = match &character.skeleton {
            Some(skeleton) => {
                let positions = skeleton.bind_positions();
                positions
                    .par_iter()
                    .enumerate()
                    .map(|(j, position)| JointReport {
                        name: skeleton.names[j].clone(),
                        parent: skeleton.parent(j).map(|p| skeleton.names[p].clone()),
                        parent_index: skeleton.parent(j),
                        position: position.to_array(),
                        inside: is_inside(&prepared.welded.mesh, position.as_dvec3()),
                        tail: skeleton.tails[j].map(|t| t.to_array()),
                    })
                    .collect()
            }
            None => Vec::new(),
        };
        Self {
            input: character.path.display().to_string(),
            space: character.space.clone(),
            parts: character
                .parts
                .iter()
                .map(|part| PartReport {
                    name: part.name.clone(),
                    vertices: part.vertices.len(),
                    triangles: part.triangles.len(),
                    binding: match part.binding {
                        PartBinding::Skinned => "skinned".into(),
                        PartBinding::Rigid { joint } => format!(
                            "rigid on {}",
                            character
                                .skeleton
                                .as_ref()
                                .and_then(|s| s.names.get(joint as usize))
                                .map_or("?", String::as_str)
                        ),
                        PartBinding::Unbound => "unbound".into(),
                    },
                })
                .collect(),
            vertices: prepared.welded.referenced_stored,
            welded_vertices: prepared.welded.mesh.vertex_count(),
            triangles: stats.triangles,
            components: stats.components,
            closed: stats.closed,
            euler_characteristic: stats.euler_characteristic,
            genus: stats.genus,
            degenerate_triangles: stats.degenerate_triangles,
            boundary_edges: stats.boundary_edges,
            boundary_loops: stats.boundary_loops,
            nonmanifold_edges: stats.nonmanifold_edges,
            inconsistently_oriented_edges: stats.inconsistently_oriented_edges,
            joints,
            gltf_meshes: character.gltf.as_ref().and_then(GltfMeshes::of),
            reference_weights: character.reference_weights.is_some(),
            clips: character
                .clips
                .iter()
                .map(|clip| ClipReport {
                    name: clip.name.clone(),
                    duration: clip.duration,
                    tracks: clip.tracks.len(),
                })
                .collect(),
            warnings: character.warnings.clone(),
        }
    }

    /// The human-readable report, with the joint tree indented by depth (up to
    /// [`MAX_TREE_INDENT`] levels).
    pub fn to_text(&self) -> String {
        let yes_no = |b: bool| if b { "yes" } else { "no" };
        let genus = self
            .genus
            .map_or("- (open surface)".to_string(), |g| g.to_string());
        let inside = self.joints.iter().filter(|j| j.inside).count();
        let mut lines = vec![format!("input:                 {}", self.input)];
        if let Some(space) = &self.space {
            lines.push(format!("units and axes:        {space}"));
        }
        if !self.parts.is_empty() {
            lines.push(format!("meshes:                {}", self.parts.len()));
        }
        for part in &self.parts {
            lines.push(format!(
                "  {:?}: {} vertices, {} triangles, {}",
                part.name, part.vertices, part.triangles, part.binding
            ));
        }
        lines.extend([
            format!(
                "vertices:              {} stored, {} welded",
                self.vertices, self.welded_vertices
            ),
            format!(
                "triangles:             {} ({} degenerate)",
                self.triangles, self.degenerate_triangles
            ),
            format!("components:            {}", self.components),
            format!("closed:                {}", yes_no(self.closed)),
            format!("euler characteristic:  {}", self.euler_characteristic),
            format!("genus:                 {genus}"),
            format!(
                "boundary:              {} edges in {} loops",
                self.boundary_edges, self.boundary_loops
            ),
            format!("non-manifold edges:    {}", self.nonmanifold_edges),
            format!(
                "misoriented edges:     {}",
                self.inconsistently_oriented_edges
            ),
            format!(
                "joints:                {} ({inside} inside the surface)",
                self.joints.len()
            ),
        ]);
        if let Some(m) = &self.gltf_meshes {
            let at = lines.len() - 1;
            lines.insert(
                at,
                format!(
                    "glTF meshes:           {} skinned on {} skin(s), {} rigid under joints",
                    m.skinned_meshes, m.skins, m.rigid_meshes
                ),
            );
        }
        for (depth, joint) in self.joint_tree() {
            let [x, y, z] = joint.position;
            let flag = if joint.inside { "inside " } else { "OUTSIDE" };
            // Indentation stops growing at MAX_TREE_INDENT; deeper joints state their depth,
            // so a 200,000-joint chain prints 200,000 short lines.
            let indent = "  ".repeat(depth.min(MAX_TREE_INDENT));
            let deep = if depth > MAX_TREE_INDENT {
                format!("[depth {depth}] ")
            } else {
                String::new()
            };
            lines.push(format!(
                "  {flag} {indent}{deep}{} ({x:.4}, {y:.4}, {z:.4})",
                joint.name
            ));
        }
        lines.push(format!(
            "reference weights:     {}",
            yes_no(self.reference_weights)
        ));
        lines.push(format!("clips:                 {}", self.clips.len()));
        for clip in &self.clips {
            lines.push(format!(
                "  {:?}: {:.3} s, {} tracks",
                clip.name, clip.duration, clip.tracks
            ));
        }
        lines.push(format!("warnings:              {}", self.warnings.len()));
        lines.extend(self.warnings.iter().map(|w| format!("  {w}")));
        lines.join("\n") + "\n"
    }

    /// Joints in depth-first order from the roots, with their depth.
    fn joint_tree(&self) -> Vec<(usize, &JointReport)> {
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); self.joints.len()];
        let mut stack = Vec::new();
        for (j, joint) in self.joints.iter().enumerate().rev() {
            match joint.parent_index {
                Some(parent) => children[parent].push(j),
                None => stack.push((0, j)),
            }
        }
        let mut order = Vec::with_capacity(self.joints.len());
        while let Some((depth, j)) = stack.pop() {
            order.push((depth, &self.joints[j]));
            // Children were collected last to first: pushing them in that order pops the
            // first child first.
            stack.extend(children[j].iter().map(|&c| (depth + 1, c)));
        }
        order
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_io::{Character, TriangleMesh};
    use atlas_skin_runtime::{Skeleton, NO_PARENT};
    use glam::Vec3;

    /// A closed tetrahedron with a joint inside, a child outside and a second root.
    fn prepared() -> Prepared {
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        };
        let mut character = Character::new("tet.obj", mesh);
        character.skeleton = Some(
            Skeleton::from_positions(
                vec!["hips".into(), "tip".into(), "prop".into()],
                vec![NO_PARENT, 0, NO_PARENT],
                &[Vec3::splat(0.1), Vec3::splat(2.0), Vec3::splat(0.2)],
            )
            .unwrap(),
        );
        Prepared::new(character)
    }

    #[test]
    fn report_measures_the_surface_and_flags_joints() {
        let report = Report::new(&prepared());
        assert_eq!(
            (report.vertices, report.welded_vertices, report.triangles),
            (4, 4, 4)
        );
        assert!(report.closed);
        assert_eq!((report.euler_characteristic, report.genus), (2, Some(0)));
        let inside: Vec<bool> = report.joints.iter().map(|j| j.inside).collect();
        assert_eq!(inside, [true, false, true]);
        assert_eq!(report.joints[1].parent.as_deref(), Some("hips"));
        let json = serde_json::to_value(&report).unwrap();
        assert_eq!(json["joints"][1]["parent"], "hips");
        assert!(json["joints"][1].get("parent_index").is_none());
    }

    #[test]
    fn deep_trees_stop_indenting() {
        let count = 1000;
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 2]],
        };
        let mut character = Character::new("chain.obj", mesh);
        character.skeleton = Some(
            Skeleton::from_positions(
                (0..count).map(|j| format!("j{j}")).collect(),
                (0..count as u32)
                    .map(|j| j.checked_sub(1).unwrap_or(NO_PARENT))
                    .collect(),
                &vec![Vec3::ZERO; count],
            )
            .unwrap(),
        );
        let text = Report::new(&Prepared::new(character)).to_text();
        let longest = text.lines().map(str::len).max().unwrap();
        assert!(longest < 120, "a line of {longest} characters");
        assert!(text.contains("[depth 999] j999 ("), "{text}");
    }

    #[test]
    fn text_indents_the_joint_tree() {
        let text = Report::new(&prepared()).to_text();
        let joints: Vec<&str> = text
            .lines()
            .filter(|l| l.contains('(') && l.starts_with("  "))
            .collect();
        assert!(joints[0].starts_with("  inside  hips ("), "{text}");
        assert!(joints[1].starts_with("  OUTSIDE   tip ("), "{text}");
        assert!(joints[2].starts_with("  inside  prop ("), "{text}");
        assert!(
            text.contains("joints:                3 (2 inside the surface)"),
            "{text}"
        );
    }
}
