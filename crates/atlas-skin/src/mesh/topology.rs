//! Connectivity of a triangle surface: edges, adjacency, components, boundary, genus.

use super::surface::SurfaceMesh;
use super::union_find::UnionFind;
use crate::tolerance::FLAT;

/// A vertex not yet given a component by [`vertex_components`].
const UNLABELLED: u32 = u32::MAX;

/// Edges and adjacency of a [`SurfaceMesh`], built once and passed to later stages.
///
/// Edge `e` joins `edges[e] = [a, b]` with `a < b`. Triangle `f`'s edge `i` joins its corners
/// `i` and `(i + 1) % 3` and is `face_edges[f][i]`. Compressed rows: the faces around edge `e`
/// are `edge_faces[edge_face_offsets[e]..edge_face_offsets[e + 1]]` (1 on a boundary, 2 inside
/// a manifold, more on a non-manifold edge); likewise `vertex_faces` and `vertex_neighbors`.
/// Vertex `v` lies in connected component `vertex_component[v]` of `component_count`
/// (vertices joined by triangles), numbered by first vertex; a vertex no triangle uses is
/// a component of its own.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Topology {
    pub edges: Vec<[u32; 2]>,
    pub face_edges: Vec<[u32; 3]>,
    pub edge_face_offsets: Vec<u32>,
    pub edge_faces: Vec<u32>,
    pub vertex_face_offsets: Vec<u32>,
    pub vertex_faces: Vec<u32>,
    pub vertex_neighbor_offsets: Vec<u32>,
    pub vertex_neighbors: Vec<u32>,
    pub vertex_component: Vec<u32>,
    pub component_count: usize,
}

