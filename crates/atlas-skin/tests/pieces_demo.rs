//! The demo character cut into pieces as game characters come (issue 12, item 4): the head
//! apart from the body, eyeballs inside the head, a hat floating above it, a belt through
//! the waist. Known answers: the head, the eyeballs and the hat move rigidly with the head
//! joint; the belt takes the weights of the body surface under it.

use atlas_skin::fixtures::demo::demo_character;
use atlas_skin::fixtures::shapes::{capsule_chain, icosphere, ring, uv_sphere};
use atlas_skin::geometry::point_triangle_distance;
use atlas_skin::mesh::SurfaceMesh;
use atlas_skin::pipeline::{skin, SkinInput, SkinParams, Skinned};
use atlas_skin::weights::pieces::PieceTreatment;
use atlas_skin::weights::SurfaceWeights;
use atlas_skin_runtime::Skeleton;
use glam::{DVec3, Vec3};

/// Grid step of the demo for these tests: coarse, so that the test is quick.
const STEP: f64 = 0.02;

/// A character assembled from pieces, each a range of stored vertices.
struct Pieces {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    skeleton: Skeleton,
    /// (name, first stored vertex, end) of every piece added after the body.
    parts: Vec<(&'static str, usize, usize)>,
}

impl Pieces {
    /// The demo below its neck top (y < 1.60, open at the neck), no other piece.
    fn body() -> Self {
        let demo = demo_character(STEP);
        let triangles = demo
            .triangles
            .iter()
            .filter(|t| t.iter().all(|&v| demo.positions[v as usize].y < 1.60))
            .copied()
            .collect();
        Self {
            positions: demo.positions,
            triangles,
            skeleton: demo.skeleton,
            parts: Vec::new(),
        }
    }

    /// Adds `mesh` scaled per axis by `scale` and moved to `centre`.
    fn add(&mut self, name: &'static str, mesh: &SurfaceMesh, scale: DVec3, centre: DVec3) {
        let first = self.positions.len();
        self.positions.extend(
            mesh.positions
                .iter()
                .map(|&p| (p * scale + centre).as_vec3()),
        );
        self.triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|v| v + first as u32)));
        self.parts.push((name, first, self.positions.len()));
    }

    /// The body, a head sphere over its neck, two eyeballs inside the head, a hat above it.
    fn with_head() -> Self {
        let mut pieces = Self::body();
        let one = DVec3::ONE;
        pieces.add(
            "head",
            &icosphere(0.11, 3),
            one,
            DVec3::new(0.0, 1.715, 0.01),
        );
        for x in [-0.04, 0.04] {
            pieces.add("eye", &icosphere(0.02, 2), one, DVec3::new(x, 1.73, 0.08));
        }
        pieces.add(
            "hat",
            &uv_sphere(1.0, 8, 24),
            DVec3::new(0.13, 0.13, 0.025),
            DVec3::new(0.0, 1.86, 0.01),
        );
        pieces
    }

    fn skin(&self) -> Skinned {
        skin(
            SkinInput {
                positions: &self.positions,
                triangles: &self.triangles,
                skeleton: &self.skeleton,
                end_joints: &[],
            },
            &SkinParams::default(),
            &mut |_| {},
        )
        .expect("skinned")
    }

    fn joint(&self, name: &str) -> u32 {
        self.skeleton
            .names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("the demo has a {name} joint")) as u32
    }

    fn part(&self, name: &str) -> impl Iterator<Item = usize> + '_ {
        let name = name.to_string();
        self.parts
            .iter()
            .filter(move |p| p.0 == name)
            .flat_map(|&(_, a, b)| a..b)
    }
}

/// The treatment of the piece that holds stored vertex `stored`.
fn treatment_of(skinned: &Skinned, stored: usize) -> PieceTreatment {
    let d = &skinned.decomposition;
    let piece_of = &d.topology.vertex_component;
    let piece = piece_of[skinned.welded_of_stored[stored] as usize];
    skinned.counts.weights.pieces[piece as usize].treatment
}

#[test]
fn head_eyeballs_and_hat_move_rigidly_with_the_head_joint() {
    let pieces = Pieces::with_head();
    let skinned = pieces.skin();
    let head = pieces.joint("head");
    for name in ["head", "eye", "hat"] {
        for v in pieces.part(name) {
            assert_eq!(
                treatment_of(&skinned, v),
                PieceTreatment::Rigid(head),
                "{name}"
            );
            let row: Vec<(u32, f32)> = skinned.weights.row(v).collect();
            assert_eq!(row, vec![(head, 1.0)], "{name} vertex {v}");
        }
    }
    let counts = &skinned.counts.weights;
    assert_eq!(counts.bent, 0, "no piece bent at joints");
    assert_eq!(
        counts.rigid,
        pieces.part("head").count() + pieces.part("eye").count() + pieces.part("hat").count()
    );
}

/// The interpolated weights of the nearest point of the weighted body surface, by a scan of
/// every face (the reference for the spatial query of the weights stage).
fn body_weights_at(skinned: &Skinned, body_faces: &[usize], p: DVec3) -> Vec<(u32, f64)> {
    let d = &skinned.decomposition;
    let w: &SurfaceWeights = &skinned.surface_weights;
    let face = *body_faces
        .iter()
        .min_by(|&&f, &&g| {
            let distance = |f: usize| {
                let [a, b, c] = d.surface.corners(f);
                point_triangle_distance(p, a, b, c)
            };
            distance(f).total_cmp(&distance(g))
        })
        .expect("a body face");
    let [a, b, c] = d.surface.corners(face);
    let [u, v, x] = atlas_skin::geometry::closest_point_on_triangle(p, a, b, c);
    let mut row: Vec<(u32, f64)> = Vec::new();
    for (&corner, share) in d.surface.triangles[face].iter().zip([u, v, x]) {
        for (j, weight) in w.row(corner as usize) {
            match row.iter_mut().find(|(k, _)| *k == j) {
                Some((_, total)) => *total += share * weight,
                None => row.push((j, share * weight)),
            }
        }
    }
    row.retain(|&(_, x)| x > 0.0);
    row.sort_by_key(|&(j, _)| j);
    row
}

