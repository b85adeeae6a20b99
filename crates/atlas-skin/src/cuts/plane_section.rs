//! Exact intersection of a plane with part of a triangle surface, chained into closed
//! curves (Lu et al. 2008 §3.1: "intersecting edges" chained into boundary curves).
//!
//! Sign rule. Vertex v has the signed distance d(v) = n · (x_v − o) to the plane through o
//! with unit normal n, snapped to 0 when |d(v)| < ε_v (ε_v = snap fraction × the longest
//! edge at v). A vertex is on the positive side when d(v) ≥ 0, so a vertex on the plane
//! counts as positive. An edge is crossed when its ends have different sides; its crossing
//! point is the end with d = 0 if there is one, else the interior point at
//! t = d(a) / (d(a) − d(b)) from a. Every triangle then has exactly 0 or 2 crossed edges, and
//! the crossing point of an edge depends on the edge alone, so curves chain without gaps and
//! faces split without slivers: an interior point has t ∈ [ε, 1 − ε] relative to the edge.

use crate::mesh::spatial_index::FaceSpheres;
use crate::mesh::{SurfaceMesh, Topology};
use glam::DVec3;

/// A plane through `point` with unit `normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub point: DVec3,
    pub normal: DVec3,
}

impl Plane {
    /// n · (p − o).
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p - self.point)
    }
}

/// Where a curve crosses an edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CrossingPoint {
    /// At a vertex of the surface (on the plane after snapping).
    Vertex(u32),
    /// Inside edge `edges[e] = [a, b]`, at `a + t (b − a)`, with t ∈ (0, 1).
    Interior(f64),
}

/// One crossed edge of a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCrossing {
    pub edge: u32,
    pub point: CrossingPoint,
}

impl EdgeCrossing {
    /// Position of the crossing point.
    pub fn position(&self, mesh: &SurfaceMesh, topology: &Topology) -> DVec3 {
        match self.point {
            CrossingPoint::Vertex(v) => mesh.positions[v as usize],
            CrossingPoint::Interior(t) => {
                let [a, b] = topology.edges[self.edge as usize];
                mesh.positions[a as usize].lerp(mesh.positions[b as usize], t)
            }
        }
    }
}

/// A closed curve: crossed edges in chain order. Consecutive crossings at the same vertex
/// are kept, one per edge.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionCurve {
    pub crossings: Vec<EdgeCrossing>,
    /// `faces[i]` holds the segment from crossing i to crossing i + 1 (cyclically).
    pub faces: Vec<u32>,
}

/// The segment of a curve inside one face, its ends as positions along the face's
/// boundary: s = k + τ on local edge k (from corner k to corner k + 1, τ ∈ [0, 1)), so a
/// corner k is s = k. Two chords of one face cross when their ends interleave on [0, 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chord {
    pub face: u32,
    pub ends: [f64; 2],
}

/// The faces a section is computed on (near one joint), with buffers reused by every
/// query. Everything is indexed locally (vertices, edges and faces of the domain), so that
/// building a domain costs O(its faces), not O(the mesh), and a query touches only the
/// domain's own arrays: it computes the signed distance and side of the domain's vertices
/// and scans its faces ([`SectionDomain::closed_sections`]); only crossed faces are traced,
/// through each local edge's faces across. (A large domain asked only for the sections
/// around a point is a [`NearRayDomain`], which builds none of this.)
#[derive(Debug, Clone)]
pub struct SectionDomain {
    /// Per local face: its face of the mesh, its corners and its edges (in the order of
    /// [`Topology::face_edges`]) as local indices.
    faces: Vec<u32>,
    local_faces: Vec<[u32; 3]>,
    local_face_edges: Vec<[u32; 3]>,
    /// Per local vertex: its vertex of the mesh, position, snap distance, signed distance
    /// and side (1 when d ≥ 0, else 0: a face is crossed when its corners' sides sum to 1
    /// or 2).
    vertices: Vec<u32>,
    local_positions: Vec<DVec3>,
    local_snap: Vec<f64>,
    /// Per local vertex: its position minus the point of the last query's plane (p − o of
    /// [`Plane::signed_distance`]), with that point's bits: the planes of one joint's
    /// search all pass through the joint, so the differences are taken once for them all
    /// (the same values, so the same distances).
    local_offsets: Vec<DVec3>,
    offsets_origin: Option<[u64; 3]>,
    local_distance: Vec<f64>,
    local_side: Vec<u8>,
    /// Per local edge: its edge of the mesh, its ends (local, in the order of
    /// [`Topology::edges`]), its two faces (local, in the order of
    /// [`Topology::faces_of_edge`]) when it is manifold with both in the domain, and the
    /// stamp of the last query that visited it.
    edges: Vec<u32>,
    edge_ends: Vec<[u32; 2]>,
    edge_faces: Vec<Option<[u32; 2]>>,
    edge_stamp: Vec<u32>,
    stamp: u32,
    /// The local faces a query crosses, in order (a buffer reused by every query).
    crossed_faces: Vec<u32>,
    chain: Chain,
}

/// The chain being traced: its crossings and faces (buffers reused by every trace).
#[derive(Debug, Clone, Default)]
struct Chain {
    crossings: Vec<EdgeCrossing>,
    faces: Vec<u32>,
}

/// What tracing a chain needs of a domain, its faces and edges indexed its own way (local
/// indices in a [`SectionDomain`], the mesh's in a [`NearRayDomain`]), for the plane of the
/// current query: one tracing for both.
trait ChainDomain {
    /// The edges of face `face`, in the order of [`Topology::face_edges`].
    fn face_edges(&self, face: u32) -> [u32; 3];
    /// Whether edge `e` has its ends on different sides.
    fn is_crossed(&mut self, e: u32) -> bool;
    fn crossing(&mut self, e: u32) -> EdgeCrossing;
    /// The face across edge `e` from `from`, if `e` is manifold and both its faces are in
    /// the domain (the first of them when there is no `from`).
    fn face_across(&self, e: u32, from: Option<u32>) -> Option<u32>;
    /// The mesh's index of face `face`.
    fn mesh_face(&self, face: u32) -> u32;
    /// Whether the current query has visited edge `e`.
    fn visited(&self, e: u32) -> bool;
    fn visit(&mut self, e: u32);
    fn chain(&mut self) -> &mut Chain;

