//! Taylor series of a run of consecutive chain indices, stored
//! coefficient-major: row `k` holds the order-`k` coefficients of every
//! index side by side, so the recursion, the evaluation of a whole window
//! and the cheap proof that a gap stays open are each a stencil or a
//! pointwise update along a row, which the compiler vectorizes.
//!
//! Column `c` is chain index `first + c - 1`: the gap `Delta` of that unit
//! and the scaled velocity `u` of its node (the unit's end away from the
//! wall). Columns `0` and `width - 1` are boundaries: the velocity in column
//! 0 reads zero (the wall's if the run starts at unit 1), the gap in the last
//! column is the ghost elongation beyond the loaded end (or zero).
//!
//! Rows are worked in whole blocks of [`LANES`] columns, past the last
//! column if need be (rows are allocated long enough): at an impact they
//! are about 20 columns long, too short for the compiler's own unrolled
//! loops, which would leave them to a scalar tail. What lands past the last
//! column is never read back into it.

/// Longest series a column is gathered into (orders up to 15).
pub const MAX_COLUMN: usize = 16;

/// Columns per block: two AVX2 registers.
pub const LANES: usize = 8;

/// `n` rounded up to whole blocks.
pub fn blocks(n: usize) -> usize {
    n.div_ceil(LANES) * LANES
}

/// Gap and velocity series of `width - 2` consecutive indices, with their
/// boundary columns.
#[derive(Debug, Clone, Default)]
pub struct Series {
    order: usize,
    width: usize,
    /// Allocated row length: room for whole blocks from any column.
    stride: usize,
    pub gap: Vec<f64>,
    pub vel: Vec<f64>,
}

impl Series {
    /// Zero series of order `order` for `units` indices.
    pub fn new(order: usize, units: usize) -> Self {
        assert!(order < MAX_COLUMN, "series order {order} is too high");
        let mut series = Series {
            order,
            ..Series::default()
        };
        series.reset(units);
        series
    }

    /// Make room for `units` indices. Coefficients are left as they were:
    /// order 0 is for the caller to set, [`expand`](Self::expand) sets the
    /// rest.
    pub fn reset(&mut self, units: usize) {
        self.width = units + 2;
        self.stride = blocks(self.width) + LANES;
        let len = (self.order + 1) * self.stride;
        self.gap.resize(len, 0.0);
        self.vel.resize(len, 0.0);
    }

    pub fn width(&self) -> usize {
        self.width
    }

    /// Where coefficient `k` of column `c` is.
    pub fn at(&self, k: usize, c: usize) -> usize {
        k * self.stride + c
    }

