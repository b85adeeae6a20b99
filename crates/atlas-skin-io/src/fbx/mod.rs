//! Autodesk FBX (binary and ASCII, FBX 6.1 to 7.7) through the `ufbx` crate (bindings to
//! the ufbx C library, which parses the file; everything below is read from its scene).
//!
//! - Skeleton: the bone nodes of the skin clusters of every skinned mesh, in node-tree
//!   order (parents first), each one's parent the nearest ancestor that is a joint. Bind
//!   pose: the clusters' `TransformLink` (ufbx `bind_to_world`), never the nodes' current
//!   transforms.
//! - Mesh: every skinned mesh's control points (no split at seams) in bind space
//!   (`TransformLink · geometry_to_bone`, i.e. the cluster's `Transform` and the mesh's
//!   geometric transform), then the unskinned meshes that belong to the character (see
//!   [`PartBinding`]), in document order; polygons triangulated by ufbx.
//! - Reference weights: the skin's, rows normalised (a warning says how many did not sum
//!   to 1); weight 1 on the joint above a rigid part. Not read for
//!   [`Contents::ForSkinning`]: ufbx does not gather the clusters' vertices into the skin's
//!   rows, and the clusters' `Indexes`/`Weights` are neither turned into rows nor checked.
//! - Units and axes converted to glTF's ([`space::SpaceConversion`]).
//!
//! - Materials: each face's base colour (the written glb gets one primitive per material).
//!
//! Animations, blend shapes, textures and UVs are not read.

mod ascii_arrays;
pub mod space;

use crate::names::unique_names;
use crate::{Character, Contents, IoError, Material, MeshPart, PartBinding, TriangleMesh};
use atlas_skin_runtime::{Rig, Skeleton, VertexWeights, NO_PARENT};
use glam::{DMat4, DVec3};
use space::SpaceConversion;
use std::collections::HashMap;
use std::path::Path;

/// Upper bound of the memory ufbx may allocate for a file, for its result and its
/// temporary data each (a hostile file declaring huge arrays fails instead of exhausting
/// the machine).
const MEMORY_LIMIT: usize = 4 << 30;

/// Rows whose stored sum is within this of 1 count as summing to 1 in the warning (the
/// tolerance the counts of `shared/data/fbx/README.md` use).
const SUM_TOLERANCE: f64 = 1e-2;

/// Reads an `.fbx` file (see the module documentation).
///
/// # Errors
/// [`IoError`] naming the file: ufbx's parse errors (not FBX, truncated, corrupt arrays,
/// indices out of range, over the memory limit), cluster weights on vertices past the end
/// of their mesh, non-finite or negative weights, non-finite positions or bind matrices,
/// a file without a mesh with triangles.
pub fn read(path: &Path) -> Result<Character, IoError> {
    read_contents(path, Contents::Everything)
}