    /// Traces from each crossed edge of crossed face `face` not yet visited by this query,
    /// adding the closed curves to `curves`.
    fn trace_from_face(&mut self, face: u32, curves: &mut Vec<SectionCurve>) {
        for e in self.face_edges(face) {
            if !self.visited(e) && self.is_crossed(e) {
                let mut chain = std::mem::take(self.chain());
                let curve = self.trace(e, &mut chain);
                *self.chain() = chain;
                if let Some(curve) = curve {
                    curves.push(curve);
                }
            }
        }
    }

    /// Follows the chain from crossed edge `start`; `Some` when it closes on `start`.
    fn trace(&mut self, start: u32, chain: &mut Chain) -> Option<SectionCurve> {
        self.visit(start);
        // The chain grows in buffers reused by every trace; a closed one is copied out at
        // its length (most chains of a query leave the domain and are dropped).
        let first = self.crossing(start);
        chain.crossings.clear();
        chain.crossings.push(first);
        chain.faces.clear();
        let (mut edge, mut from) = (start, None);
        loop {
            let face = self.face_across(edge, from)?;
            let mut others = self
                .face_edges(face)
                .into_iter()
                .filter(|&g| g != edge && self.is_crossed(g));
            let next = others.next()?;
            if others.next().is_some() {
                return None;
            }
            chain.faces.push(self.mesh_face(face));
            if next == start {
                return Some(SectionCurve {
                    crossings: chain.crossings.clone(),
                    faces: chain.faces.clone(),
                });
            }
            if self.visited(next) {
                return None;
            }
            self.visit(next);
            let crossing = self.crossing(next);
            chain.crossings.push(crossing);
            (edge, from) = (next, Some(face));
        }
    }
}

/// Where a chain crosses the edge with ends `a`, `b` (mesh vertices) at snapped signed
/// distances `da`, `db` (see the sign rule above).
#[inline(always)]
fn crossing_point(a: u32, b: u32, da: f64, db: f64) -> CrossingPoint {
    if da == 0.0 {
        CrossingPoint::Vertex(a)
    } else if db == 0.0 {
        CrossingPoint::Vertex(b)
    } else {
        CrossingPoint::Interior(da / (da - db))
    }
}

/// The signed distance of a vertex at `p` with snap distance `snap` to `plane`, snapped to
/// 0 (the sign rule above).
#[inline(always)]
fn snapped_distance(plane: &Plane, p: DVec3, snap: f64) -> f64 {
    snapped(plane.signed_distance(p), snap)
}

/// A vertex's signed distance `signed` snapped to 0 within its snap distance `snap`.
#[inline(always)]
fn snapped(signed: f64, snap: f64) -> f64 {
    if signed.abs() < snap {
        0.0
    } else {
        signed
    }
}

/// Whether the plane crosses a face: 1 or 2 of its corners on the non-negative side
/// (`side`: 1 for a vertex on the plane or its positive side, else 0).
#[inline(always)]
fn face_crossed(side: &[u8], [a, b, c]: [u32; 3]) -> bool {
    (side[a as usize] + side[b as usize] + side[c as usize]).wrapping_sub(1) < 2
}

/// Below this many faces a domain's scan (about 13 instructions a face, and the tracing of
/// every section) costs less than the descent of the face hierarchy along a segment (60 to
/// 80 boxes of about 120 instructions on the benchmark's characters) and the rotation of
/// the curves it finds (measured: 350, 500, 800 and 1,200 faces; 500 did least work). With
/// the larger domains built as [`NearRayDomain`]s, 250 and 350 did the same work as 500
/// to within 0.5%.
const SEGMENT_QUERY_FACES: usize = 500;

/// Maps from the mesh's vertices, edges and faces to a domain's (0, or 1 + the local
/// index) used while building a [`SectionDomain`]: allocated once per thread for the whole
/// mesh and cleared entry by entry, so that a domain costs O(its faces).
///
/// A [`NearRayDomain`] uses more maps: the stamp of the query that last visited each
/// edge, and of the query that last computed each vertex's snapped signed distance (kept
/// beside), with the last stamp given (a number that only grows, so that no map is cleared
/// but when it wraps).
#[derive(Debug, Clone, Default)]
pub struct DomainScratch {
    vertex: Vec<u32>,
    edge: Vec<u32>,
    face: Vec<u32>,
    edge_query: Vec<u32>,
    vertex_query: Vec<u32>,
    vertex_distance: Vec<f64>,
    query: u32,
}

impl DomainScratch {
    /// Grows the maps to the mesh's sizes (all zero; a zeroed allocation, whose pages the
    /// system provides as they are first touched).
    fn fit(&mut self, mesh: &SurfaceMesh, topology: &Topology) {
        for (map, n) in [
            (&mut self.vertex, mesh.vertex_count()),
            (&mut self.edge, topology.edges.len()),
            (&mut self.face, mesh.triangle_count()),
        ] {
            if map.len() < n {
                *map = vec![0; n];
            }
        }
    }

    /// Grows the maps of a [`NearRayDomain`] to the mesh's sizes (new entries hold no
    /// stamp: 0).
    fn fit_marks(&mut self, mesh: &SurfaceMesh, topology: &Topology) {
        let (edges, vertices) = (topology.edges.len(), mesh.vertex_count());
        if self.edge_query.len() < edges {
            self.edge_query.resize(edges, 0);
        }
        if self.vertex_query.len() < vertices {
            self.vertex_query.resize(vertices, 0);
            self.vertex_distance.resize(vertices, 0.0);
        }
    }

    /// A new query's stamp (never 0).
    fn next_query(&mut self) {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.edge_query.fill(0);
            self.vertex_query.fill(0);
            self.query = 1;
        }
    }
}

/// [`DomainScratch`]es lent to the jobs of a parallel loop and given back when a job ends,
/// so that the loop allocates as many as run at once (one a thread) rather than one a job:
/// rayon's `map_init` makes a new one for every piece it splits the loop into. A
/// scratch's maps span the mesh; at 5.4M triangles they are over glibc's 32 MB limit for
/// reusing freed blocks, so each new one was new memory that the kernel zeroes page by
/// page (the plane search's page faults on two threads: 6 thousand at 1.15M triangles,
/// 91–111 thousand at 5.4M).
#[derive(Debug, Default)]
pub struct ScratchPool(std::sync::Mutex<Vec<DomainScratch>>);

