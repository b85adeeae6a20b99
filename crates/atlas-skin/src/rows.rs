//! Compressed rows: a list of values per index of `0..n`, stored as one array of values and
//! an array of offsets (row i is `values[offsets[i]..offsets[i + 1]]`), the layout of
//! adjacency lists, spatial grids and per-vertex weight lists.

use rayon::prelude::*;

/// Rows per parallel work item of [`Rows::par_build`] where the work per row is small.
pub const PAR_CHUNK: usize = 2048;

/// Rows of values over `0..n`: row i is `values[offsets[i] as usize..offsets[i + 1] as usize]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rows<T> {
    /// n + 1 non-decreasing offsets, starting at 0.
    pub offsets: Vec<u32>,
    pub values: Vec<T>,
}

impl<T> Rows<T> {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of row `i`.
    pub fn row(&self, i: usize) -> &[T] {
        &self.values[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

impl<T: Copy + Default> Rows<T> {
    /// Groups `(row, value)` entries into `n` rows by a counting sort: each row keeps its
    /// values in the order the entries come. `entries` is walked twice (to count, then to
    /// fill); every row index must be `< n`.
    pub fn group(n: usize, entries: impl Iterator<Item = (usize, T)> + Clone) -> Self {
        let mut offsets = vec![0u32; n + 1];
        for (i, _) in entries.clone() {
            offsets[i + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut next = offsets.clone();
        let mut values = vec![T::default(); offsets[n] as usize];
        for (i, value) in entries {
            values[next[i] as usize] = value;
            next[i] += 1;
        }
        Self { offsets, values }
    }
}

impl<T: Copy + Default> Rows<T> {
    /// [`Rows::group`] of the entries `k` in `0..count` whose `key(k)` is some row index
    /// (`< n`), with value `value(k)`: the same rows, from plain index loops (no iterator
    /// to clone and walk twice), for large groupings (the duplicate faces of a mesh).
    pub fn group_indexed(
        n: usize,
        count: usize,
        key: impl Fn(usize) -> Option<usize>,
        value: impl Fn(usize) -> T,
    ) -> Self {
        let mut offsets = vec![0u32; n + 1];
        for k in 0..count {
            if let Some(i) = key(k) {
                offsets[i + 1] += 1;
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut next = offsets[..n].to_vec();
        let mut values = vec![T::default(); offsets[n] as usize];
        for k in 0..count {
            if let Some(i) = key(k) {
                values[next[i] as usize] = value(k);
                next[i] += 1;
            }
        }
        Self { offsets, values }
    }
}

impl<T: Send> Rows<T> {
    /// Builds `n` rows in parallel, in chunks of `chunk` rows: `fill(i, scratch, out)`
    /// appends row i's values to `out`; `scratch` is working memory reused within a chunk.
    pub fn par_build<S: Default>(
        n: usize,
        chunk: usize,
        fill: impl Fn(usize, &mut S, &mut Vec<T>) + Sync,
    ) -> Self {
        let chunks: Vec<(Vec<u32>, Vec<T>)> = (0..n.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let range = c * chunk..((c + 1) * chunk).min(n);
                let mut lengths = Vec::with_capacity(range.len());
                let mut values = Vec::new();
                let mut scratch = S::default();
                for i in range {
                    let before = values.len();
                    fill(i, &mut scratch, &mut values);
                    lengths.push((values.len() - before) as u32);
                }
                (lengths, values)
            })
            .collect();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        let mut values = Vec::with_capacity(chunks.iter().map(|c| c.1.len()).sum());
        for (lengths, chunk_values) in chunks {
            for length in lengths {
                offsets.push(offsets[offsets.len() - 1] + length);
            }
            values.extend(chunk_values);
        }
        Self { offsets, values }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grouping_keeps_entry_order_within_a_row() {
        let rows = Rows::group(4, [(2, 'a'), (0, 'b'), (2, 'c'), (3, 'd')].into_iter());
        assert_eq!(rows.offsets, [0, 1, 1, 3, 4]);
        assert_eq!(
            (rows.row(0), rows.row(1), rows.row(2)),
            (&['b'][..], &[][..], &['a', 'c'][..])
        );
    }

    #[test]
    fn indexed_grouping_equals_grouping() {
        let key = |k: usize| (k % 7 != 3).then_some((k * 5) % 11);
        let indexed = Rows::group_indexed(11, 100, key, |k| k as u32);
        let entries = (0..100).filter_map(|k| key(k).map(|i| (i, k as u32)));
        assert_eq!(indexed, Rows::group(11, entries));
    }

    #[test]
    fn parallel_rows_equal_sequential_ones() {
        let fill = |i: usize, _: &mut (), out: &mut Vec<usize>| out.extend(0..i % 5);
        let rows = Rows::par_build(1000, 64, fill);
        let entries = (0..1000).flat_map(|i| (0..i % 5).map(move |k| (i, k)));
        assert_eq!(rows, Rows::group(1000, entries));
    }
}