/// [`read`], with the stored weights only for [`Contents::Everything`]: with
/// [`Contents::ForSkinning`] the character has no reference weights, and the clusters'
/// vertices and weights are not checked (a weight on a vertex past the mesh, or a negative
/// one, does not stop it). The bind pose (the clusters' `TransformLink` and `Transform`)
/// is read and checked either way.
pub fn read_contents(path: &Path, contents: Contents) -> Result<Character, IoError> {
    let bytes = crate::text::read_bytes(path)?;
    let stored_weights = contents == Contents::Everything;
    let scene = load_scene(path, &bytes, stored_weights)?;
    if scene.metadata.ascii {
        ascii_arrays::check(path, &String::from_utf8_lossy(&bytes))?;
    }
    let mut warnings = Vec::new();
    let space = SpaceConversion::new(
        &scene.settings.axes,
        scene.settings.unit_meters,
        &mut warnings,
    );
    let skinned: Vec<&ufbx::Mesh> = scene
        .meshes
        .iter()
        .filter(|m| !m.skin_deformers.is_empty())
        .map(|m| &**m)
        .collect();
    let joints = Joints::from_clusters(path, &scene, &skinned, &mut warnings)?;
    let mut builder = PartsBuilder {
        path,
        space: &space,
        joints: &joints,
        mesh: TriangleMesh::default(),
        rows: stored_weights.then(Vec::new),
        parts: Vec::new(),
        stored_sums: SumCount::default(),
        materials: Vec::new(),
        material_of: HashMap::new(),
        triangle_materials: Vec::new(),
    };
    for mesh in scene.meshes.iter() {
        builder.add_mesh(&scene, mesh, &mut warnings)?;
    }
    if builder.mesh.triangles.is_empty() {
        return Err(IoError::invalid(
            path,
            "the file has no mesh with triangles",
        ));
    }
    let PartsBuilder {
        mesh,
        rows,
        parts,
        stored_sums,
        materials,
        triangle_materials,
        ..
    } = builder;
    let mut character = Character::new(path, mesh);
    if !joints.nodes.is_empty() {
        let skeleton = joints.skeleton(path, &scene, &space)?;
        stored_sums.warn(&mut warnings);
        character.rig = Some(Rig::from_skeleton(&skeleton));
        character.skeleton = Some(skeleton);
        character.reference_weights = rows.map(VertexWeights::from_rows);
    }
    character.parts = parts;
    if !materials.is_empty() {
        character.materials = materials;
        character.triangle_materials = triangle_materials;
    }
    character.space = Some(space.description.clone());
    character.warnings = warnings;
    Ok(character)
}

/// ufbx's scene of `bytes`, forced to be FBX, strict about indices, without animation;
/// the skins' per-vertex weights (`ufbx::SkinDeformer::vertices` and `weights`) only with
/// `stored_weights`.
fn load_scene(path: &Path, bytes: &[u8], stored_weights: bool) -> Result<ufbx::SceneRoot, IoError> {
    let limits = ufbx::AllocatorOpts {
        memory_limit: MEMORY_LIMIT,
        ..Default::default()
    };
    let options = ufbx::LoadOpts {
        file_format: ufbx::FileFormat::Fbx,
        no_format_from_content: true,
        no_format_from_extension: true,
        ignore_animation: true,
        ignore_embedded: true,
        skip_skin_vertices: !stored_weights,
        index_error_handling: ufbx::IndexErrorHandling::AbortLoading,
        temp_allocator: ufbx::AllocatorOpts {
            memory_limit: MEMORY_LIMIT,
            ..Default::default()
        },
        result_allocator: limits,
        ..Default::default()
    };
    ufbx::load_memory(bytes, options).map_err(|error| {
        let info = error.info();
        let detail = if info.is_empty() {
            String::new()
        } else {
            format!(" ({info})")
        };
        IoError::invalid(
            path,
            format!("not a readable FBX file: {}{detail}", error.description),
        )
    })
}

/// The skin joints: cluster bone nodes in node-tree order, with their bind transforms in
/// the file's space.
struct Joints {
    /// Node index (ufbx `typed_id`) of each joint.
    nodes: Vec<usize>,
    /// Joint of a node.
    of_node: HashMap<usize, u32>,
    /// `TransformLink` of each joint (file space).
    bind_world: Vec<DMat4>,
}

