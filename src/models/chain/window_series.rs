//! Taylor series of a run of consecutive chain indices, stored
//! coefficient-major: row `k` holds the order-`k` coefficients of every
//! index side by side, so the recursion, the evaluation of a whole window
//! and the cheap proof that a gap stays open are each a stencil or a
//! pointwise update along a row, four columns to a register.
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
//! column is never read back into it. The one to three blocks of an
//! impact's reach get their own copies of the kernels (the count known, the
//! loops unroll and lose their bounds checks), and the recursion computes
//! one row, then the other, alternating from order to order, so that no
//! row is read back one column off right after it was stored.

use wide::f64x4;

use crate::numerics::fused::mul_add;

/// Longest series a column is gathered into (orders up to 15).
pub const MAX_COLUMN: usize = 16;

/// Columns per block: two AVX2 registers.
pub const LANES: usize = 8;

/// Blocks whose sums run side by side in the row passes: enough
/// independent chains to hide the latency of each step.
const GROUP: usize = 2;

/// `1 / (k + 1)` for the step from order `k` to `k + 1`.
const INVERSES: [f64; MAX_COLUMN] = {
    let mut inverses = [0.0; MAX_COLUMN];
    let mut k = 0;
    while k < MAX_COLUMN {
        inverses[k] = 1.0 / (k + 1) as f64;
        k += 1;
    }
    inverses
};

// The row kernels hold their blocks in explicit four-column registers
// (`wide::f64x4`, moved in and out with `bytemuck::cast`): left to the
// compiler, their lanes came out shuffled and partly scalar, and its choices
// moved with unrelated changes elsewhere in the crate. `f64x4::mul_add`
// fuses exactly where `mul_add` does (where the build target has FMA, and
// on every aarch64 target), so both give the same bits.

/// Registers of four columns per block.
const QUADS: usize = LANES / 4;

/// A block of columns in registers.
type Block = [f64x4; QUADS];

/// A block of columns into registers.
#[inline(always)]
fn load(block: &[f64; LANES]) -> Block {
    bytemuck::cast(*block)
}

/// Registers back into a block of columns.
#[inline(always)]
fn store(block: &mut [f64; LANES], registers: Block) {
    *block = bytemuck::cast(registers);
}

/// [`blocks_at`], to write.
#[inline(always)]
fn blocks_at_mut<const G: usize>(row: &mut [f64], at: usize) -> &mut [[f64; LANES]; G] {
    row[at..at + G * LANES]
        .as_chunks_mut::<LANES>()
        .0
        .try_into()
        .expect("G blocks")
}