impl Topology {
    /// Builds the topology of `mesh` in O(V + F): the half-edges are grouped by their
    /// smaller vertex with a counting sort (which keeps the stored order (f, i) within a
    /// group), then each group, a few entries, is sorted by its larger vertex (keys
    /// `b · 2³² + 3f + i`, unique, so the order is that of a stable sort by b),
    /// which gives the order (a, b, f, i) of edges and of their faces. The components are
    /// labelled here, once for every stage that reads them (the inside-out pieces, the
    /// holding regions, the loose pieces of the weights).
    pub fn new(mesh: &SurfaceMesh) -> Self {
        let nv = mesh.vertex_count();
        let triangles = &mesh.triangles;
        let half_edges = |t: &[u32; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
        let mut half_offsets = vec![0u32; nv + 1];
        for t in triangles {
            for (a, b) in half_edges(t) {
                half_offsets[a.min(b) as usize + 1] += 1;
            }
        }
        prefix_sums(&mut half_offsets);
        let mut next = half_offsets[..nv].to_vec();
        let mut half = vec![0u64; 3 * triangles.len()];
        for (f, t) in triangles.iter().enumerate() {
            for (i, (a, b)) in half_edges(t).into_iter().enumerate() {
                let slot = &mut next[a.min(b) as usize];
                half[*slot as usize] = (u64::from(a.max(b)) << 32) | (3 * f + i) as u64;
                *slot += 1;
            }
        }
        let mut edges = Vec::new();
        let mut face_edges = vec![[0u32; 3]; triangles.len()];
        let mut edge_face_offsets = vec![0u32];
        let mut edge_faces = Vec::with_capacity(half.len());
        for a in 0..nv {
            let group = &mut half[half_offsets[a] as usize..half_offsets[a + 1] as usize];
            sort_group(group);
            let mut previous = None;
            for &key in group.iter() {
                let (b, k) = ((key >> 32) as u32, (key & u64::from(u32::MAX)) as usize);
                if previous != Some(b) {
                    if !edges.is_empty() {
                        edge_face_offsets.push(edge_faces.len() as u32);
                    }
                    edges.push([a as u32, b]);
                    previous = Some(b);
                }
                face_edges[k / 3][k % 3] = edges.len() as u32 - 1;
                edge_faces.push((k / 3) as u32);
            }
        }
        if !edges.is_empty() {
            edge_face_offsets.push(edge_faces.len() as u32);
        }

        // Both row sets come sorted: a vertex's faces in stored order, its neighbours x < v
        // (edges (x, v)) before those y > v (edges (v, y)), each in edge order.
        let mut vertex_face_offsets = vec![0u32; nv + 1];
        for t in triangles {
            for &v in t {
                vertex_face_offsets[v as usize + 1] += 1;
            }
        }
        prefix_sums(&mut vertex_face_offsets);
        next.copy_from_slice(&vertex_face_offsets[..nv]);
        let mut vertex_faces = vec![0u32; 3 * triangles.len()];
        for (f, t) in triangles.iter().enumerate() {
            for &v in t {
                let slot = &mut next[v as usize];
                vertex_faces[*slot as usize] = f as u32;
                *slot += 1;
            }
        }
        // Edge e seen from its first end, then from its second.
        let mut vertex_neighbor_offsets = vec![0u32; nv + 1];
        for &[a, b] in edges.iter().filter(|[a, b]| a != b) {
            vertex_neighbor_offsets[a as usize + 1] += 1;
            vertex_neighbor_offsets[b as usize + 1] += 1;
        }
        prefix_sums(&mut vertex_neighbor_offsets);
        next.copy_from_slice(&vertex_neighbor_offsets[..nv]);
        let mut vertex_neighbors = vec![0u32; vertex_neighbor_offsets[nv] as usize];
        for &[a, b] in edges.iter().filter(|[a, b]| a != b) {
            for (from, to) in [(a, b), (b, a)] {
                let slot = &mut next[from as usize];
                vertex_neighbors[*slot as usize] = to;
                *slot += 1;
            }
        }
        let (vertex_component, component_count) =
            vertex_components(&vertex_neighbor_offsets, &vertex_neighbors);
        Self {
            edges,
            face_edges,
            edge_face_offsets,
            edge_faces,
            vertex_face_offsets,
            vertex_faces,
            vertex_neighbor_offsets,
            vertex_neighbors,
            vertex_component,
            component_count,
        }
    }

    /// Faces around edge `e`.
    pub fn faces_of_edge(&self, e: usize) -> &[u32] {
        &self.edge_faces[self.edge_face_offsets[e] as usize..self.edge_face_offsets[e + 1] as usize]
    }

    /// Faces around vertex `v`.
    pub fn faces_of_vertex(&self, v: usize) -> &[u32] {
        &self.vertex_faces
            [self.vertex_face_offsets[v] as usize..self.vertex_face_offsets[v + 1] as usize]
    }

    /// Vertices joined to `v` by an edge.
    pub fn neighbors(&self, v: usize) -> &[u32] {
        &self.vertex_neighbors
            [self.vertex_neighbor_offsets[v] as usize..self.vertex_neighbor_offsets[v + 1] as usize]
    }

    /// Faces sharing an edge with face `f` (across manifold and non-manifold edges).
    pub fn face_neighbors(&self, f: usize) -> impl Iterator<Item = u32> + '_ {
        self.face_edges[f]
            .iter()
            .flat_map(move |&e| self.faces_of_edge(e as usize).iter().copied())
            .filter(move |&g| g as usize != f)
    }
}

/// Component index of every vertex of the rows `neighbor_offsets`, `neighbors` (#V + 1 and
/// 2E), by a depth-first walk from each unlabelled vertex in order, so numbered by first
/// vertex. Returns (#V labels, count).
fn vertex_components(neighbor_offsets: &[u32], neighbors: &[u32]) -> (Vec<u32>, usize) {
    let n = neighbor_offsets.len() - 1;
    let mut label = vec![UNLABELLED; n];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for start in 0..n {
        if label[start] != UNLABELLED {
            continue;
        }
        label[start] = count;
        stack.push(start);
        while let Some(v) = stack.pop() {
            let row = neighbor_offsets[v] as usize..neighbor_offsets[v + 1] as usize;
            for &u in &neighbors[row] {
                if label[u as usize] == UNLABELLED {
                    label[u as usize] = count;
                    stack.push(u as usize);
                }
            }
        }
        count += 1;
    }
    (label, count as usize)
}

/// Turns counts `c[1..]` (with `c[0] = 0`) into offsets: `c[i]` becomes the sum of the
/// counts before row i.
fn prefix_sums(counts: &mut [u32]) {
    for i in 1..counts.len() {
        counts[i] += counts[i - 1];
    }
}