impl ScratchPool {
    /// A scratch given back earlier, or a new one.
    pub fn lend(&self) -> LentScratch<'_> {
        let scratch = self.0.lock().ok().and_then(|mut free| free.pop());
        LentScratch {
            pool: self,
            scratch: scratch.unwrap_or_default(),
        }
    }
}

/// A [`DomainScratch`] of a [`ScratchPool`], given back when dropped.
#[derive(Debug)]
pub struct LentScratch<'a> {
    pool: &'a ScratchPool,
    scratch: DomainScratch,
}

impl std::ops::Deref for LentScratch<'_> {
    type Target = DomainScratch;
    fn deref(&self) -> &DomainScratch {
        &self.scratch
    }
}

impl std::ops::DerefMut for LentScratch<'_> {
    fn deref_mut(&mut self) -> &mut DomainScratch {
        &mut self.scratch
    }
}

impl Drop for LentScratch<'_> {
    fn drop(&mut self) {
        if let Ok(mut free) = self.pool.0.lock() {
            free.push(std::mem::take(&mut self.scratch));
        }
    }
}

/// Snap distance of every vertex: `fraction` × its longest incident edge (0 for an isolated
/// vertex).
pub fn vertex_snap_distances(mesh: &SurfaceMesh, topology: &Topology, fraction: f64) -> Vec<f64> {
    let mut snap = vec![0.0f64; mesh.vertex_count()];
    for &[a, b] in &topology.edges {
        let length = mesh.positions[a as usize].distance(mesh.positions[b as usize]);
        for v in [a, b] {
            snap[v as usize] = snap[v as usize].max(fraction * length);
        }
    }
    snap
}

impl SectionDomain {
    /// A domain of `faces` of `mesh`; faces with a repeated vertex index are left out (a
    /// curve reaching them is open). `scratch` maps the mesh's indices to local ones while
    /// building and is left clean for the next domain.
    pub fn new(
        mesh: &SurfaceMesh,
        topology: &Topology,
        vertex_snap: &[f64],
        faces: Vec<u32>,
        scratch: &mut DomainScratch,
    ) -> Self {
        let faces = proper_faces(mesh, faces);
        scratch.fit(mesh, topology);
        let DomainScratch {
            vertex: local_vertex_of,
            edge: local_edge_of,
            face: local_face_of,
            ..
        } = scratch;
        // At most three of each per face: the lists never grow.
        let mut vertices = Vec::with_capacity(3 * faces.len());
        let mut edges = Vec::with_capacity(3 * faces.len());
        // Slot 0 means "not yet local"; a local index is stored plus one.
        let local = |slots: &mut [u32], list: &mut Vec<u32>, global: u32| {
            let slot = &mut slots[global as usize];
            if *slot == 0 {
                list.push(global);
                *slot = list.len() as u32;
            }
            *slot - 1
        };
        for (i, &f) in faces.iter().enumerate() {
            local_face_of[f as usize] = i as u32 + 1;
        }
        // Corners and edges read one by one: `array::map` is not inlined here, and these
        // loops are most of a domain's cost.
        let mut local_faces = Vec::with_capacity(faces.len());
        let mut local_face_edges = Vec::with_capacity(faces.len());
        for &f in &faces {
            let [a, b, c] = mesh.triangles[f as usize];
            local_faces.push([
                local(local_vertex_of, &mut vertices, a),
                local(local_vertex_of, &mut vertices, b),
                local(local_vertex_of, &mut vertices, c),
            ]);
            let [d, e, g] = topology.face_edges[f as usize];
            local_face_edges.push([
                local(local_edge_of, &mut edges, d),
                local(local_edge_of, &mut edges, e),
                local(local_edge_of, &mut edges, g),
            ]);
        }
        let in_domain = |f: u32| local_face_of[f as usize].checked_sub(1);
        let mut edge_ends = Vec::with_capacity(edges.len());
        let mut edge_faces = Vec::with_capacity(edges.len());
        for &e in &edges {
            let [a, b] = topology.edges[e as usize];
            edge_ends.push([
                local_vertex_of[a as usize] - 1,
                local_vertex_of[b as usize] - 1,
            ]);
            edge_faces.push(match topology.faces_of_edge(e as usize) {
                &[f, g] => in_domain(f).zip(in_domain(g)).map(|(f, g)| [f, g]),
                _ => None,
            });
        }
        for &v in &vertices {
            local_vertex_of[v as usize] = 0;
        }
        for &e in &edges {
            local_edge_of[e as usize] = 0;
        }
        for &f in &faces {
            local_face_of[f as usize] = 0;
        }
        let local_positions: Vec<DVec3> = vertices
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect();
        let local_snap: Vec<f64> = vertices.iter().map(|&v| vertex_snap[v as usize]).collect();
        Self {
            faces,
            local_faces,
            local_face_edges,
            local_offsets: vec![DVec3::ZERO; local_positions.len()],
            offsets_origin: None,
            local_positions,
            local_snap,
            local_distance: vec![0.0; vertices.len()],
            local_side: vec![0; vertices.len()],
            vertices,
            edge_stamp: vec![0; edges.len()],
            edges,
            edge_ends,
            edge_faces,
            stamp: 0,
            crossed_faces: Vec::new(),
            chain: Chain::default(),
        }
    }

    /// The closed curves in which `plane` meets the domain's faces. A chain that leaves the
    /// domain (a face outside it, a boundary or non-manifold edge) is open and dropped.
    /// Cost O(faces of the domain).
    pub fn closed_sections(&mut self, plane: &Plane) -> Vec<SectionCurve> {
        self.classify(plane);
        // The crossed faces first (a read-only scan, the hot loop), then the tracing.
        let mut crossed = std::mem::take(&mut self.crossed_faces);
        crossed.clear();
        // A slice, not the vector, so that its start and length stay in registers.
        let side: &[u8] = &self.local_side;
        for (i, &face) in self.local_faces.iter().enumerate() {
            if face_crossed(side, face) {
                crossed.push(i as u32);
            }
        }
        let mut curves = Vec::new();
        for &i in &crossed {
            self.trace_from_face(i, &mut curves);
        }
        self.crossed_faces = crossed;
        curves
    }