    /// The series of column `c` of `rows` (`gap` or `vel`) into `out`.
    pub fn column<'o>(&self, rows: &[f64], c: usize, out: &'o mut [f64]) -> &'o [f64] {
        let out = &mut out[..=self.order];
        for (x, &r) in out.iter_mut().zip(rows[c..].iter().step_by(self.stride)) {
            *x = r;
        }
        out
    }

    /// `sum_k rows[k][c] tau^k`.
    pub fn value(&self, rows: &[f64], c: usize, tau: f64) -> f64 {
        let mut column = [0.0; MAX_COLUMN];
        self.column(rows, c, &mut column)
            .iter()
            .rev()
            .fold(0.0, |p, &x| p * tau + x)
    }

    /// Gaps and velocities of columns `first..first + tau.len()`, each at
    /// its own `tau`, into `gaps` and `vels`. All three are whole blocks
    /// long (see [`blocks`]); past the last column they hold anything.
    pub fn values(&self, first: usize, tau: &[f64], gaps: &mut [f64], vels: &mut [f64]) {
        let (taus, _) = tau.as_chunks::<LANES>();
        debug_assert_eq!(taus.len() * LANES, tau.len(), "whole blocks only");
        for (out, rows) in [(gaps, &self.gap), (vels, &self.vel)] {
            let (out, _) = out[..tau.len()].as_chunks_mut::<LANES>();
            // Block by block, each sum held in registers through all the
            // orders: a short row would otherwise wait on memory each order.
            for (j, (p, t)) in out.iter_mut().zip(taus).enumerate() {
                let block = |k: usize| -> [f64; LANES] {
                    let at = self.at(k, first + j * LANES);
                    rows[at..at + LANES].try_into().expect("a block of a row")
                };
                let mut sum = block(self.order);
                for k in (0..self.order).rev() {
                    let c = block(k);
                    sum = std::array::from_fn(|i| sum[i] * t[i] + c[i]);
                }
                *p = sum;
            }
        }
    }

    /// Fill orders `1..=K` from order 0. The boundary columns are set here:
    /// velocity zero on the left, the ghost elongation `ghost` (order 0
    /// only) on the right. Orders above `2i` of the `i`-th column from an
    /// open end are not valid (they would need states beyond it); the left
    /// end is exact when it is the wall, the right when it is unit N.
    ///
    /// `block`: columns from this one on are the end block in resting
    /// contact: shut at every order, their nodes and the node on the
    /// block's left moving as one rigid body pushed by the ghost and pulled
    /// by the unit left of it; a block from column 1 includes the wall
    /// and is at rest.
    pub fn expand(&mut self, ghost: f64, block: Option<usize>) {
        let (w, s) = (self.width, self.stride);
        let n = blocks(w - 2);
        for k in 0..=self.order {
            self.vel[k * s] = 0.0;
            self.gap[k * s + w - 1] = if k == 0 { ghost } else { 0.0 };
        }
        for k in 0..self.order {
            let inv = 1.0 / (k + 1) as f64;
            let (done, next) = self.gap.split_at_mut((k + 1) * s);
            let (gap, next_gap) = (&done[k * s..], &mut next[..s]);
            let (done, next) = self.vel.split_at_mut((k + 1) * s);
            let (vel, next_vel) = (&done[k * s..], &mut next[..s]);
            // Delta_n' = u_n - u_{n-1},  u_n' = Delta_{n+1} - Delta_n.
            differences(&mut next_gap[1..=n], &mut next_vel[1..=n], gap, vel, inv);
            // The whole blocks ran over the ghost: it is zero past order 0.
            next_gap[w - 1] = 0.0;
            if let Some(b) = block.filter(|&b| b < w - 1) {
                let rigid = match b {
                    1 => 0.0,
                    _ => (gap[w - 1] - gap[b - 1]) * inv / (w - b) as f64,
                };
                next_gap[b..w - 1].fill(0.0);
                next_vel[(b - 1).max(1)..w - 1].fill(rigid);
            }
        }
    }

    /// For columns `first..first + open.len()`, whether the gap is proven
    /// not to fall through zero on `[0, span]`: it stays above zero,
    /// `Delta_0 > sum_{k >= 1} |Delta_k| span^k`, or it starts at or above
    /// zero and rises all along, `Delta_1 > sum_{k >= 2} k |Delta_k|
    /// span^(k-1)` (both padded for rounding), or it is constant.
    pub fn open_over(&self, first: usize, span: f64, open: &mut [bool]) {
        for (j, open) in open.chunks_mut(LANES).enumerate() {
            let block = |k: usize| -> [f64; LANES] {
                let at = self.at(k, first + j * LANES);
                self.gap[at..at + LANES]
                    .try_into()
                    .expect("a block of a row")
            };
            // Block by block, the bounds held in registers through all the
            // orders.
            let (mut reach, mut turn) = ([0.0; LANES], [0.0; LANES]);
            let mut power = 1.0; // span^(k - 1)
            for k in 1..=self.order {
                let c = block(k);
                let factor = k as f64 * power;
                if k >= 2 {
                    turn = std::array::from_fn(|i| turn[i] + c[i].abs() * factor);
                }
                power *= span;
                reach = std::array::from_fn(|i| reach[i] + c[i].abs() * power);
            }
            let (values, slopes) = (block(0), block(1));
            for (i, o) in open.iter_mut().enumerate() {
                let (c, b, t) = (values[i], reach[i], turn[i]);
                let above = c - b * (1.0 + 1e-12) > 0.0 || b == 0.0;
                let rising = c >= 0.0 && slopes[i] - t * (1.0 + 1e-12) > 0.0;
                *o = above || rising;
            }
        }
    }

    /// Copy columns `from..from + count` of `source` (same order) into
    /// columns `to..` of this series, every order.
    pub fn copy_columns(&mut self, source: &Series, from: usize, to: usize, count: usize) {
        for k in 0..=self.order {
            let (dst, src) = (self.at(k, to), source.at(k, from));
            self.gap[dst..dst + count].copy_from_slice(&source.gap[src..src + count]);
            self.vel[dst..dst + count].copy_from_slice(&source.vel[src..src + count]);
        }
    }
}