/// The blocks of `row` from column `at` on, `G` of them.
#[inline(always)]
fn blocks_at<const G: usize>(row: &[f64], at: usize) -> &[[f64; LANES]; G] {
    row[at..at + G * LANES]
        .as_chunks::<LANES>()
        .0
        .try_into()
        .expect("G blocks")
}

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
    /// Gap series `Delta`, coefficient-major: coefficient `k` of column `c`
    /// is at [`Series::at`]`(k, c)`.
    pub gap: Vec<f64>,
    /// Scaled velocity series `u`, laid out as `gap`.
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

    /// Columns, the two boundary columns included.
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
            .fold(0.0, |p, &x| mul_add(p, tau, x))
    }

    /// Gaps and velocities of columns `first..first + tau.len()`, each at
    /// its own `tau`, into `gaps` and `vels`. All three are whole blocks
    /// long (see [`blocks`]); past the last column they hold anything.
    pub fn values(&self, first: usize, tau: &[f64], gaps: &mut [f64], vels: &mut [f64]) {
        let (taus, _) = tau.as_chunks::<LANES>();
        debug_assert_eq!(taus.len() * LANES, tau.len(), "whole blocks only");
        let (gaps, _) = gaps[..tau.len()].as_chunks_mut::<LANES>();
        let (vels, _) = vels[..tau.len()].as_chunks_mut::<LANES>();
        let mut j = 0;
        while j < taus.len() {
            let column = first + j * LANES;
            let out = (&mut gaps[j..], &mut vels[j..]);
            j += if taus.len() - j >= GROUP {
                self.values_of::<GROUP>(column, &taus[j..], out)
            } else {
                self.values_of::<1>(column, &taus[j..], out)
            };
        }
    }

    /// [`values`](Self::values) of the `G` blocks from `column`: the `2 G`
    /// Horner sums (both rows) go through the orders side by side, held in
    /// registers, so that each waits on its own last step only. Returns `G`.
    #[inline(always)]
    fn values_of<const G: usize>(
        &self,
        column: usize,
        taus: &[[f64; LANES]],
        (gaps, vels): (&mut [[f64; LANES]], &mut [[f64; LANES]]),
    ) -> usize {
        let t: [Block; G] = std::array::from_fn(|b| load(&taus[b]));
        let mut sums = [[[f64x4::ZERO; QUADS]; G]; 2];
        for k in (0..=self.order).rev() {
            let at = self.at(k, column);
            for (sum, rows) in sums.iter_mut().zip([&self.gap, &self.vel]) {
                for ((s, t), c) in sum.iter_mut().zip(&t).zip(blocks_at::<G>(rows, at)) {
                    let c = load(c);
                    *s = std::array::from_fn(|q| s[q].mul_add(t[q], c[q]));
                }
            }
        }
        let [g, v] = sums;
        for b in 0..G {
            store(&mut gaps[b], g[b]);
            store(&mut vels[b], v[b]);
        }
        G
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
        // An impact's reach is a few blocks wide: with the count known
        // here, the row loops unroll and lose their bounds checks.
        match blocks(self.width - 2) / LANES {
            1 => self.expand_blocks(1, ghost, block),
            2 => self.expand_blocks(2, ghost, block),
            3 => self.expand_blocks(3, ghost, block),
            n => self.expand_blocks(n, ghost, block),
        }
    }

    /// [`expand`](Self::expand) over `count` blocks of columns.
    #[inline(always)]
    fn expand_blocks(&mut self, count: usize, ghost: f64, block: Option<usize>) {
        let (w, s, n) = (self.width, self.stride, count * LANES);
        let rows = self.order + 1;
        // The boundary columns: set here for every order, not as each is
        // computed (the next order would read them back at once; see
        // `differences`). Only a ghost inside the blocks, which they run
        // over, is put back after each gap row.
        for k in 0..rows {
            self.vel[k * s] = 0.0;
            self.gap[k * s + w - 1] = if k == 0 { ghost } else { 0.0 };
        }
        let mut gaps = self.gap[..rows * s].chunks_exact_mut(s);
        let mut vels = self.vel[..rows * s].chunks_exact_mut(s);
        let (Some(mut gap), Some(mut vel)) = (gaps.next(), vels.next()) else {
            return;
        };
        // Where the whole blocks run over the ghost, which is zero past
        // order 0.
        let ghost_column = (w - 1 <= n).then_some(w - 2);
        for (k, ((next_gap, next_vel), inv)) in gaps.zip(vels).zip(INVERSES).enumerate() {
            // Delta_n' = u_n - u_{n-1},  u_n' = Delta_{n+1} - Delta_n.
            differences(
                (&mut next_gap[1..=n], &mut next_vel[1..=n]),
                (gap, vel),
                (inv, ghost_column),
                k % 2 == 0,
            );
            if let Some(b) = block.filter(|&b| b < w - 1) {
                let rigid = match b {
                    1 => 0.0,
                    _ => (gap[w - 1] - gap[b - 1]) * inv / (w - b) as f64,
                };
                next_gap[b..w - 1].fill(0.0);
                next_vel[(b - 1).max(1)..w - 1].fill(rigid);
            }
            (gap, vel) = (next_gap, next_vel);
        }
    }

    /// For columns `first..first + open.len()`, whether the gap is proven
    /// not to fall through zero on `[0, span]`: it stays above zero,
    /// `Delta_0 > sum_{k >= 1} |Delta_k| span^k`, or it starts at or above
    /// zero and rises all along, `Delta_1 > sum_{k >= 2} k |Delta_k|
    /// span^(k-1)` (both padded for rounding), or it is constant.
    pub fn open_over(&self, first: usize, span: f64, open: &mut [bool]) {
        // What order k weighs in each bound: span^k, and k span^(k-1) from
        // order 2 on.
        let mut weights = [[0.0; 2]; MAX_COLUMN];
        let (mut power, mut k) = (1.0, 1.0);
        for weight in &mut weights[1..=self.order] {
            let turn = if k >= 2.0 { k * power } else { 0.0 };
            power *= span;
            *weight = [power, turn];
            k += 1.0;
        }
        let mut j = 0;
        while j < open.len() {
            let column = first + j;
            let open = &mut open[j..];
            // A group's blocks must hold a column each: rows are padded by
            // one block only.
            j += if open.len() > (GROUP - 1) * LANES {
                self.open_of::<GROUP>(column, &weights, open)
            } else {
                self.open_of::<1>(column, &weights, open)
            };
        }
    }

    /// [`open_over`](Self::open_over) of up to `G` blocks from `column`,
    /// the `2 G` bounds held in registers through all the orders. Returns
    /// the columns done.
    #[inline(always)]
    fn open_of<const G: usize>(
        &self,
        column: usize,
        weights: &[[f64; 2]; MAX_COLUMN],
        open: &mut [bool],
    ) -> usize {
        let row = |k: usize| blocks_at::<G>(&self.gap, self.at(k, column));
        let (mut reach, mut turn) = ([[f64x4::ZERO; QUADS]; G], [[f64x4::ZERO; QUADS]; G]);
        for (k, &[to_reach, to_turn]) in (1..=self.order).zip(&weights[1..]) {
            let (to_reach, to_turn) = (f64x4::splat(to_reach), f64x4::splat(to_turn));
            let row = row(k);
            for ((r, t), c) in reach.iter_mut().zip(&mut turn).zip(row) {
                for (q, c) in load(c).into_iter().enumerate() {
                    let c = c.abs();
                    r[q] = c.mul_add(to_reach, r[q]);
                    t[q] = c.mul_add(to_turn, t[q]);
                }
            }
        }
        // Every lane's verdict at once, without short cuts, as one bit per
        // column.
        let (values, slopes) = (row(0), row(1));
        let (zero, pad) = (f64x4::ZERO, f64x4::splat(1.0 + 1e-12));
        let mut proven = 0u32;
        for b in 0..G {
            let (c, s) = (load(&values[b]), load(&slopes[b]));
            for q in 0..QUADS {
                let (reach, turn) = (reach[b][q], turn[b][q]);
                let above = (c[q] - reach * pad).simd_gt(zero) | reach.simd_eq(zero);
                let rising = c[q].simd_ge(zero) & (s[q] - turn * pad).simd_gt(zero);
                proven |= (above | rising).to_bitmask() << (b * LANES + 4 * q);
            }
        }
        let done = open.len().min(G * LANES);
        for (i, open) in open[..done].iter_mut().enumerate() {
            *open = proven >> i & 1 == 1;
        }
        done
    }

    /// The values at scaled time `sigma` of columns `first..=last`, each
    /// series begun at its `origin` (by column), into order 0 of `window`
    /// from its column 1, made to hold them (`tau` is scratch).
    pub fn load(
        &self,
        window: &mut Series,
        origin: &[f64],
        (first, last): (usize, usize),
        sigma: f64,
        tau: &mut Vec<f64>,
    ) {
        let count = last - first + 1;
        window.reset(count);
        tau.clear();
        tau.extend(origin[first..=last].iter().map(|o| (sigma - o).max(0.0)));
        // Whole blocks: past the window, row 0 is set by the expansion.
        tau.resize(blocks(count), 0.0);
        let (gaps, vels) = (
            &mut window.gap[1..=blocks(count)],
            &mut window.vel[1..=blocks(count)],
        );
        self.values(first, tau, gaps, vels);
    }

    /// Copy columns `from..from + count` of `source` (same order) into
    /// columns `to..` of this series, every order.
    pub fn copy_columns(&mut self, source: &Series, from: usize, to: usize, count: usize) {
        let (rows, stride) = (self.order + 1, self.stride);
        for (dst, src) in [(&mut self.gap, &source.gap), (&mut self.vel, &source.vel)] {
            let dst = dst.chunks_exact_mut(stride).take(rows);
            for (dst, src) in dst.zip(src.chunks_exact(source.stride)) {
                copy_run(&mut dst[to..to + count], &src[from..from + count]);
            }
        }
    }
}