    /// Computes every vertex's signed distance and side for `plane` and starts a new stamp.
    fn classify(&mut self, plane: &Plane) {
        let origin = plane.point.to_array().map(f64::to_bits);
        if self.offsets_origin != Some(origin) {
            for (q, p) in self.local_offsets.iter_mut().zip(&self.local_positions) {
                *q = *p - plane.point;
            }
            self.offsets_origin = Some(origin);
        }
        for ((d, side), (q, snap)) in self
            .local_distance
            .iter_mut()
            .zip(&mut self.local_side)
            .zip(self.local_offsets.iter().zip(&self.local_snap))
        {
            // `snapped_distance` of the vertex: n · (p − o), with p − o kept.
            *d = snapped(plane.normal.dot(*q), *snap);
            *side = u8::from(*d >= 0.0);
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.edge_stamp.fill(0);
            self.stamp = 1;
        }
    }
}

impl ChainDomain for SectionDomain {
    fn face_edges(&self, face: u32) -> [u32; 3] {
        self.local_face_edges[face as usize]
    }

    fn is_crossed(&mut self, e: u32) -> bool {
        let [a, b] = self.edge_ends[e as usize];
        self.local_side[a as usize] != self.local_side[b as usize]
    }

    fn crossing(&mut self, e: u32) -> EdgeCrossing {
        let [a, b] = self.edge_ends[e as usize];
        EdgeCrossing {
            edge: self.edges[e as usize],
            point: crossing_point(
                self.vertices[a as usize],
                self.vertices[b as usize],
                self.local_distance[a as usize],
                self.local_distance[b as usize],
            ),
        }
    }

    fn face_across(&self, e: u32, from: Option<u32>) -> Option<u32> {
        let faces = self.edge_faces[e as usize]?;
        match from {
            Some(g) if faces[0] == g => Some(faces[1]),
            _ => Some(faces[0]),
        }
    }

    fn mesh_face(&self, face: u32) -> u32 {
        self.faces[face as usize]
    }

    fn visited(&self, e: u32) -> bool {
        self.edge_stamp[e as usize] == self.stamp
    }

    fn visit(&mut self, e: u32) {
        self.edge_stamp[e as usize] = self.stamp;
    }

    fn chain(&mut self) -> &mut Chain {
        &mut self.chain
    }
}

/// The faces near one joint, asked only for the closed sections around the joint's point
/// ([`NearRayDomain::sections_around`]): a large domain, of which a plane's query traces
/// the few crossed faces near one ray. Nothing is gathered or indexed locally: a face is in
/// the domain when its sphere comes within the domain's radius of its centre (the test of
/// [`FaceSpheres::faces_near`]) and it has no repeated vertex index, a vertex's signed
/// distance is computed when a query's tracing first reads it (and kept for the query in
/// the mesh-sized maps of [`DomainScratch`]), and the edges a query visits are stamped
/// there too. Building one costs nothing per face, where gathering the faces of the ball
/// cost each joint the surface within 4 r of it: a tree of 5,461 joints spread through a
/// sphere of 100,000 vertices gathered most of the sphere for each of its 2,167 searched
/// joints (issue 45); a [`SectionDomain`] costs about 315 instructions a face (on
/// makehuman) for local arrays that such a query barely reads. The tracing is the same
/// (the trait `ChainDomain`).
#[derive(Debug)]
pub struct NearRayDomain<'a> {
    mesh: &'a SurfaceMesh,
    topology: &'a Topology,
    vertex_snap: &'a [f64],
    spheres: &'a FaceSpheres,
    scratch: &'a mut DomainScratch,
    /// The domain's ball: the faces whose spheres come within `radius` of `centre`.
    centre: DVec3,
    radius: f64,
    /// The plane of the current query.
    plane: Plane,
    /// A box holding the domain's vertices (the ball grown by the largest face's
    /// diameter) and the largest snap distance of the mesh's vertices (what
    /// [`Self::sections_around`] bounds its segment by).
    bounds: [DVec3; 2],
    max_snap: f64,
    /// The mesh faces near a query's segment (a buffer reused by every query).
    segment_faces: Vec<u32>,
    chain: Chain,
}