#[test]
fn a_belt_through_the_waist_takes_the_weights_of_the_body_under_it() {
    let mut pieces = Pieces::with_head();
    pieces.add(
        "belt",
        &ring(0.175, 0.12, 0.012, 1.12, 48, 8),
        DVec3::ONE,
        DVec3::ZERO,
    );
    let skinned = pieces.skin();
    let d = &skinned.decomposition;
    let piece_of = &d.topology.vertex_component;
    let body_piece = piece_of[skinned.welded_of_stored[0] as usize];
    let body_faces: Vec<usize> = (0..d.surface.triangle_count())
        .filter(|&f| piece_of[d.surface.triangles[f][0] as usize] == body_piece)
        .collect();
    let arms_and_head: Vec<u32> = [
        "head",
        "neck",
        "upperarm_l",
        "upperarm_r",
        "hand_l",
        "hand_r",
    ]
    .iter()
    .map(|n| pieces.joint(n))
    .collect();
    let waist = [pieces.joint("hips"), pieces.joint("spine")];
    let mut joints_seen = Vec::new();
    for v in pieces.part("belt") {
        assert_eq!(treatment_of(&skinned, v), PieceTreatment::Attached);
        let s = skinned.welded_of_stored[v] as usize;
        let mut row: Vec<(u32, f64)> = skinned.surface_weights.row(s).collect();
        row.sort_by_key(|&(j, _)| j);
        let expected = body_weights_at(&skinned, &body_faces, d.surface.positions[s]);
        assert_eq!(
            row.len(),
            expected.len(),
            "belt vertex {v}: {row:?} vs {expected:?}"
        );
        for ((j, x), (k, y)) in row.iter().zip(&expected) {
            assert!(
                j == k && (x - y).abs() < 1e-9,
                "belt vertex {v}: {row:?} vs {expected:?}"
            );
        }
        // The waist under the belt moves it: no arm or head weight, most on hips or spine.
        assert!(
            row.iter().all(|(j, _)| !arms_and_head.contains(j)),
            "{row:?}"
        );
        let waist_share: f64 = row
            .iter()
            .filter(|(j, _)| waist.contains(j))
            .map(|r| r.1)
            .sum();
        assert!(waist_share > 0.9, "{row:?}");
        joints_seen.extend(row.iter().map(|&(j, _)| j));
    }
    joints_seen.sort_unstable();
    joints_seen.dedup();
    assert!(
        joints_seen.len() >= 2,
        "the belt bends with the waist: {joints_seen:?}"
    );
    // The head, eyeballs and hat stay rigid beside it.
    let head = pieces.joint("head");
    assert!(pieces
        .part("hat")
        .all(|v| skinned.weights.row(v).collect::<Vec<_>>() == vec![(head, 1.0)]));
}

#[test]
fn loose_pieces_do_not_change_the_weights_of_the_body() {
    let alone = Pieces::body();
    let with_head = Pieces::with_head();
    let (a, b) = (alone.skin(), with_head.skin());
    for v in 0..alone.positions.len() {
        let (x, y): (Vec<_>, Vec<_>) = (a.weights.row(v).collect(), b.weights.row(v).collect());
        assert_eq!(x, y, "body vertex {v}");
    }
}

#[test]
fn a_braid_hanging_from_the_head_over_the_shoulder_moves_with_the_head() {
    // A braid that starts inside the head and ends 6 cm above the left upper arm: its
    // lower end is nearer the arm's skin and bone than the head's, but it hangs from the
    // head, as an artist binds it.
    let mut pieces = Pieces::with_head();
    let (braid, _) = capsule_chain(
        &[DVec3::new(0.10, 1.70, 0.0), DVec3::new(0.22, 1.52, 0.0)],
        &[],
        0.012,
        8,
        12,
    );
    pieces.add("braid", &braid, DVec3::ONE, DVec3::ZERO);
    let skinned = pieces.skin();
    let head = pieces.joint("head");
    let d = &skinned.decomposition;
    let lowest = pieces
        .part("braid")
        .min_by(|&u, &v| pieces.positions[u].y.total_cmp(&pieces.positions[v].y))
        .expect("a braid vertex");
    let arm_bone = [DVec3::new(0.22, 1.40, 0.0), DVec3::new(0.48, 1.40, 0.0)];
    let p = d.surface.positions[skinned.welded_of_stored[lowest] as usize];
    assert!(
        atlas_skin::geometry::point_segment_distance(p, arm_bone[0], arm_bone[1])
            < p.distance(DVec3::new(0.0, 1.60, 0.0)),
        "the braid's end lies nearer the arm's bone than the head joint"
    );
    for v in pieces.part("braid") {
        assert_eq!(treatment_of(&skinned, v), PieceTreatment::Rigid(head));
        let row: Vec<(u32, f32)> = skinned.weights.row(v).collect();
        assert_eq!(row, vec![(head, 1.0)], "braid vertex {v}");
    }
}