/// Sorts the half-edges around one vertex: a few entries by insertion (where the library
/// sort's set-up costs more than the sort), a long group (a fan's centre) by the library.
fn sort_group(keys: &mut [u64]) {
    if keys.len() > 16 {
        keys.sort_unstable();
        return;
    }
    for i in 1..keys.len() {
        let key = keys[i];
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            j -= 1;
        }
        keys[j] = key;
    }
}

/// Facts about one connected component.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComponentStats {
    pub vertices: usize,
    pub triangles: usize,
    pub closed: bool,
    pub euler: i64,
    pub boundary_loops: usize,
    /// g = (2 − χ − b) / 2 for an orientable surface with b boundary loops.
    pub genus: i64,
}

/// Facts about a whole surface, as `atlas-skin inspect` reports them.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MeshStats {
    pub vertices: usize,
    pub triangles: usize,
    pub edges: usize,
    pub components: usize,
    /// Every edge has exactly two faces.
    pub closed: bool,
    pub boundary_edges: usize,
    pub boundary_loops: usize,
    pub nonmanifold_edges: usize,
    /// Interior edges whose two faces run along them in the same direction.
    pub inconsistently_oriented_edges: usize,
    /// Triangles with a repeated vertex or an area below 1e-12 × diagonal².
    pub degenerate_triangles: usize,
    /// χ = V − E + F over vertices used by triangles.
    pub euler_characteristic: i64,
    /// Σ over components of their genus, when the surface is closed.
    pub genus: Option<i64>,
    pub per_component: Vec<ComponentStats>,
}

impl MeshStats {
    /// Measures `mesh` with its `topology`.
    pub fn new(mesh: &SurfaceMesh, topology: &Topology) -> Self {
        let (label, count) = (&topology.vertex_component, topology.component_count);
        let mut per = vec![(0usize, 0usize, 0usize, 0usize); count]; // V, E, F, boundary edges
        let mut used = vec![false; mesh.vertex_count()];
        for t in &mesh.triangles {
            for &v in t {
                used[v as usize] = true;
            }
            per[label[t[0] as usize] as usize].2 += 1;
        }
        for (v, &u) in used.iter().enumerate() {
            if u {
                per[label[v] as usize].0 += 1;
            }
        }
        let edges = edge_census(mesh, topology, label, &mut per);
        let (boundary_edges, nonmanifold_edges, inconsistent, loops_per) = (
            edges.boundary,
            edges.nonmanifold,
            edges.inconsistently_oriented,
            edges.loops_per_component,
        );
        let degenerate_triangles = degenerate_triangles(mesh);
        let per_component: Vec<ComponentStats> = per
            .iter()
            .zip(&loops_per)
            .filter(|((v, _, f, _), _)| *v > 0 && *f > 0)
            .map(|(&(v, e, f, b), &loops)| {
                let euler = v as i64 - e as i64 + f as i64;
                ComponentStats {
                    vertices: v,
                    triangles: f,
                    closed: b == 0,
                    euler,
                    boundary_loops: loops,
                    genus: (2 - euler - loops as i64) / 2,
                }
            })
            .collect();
        let closed = boundary_edges == 0 && nonmanifold_edges == 0;
        let euler_characteristic = per_component.iter().map(|c| c.euler).sum();
        Self {
            vertices: used.iter().filter(|&&u| u).count(),
            triangles: mesh.triangle_count(),
            edges: topology.edges.len(),
            components: per_component.len(),
            closed,
            boundary_edges,
            boundary_loops: loops_per.iter().sum(),
            nonmanifold_edges,
            inconsistently_oriented_edges: inconsistent,
            degenerate_triangles,
            euler_characteristic,
            genus: closed.then(|| per_component.iter().map(|c| c.genus).sum()),
            per_component,
        }
    }
}

/// Edges of a surface by kind, for [`MeshStats`].
struct EdgeCensus {
    boundary: usize,
    nonmanifold: usize,
    inconsistently_oriented: usize,
    /// Boundary loops of every component.
    loops_per_component: Vec<usize>,
}