impl<'a> NearRayDomain<'a> {
    /// The domain of the faces of `mesh` (indexed by `spheres`) whose spheres come within
    /// `radius` of `centre`, but those with a repeated vertex index; `max_snap`: the
    /// largest of `vertex_snap`.
    fn new(
        mesh: &'a SurfaceMesh,
        topology: &'a Topology,
        (vertex_snap, max_snap): (&'a [f64], f64),
        spheres: &'a FaceSpheres,
        (centre, radius): (DVec3, f64),
        scratch: &'a mut DomainScratch,
    ) -> Self {
        scratch.fit_marks(mesh, topology);
        // A vertex of a face in the domain lies within the face's radius r of its centre,
        // which lies within `radius` + r of `centre`.
        let reach = DVec3::splat(radius + 2.0 * spheres.max_radius());
        Self {
            mesh,
            topology,
            vertex_snap,
            spheres,
            scratch,
            centre,
            radius,
            plane: Plane {
                point: DVec3::ZERO,
                normal: DVec3::Z,
            },
            bounds: [centre - reach, centre + reach],
            max_snap,
            segment_faces: Vec::new(),
            chain: Chain::default(),
        }
    }

    /// The closed sections that can contain the plane's point, as
    /// [`JointSections::sections_around`] gives them, through the faces near the ray of
    /// [`polygon_contains`].
    ///
    /// Why they are all there: with (u, w) the plane's axes of [`polygon_contains`], a curve
    /// containing o = `plane.point` has a segment q₀q₁ that its test sees crossing the ray
    /// o + s·u, s > 0, so a point q of the segment (of one face) has |(q − o)·w| ≤ δ and
    /// (q − o)·u ≥ −δ for the test's rounding δ, and |(q − o)·n| ≤ ε_max + δ (a crossing
    /// at a snapped vertex is off the plane by less than its snap distance ε_v): the face
    /// comes within ε_max + 3δ of the segment from o along u to where the ray leaves the
    /// domain's box grown by that much. Only the faces near that segment (from the hierarchy
    /// of `spheres`) and crossed are traced; δ is taken as 10⁻⁹ of the coordinates' size,
    /// far above the rounding of a few units in the last place. A closed curve is the same
    /// from any of its edges but for where it starts: [`SectionDomain::closed_sections`]
    /// reaches it first at its lowest face, from that face's first crossed edge, which is
    /// where it is rotated to.
    pub fn sections_around(&mut self, plane: &Plane) -> Vec<SectionCurve> {
        let spheres = self.spheres;
        self.plane = *plane;
        self.scratch.next_query();
        let o = plane.point;
        let (u, _) = plane.normal.any_orthonormal_pair();
        let [lo, hi] = self.bounds;
        let slack = 1e-9 * ((hi - lo).length() + lo.abs().max(hi.abs()).max(o.abs()).max_element());
        let radius = self.max_snap + slack;
        // Where the ray leaves the domain's box grown by the radius: no face of the domain
        // comes within the radius of the ray beyond.
        let exit = |axis: usize| match u[axis] {
            d if d > 0.0 => (hi[axis] + radius - o[axis]) / d,
            d if d < 0.0 => (lo[axis] - radius - o[axis]) / d,
            _ if (lo[axis] - radius..=hi[axis] + radius).contains(&o[axis]) => f64::INFINITY,
            _ => f64::NEG_INFINITY,
        };
        let length = exit(0).min(exit(1)).min(exit(2)) + slack;
        let mut near = std::mem::take(&mut self.segment_faces);
        near.clear();
        if length >= 0.0 {
            spheres.faces_near_segment(o, u, length, radius, &mut near);
        }
        let mut curves = Vec::new();
        for &f in &near {
            if self.holds(f) && self.face_crossed(f) {
                self.trace_from_face(f, &mut curves);
            }
        }
        self.segment_faces = near;
        let mut ordered: Vec<(u32, SectionCurve)> = curves
            .into_iter()
            .map(|curve| self.as_closed_sections_has_it(curve))
            .collect();
        ordered.sort_unstable_by_key(|(first, _)| *first);
        ordered.into_iter().map(|(_, curve)| curve).collect()
    }

    /// Whether face `f` of the mesh is in the domain.
    fn holds(&self, f: u32) -> bool {
        self.spheres.is_near(f, self.centre, self.radius) && is_proper(self.mesh, f)
    }

    /// The snapped signed distance of vertex `v` to the current plane, computed once per
    /// query.
    fn distance(&mut self, v: u32) -> f64 {
        let v = v as usize;
        let scratch = &mut *self.scratch;
        if scratch.vertex_query[v] != scratch.query {
            scratch.vertex_query[v] = scratch.query;
            scratch.vertex_distance[v] =
                snapped_distance(&self.plane, self.mesh.positions[v], self.vertex_snap[v]);
        }
        scratch.vertex_distance[v]
    }

    /// 1 when vertex `v` is on the plane or its positive side, else 0.
    fn side(&mut self, v: u32) -> u8 {
        u8::from(self.distance(v) >= 0.0)
    }

    /// Whether the current plane crosses face `f` ([`face_crossed`]).
    fn face_crossed(&mut self, f: u32) -> bool {
        let [a, b, c] = self.mesh.triangles[f as usize];
        (self.side(a) + self.side(b) + self.side(c)).wrapping_sub(1) < 2
    }

    /// A closed `curve` traced from any of its edges, started where
    /// [`SectionDomain::closed_sections`] starts it (the first crossed edge of its lowest
    /// face, into that edge's first face), with that face: the key of its place in that
    /// list.
    fn as_closed_sections_has_it(&mut self, curve: SectionCurve) -> (u32, SectionCurve) {
        let m = curve.faces.len();
        let j = (0..m)
            .min_by_key(|&k| curve.faces[k])
            .expect("a closed curve has faces");
        let lowest = curve.faces[j];
        let start = self.topology.face_edges[lowest as usize]
            .into_iter()
            .find(|&e| self.is_crossed(e))
            .expect("a traced face is crossed");
        // Face j lies between crossings j and j + 1.
        let k = if curve.crossings[j].edge == start {
            j
        } else {
            (j + 1) % m
        };
        debug_assert_eq!(curve.crossings[k].edge, start);
        let into = self
            .face_across(start, None)
            .expect("a closed curve's edges are manifold");
        let SectionCurve {
            mut crossings,
            mut faces,
        } = curve;
        if into == faces[k] {
            crossings.rotate_left(k);
            faces.rotate_left(k);
        } else {
            // The other way round: crossings k, k − 1, …; faces k − 1, k − 2, ….
            crossings.reverse();
            crossings.rotate_left(m - 1 - k);
            faces.reverse();
            faces.rotate_left((m - k) % m);
        }
        let rotated = SectionCurve { crossings, faces };
        (lowest, rotated)
    }
}

impl ChainDomain for NearRayDomain<'_> {
    fn face_edges(&self, face: u32) -> [u32; 3] {
        self.topology.face_edges[face as usize]
    }

    fn is_crossed(&mut self, e: u32) -> bool {
        let [a, b] = self.topology.edges[e as usize];
        self.side(a) != self.side(b)
    }

    fn crossing(&mut self, e: u32) -> EdgeCrossing {
        let [a, b] = self.topology.edges[e as usize];
        let (da, db) = (self.distance(a), self.distance(b));
        EdgeCrossing {
            edge: e,
            point: crossing_point(a, b, da, db),
        }
    }

    fn face_across(&self, e: u32, from: Option<u32>) -> Option<u32> {
        match *self.topology.faces_of_edge(e as usize) {
            [f, g] if self.holds(f) && self.holds(g) => match from {
                Some(h) if f == h => Some(g),
                _ => Some(f),
            },
            _ => None,
        }
    }

    fn mesh_face(&self, face: u32) -> u32 {
        face
    }

    fn visited(&self, e: u32) -> bool {
        self.scratch.edge_query[e as usize] == self.scratch.query
    }