impl Joints {
    fn from_clusters(
        path: &Path,
        scene: &ufbx::Scene,
        skinned: &[&ufbx::Mesh],
        warnings: &mut Vec<String>,
    ) -> Result<Self, IoError> {
        let mut bind_of_node: HashMap<usize, DMat4> = HashMap::new();
        let mut disagreeing = Vec::new();
        for mesh in skinned {
            for cluster in mesh.skin_deformers[0].clusters.iter() {
                let Some(bone) = &cluster.bone_node else {
                    continue;
                };
                let node = bone.element.typed_id as usize;
                let bind = finite_matrix(path, &cluster.bind_to_world, &cluster.element.name)?;
                let first = *bind_of_node.entry(node).or_insert(bind);
                if !first.abs_diff_eq(bind, 1e-4 * first.col(3).truncate().length().max(1.0)) {
                    disagreeing.push(bone.element.name.to_string());
                }
            }
            if mesh.skin_deformers.len() > 1 {
                warnings.push(format!(
                    "mesh {:?} has {} skins: only the first is read",
                    mesh.element.name.to_string(),
                    mesh.skin_deformers.len()
                ));
            }
        }
        disagreeing.sort();
        disagreeing.dedup();
        if !disagreeing.is_empty() {
            warnings.push(format!(
                "the bind pose of joints {} differs between meshes: the first mesh's is used",
                disagreeing.join(", ")
            ));
        }
        let nodes: Vec<usize> = tree_order(scene)
            .into_iter()
            .filter(|n| bind_of_node.contains_key(n))
            .collect();
        let of_node = nodes
            .iter()
            .enumerate()
            .map(|(j, &n)| (n, j as u32))
            .collect();
        let bind_world = nodes.iter().map(|n| bind_of_node[n]).collect();
        Ok(Self {
            nodes,
            of_node,
            bind_world,
        })
    }

    /// The nearest joint at or above `node` in the node tree.
    fn joint_above(&self, scene: &ufbx::Scene, node: &ufbx::Node) -> Option<u32> {
        let mut current = Some(node);
        // A tree has no path longer than its node count.
        for _ in 0..=scene.nodes.len() {
            let here = current?;
            if let Some(&joint) = self.of_node.get(&(here.element.typed_id as usize)) {
                return Some(joint);
            }
            current = here.parent.as_deref();
        }
        None
    }

    /// The skeleton in glTF's space: names from the nodes (made unique, `joint<j>` when
    /// empty), parents the nearest joint ancestors, inverse binds `(C · TransformLink ·
    /// C⁻¹)⁻¹` with C the space conversion.
    fn skeleton(
        &self,
        path: &Path,
        scene: &ufbx::Scene,
        space: &SpaceConversion,
    ) -> Result<Skeleton, IoError> {
        let wanted = self
            .nodes
            .iter()
            .enumerate()
            .map(|(j, &n)| {
                let name = scene.nodes[n].element.name.to_string();
                if name.is_empty() {
                    format!("joint{j}")
                } else {
                    name
                }
            })
            .collect();
        let parents = self
            .nodes
            .iter()
            .map(|&n| {
                scene.nodes[n]
                    .parent
                    .as_deref()
                    .and_then(|p| self.joint_above(scene, p))
                    .unwrap_or(NO_PARENT)
            })
            .collect();
        let inverse_bind = self
            .bind_world
            .iter()
            .map(|&b| space.frame(b).inverse().as_mat4())
            .collect();
        Skeleton::new(unique_names(wanted), parents, inverse_bind).map_err(|cause| {
            IoError::Skeleton {
                path: path.to_path_buf(),
                cause,
            }
        })
    }
}

/// Node indices in depth-first order from the root (parents before children), then any
/// node the walk did not reach.
fn tree_order(scene: &ufbx::Scene) -> Vec<usize> {
    let count = scene.nodes.len();
    let mut seen = vec![false; count];
    let mut order = Vec::with_capacity(count);
    let mut stack = vec![&*scene.root_node];
    while let Some(node) = stack.pop() {
        let index = node.element.typed_id as usize;
        if index >= count || std::mem::replace(&mut seen[index], true) {
            continue;
        }
        order.push(index);
        stack.extend(node.children.iter().rev().map(|c| &**c));
    }
    order.extend((0..count).filter(|&n| !seen[n]));
    order
}

/// `matrix` (ufbx's 3×4 affine) as a 4×4 matrix; an error naming `what` when not finite.
fn finite_matrix(path: &Path, m: &ufbx::Matrix, what: &ufbx::String) -> Result<DMat4, IoError> {
    let matrix = DMat4::from_cols_array(&[
        m.m00, m.m10, m.m20, 0.0, m.m01, m.m11, m.m21, 0.0, m.m02, m.m12, m.m22, 0.0, m.m03, m.m13,
        m.m23, 1.0,
    ]);
    if matrix.is_finite() {
        Ok(matrix)
    } else {
        Err(IoError::invalid(
            path,
            format!("{:?} has a non-finite bind matrix", what.to_string()),
        ))
    }
}