/// Counts boundary (one face), non-manifold (three or more) and inconsistently oriented
/// (two faces running the edge the same way) edges and the boundary loops per component;
/// adds every edge, and every boundary edge, to its component's entry of `per`
/// ((V, E, F, boundary edges) per component of `label`).
fn edge_census(
    mesh: &SurfaceMesh,
    topology: &Topology,
    label: &[u32],
    per: &mut [(usize, usize, usize, usize)],
) -> EdgeCensus {
    let mut boundary_edges = 0;
    let mut nonmanifold_edges = 0;
    let mut inconsistent = 0;
    let mut boundary_sets = UnionFind::new(mesh.vertex_count());
    let mut boundary_vertex = vec![false; mesh.vertex_count()];
    for (e, &[a, b]) in topology.edges.iter().enumerate() {
        let c = label[a as usize] as usize;
        per[c].1 += 1;
        let faces = topology.faces_of_edge(e);
        match faces.len() {
            1 => {
                boundary_edges += 1;
                per[c].3 += 1;
                boundary_vertex[a as usize] = true;
                boundary_vertex[b as usize] = true;
                boundary_sets.union(a, b);
            }
            2 => {
                let forward = |f: u32| {
                    let t = mesh.triangles[f as usize];
                    (0..3).any(|i| t[i] == a && t[(i + 1) % 3] == b)
                };
                if forward(faces[0]) == forward(faces[1]) {
                    inconsistent += 1;
                }
            }
            _ => nonmanifold_edges += 1,
        }
    }
    let mut loops_per = vec![0usize; per.len()];
    for v in 0..mesh.vertex_count() {
        if boundary_vertex[v] && boundary_sets.find(v as u32) == v as u32 {
            loops_per[label[v] as usize] += 1;
        }
    }
    EdgeCensus {
        boundary: boundary_edges,
        nonmanifold: nonmanifold_edges,
        inconsistently_oriented: inconsistent,
        loops_per_component: loops_per,
    }
}