    fn visit(&mut self, e: u32) {
        self.scratch.edge_query[e as usize] = self.scratch.query;
    }

    fn chain(&mut self) -> &mut Chain {
        &mut self.chain
    }
}

/// The faces near one joint that the plane search asks for the sections around the joint
/// ([`JointSections::sections_around`]): a [`SectionDomain`] scanned whole below
/// `SEGMENT_QUERY_FACES` faces, else a [`NearRayDomain`].
#[derive(Debug)]
pub enum JointSections<'a> {
    Scanned(SectionDomain),
    NearRay(NearRayDomain<'a>),
}

impl<'a> JointSections<'a> {
    /// The domain of the faces of `mesh` (indexed by `spheres`) of
    /// [`FaceSpheres::faces_near`] `centre` within `radius`; faces with a repeated vertex
    /// index are left out. `max_snap`: the largest of `vertex_snap`. `scratch` is held by a
    /// large domain until it is dropped.
    pub fn new(
        mesh: &'a SurfaceMesh,
        topology: &'a Topology,
        snap: (&'a [f64], f64),
        spheres: &'a FaceSpheres,
        ball: (DVec3, f64),
        scratch: &'a mut DomainScratch,
    ) -> Self {
        let (centre, radius) = ball;
        let proper = |f| is_proper(mesh, f);
        match spheres.fewer_faces_near(centre, radius, SEGMENT_QUERY_FACES, proper) {
            Some(faces) => {
                Self::Scanned(SectionDomain::new(mesh, topology, snap.0, faces, scratch))
            }
            None => Self::NearRay(NearRayDomain::new(
                mesh, topology, snap, spheres, ball, scratch,
            )),
        }
    }

    /// The closed sections of [`SectionDomain::closed_sections`] that can contain the
    /// plane's point (every one that [`polygon_contains`] of `plane.normal` and
    /// `plane.point` accepts, and perhaps others), each as that list has it (the same
    /// crossings from the same start), in its order. A small domain lists all its closed
    /// sections.
    pub fn sections_around(&mut self, plane: &Plane) -> Vec<SectionCurve> {
        match self {
            Self::Scanned(domain) => domain.closed_sections(plane),
            Self::NearRay(domain) => domain.sections_around(plane),
        }
    }
}

/// `faces` without those with a repeated vertex index (a curve reaching them is open).
fn proper_faces(mesh: &SurfaceMesh, faces: Vec<u32>) -> Vec<u32> {
    faces.into_iter().filter(|&f| is_proper(mesh, f)).collect()
}

/// Whether face `f` has three distinct vertex indices.
fn is_proper(mesh: &SurfaceMesh, f: u32) -> bool {
    let [a, b, c] = mesh.triangles[f as usize];
    a != b && b != c && a != c
}

impl SectionCurve {
    /// Crossing positions in chain order.
    pub fn positions(&self, mesh: &SurfaceMesh, topology: &Topology) -> Vec<DVec3> {
        self.crossings
            .iter()
            .map(|c| c.position(mesh, topology))
            .collect()
    }

    /// The curve's segments as chords of their faces; a segment whose ends are one vertex
    /// (the curve running through a vertex) is no chord and is left out.
    pub fn chords<'a>(
        &'a self,
        mesh: &'a SurfaceMesh,
        topology: &'a Topology,
    ) -> impl Iterator<Item = Chord> + 'a {
        let n = self.crossings.len();
        (0..n).filter_map(move |i| {
            let (a, b) = (self.crossings[i], self.crossings[(i + 1) % n]);
            if matches!((a.point, b.point), (CrossingPoint::Vertex(u), CrossingPoint::Vertex(v)) if u == v)
            {
                return None;
            }
            let face = self.faces[i];
            Some(Chord {
                face,
                ends: [a, b].map(|c| boundary_position(mesh, topology, face, c)),
            })
        })
    }
}

/// Position of a crossing along the boundary of `face` (see [`Chord`]).
fn boundary_position(mesh: &SurfaceMesh, topology: &Topology, face: u32, c: EdgeCrossing) -> f64 {
    let t = mesh.triangles[face as usize];
    match c.point {
        CrossingPoint::Vertex(v) => {
            let corner = t.iter().position(|&w| w == v);
            debug_assert!(
                corner.is_some(),
                "a crossing vertex is a corner of its face"
            );
            corner.unwrap_or(0) as f64
        }
        CrossingPoint::Interior(tau) => {
            let k = topology.face_edges[face as usize]
                .iter()
                .position(|&e| e == c.edge);
            debug_assert!(k.is_some(), "a crossing edge is an edge of its face");
            let k = k.unwrap_or(0);
            let forward = topology.edges[c.edge as usize][0] == t[k];
            k as f64 + if forward { tau } else { 1.0 - tau }
        }
    }
}

impl Chord {
    /// Whether two chords of the same face cross, or come within `gap` of each other's
    /// ends along the boundary (a shared vertex, or ends that would make a sliver).
    pub fn crosses_or_touches(&self, other: &Chord, gap: f64) -> bool {
        let near = |x: f64, y: f64| {
            let d = (x - y).abs();
            d.min(3.0 - d) < gap
        };
        if self
            .ends
            .iter()
            .any(|&x| other.ends.iter().any(|&y| near(x, y)))
        {
            return true;
        }
        let (lo, hi) = (
            self.ends[0].min(self.ends[1]),
            self.ends[0].max(self.ends[1]),
        );
        let inside = |x: f64| lo < x && x < hi;
        inside(other.ends[0]) != inside(other.ends[1])
    }
}

/// Length of the closed polygon `points`.
pub fn closed_length(points: &[DVec3]) -> f64 {
    points
        .iter()
        .zip(points.iter().cycle().skip(1))
        .map(|(a, b)| a.distance(*b))
        .sum()
}