// Row kernels over whole blocks. Each takes its rows as separate slices,
// which tells the compiler they do not overlap.

/// One order of the recursion over whole blocks from column 1:
/// `next_gap[i] = (vel[i + 1] - vel[i]) * scale` and `next_vel[i] =
/// (gap[i + 2] - gap[i + 1]) * scale`, the rows of order `k` given from
/// column 0 and the next ones from column 1; `next_gap[ghost]`, if any, is
/// left zero. `gap_first` says which row to compute first: alternate it
/// from order to order, and each row reads, one column off, a row stored
/// a whole row's pass earlier. On the short rows of an impact, a row read
/// back right after it was stored would wait for the stores to reach
/// memory (a load across two pending stores is not forwarded).
#[inline(always)]
fn differences(
    (next_gap, next_vel): (&mut [f64], &mut [f64]),
    (gap, vel): (&[f64], &[f64]),
    (scale, ghost): (f64, Option<usize>),
    gap_first: bool,
) {
    if gap_first {
        gap_row(next_gap, vel, scale, ghost);
        vel_row(next_vel, gap, scale);
    } else {
        vel_row(next_vel, gap, scale);
        gap_row(next_gap, vel, scale, ghost);
    }
}

/// `Delta_n' = u_n - u_{n-1}` over whole blocks (see [`differences`]).
#[inline(always)]
fn gap_row(next_gap: &mut [f64], vel: &[f64], scale: f64, ghost: Option<usize>) {
    let n = next_gap.len();
    let (blocks, _) = next_gap.as_chunks_mut::<LANES>();
    debug_assert_eq!(blocks.len() * LANES, n, "whole blocks only");
    let (left, _) = vel[..n].as_chunks::<LANES>();
    let (here, _) = vel[1..=n].as_chunks::<LANES>();
    let scale = f64x4::splat(scale);
    for ((g, left), here) in blocks.iter_mut().zip(left).zip(here) {
        let (left, here) = (load(left), load(here));
        store(g, std::array::from_fn(|q| (here[q] - left[q]) * scale));
    }
    if let Some(at) = ghost {
        next_gap[at] = 0.0;
    }
}