/// Triangles with a repeated corner or an area of at most [`FLAT`] times the squared
/// diagonal.
fn degenerate_triangles(mesh: &SurfaceMesh) -> usize {
    let diag2 = mesh.diagonal().powi(2);
    (0..mesh.triangle_count())
        .filter(|&f| {
            let t = mesh.triangles[f];
            t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || mesh.triangle_area(f) <= FLAT * diag2
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn tetrahedron() -> SurfaceMesh {
        SurfaceMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        }
    }

    /// The reference: half-edges sorted as tuples (a, b, f, i), rows sorted one by one.
    fn reference_topology(mesh: &SurfaceMesh) -> Topology {
        let nv = mesh.vertex_count();
        let mut half: Vec<(u32, u32, u32, u8)> = Vec::new();
        for (f, t) in mesh.triangles.iter().enumerate() {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                half.push((a.min(b), a.max(b), f as u32, i as u8));
            }
        }
        half.sort_unstable();
        let mut topology = Topology {
            face_edges: vec![[0u32; 3]; mesh.triangles.len()],
            edge_face_offsets: vec![0],
            ..Topology::default()
        };
        for (k, &(a, b, f, i)) in half.iter().enumerate() {
            if k > 0 && (half[k - 1].0, half[k - 1].1) != (a, b) {
                topology
                    .edge_face_offsets
                    .push(topology.edge_faces.len() as u32);
            }
            if k == 0 || (half[k - 1].0, half[k - 1].1) != (a, b) {
                topology.edges.push([a, b]);
            }
            topology.face_edges[f as usize][i as usize] = topology.edges.len() as u32 - 1;
            topology.edge_faces.push(f);
        }
        if !half.is_empty() {
            topology
                .edge_face_offsets
                .push(topology.edge_faces.len() as u32);
        }
        let sorted_rows = |pairs: Vec<(u32, u32)>| {
            let mut rows = vec![Vec::new(); nv];
            for (k, v) in pairs {
                rows[k as usize].push(v);
            }
            let mut offsets = vec![0u32];
            let mut values = Vec::new();
            for mut row in rows {
                row.sort_unstable();
                values.extend(row);
                offsets.push(values.len() as u32);
            }
            (offsets, values)
        };
        (topology.vertex_face_offsets, topology.vertex_faces) = sorted_rows(
            mesh.triangles
                .iter()
                .enumerate()
                .flat_map(|(f, t)| t.iter().map(move |&v| (v, f as u32)))
                .collect(),
        );
        (topology.vertex_neighbor_offsets, topology.vertex_neighbors) = sorted_rows(
            topology
                .edges
                .iter()
                .filter(|e| e[0] != e[1])
                .flat_map(|e| [(e[0], e[1]), (e[1], e[0])])
                .collect(),
        );
        topology
    }

    /// Random triangles over few vertices (non-manifold edges, repeated corners, unused
    /// vertices), the demo's welded surface and an empty mesh: the counting sort builds
    /// the reference's topology and components.
    #[test]
    fn counting_sort_gives_the_reference_topology() {
        let mut rng = atlas_skin_runtime::random_pose::SplitMix64::new(5);
        let mut meshes = vec![
            SurfaceMesh {
                positions: vec![DVec3::ZERO; 3],
                triangles: Vec::new(),
            },
            tetrahedron(),
        ];
        for n in [4, 9, 30] {
            let mut pick = || (rng.next_f64() * n as f64) as u32;
            meshes.push(SurfaceMesh {
                positions: vec![DVec3::ZERO; n + 2],
                triangles: (0..3 * n).map(|_| [pick(), pick(), pick()]).collect(),
            });
        }
        let demo = crate::fixtures::demo::demo_character(0.03);
        meshes.push(
            crate::mesh::weld(
                &demo.positions,
                &demo.triangles,
                crate::mesh::weld::DEFAULT_WELD_TOLERANCE,
            )
            .mesh,
        );
        for mesh in &meshes {
            let (fast, reference) = (Topology::new(mesh), reference_topology(mesh));
            assert_eq!(fast.edges, reference.edges);
            assert_eq!(fast.face_edges, reference.face_edges);
            assert_eq!(fast.edge_face_offsets, reference.edge_face_offsets);
            assert_eq!(fast.edge_faces, reference.edge_faces);
            assert_eq!(fast.vertex_face_offsets, reference.vertex_face_offsets);
            assert_eq!(fast.vertex_faces, reference.vertex_faces);
            assert_eq!(
                fast.vertex_neighbor_offsets,
                reference.vertex_neighbor_offsets
            );
            assert_eq!(fast.vertex_neighbors, reference.vertex_neighbors);
            let (component, count) = reference_components(mesh);
            assert_eq!(fast.vertex_component, component);
            assert_eq!(fast.component_count, count);
        }
    }

    /// The reference components: corners of a triangle joined in a union–find, the sets
    /// numbered in the order of their first vertex.
    fn reference_components(mesh: &SurfaceMesh) -> (Vec<u32>, usize) {
        let mut sets = UnionFind::new(mesh.vertex_count());
        for &[a, b, c] in &mesh.triangles {
            sets.union(a, b);
            sets.union(b, c);
        }
        let mut number_of_root = vec![u32::MAX; mesh.vertex_count()];
        let mut count = 0;
        let component = (0..mesh.vertex_count() as u32)
            .map(|v| {
                let root = sets.find(v) as usize;
                if number_of_root[root] == u32::MAX {
                    number_of_root[root] = count;
                    count += 1;
                }
                number_of_root[root]
            })
            .collect();
        (component, count as usize)
    }

    #[test]
    fn closed_tetrahedron_is_a_sphere() {
        let mesh = tetrahedron();
        let topo = Topology::new(&mesh);
        let stats = MeshStats::new(&mesh, &topo);
        assert_eq!(stats.edges, 6);
        assert!(stats.closed);
        assert_eq!(stats.euler_characteristic, 2);
        assert_eq!(stats.genus, Some(0));
        assert_eq!(stats.inconsistently_oriented_edges, 0);
        assert_eq!(topo.neighbors(0), &[1, 2, 3]);
        assert_eq!(topo.face_neighbors(0).count(), 3);
    }

    #[test]
    fn open_surface_has_boundary_loop_and_no_genus() {
        let mut mesh = tetrahedron();
        mesh.triangles.pop();
        let stats = MeshStats::new(&mesh, &Topology::new(&mesh));
        assert!(!stats.closed);
        assert_eq!(stats.boundary_edges, 3);
        assert_eq!(stats.boundary_loops, 1);
        assert_eq!(stats.euler_characteristic, 1);
        assert_eq!(stats.genus, None);
        assert_eq!(stats.per_component[0].genus, 0);
    }
}
