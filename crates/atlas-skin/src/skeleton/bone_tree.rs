//! The nearest of a set of bone segments to a point among those a filter admits, exactly:
//! a bounding-volume hierarchy of the segments' boxes, searched nearest box first.
//!
//! Every segment carries a key (for the ownership of [`crate::weights::ownership`], the
//! depth-first position of the joint that moves it, so that the bones of a joint's subtree
//! are the keys of one range) and every node the smallest and largest key below it: a
//! filter on a range of keys skips whole subtrees of the hierarchy. A node whose box is no
//! nearer than the best distance found so far is skipped too: its segments cannot be
//! nearer, and segments exactly as near do not change the minimum (bones on one line at
//! one distance, the siblings of one root, cost one descent, not one test each).
//!
//! Nodes split their segments in two halves, at the median of the midpoints along the
//! widest axis ([`Split::Space`]) or at the median key ([`Split::Keys`]: the nodes of a key
//! range are few, for queries inside a small range), so the depth is ⌈log₂(n / 4)⌉ + 1 at
//! most whatever the positions.

use crate::geometry::point_segment_distance;
use glam::DVec3;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::ops::ControlFlow;

/// Segments per leaf.
const LEAF: usize = 4;

/// Deeper than any tree of fewer than 2⁶⁰ segments.
const MAX_DEPTH: usize = 64;

/// Levels of the trees searched with a short stack ([`BoneTree::nearest_distance`]): up to
/// 2¹⁷ segments.
const SHALLOW_DEPTH: usize = 16;

/// How a node divides its segments between its two children.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// At the median midpoint along the widest axis of the midpoints.
    Space,
    /// At the median key.
    Keys,
}

/// Which keys a query admits: those in the half-open range, or those outside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keys {
    Inside(u32, u32),
    Outside(u32, u32),
}

impl Keys {
    /// Every key.
    pub const ALL: Self = Self::Outside(0, 0);

    fn admits(self, key: u32) -> bool {
        match self {
            Self::Inside(lo, hi) => (lo..hi).contains(&key),
            Self::Outside(lo, hi) => !(lo..hi).contains(&key),
        }
    }

    /// Whether some key of [least, most] is admitted.
    fn may_admit(self, least: u32, most: u32) -> bool {
        match self {
            Self::Inside(lo, hi) => most >= lo && least < hi,
            Self::Outside(lo, hi) => least < lo || most >= hi,
        }
    }
}

/// A segment with its key.
#[derive(Debug, Clone, Copy)]
struct Item {
    start: DVec3,
    end: DVec3,
    key: u32,
}

impl Item {
    fn distance(&self, p: DVec3) -> f64 {
        point_segment_distance(p, self.start, self.end)
    }

    fn middle(&self) -> DVec3 {
        self.start.midpoint(self.end)
    }
}

/// A node: its box, its key range and either its segments (a leaf) or its children (the
/// left one next in the array, the right one at `right`).
#[derive(Debug, Clone, Copy)]
struct Node {
    min: DVec3,
    max: DVec3,
    least_key: u32,
    most_key: u32,
    first: u32,
    /// Segments of a leaf; 0 for an inner node.
    count: u32,
    right: u32,
}

impl Node {
    /// Distance from `p` to the box (0 inside).
    fn distance(&self, p: DVec3) -> f64 {
        (self.min - p).max(p - self.max).max(DVec3::ZERO).length()
    }
}

/// Segments with keys in a bounding-volume hierarchy.
#[derive(Debug, Clone)]
pub struct BoneTree {
    items: Vec<Item>,
    nodes: Vec<Node>,
    /// Levels of nodes: 1 for a single leaf.
    levels: usize,
}

impl BoneTree {
    /// The tree of `segments`, given as (key, start, end).
    pub fn new(segments: impl IntoIterator<Item = (u32, DVec3, DVec3)>, split: Split) -> Self {
        let mut items: Vec<Item> = segments
            .into_iter()
            .map(|(key, start, end)| Item { start, end, key })
            .collect();
        let mut nodes = Vec::with_capacity(2 * items.len().div_ceil(LEAF));
        if !items.is_empty() {
            build(&mut items, 0, split, &mut nodes);
        }
        let levels = levels(items.len());
        Self {
            items,
            nodes,
            levels,
        }
    }

    /// The tree of `segments`, keyed by their indices.
    pub fn of_segments(segments: &[[DVec3; 2]]) -> Self {
        Self::new(
            (0u32..).zip(segments).map(|(k, &[a, b])| (k, a, b)),
            Split::Space,
        )
    }

    /// The smallest [`point_segment_distance`] from `p` to the segments (infinity when
    /// there are none).
    pub fn nearest(&self, p: DVec3) -> f64 {
        self.nearest_distance(p, Keys::ALL, |_, _| true)
    }

