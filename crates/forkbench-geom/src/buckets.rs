//! The obstacles' spatial index: a uniform grid of buckets holding the shapes whose bounds overlap each, laid out densely for queries.

use std::collections::HashMap;
use std::sync::OnceLock;

/// Axis-aligned bounds: min x, min y, max x, max y.
pub(crate) type Bounds = [f64; 4];

/// Side of a bucket.
const BUCKET_M: f64 = 2.0;
/// Shapes spanning more buckets than this go to the always-tested list.
const MAX_BUCKETS_PER_SHAPE: i64 = 4096;
/// A dense layout may hold at most this many buckets per filed entry (plus a floor), so
/// shapes scattered far apart cannot make it large; past that the hash map answers.
const DENSE_CELLS_PER_ENTRY: i64 = 64;
const DENSE_CELLS_FLOOR: i64 = 1 << 16;

/// The bucket range (inclusive) that `b` overlaps.
fn bucket_range(b: &Bounds) -> ([i64; 2], [i64; 2]) {
    let cell = |v: f64| (v / BUCKET_M).floor().clamp(-1e12, 1e12) as i64;
    ([cell(b[0]), cell(b[1])], [cell(b[2]), cell(b[3])])
}

/// Shape indices by bucket. Registration files into a hash map; the first query lays
/// the map out as a dense grid (rebuilt after the next registration), which answers
/// without hashing.
#[derive(Default)]
pub(crate) struct Buckets {
    map: HashMap<(i64, i64), Vec<usize>>,
    /// Shapes too large (or too odd) to bucket, returned by every query.
    large: Vec<usize>,
    dense: OnceLock<Option<Dense>>,
}

/// The buckets from `lo` on, `dims` wide, row by row.
struct Dense {
    lo: [i64; 2],
    dims: [i64; 2],
    cells: Vec<Vec<usize>>,
}

impl Buckets {
    /// Files shape `i` with bounds `b`.
    pub fn register(&mut self, i: usize, b: &Bounds) {
        self.dense = OnceLock::new();
        let (lo, hi) = bucket_range(b);
        let span = (hi[0] - lo[0] + 1).saturating_mul(hi[1] - lo[1] + 1);
        if !(b.iter().all(|v| v.is_finite()) && span <= MAX_BUCKETS_PER_SHAPE) {
            self.large.push(i);
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                self.map.entry((x, y)).or_default().push(i);
            }
        }
    }

    /// Calls `f` with every shape whose buckets overlap `b` grown by `reach_m`, in no
    /// particular order and possibly more than once.
    pub fn each_near(&self, b: &Bounds, reach_m: f64, mut f: impl FnMut(usize)) {
        let grown = [
            b[0] - reach_m,
            b[1] - reach_m,
            b[2] + reach_m,
            b[3] + reach_m,
        ];
        let (lo, hi) = bucket_range(&grown);
        self.large.iter().for_each(|&i| f(i));
        match self.dense.get_or_init(|| self.layout()) {
            Some(d) => d.each(lo, hi, &mut f),
            None => self.each_hashed(lo, hi, &mut f),
        }
    }

    fn each_hashed(&self, lo: [i64; 2], hi: [i64; 2], f: &mut impl FnMut(usize)) {
        let span = (hi[0] - lo[0] + 1).saturating_mul(hi[1] - lo[1] + 1);
        if span > self.map.len() as i64 {
            // A query wider than the map: every bucketed shape.
            self.map.values().flatten().for_each(|&i| f(i));
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                if let Some(v) = self.map.get(&(x, y)) {
                    v.iter().for_each(|&i| f(i));
                }
            }
        }
    }

    /// The dense grid over the filed buckets, or `None` when it would be too large.
    fn layout(&self) -> Option<Dense> {
        let mut lo = [i64::MAX; 2];
        let mut hi = [i64::MIN; 2];
        for &(x, y) in self.map.keys() {
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
        if self.map.is_empty() {
            return Some(Dense {
                lo: [0, 0],
                dims: [0, 0],
                cells: Vec::new(),
            });
        }
        let dims = [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1];
        let entries: usize = self.map.values().map(Vec::len).sum();
        let budget = (entries as i64)
            .saturating_mul(DENSE_CELLS_PER_ENTRY)
            .max(DENSE_CELLS_FLOOR);
        if dims[0].saturating_mul(dims[1]) > budget {
            return None;
        }
        let mut cells = vec![Vec::new(); (dims[0] * dims[1]) as usize];
        for (&(x, y), v) in &self.map {
            cells[((y - lo[1]) * dims[0] + (x - lo[0])) as usize] = v.clone();
        }
        Some(Dense { lo, dims, cells })
    }
}

impl Dense {
    /// Calls `f` with the shapes of the buckets in `lo..=hi` (clipped to the grid).
    fn each(&self, lo: [i64; 2], hi: [i64; 2], f: &mut impl FnMut(usize)) {
        let x0 = lo[0].max(self.lo[0]);
        let y0 = lo[1].max(self.lo[1]);
        let x1 = hi[0].min(self.lo[0] + self.dims[0] - 1);
        let y1 = hi[1].min(self.lo[1] + self.dims[1] - 1);
        for y in y0..=y1 {
            let row = (y - self.lo[1]) * self.dims[0] - self.lo[0];
            for x in x0..=x1 {
                self.cells[(row + x) as usize].iter().for_each(|&i| f(i));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shape whose bounds meet the grown query comes back from the dense layout,
    /// and the dense layout returns no shape the hash map would not.
    #[test]
    fn the_dense_layout_finds_every_shape_the_query_meets() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut unit = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut b = Buckets::default();
        let mut all = Vec::new();
        for i in 0..400 {
            let (x, y) = (unit() * 60.0 - 10.0, unit() * 40.0 - 10.0);
            let (w, h) = (unit() * 5.0, unit() * 5.0);
            let bounds = [x, y, x + w, y + h];
            b.register(i, &bounds);
            all.push(bounds);
        }
        b.register(400, &[-1e9, -1e9, 1e9, 1e9]);
        all.push([-1e9, -1e9, 1e9, 1e9]);
        for _ in 0..2000 {
            let (x, y) = (unit() * 80.0 - 20.0, unit() * 60.0 - 20.0);
            let q = [x, y, x + unit() * 15.0, y + unit() * 15.0];
            let reach = [0.0, 0.5, 3.0][(unit() * 3.0) as usize % 3];
            let mut dense = Vec::new();
            b.each_near(&q, reach, |i| dense.push(i));
            let mut hashed = Vec::new();
            let (lo, hi) = bucket_range(&[q[0] - reach, q[1] - reach, q[2] + reach, q[3] + reach]);
            b.large.iter().for_each(|&i| hashed.push(i));
            b.each_hashed(lo, hi, &mut |i| hashed.push(i));
            for v in [&mut dense, &mut hashed] {
                v.sort_unstable();
                v.dedup();
            }
            for (i, s) in all.iter().enumerate() {
                let meets = s[0] <= q[2] + reach
                    && q[0] - reach <= s[2]
                    && s[1] <= q[3] + reach
                    && q[1] - reach <= s[3];
                assert!(!meets || dense.contains(&i), "shape {i} missed by {q:?}");
            }
            assert!(dense.iter().all(|i| hashed.contains(i)));
        }
        assert!(
            b.dense.get().is_some_and(Option::is_some),
            "laid out densely"
        );
    }
}