/// `u_n' = Delta_{n+1} - Delta_n` over whole blocks (see [`differences`]).
#[inline(always)]
fn vel_row(next_vel: &mut [f64], gap: &[f64], scale: f64) {
    let n = next_vel.len();
    let (blocks, _) = next_vel.as_chunks_mut::<LANES>();
    let (own, _) = gap[1..=n].as_chunks::<LANES>();
    let (right, _) = gap[2..n + 2].as_chunks::<LANES>();
    let scale = f64x4::splat(scale);
    for ((v, own), right) in blocks.iter_mut().zip(own).zip(right) {
        let (own, right) = (load(own), load(right));
        store(v, std::array::from_fn(|q| (right[q] - own[q]) * scale));
    }
}

/// `to.copy_from_slice(from)`, inline for the one to two blocks an
/// impact's reach is wide: as two blocks that overlap in the middle,
/// where a call to `memcpy` for a few dozen bytes would cost more than the
/// copy.
#[inline(always)]
fn copy_run(to: &mut [f64], from: &[f64]) {
    let n = from.len();
    if (LANES..=2 * LANES).contains(&n) && to.len() == n {
        let (head, tail) = (blocks_at::<1>(from, 0), blocks_at::<1>(from, n - LANES));
        let (head, tail) = (load(&head[0]), load(&tail[0]));
        store(&mut blocks_at_mut::<1>(to, 0)[0], head);
        store(&mut blocks_at_mut::<1>(to, n - LANES)[0], tail);
    } else {
        to.copy_from_slice(from);
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

    /// Order 0 of `units` indices, from smooth but irregular profiles.
    fn profile(units: usize) -> (Vec<f64>, Vec<f64>) {
        let at = |i: usize, f: f64| (f * i as f64).sin() * 0.1 + 0.02 * (i % 3) as f64;
        (
            (1..=units).map(|i| at(i, 1.3)).collect(),
            (1..=units).map(|i| at(i, 0.7)).collect(),
        )
    }

    /// A series of `units` indices over rows left dirty by a wider one, as
    /// the scratch series is between impacts.
    fn dirty(order: usize, units: usize) -> Series {
        let mut s = Series::new(order, 48);
        s.gap.fill(7.0);
        s.vel.fill(-3.0);
        s.reset(units);
        let (d, u) = profile(units);
        s.gap[1..=units].copy_from_slice(&d);
        s.vel[1..=units].copy_from_slice(&u);
        s
    }

    #[test]
    fn every_width_expands_as_the_plain_recursion() {
        // Widths of one to six blocks: the short ones take the unrolled
        // kernels, the rest the general one.
        let (order, ghost) = (9, 0.3);
        for units in 1..=44 {
            let mut s = dirty(order, units);
            s.expand(ghost, None);
            // The recursion column by column, boundaries by hand.
            let (d, u) = profile(units);
            let mut gap = vec![vec![0.0; units + 2]; order + 1];
            let mut vel = vec![vec![0.0; units + 2]; order + 1];
            gap[0][1..=units].copy_from_slice(&d);
            vel[0][1..=units].copy_from_slice(&u);
            gap[0][units + 1] = ghost;
            for k in 0..order {
                let inv = 1.0 / (k + 1) as f64;
                for i in 1..=units {
                    gap[k + 1][i] = (vel[k][i] - vel[k][i - 1]) * inv;
                    vel[k + 1][i] = (gap[k][i + 1] - gap[k][i]) * inv;
                }
            }
            for k in 0..=order {
                for i in 1..=units {
                    assert_eq!(
                        s.gap[s.at(k, i)],
                        gap[k][i],
                        "{units} units, gap {i}, order {k}"
                    );
                    assert_eq!(
                        s.vel[s.at(k, i)],
                        vel[k][i],
                        "{units} units, vel {i}, order {k}"
                    );
                }
            }
        }
    }

    #[test]
    fn every_width_evaluates_and_proves_as_each_column_alone() {
        let order = 9;
        for units in 1..=44 {
            let mut s = dirty(order, units);
            s.expand(0.3, None);
            let n = blocks(units);
            let tau: Vec<f64> = (0..n).map(|i| 0.004 * (i % 7) as f64).collect();
            let (mut gaps, mut vels) = (vec![0.0; n], vec![0.0; n]);
            s.values(1, &tau, &mut gaps, &mut vels);
            for i in 0..units {
                assert_eq!(
                    gaps[i],
                    s.value(&s.gap, i + 1, tau[i]),
                    "{units} units, gap {i}"
                );
                assert_eq!(
                    vels[i],
                    s.value(&s.vel, i + 1, tau[i]),
                    "{units} units, vel {i}"
                );
            }
            // Each gap's bounds summed on its own, far from any tie.
            let span = 0.6;
            let mut open = vec![false; units];
            s.open_over(1, span, &mut open);
            for (i, &proven) in open.iter().enumerate() {
                let mut column = [0.0; MAX_COLUMN];
                let c = s.column(&s.gap, i + 1, &mut column);
                let reach: f64 = (1..=order).map(|k| c[k].abs() * span.powi(k as i32)).sum();
                let turn: f64 = (2..=order)
                    .map(|k| k as f64 * c[k].abs() * span.powi(k as i32 - 1))
                    .sum();
                let expected =
                    c[0] > reach * (1.0 + 1e-9) || c[0] >= 0.0 && c[1] > turn * (1.0 + 1e-9);
                let refuted =
                    c[0] < reach * (1.0 - 1e-9) && (c[0] < 0.0 || c[1] < turn * (1.0 - 1e-9));
                assert!(expected || refuted, "{units} units, gap {i}: a near tie");
                assert_eq!(proven, expected, "{units} units, gap {i}");
            }
            // Both verdicts occur, once there are a few gaps.
            let both = open.contains(&true) && open.contains(&false);
            assert!(both || units < 4, "{units} units: {open:?}");
        }
    }

    #[test]
    fn an_end_block_stays_shut_and_rigid_at_every_order() {
        let order = 9;
        for units in [3, 8, 15, 16, 24, 30] {
            for b in [1, 2, units / 2 + 1, units] {
                let mut s = dirty(order, units);
                s.gap[b..=units].fill(0.0);
                s.expand(-0.2, Some(b));
                for k in 1..=order {
                    // Shut at every order, and one velocity from the node on
                    // the block's left (the wall's zero if it starts at 1).
                    let rigid = s.vel[s.at(k, (b - 1).max(1))];
                    for i in b..=units {
                        assert_eq!(
                            s.gap[s.at(k, i)],
                            0.0,
                            "{units} units, block {b}, order {k}"
                        );
                        assert_eq!(
                            s.vel[s.at(k, i)],
                            rigid,
                            "{units} units, block {b}, order {k}"
                        );
                    }
                    if b == 1 {
                        assert_eq!(rigid, 0.0, "{units} units: held at the wall");
                    }
                }
            }
        }
    }

    #[test]
    fn a_run_from_inside_the_series_to_its_last_column_proves_as_the_whole() {
        // The chain proves an impact's reach from a column inside its
        // scratch series: the same verdicts as a proof over every column.
        let units = 21;
        let mut s = dirty(9, units);
        s.expand(0.3, None);
        let mut whole = vec![false; units];
        s.open_over(1, 0.6, &mut whole);
        for first in 2..=units {
            let mut part = vec![false; units + 1 - first];
            s.open_over(first, 0.6, &mut part);
            assert_eq!(part, whole[first - 1..], "from column {first}");
        }
    }

    #[test]
    fn runs_of_any_length_copy_whole() {
        let from: Vec<f64> = (0..20).map(f64::from).collect();
        for n in 0..=20 {
            let mut to = vec![-1.0; n];
            copy_run(&mut to, &from[..n]);
            assert_eq!(to, from[..n]);
        }
    }
}