    /// The smallest [`point_segment_distance`] from `p` to a segment whose key `keys`
    /// admits and for which `admit(key, end)` holds (infinity when there is none): the
    /// minimum of a scan of every admitted segment, to rounding (a box whose computed
    /// distance equals the best is skipped, while a segment in it might compute a few
    /// units in the last place less).
    pub fn nearest_distance(
        &self,
        p: DVec3,
        keys: Keys,
        admit: impl Fn(u32, DVec3) -> bool,
    ) -> f64 {
        // The stack holds at most one node per level plus one. Sized for the deepest tree,
        // its 65 entries were zeroed by every query: a fifth of the queries' instructions
        // on a skeleton of 20 bones.
        if self.levels <= SHALLOW_DEPTH {
            self.search::<{ SHALLOW_DEPTH + 1 }>(p, keys, admit)
        } else {
            self.search::<{ MAX_DEPTH + 1 }>(p, keys, admit)
        }
    }

    /// [`BoneTree::nearest_distance`] with a stack of `STACK` entries (more than the
    /// levels).
    fn search<const STACK: usize>(
        &self,
        p: DVec3,
        keys: Keys,
        admit: impl Fn(u32, DVec3) -> bool,
    ) -> f64 {
        let mut best = f64::INFINITY;
        let Some(root) = self.nodes.first() else {
            return best;
        };
        // Nodes still to visit with their boxes' distances, the nearest on top.
        let mut stack = [(0u32, 0.0f64); STACK];
        stack[0] = (0, root.distance(p));
        let mut size = 1;
        while size > 0 {
            size -= 1;
            let (index, box_distance) = stack[size];
            let node = &self.nodes[index as usize];
            if box_distance >= best || !keys.may_admit(node.least_key, node.most_key) {
                continue;
            }
            if node.count > 0 {
                let leaf = &self.items[node.first as usize..(node.first + node.count) as usize];
                for item in leaf {
                    if keys.admits(item.key) && admit(item.key, item.end) {
                        best = best.min(item.distance(p));
                    }
                }
                continue;
            }
            let (left, right) = (index + 1, node.right);
            let near = |child: u32| self.nodes[child as usize].distance(p);
            let (left_distance, right_distance) = (near(left), near(right));
            let (first, second) = if left_distance <= right_distance {
                ((left, left_distance), (right, right_distance))
            } else {
                ((right, right_distance), (left, left_distance))
            };
            // The farther child below the nearer, so that the nearer is searched first.
            stack[size] = second;
            stack[size + 1] = first;
            size += 2;
        }
        best
    }

    /// The keys, increasing, of the segments within `radius` of `p`
    /// ([`point_segment_distance`] ≤ `radius`): the same as a scan of every segment.
    pub fn within(&self, p: DVec3, radius: f64) -> Vec<u32> {
        let mut found = Vec::new();
        let _: ControlFlow<()> = self.visit_within(p, radius, |key| {
            found.push(key);
            ControlFlow::Continue(())
        });
        found.sort_unstable();
        found
    }

    /// [`Self::within`] when it finds at most `most` segments; `None` at the one after,
    /// found without looking further (thousands of bones lying along one another are all
    /// as near to a point beside them).
    pub fn within_at_most(&self, p: DVec3, radius: f64, most: usize) -> Option<Vec<u32>> {
        let mut found = Vec::new();
        let crowded = self.visit_within(p, radius, |key| {
            if found.len() == most {
                return ControlFlow::Break(());
            }
            found.push(key);
            ControlFlow::Continue(())
        });
        if crowded.is_break() {
            return None;
        }
        found.sort_unstable();
        Some(found)
    }

    /// A key of a segment within `radius` of `p` for which `admit(key)` holds, `None` when
    /// there is none (the same answer as a scan; which key, when several qualify, is the
    /// first met in the tree's order). Stops at the first: the thousands of sibling bones
    /// through one point cost one descent.
    pub fn find_within(&self, p: DVec3, radius: f64, admit: impl Fn(u32) -> bool) -> Option<u32> {
        match self.visit_within(p, radius, |key| {
            if admit(key) {
                ControlFlow::Break(key)
            } else {
                ControlFlow::Continue(())
            }
        }) {
            ControlFlow::Break(key) => Some(key),
            ControlFlow::Continue(()) => None,
        }
    }