/// Whether `p` lies inside the closed polygon `points` of the plane with unit `normal`
/// (even–odd crossing rule in plane coordinates; each edge's test is independent of the
/// others, so the plane coordinates are computed as the edges are walked, without a copy).
pub fn polygon_contains(points: &[DVec3], normal: DVec3, p: DVec3) -> bool {
    let Some(&last) = points.last() else {
        return false;
    };
    let (u, w) = normal.any_orthonormal_pair();
    let planar = |q: DVec3| ((q - p).dot(u), (q - p).dot(w));
    let mut inside = false;
    let (mut x0, mut y0) = planar(last);
    for &q in points {
        let (x1, y1) = planar(q);
        if (y0 > 0.0) != (y1 > 0.0) && x0 + (x1 - x0) * (-y0) / (y1 - y0) > 0.0 {
            inside = !inside;
        }
        (x0, y0) = (x1, y1);
    }
    inside
}

/// Largest distance between two of `points` (the curve's approximate diameter D, §3.3):
/// O(m²) over the m points.
pub fn diameter(points: &[DVec3]) -> f64 {
    points
        .iter()
        .enumerate()
        .flat_map(|(i, a)| points[i + 1..].iter().map(move |b| a.distance(*b)))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::{icosphere, uv_sphere};
    use std::f64::consts::PI;

    fn all_faces(mesh: &SurfaceMesh) -> Vec<u32> {
        (0..mesh.triangle_count() as u32).collect()
    }

    /// The domain of every face of `mesh`, vertices snapped within 0.01 of their longest edge.
    fn whole_mesh_domain(mesh: &SurfaceMesh, topology: &Topology) -> SectionDomain {
        let snap = vertex_snap_distances(mesh, topology, 0.01);
        let faces = all_faces(mesh);
        SectionDomain::new(mesh, topology, &snap, faces, &mut DomainScratch::default())
    }

    /// Deterministic numbers in [0, 1) (a linear congruential generator).
    fn numbers(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A scratch given back to its pool is lent again, maps and stamps kept; two lent at
    /// once are two.
    #[test]
    fn a_pool_lends_its_scratches_again() {
        let mesh = icosphere(1.0, 1);
        let topology = Topology::new(&mesh);
        let pool = ScratchPool::default();
        {
            let mut scratch = pool.lend();
            scratch.fit(&mesh, &topology);
            scratch.next_query();
        }
        let (first, second) = (pool.lend(), pool.lend());
        assert_eq!(first.vertex.len(), mesh.vertex_count());
        assert_eq!(first.query, 1);
        assert!(second.vertex.is_empty());
        drop((first, second));
        assert_eq!(pool.0.lock().unwrap().len(), 2);
    }

    /// The sections around a point (of a [`NearRayDomain`], and of [`JointSections`]) are
    /// those of every closed section (of a [`SectionDomain`]) that contain it, as that list
    /// has them (same start, same order): a sphere, a bent tube and a U-shaped tube (planes
    /// meeting both arms), domains of the faces near vertices and near random points, planes
    /// through them along the axes and at random.
    #[test]
    fn sections_around_a_point_are_the_closed_sections_that_contain_it() {
        use crate::fixtures::shapes::{bent_cylinder, capsule_chain};
        let u_points = [
            DVec3::new(-0.6, 1.5, 0.0),
            DVec3::new(-0.6, 0.0, 0.0),
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::new(0.6, 1.5, 0.0),
        ];
        let meshes = [
            icosphere(1.0, 3),
            bent_cylinder(0.2, 1.0, 60.0, 16, 8).0,
            capsule_chain(&u_points, &[], 0.25, 12, 6).0,
        ];
        for mesh in &meshes {
            let topology = Topology::new(mesh);
            let snap = vertex_snap_distances(mesh, &topology, 0.01);
            let max_snap = snap.iter().copied().fold(0.0, f64::max);
            let spheres = FaceSpheres::new(mesh);
            let (mut scratch, mut joint_scratch) = Default::default();
            // Stamps about to wrap: the maps are cleared on the way.
            let mut near_scratch = DomainScratch {
                query: u32::MAX - 100,
                ..DomainScratch::default()
            };
            let mut random = numbers(17);
            let (lo, hi) = mesh.bounding_box();
            let (mut compared, mut left_out) = (0, 0);
            for trial in 0..40 {
                let point = if trial % 4 == 0 {
                    mesh.positions[(random() * mesh.vertex_count() as f64) as usize]
                } else {
                    lo + (hi - lo) * DVec3::new(random(), random(), random())
                };
                let radius = (0.2 + random()) * (hi - lo).length() / 2.0;
                let faces = spheres.faces_near(point, radius);
                let mut domain = SectionDomain::new(mesh, &topology, &snap, faces, &mut scratch);
                let (ball, snap) = ((point, radius), (snap.as_slice(), max_snap));
                let mut near =
                    NearRayDomain::new(mesh, &topology, snap, &spheres, ball, &mut near_scratch);
                let mut joint =
                    JointSections::new(mesh, &topology, snap, &spheres, ball, &mut joint_scratch);
                for k in 0..8 {
                    let normal = match k {
                        0 => DVec3::Y,
                        1 => DVec3::X,
                        _ => DVec3::new(random() - 0.5, random() - 0.5, random() - 0.5).normalize(),
                    };
                    let plane = Plane { point, normal };
                    let around = |curves: &[SectionCurve]| -> Vec<SectionCurve> {
                        curves
                            .iter()
                            .filter(|c| {
                                polygon_contains(&c.positions(mesh, &topology), normal, point)
                            })
                            .cloned()
                            .collect()
                    };
                    let all = domain.closed_sections(&plane);
                    let fast = near.sections_around(&plane);
                    assert!(fast.iter().all(|c| all.contains(c)));
                    assert_eq!(around(&fast), around(&all));
                    let chosen = joint.sections_around(&plane);
                    assert_eq!(around(&chosen), around(&all));
                    compared += around(&all).len();
                    left_out += all.len() - fast.len();
                }
            }
            assert!(compared > 20 && left_out > 0, "{compared} {left_out}");
        }
    }

    /// The distances of a query through the point of the query before (its differences
    /// p − o kept) are those of `snapped_distance`, bit for bit, and its sections those of
    /// a new domain: planes through one point and through others in turn, points with
    /// negative zeros among them.
    #[test]
    fn kept_differences_give_the_distances_of_the_formula() {
        let mesh = icosphere(1.0, 3);
        let topology = Topology::new(&mesh);
        let new_domain = || whole_mesh_domain(&mesh, &topology);
        let mut domain = new_domain();
        let mut random = numbers(5);
        let points = [
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(0.0, -0.0, 0.25),
            DVec3::new(-0.0, 0.0, 0.25),
        ];
        for k in 0..30 {
            let point = points[(k / 3) % points.len()];
            let normal = DVec3::new(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
            let plane = Plane { point, normal };
            let curves = domain.closed_sections(&plane);
            for (v, &d) in domain.local_distance.iter().enumerate() {
                let p = domain.local_positions[v];
                let expected = snapped_distance(&plane, p, domain.local_snap[v]);
                assert_eq!(d.to_bits(), expected.to_bits(), "query {k}, vertex {v}");
            }
            assert_eq!(curves, new_domain().closed_sections(&plane), "query {k}");
        }
    }

    #[test]
    fn equator_of_a_sphere_is_one_closed_circle() {
        let mesh = icosphere(1.0, 4);
        let topology = Topology::new(&mesh);
        let mut domain = whole_mesh_domain(&mesh, &topology);
        let plane = Plane {
            point: DVec3::new(0.0, 0.0, 0.3),
            normal: DVec3::Z,
        };
        let curves = domain.closed_sections(&plane);
        assert_eq!(curves.len(), 1);
        let points = curves[0].positions(&mesh, &topology);
        let radius = (1.0f64 - 0.09).sqrt();
        assert!((closed_length(&points) - 2.0 * PI * radius).abs() < 0.02 * radius);
        assert!((diameter(&points) - 2.0 * radius).abs() < 0.02);
        assert!(points
            .iter()
            .all(|p| plane.signed_distance(*p).abs() < 0.01 * 0.2));
        assert!(polygon_contains(&points, plane.normal, plane.point));
        assert!(!polygon_contains(
            &points,
            plane.normal,
            plane.point + DVec3::X
        ));
    }

    #[test]
    fn a_plane_through_vertices_chains_through_them() {
        // The uv sphere's equator ring lies exactly on z = 0.
        let mesh = uv_sphere(1.0, 8, 16);
        let topology = Topology::new(&mesh);
        let mut domain = whole_mesh_domain(&mesh, &topology);
        let plane = Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        };
        let curves = domain.closed_sections(&plane);
        assert_eq!(curves.len(), 1);
        let mut vertices: Vec<u32> = curves[0]
            .crossings
            .iter()
            .map(|c| match c.point {
                CrossingPoint::Vertex(v) => v,
                CrossingPoint::Interior(t) => panic!("interior crossing at {t}"),
            })
            .collect();
        vertices.dedup();
        assert_eq!(vertices.len(), 16);
    }

    #[test]
    fn a_curve_leaving_the_domain_is_open() {
        let mesh = icosphere(1.0, 3);
        let topology = Topology::new(&mesh);
        let snap = vertex_snap_distances(&mesh, &topology, 0.01);
        let upper: Vec<u32> = all_faces(&mesh)
            .into_iter()
            .filter(|&f| mesh.corners(f as usize).iter().all(|c| c.y > -0.2))
            .collect();
        let mut domain = SectionDomain::new(
            &mesh,
            &topology,
            &snap,
            upper,
            &mut DomainScratch::default(),
        );
        let plane = Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        };
        assert!(domain.closed_sections(&plane).is_empty());
        let horizontal = Plane {
            point: DVec3::Y * 0.5,
            normal: DVec3::Y,
        };
        assert_eq!(domain.closed_sections(&horizontal).len(), 1);
    }

    /// The reference: the polygon copied into plane coordinates, then the even–odd rule.
    fn reference_contains(points: &[DVec3], normal: DVec3, p: DVec3) -> bool {
        let (u, w) = normal.any_orthonormal_pair();
        let planar: Vec<(f64, f64)> = points
            .iter()
            .map(|q| ((*q - p).dot(u), (*q - p).dot(w)))
            .collect();
        let mut inside = false;
        for (i, &(x0, y0)) in planar.iter().enumerate() {
            let (x1, y1) = planar[(i + 1) % planar.len()];
            if (y0 > 0.0) != (y1 > 0.0) && x0 + (x1 - x0) * (-y0) / (y1 - y0) > 0.0 {
                inside = !inside;
            }
        }
        inside
    }

    /// Random star-shaped and self-crossing polygons, points inside, outside and on
    /// vertices: the same answers as the reference.
    #[test]
    fn containment_without_a_copy_answers_as_the_reference() {
        let mut rng = atlas_skin_runtime::random_pose::SplitMix64::new(11);
        let mut next = || rng.next_f64() * 2.0 - 1.0;
        for n in [0, 1, 3, 7, 20] {
            let normal = DVec3::new(next(), next(), next()).normalize();
            let (u, w) = normal.any_orthonormal_pair();
            let points: Vec<DVec3> = (0..n)
                .map(|_| u * next() + w * next() + normal * 0.01 * next())
                .collect();
            let mut queries: Vec<DVec3> = (0..200).map(|_| u * next() + w * next()).collect();
            queries.extend(&points);
            for p in queries {
                assert_eq!(
                    polygon_contains(&points, normal, p),
                    reference_contains(&points, normal, p)
                );
            }
        }
    }

    #[test]
    fn chords_cross_when_their_ends_interleave() {
        let chord = |a: f64, b: f64| Chord {
            face: 0,
            ends: [a, b],
        };
        let gap = 0.01;
        // Parallel chords cutting corner 1 off at two depths: no conflict.
        assert!(!chord(0.5, 1.5).crosses_or_touches(&chord(0.8, 1.2), gap));
        // Interleaved ends cross.
        assert!(chord(0.5, 1.5).crosses_or_touches(&chord(1.2, 2.5), gap));
        // A shared corner (s = 1) or ends closer than the gap touch.
        assert!(chord(1.0, 2.5).crosses_or_touches(&chord(1.0, 0.5), gap));
        assert!(chord(0.5, 1.5).crosses_or_touches(&chord(1.505, 2.5), gap));
        // Ends on either side of s = 0 are close across the wrap.
        assert!(chord(0.002, 1.5).crosses_or_touches(&chord(2.999, 1.8), gap));
    }
}
