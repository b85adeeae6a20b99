//! A sparse row summed in a dense array: entries added in any order, by index, then read
//! out ascending and cleared, in O(entries set · log) whatever the array's length (the
//! rows of Q in [`super::inpaint`], the smoothed rows of [`super::smooth`]).

/// A sparse row accumulated in a dense array: the values and which entries were set.
pub struct RowScratch {
    values: Vec<f64>,
    set: Vec<bool>,
    touched: Vec<u32>,
}

impl RowScratch {
    /// Room for the indices below `n`.
    pub fn new(n: usize) -> Self {
        Self {
            values: vec![0.0; n],
            set: vec![false; n],
            touched: Vec::new(),
        }
    }

    /// Adds `value` to entry `j`.
    pub fn add(&mut self, j: u32, value: f64) {
        if !self.set[j as usize] {
            self.set[j as usize] = true;
            self.touched.push(j);
        }
        self.values[j as usize] += value;
    }

    /// Appends the entries set, ascending, and clears them.
    pub fn drain_into(&mut self, out: &mut Vec<(u32, f64)>) {
        self.touched.sort_unstable();
        for &j in &self.touched {
            out.push((j, self.values[j as usize]));
            self.values[j as usize] = 0.0;
            self.set[j as usize] = false;
        }
        self.touched.clear();
    }
}