    /// Calls `visit` with the key and the distance of every segment within `radius` of
    /// `p`, nearest first (equal distances in any order), until it breaks: the k nearest
    /// cost about k descents, not a scan.
    pub fn visit_nearest_first<B>(
        &self,
        p: DVec3,
        radius: f64,
        mut visit: impl FnMut(u32, f64) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        // (distance, 0 for a node or 1 for a segment, index); distances are non-negative,
        // so their bits order them.
        let mut heap: BinaryHeap<Reverse<(u64, u8, u32)>> = BinaryHeap::new();
        if let Some(root) = self.nodes.first() {
            heap.push(Reverse((root.distance(p).to_bits(), 0, 0)));
        }
        // Boxes are passed over only when clearly farther, as in `visit_within`.
        let reach = radius * (1.0 + 1e-9);
        while let Some(Reverse((bits, kind, index))) = heap.pop() {
            let distance = f64::from_bits(bits);
            if distance > reach {
                break;
            }
            if kind == 1 {
                if distance <= radius {
                    visit(self.items[index as usize].key, distance)?;
                }
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                for i in node.first..node.first + node.count {
                    let d = self.items[i as usize].distance(p);
                    heap.push(Reverse((d.to_bits(), 1, i)));
                }
            } else {
                for child in [index + 1, node.right] {
                    let d = self.nodes[child as usize].distance(p);
                    heap.push(Reverse((d.to_bits(), 0, child)));
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Calls `visit` with the key of every segment within `radius` of `p` until it breaks.
    fn visit_within<B>(
        &self,
        p: DVec3,
        radius: f64,
        mut visit: impl FnMut(u32) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        if self.nodes.is_empty() {
            return ControlFlow::Continue(());
        }
        // Boxes are skipped only when clearly farther: the exact test is the segment's.
        let reach = radius * (1.0 + 1e-9);
        let mut stack = vec![0u32];
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            if node.distance(p) > reach {
                continue;
            }
            if node.count > 0 {
                let leaf = &self.items[node.first as usize..(node.first + node.count) as usize];
                for item in leaf.iter().filter(|item| item.distance(p) <= radius) {
                    visit(item.key)?;
                }
            } else {
                stack.extend([index + 1, node.right]);
            }
        }
        ControlFlow::Continue(())
    }
}

/// Levels of the tree [`build`] makes of `n` segments: a leaf holds up to [`LEAF`], and
/// the larger half of a node is its right child.
fn levels(n: usize) -> usize {
    if n <= LEAF {
        1
    } else {
        1 + levels(n - n / 2)
    }
}

/// Appends the nodes of `items` (from position `first` of the tree's items) to `nodes`.
fn build(items: &mut [Item], first: usize, split: Split, nodes: &mut Vec<Node>) {
    let mut node = Node {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
        least_key: u32::MAX,
        most_key: 0,
        first: first as u32,
        count: 0,
        right: 0,
    };
    let (mut low, mut high) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for item in items.iter() {
        node.min = node.min.min(item.start).min(item.end);
        node.max = node.max.max(item.start).max(item.end);
        node.least_key = node.least_key.min(item.key);
        node.most_key = node.most_key.max(item.key);
        low = low.min(item.middle());
        high = high.max(item.middle());
    }
    let here = nodes.len();
    nodes.push(node);
    if items.len() <= LEAF {
        nodes[here].count = items.len() as u32;
        return;
    }
    let half = items.len() / 2;
    match split {
        Split::Space => {
            let extent = high - low;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let middle = |item: &Item| item.middle()[axis];
            items.select_nth_unstable_by(half, |a, b| middle(a).total_cmp(&middle(b)));
        }
        Split::Keys => {
            items.select_nth_unstable_by_key(half, |item| item.key);
        }
    }
    let (left, right) = items.split_at_mut(half);
    build(left, first, split, nodes);
    nodes[here].right = nodes.len() as u32;
    build(right, first + half, split, nodes);
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::random_pose::SplitMix64;

    /// The minimum over a scan of every admitted segment.
    fn scan(segments: &[(u32, DVec3, DVec3)], p: DVec3, keys: Keys, skip: Option<u32>) -> f64 {
        segments
            .iter()
            .filter(|&&(key, _, _)| keys.admits(key) && Some(key) != skip)
            .map(|&(_, a, b)| point_segment_distance(p, a, b))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn the_tree_finds_the_minimum_of_a_scan() {
        let mut rng = SplitMix64::new(11);
        let mut unit = move || rng.next_f64();
        for case in 0..40 {
            let n = [0, 1, 3, 5, 17, 100, 400][case % 7];
            let random_point = |unit: &mut dyn FnMut() -> f64| {
                DVec3::new(unit() * 2.0 - 1.0, unit() * 2.0 - 1.0, unit() * 2.0 - 1.0)
            };
            let segments: Vec<(u32, DVec3, DVec3)> = (0..n)
                .map(|k| {
                    let key = (unit() * 30.0) as u32;
                    let a = random_point(&mut unit);
                    match k % 4 {
                        // Collinear bones from one point (siblings of a root), many at
                        // the same distance from points around the line.
                        0 => (key, DVec3::ZERO, DVec3::Y * unit()),
                        // A point.
                        1 => (key, a, a),
                        _ => (key, a, random_point(&mut unit)),
                    }
                })
                .collect();
            let split = if case % 2 == 0 {
                Split::Space
            } else {
                Split::Keys
            };
            let tree = BoneTree::new(segments.iter().copied(), split);
            for q in 0..100 {
                let p = if q % 3 == 0 {
                    // Equidistant from the collinear bones.
                    let angle = unit() * std::f64::consts::TAU;
                    DVec3::new(0.3 * angle.cos(), unit() * 0.5, 0.3 * angle.sin())
                } else {
                    random_point(&mut unit)
                };
                let lo = (unit() * 30.0) as u32;
                let hi = lo + (unit() * 10.0) as u32;
                let skip = (q % 5 == 0).then_some(lo);
                for keys in [Keys::ALL, Keys::Inside(lo, hi), Keys::Outside(lo, hi)] {
                    let expected = scan(&segments, p, keys, skip);
                    let got = tree.nearest_distance(p, keys, |key, _| Some(key) != skip);
                    assert!(
                        got == expected || (got - expected).abs() < 1e-12,
                        "case {case}, {keys:?} at {p}: {got} vs {expected}"
                    );
                }
            }
        }
    }

    /// [`levels`] counts the levels [`build`] makes (the short stack of
    /// [`BoneTree::nearest_distance`] relies on it), around the sizes where a level is
    /// added and past the short stack's limit.
    #[test]
    fn levels_are_those_of_the_built_tree() {
        fn depth(nodes: &[Node], index: usize) -> usize {
            let node = &nodes[index];
            if node.count > 0 {
                1
            } else {
                1 + depth(nodes, index + 1).max(depth(nodes, node.right as usize))
            }
        }
        for n in [1, 4, 5, 8, 9, 16, 17, 33, 100, 1000, 4097, 300_000] {
            let segments = (0..n as u32).map(|k| (k, DVec3::X * k as f64, DVec3::ZERO));
            let tree = BoneTree::new(segments, Split::Keys);
            assert_eq!(tree.levels, depth(&tree.nodes, 0), "{n} segments");
        }
        assert!(levels(300_000) > SHALLOW_DEPTH);
    }

    /// Short, long, crossing and point segments, queried inside and far outside their box:
    /// the nearest distance and the segments within a radius of a scan of every segment.
    #[test]
    fn the_tree_finds_what_a_scan_of_unkeyed_segments_finds() {
        let mut rng = SplitMix64::new(4);
        let mut random =
            |scale: f64| DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * scale;
        for (count, length) in [(0, 0.1), (1, 0.0), (50, 0.05), (300, 0.3), (40, 3.0)] {
            let segments: Vec<[DVec3; 2]> = (0..count)
                .map(|_| {
                    let a = random(2.0);
                    [a, a + (random(2.0) - DVec3::ONE) * length]
                })
                .collect();
            let tree = BoneTree::of_segments(&segments);
            for _ in 0..300 {
                let p = random(8.0) - DVec3::splat(2.0);
                let scanned = segments
                    .iter()
                    .map(|&[a, b]| point_segment_distance(p, a, b))
                    .fold(f64::INFINITY, f64::min);
                let nearest = tree.nearest(p);
                assert!(nearest == scanned || (nearest - scanned).abs() < 1e-12);
                let radius = 0.5;
                let near: Vec<u32> = (0..segments.len() as u32)
                    .filter(|&k| {
                        let [a, b] = segments[k as usize];
                        point_segment_distance(p, a, b) <= radius
                    })
                    .collect();
                assert_eq!(tree.within(p, radius), near);
                // A filter that admits only odd keys: found when a scan finds one.
                let odd = |k: u32| k % 2 == 1;
                let found = tree.find_within(p, radius, odd);
                assert_eq!(found.is_some(), near.iter().any(|&k| odd(k)));
                assert!(found.is_none_or(|k| odd(k) && near.contains(&k)));
                // Nearest first: the distances of a scan, sorted.
                let mut visited = Vec::new();
                let _: ControlFlow<()> = tree.visit_nearest_first(p, radius, |k, d| {
                    visited.push((k, d));
                    ControlFlow::Continue(())
                });
                assert!(visited.windows(2).all(|w| w[0].1 <= w[1].1));
                let mut keys: Vec<u32> = visited.iter().map(|&(k, _)| k).collect();
                keys.sort_unstable();
                assert_eq!(keys, near);
            }
        }
    }
}
