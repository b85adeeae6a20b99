//! Shortest distances along the edges of a surface (Dijkstra 1959) from several sources,
//! optionally within a radius. The evaluation measures bleeding with it.

use super::surface::SurfaceMesh;
use super::topology::Topology;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// A heap entry: a tentative distance and a tie-breaking key (a vertex index, or
/// `Reverse` of one), ordered so that `BinaryHeap` (a max-heap) pops the smallest distance
/// first and, among equal distances, the smallest key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest<K> {
    pub distance: f64,
    pub key: K,
}

impl<K: Ord> Eq for Nearest<K> {}

impl<K: Ord> Ord for Nearest<K> {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .distance
            .total_cmp(&self.distance)
            .then(other.key.cmp(&self.key))
    }
}

impl<K: Ord> PartialOrd for Nearest<K> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Edge-path distances of one multi-source search, d(v) = min over sources s and edge
/// paths s → v of the summed edge lengths; working memory for #V vertices, reused across
/// searches ([`EdgeDistances::clear`] resets only what a search touched).
#[derive(Debug, Clone)]
pub struct EdgeDistances {
    /// #V distances, infinite where not reached.
    distance: Vec<f64>,
    reached: Vec<u32>,
    /// Equal distances settle from the largest vertex index down.
    heap: BinaryHeap<Nearest<Reverse<u32>>>,
}

impl EdgeDistances {
    /// Working memory for `vertex_count` vertices, nothing reached.
    pub fn new(vertex_count: usize) -> Self {
        Self {
            distance: vec![f64::INFINITY; vertex_count],
            reached: Vec::new(),
            heap: BinaryHeap::new(),
        }
    }

    /// Distances from `sources` (each at distance 0) to every vertex whose distance is at
    /// most `radius` (infinite for no bound).
    pub fn search(
        &mut self,
        surface: &SurfaceMesh,
        topology: &Topology,
        sources: impl IntoIterator<Item = u32>,
        radius: f64,
    ) {
        for s in sources {
            if self.distance[s as usize].is_infinite() {
                self.reached.push(s);
            }
            self.distance[s as usize] = 0.0;
            self.heap.push(Nearest {
                distance: 0.0,
                key: Reverse(s),
            });
        }
        while let Some(Nearest {
            distance,
            key: Reverse(vertex),
        }) = self.heap.pop()
        {
            let v = vertex as usize;
            if distance > self.distance[v] {
                continue;
            }
            let p = surface.positions[v];
            for &n in topology.neighbors(v) {
                let u = n as usize;
                let d = distance + p.distance(surface.positions[u]);
                if d <= radius && d < self.distance[u] {
                    if self.distance[u].is_infinite() {
                        self.reached.push(n);
                    }
                    self.distance[u] = d;
                    self.heap.push(Nearest {
                        distance: d,
                        key: Reverse(n),
                    });
                }
            }
        }
    }

    /// Whether the last search reached `vertex`.
    pub fn reached(&self, vertex: u32) -> bool {
        self.distance[vertex as usize].is_finite()
    }

    /// Forgets the last search.
    pub fn clear(&mut self) {
        for &v in &self.reached {
            self.distance[v as usize] = f64::INFINITY;
        }
        self.reached.clear();
    }
}