/// How many stored skin rows summed to 1 (before normalising), and how many were empty.
#[derive(Default)]
struct SumCount {
    rows: usize,
    summing_to_one: usize,
    unweighted: usize,
}

impl SumCount {
    fn warn(&self, warnings: &mut Vec<String>) {
        if self.summing_to_one < self.rows {
            warnings.push(format!(
                "skin weights sum to 1 on {} of {} skinned vertices: rows normalised",
                self.summing_to_one, self.rows
            ));
        }
        if self.unweighted > 0 {
            warnings.push(format!(
                "{} vertices of skinned meshes have no skin weight (they cannot be posed)",
                self.unweighted
            ));
        }
    }
}

/// The character's mesh and weight rows, one FBX mesh at a time.
struct PartsBuilder<'a> {
    path: &'a Path,
    space: &'a SpaceConversion,
    joints: &'a Joints,
    mesh: TriangleMesh,
    /// One weight row per vertex of `mesh`; `None` when the stored weights are not read.
    rows: Option<Vec<Vec<(u32, f32)>>>,
    parts: Vec<MeshPart>,
    stored_sums: SumCount,
    materials: Vec<Material>,
    /// Index in `materials` of a ufbx material (by element id).
    material_of: HashMap<u32, u32>,
    triangle_materials: Vec<Option<u32>>,
}