// Row kernels over whole blocks. Each takes its rows as separate slices,
// which tells the compiler they do not overlap.

/// One order of the recursion over whole blocks from column 1:
/// `next_gap[i] = (vel[i + 1] - vel[i]) * scale` and `next_vel[i] =
/// (gap[i + 2] - gap[i + 1]) * scale`, the rows of order `k` given from
/// column 0 and the next ones from column 1.
#[inline]
fn differences(next_gap: &mut [f64], next_vel: &mut [f64], gap: &[f64], vel: &[f64], scale: f64) {
    let n = next_gap.len();
    let (next_gap, _) = next_gap.as_chunks_mut::<LANES>();
    let (next_vel, _) = next_vel[..n].as_chunks_mut::<LANES>();
    debug_assert_eq!(next_gap.len() * LANES, n, "whole blocks only");
    let block = |row: &[f64], at: usize| -> [f64; LANES] {
        row[at..at + LANES].try_into().expect("a block of a row")
    };
    for (j, (g, v)) in next_gap.iter_mut().zip(next_vel).enumerate() {
        let c = j * LANES;
        let (left, here) = (block(vel, c), block(vel, c + 1));
        let (own, right) = (block(gap, c + 1), block(gap, c + 2));
        // Delta_n' = u_n - u_{n-1},  u_n' = Delta_{n+1} - Delta_n.
        *g = std::array::from_fn(|i| (here[i] - left[i]) * scale);
        *v = std::array::from_fn(|i| (right[i] - own[i]) * scale);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expansion_follows_the_free_chain_by_hand() {
        // Two units at the wall, the second loaded by a ghost of 0.5:
        // Delta' = (u_1, u_2 - u_1), u' = (Delta_2 - Delta_1, 0.5 - Delta_2).
        let mut s = Series::new(2, 2);
        let (d, u) = ([0.3, 0.1], [0.2, -0.4]);
        s.gap[1..=2].copy_from_slice(&d);
        s.vel[1..=2].copy_from_slice(&u);
        s.expand(0.5, None);
        assert_eq!(s.gap[s.at(1, 1)], u[0]);
        assert_eq!(s.gap[s.at(1, 2)], u[1] - u[0]);
        assert_eq!(s.vel[s.at(1, 1)], d[1] - d[0]);
        assert_eq!(s.vel[s.at(1, 2)], 0.5 - d[1]);
        // Second order: Delta_1'' / 2 = u_1' / 2 = (Delta_2 - Delta_1) / 2.
        assert_eq!(s.gap[s.at(2, 1)], (d[1] - d[0]) / 2.0);
        // u_2'' / 2 = -Delta_2' / 2 = -(u_2 - u_1) / 2.
        assert_eq!(s.vel[s.at(2, 2)], -(u[1] - u[0]) / 2.0);
        // Evaluation agrees with the columns' own Horner sums.
        let mut column = [0.0; 3];
        let series = s.column(&s.gap, 2, &mut column).to_vec();
        let tau = 0.01;
        let by_hand = series[0] + series[1] * tau + series[2] * tau * tau;
        assert!((s.value(&s.gap, 2, tau) - by_hand).abs() < 1e-16);
    }

    #[test]
    fn a_gap_that_may_close_is_not_called_open() {
        let mut s = Series::new(1, 2);
        s.gap[1] = 1.0;
        s.gap[2] = 1.0;
        let (first, second) = (s.at(1, 1), s.at(1, 2));
        s.gap[first] = -10.0; // closes at 0.1
        s.gap[second] = -1.0; // closes at 1
        let mut open = [true; 2];
        s.open_over(1, 0.5, &mut open);
        assert_eq!(open, [false, true]);
        // Rising from zero all along the span is not a fall; turning back
        // down within it may be.
        s.gap[1] = 0.0;
        s.gap[first] = 1.0;
        s.open_over(1, 0.1, &mut open[..1]);
        assert!(open[0]);
        let mut s = Series::new(2, 1);
        let (slope, curvature) = (s.at(1, 1), s.at(2, 1));
        (s.gap[slope], s.gap[curvature]) = (1.0, -10.0); // turns at 0.05
        s.open_over(1, 0.1, &mut open[..1]);
        assert!(!open[0]);
        s.open_over(1, 0.04, &mut open[..1]);
        assert!(open[0]);
    }
}