impl PartsBuilder<'_> {
    /// Adds `mesh` if it belongs to the character: skinned (once, in bind space), or each
    /// node instancing it that hangs under a joint (rigid on it) or elsewhere under the
    /// skeleton's top node (rigid on the root joint); without a skeleton, every instance in
    /// its world placement.
    fn add_mesh(
        &mut self,
        scene: &ufbx::Scene,
        mesh: &ufbx::Mesh,
        warnings: &mut Vec<String>,
    ) -> Result<(), IoError> {
        let name = mesh.element.name.to_string();
        if let Some(skin) = mesh.skin_deformers.first() {
            if let Some(bind) = self.skinned_bind(skin)? {
                let rows = if self.rows.is_some() {
                    self.skin_rows(mesh, skin, &name)?
                } else {
                    Vec::new()
                };
                return self.push(mesh, &name, bind, PartBinding::Skinned, rows);
            }
            warnings.push(format!(
                "mesh {name:?} has a skin without bones: read as unskinned"
            ));
        }
        for node in mesh.element.instances.iter() {
            let label = if name.is_empty() {
                node.element.name.to_string()
            } else {
                name.clone()
            };
            let world = finite_matrix(self.path, &node.geometry_to_world, &node.element.name)?;
            if self.joints.nodes.is_empty() {
                self.push(mesh, &label, world, PartBinding::Unbound, Vec::new())?;
                continue;
            }
            match self.joints.joint_above(scene, node) {
                Some(joint) => {
                    // Bind placement: from the joint's current frame back to its bind frame.
                    let joint_node = &scene.nodes[self.joints.nodes[joint as usize]];
                    let current = finite_matrix(
                        self.path,
                        &joint_node.node_to_world,
                        &joint_node.element.name,
                    )?;
                    let bind = self.joints.bind_world[joint as usize] * current.inverse() * world;
                    let rows = self.rigid_rows(joint, mesh);
                    self.push(mesh, &label, bind, PartBinding::Rigid { joint }, rows)?;
                }
                None if self.shares_top_node(scene, node) => {
                    // Joint 0 comes first in tree order: a root of the skeleton.
                    warnings.push(format!(
                        "mesh {label:?} is neither skinned nor under a joint, but in the \
                         skeleton's node tree: made rigid on the root joint"
                    ));
                    let rows = self.rigid_rows(0, mesh);
                    self.push(mesh, &label, world, PartBinding::Rigid { joint: 0 }, rows)?;
                }
                None => warnings.push(format!(
                    "mesh {label:?} is neither skinned nor in the skeleton's node tree: skipped"
                )),
            }
        }
        Ok(())
    }

    /// The bind placement of a skinned mesh, `TransformLink · geometry_to_bone` of its first
    /// cluster with a bone; `None` when no cluster has one.
    fn skinned_bind(&self, skin: &ufbx::SkinDeformer) -> Result<Option<DMat4>, IoError> {
        let Some(cluster) = skin.clusters.iter().find(|c| c.bone_node.is_some()) else {
            return Ok(None);
        };
        let link = finite_matrix(self.path, &cluster.bind_to_world, &cluster.element.name)?;
        let to_bone = finite_matrix(self.path, &cluster.geometry_to_bone, &cluster.element.name)?;
        Ok(Some(link * to_bone))
    }

    /// The weight rows of a mesh rigid on `joint`: weight 1 on it (none when the stored
    /// weights are not read).
    fn rigid_rows(&self, joint: u32, mesh: &ufbx::Mesh) -> Vec<Vec<(u32, f32)>> {
        if self.rows.is_some() {
            vec![vec![(joint, 1.0)]; mesh.num_vertices]
        } else {
            Vec::new()
        }
    }

    /// The stored weight rows of a skinned mesh on the skeleton's joints, normalised.
    fn skin_rows(
        &mut self,
        mesh: &ufbx::Mesh,
        skin: &ufbx::SkinDeformer,
        name: &str,
    ) -> Result<Vec<Vec<(u32, f32)>>, IoError> {
        let vertex_count = mesh.num_vertices;
        let mut joint_of_cluster = Vec::with_capacity(skin.clusters.len());
        for cluster in skin.clusters.iter() {
            if let Some(&bad) = cluster
                .vertices
                .iter()
                .find(|&&v| v as usize >= vertex_count)
            {
                return Err(IoError::invalid(
                    self.path,
                    format!(
                        "cluster {:?} of mesh {name:?} weights vertex {bad}, but the mesh has \
                         {vertex_count} vertices",
                        cluster.element.name.to_string()
                    ),
                ));
            }
            joint_of_cluster.push(cluster.bone_node.as_ref().and_then(|bone| {
                self.joints
                    .of_node
                    .get(&(bone.element.typed_id as usize))
                    .copied()
            }));
        }
        let mut rows = Vec::with_capacity(vertex_count);
        for v in 0..vertex_count {
            let mut row: Vec<(u32, f64)> = Vec::new();
            if let Some(vertex) = skin.vertices.get(v) {
                let begin = vertex.weight_begin as usize;
                let end = begin + vertex.num_weights as usize;
                for weight in skin.weights.get(begin..end).unwrap_or_default() {
                    if !weight.weight.is_finite() || weight.weight < 0.0 {
                        return Err(IoError::invalid(
                            self.path,
                            format!(
                                "mesh {name:?}: vertex {v} has skin weight {}",
                                weight.weight
                            ),
                        ));
                    }
                    let joint = joint_of_cluster
                        .get(weight.cluster_index as usize)
                        .copied()
                        .flatten();
                    // Clusters of the same bone add up; zero weights are dropped.
                    let Some(joint) = joint.filter(|_| weight.weight > 0.0) else {
                        continue;
                    };
                    match row.iter_mut().find(|(j, _)| *j == joint) {
                        Some(entry) => entry.1 += weight.weight,
                        None => row.push((joint, weight.weight)),
                    }
                }
            }
            let sum: f64 = row.iter().map(|(_, w)| w).sum();
            if row.is_empty() {
                self.stored_sums.unweighted += 1;
            } else {
                self.stored_sums.rows += 1;
                if (sum - 1.0).abs() <= SUM_TOLERANCE {
                    self.stored_sums.summing_to_one += 1;
                }
            }
            rows.push(
                row.into_iter()
                    .map(|(j, w)| (j, (w / sum) as f32))
                    .collect(),
            );
        }
        Ok(rows)
    }

    /// The index of `material` in the character's materials, added on first use: its base
    /// colour (ufbx's PBR reading of the FBX material: diffuse colour × factor) clamped to
    /// [0, 1], white where not finite.
    fn material_index(&mut self, material: &ufbx::Material) -> u32 {
        let id = material.element.element_id;
        if let Some(&index) = self.material_of.get(&id) {
            return index;
        }
        let color = material.pbr.base_color.value_vec4;
        let factor = match &material.pbr.base_factor {
            f if f.has_value => f.value_vec4.x,
            _ => 1.0,
        };
        let rgb = [color.x, color.y, color.z].map(|c| c * factor);
        let base_color = [rgb[0], rgb[1], rgb[2], color.w].map(|c| {
            if c.is_finite() {
                c.clamp(0.0, 1.0) as f32
            } else {
                1.0
            }
        });
        let index = self.materials.len() as u32;
        self.materials.push(Material {
            name: material.element.name.to_string(),
            base_color,
        });
        self.material_of.insert(id, index);
        index
    }

    /// Whether `node` hangs under the same top node (child of the root) as the skeleton.
    fn shares_top_node(&self, scene: &ufbx::Scene, node: &ufbx::Node) -> bool {
        let top = |node: &ufbx::Node| {
            let mut current = node;
            for _ in 0..=scene.nodes.len() {
                match current.parent.as_deref() {
                    Some(parent) if !parent.is_root => current = parent,
                    _ => break,
                }
            }
            current.element.typed_id
        };
        let skeleton_top = top(&scene.nodes[self.joints.nodes[0]]);
        top(node) == skeleton_top
    }

    /// Appends `mesh`'s control points placed by `placement` (then converted to glTF's
    /// space) and its triangles, with one weight row per control point (`rows`, padded
    /// with empty rows; dropped when the stored weights are not read).
    fn push(
        &mut self,
        mesh: &ufbx::Mesh,
        name: &str,
        placement: DMat4,
        binding: PartBinding,
        rows: Vec<Vec<(u32, f32)>>,
    ) -> Result<(), IoError> {
        let first = self.mesh.positions.len();
        for (v, p) in mesh.vertices.iter().enumerate() {
            let stored = DVec3::new(p.x, p.y, p.z);
            let position = self.space.point(placement.transform_point3(stored));
            if !position.is_finite() {
                return Err(IoError::invalid(
                    self.path,
                    format!("mesh {name:?}: vertex {v} {stored} is not finite once placed"),
                ));
            }
            self.mesh.positions.push(position.as_vec3());
        }
        let first_triangle = self.mesh.triangles.len();
        let mut corners = Vec::new();
        for (f, &face) in mesh.faces.iter().enumerate() {
            ufbx::triangulate_face_vec(&mut corners, mesh, face);
            let material = mesh
                .face_material
                .get(f)
                .and_then(|&m| mesh.materials.get(m as usize))
                .map(|m| self.material_index(m));
            for t in corners.chunks_exact(3) {
                let vertex = |k: usize| -> Result<u32, IoError> {
                    let v = mesh.vertex_indices.get(t[k] as usize).copied();
                    v.filter(|&v| (v as usize) < mesh.vertices.len())
                        .map(|v| v + first as u32)
                        .ok_or_else(|| {
                            IoError::invalid(
                                self.path,
                                format!("mesh {name:?}: a face corner is out of range"),
                            )
                        })
                };
                let (a, b, c) = (vertex(0)?, vertex(1)?, vertex(2)?);
                self.mesh.triangles.push(if self.space.mirrored {
                    [a, c, b]
                } else {
                    [a, b, c]
                });
                self.triangle_materials.push(material);
            }
        }
        if let Some(all) = &mut self.rows {
            all.extend(rows);
            all.resize(self.mesh.positions.len(), Vec::new());
        }
        self.parts.push(MeshPart {
            name: name.to_string(),
            vertices: first..self.mesh.positions.len(),
            triangles: first_triangle..self.mesh.triangles.len(),
            binding,
        });
        Ok(())
    }
}
