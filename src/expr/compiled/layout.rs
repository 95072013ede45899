//! Where compiled code finds each register's coefficients (a value is a
//! series of one): three buffers, which the code reaches through its
//! windows (`machine.rs`).
//!
//! - the work buffer: the main series of every computed register, one
//!   after another, then the helper series (the partner `cos` of a
//!   `sin`), `width` coefficients each, as the interpreter keeps them;
//!   an evaluation's outputs after them;
//! - the state: the inputs' series (a flow's, which its code writes
//!   order by order) or values, read in place (the interpreter copies
//!   them into its registers);
//! - the pool, read only: each constant register's series (the constant,
//!   then zeros), the integers up to `width` that the recurrences divide
//!   and weigh by, and `-1`.

use crate::expr::tape::{Op, Reg, Tape};

/// One of the buffers the compiled code is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Base {
    Work,
    State,
    Pool,
}

/// A coefficient's place: its buffer and byte offset there.
pub type Place = (Base, i32);

pub struct Layout {
    pub pool: Vec<f64>,
    /// Each register's series: its buffer and the index of its order 0.
    series: Vec<(Base, usize)>,
    /// Where the helper series start in the work buffer.
    helpers: usize,
    /// Where the integers start in the pool.
    integers: usize,
    /// How much of the state the rates read (the inputs' series).
    state: usize,
}

/// The byte offset of coefficient `index` (displacements are 32-bit; the
/// sizes compiled are capped far below).
fn bytes(index: usize) -> i32 {
    i32::try_from(index * size_of::<f64>()).expect("compiled series are capped in size")
}

impl Layout {
    pub fn new(tape: &Tape, width: usize) -> Layout {
        let mut pool = Vec::new();
        // The computed registers' series one after another, with no room
        // left for the others (the code reaches more of them through its
        // windows, see `machine.rs`).
        let mut computed = 0;
        let series = (0..tape.ops.len())
            .map(|r| match tape.ops[r] {
                Op::Const(c) => {
                    let at = pool.len();
                    pool.push(c);
                    pool.resize(at + width, 0.0);
                    (Base::Pool, at)
                }
                Op::Input(i) => (Base::State, i as usize * width),
                _ => {
                    computed += 1;
                    (Base::Work, (computed - 1) * width)
                }
            })
            .collect();
        let integers = pool.len();
        pool.extend((0..=width).map(|j| j as f64));
        pool.push(-1.0);
        let inputs = (tape.ops.iter())
            .filter_map(|op| match op {
                Op::Input(i) => Some(*i as usize + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        Layout {
            pool,
            series,
            helpers: computed * width,
            integers,
            state: inputs * width,
        }
    }

    /// Coefficient `k` of register `r`.
    pub fn at(&self, r: Reg, k: usize) -> Place {
        let (base, start) = self.series[r as usize];
        (base, bytes(start + k))
    }

    /// Coefficient `k` of register `r`'s helper series (a computed
    /// register's).
    pub fn helper(&self, r: Reg, k: usize) -> Place {
        let (_, start) = self.series[r as usize];
        (Base::Work, bytes(self.helpers + start + k))
    }

    /// Where an evaluation leaves its output `i`.
    pub fn output(&self, i: usize) -> Place {
        (Base::Work, bytes(2 * self.helpers + i))
    }

    /// How long the work buffer is for `outputs` evaluated outputs.
    pub fn work(&self, outputs: usize) -> usize {
        2 * self.helpers + outputs
    }

    /// The bytes of each buffer the code reads most (work, state, pool),
    /// with `outputs` evaluated outputs: where its windows go. (A flow's
    /// code also writes the series of states no rate reads, past the
    /// state's extent, from its base.)
    pub fn extents(&self, outputs: usize) -> [usize; 3] {
        [self.work(outputs), self.state, self.pool.len()].map(|n| n * size_of::<f64>())
    }

    /// The integer `j` as a float.
    pub fn integer(&self, j: usize) -> Place {
        (Base::Pool, bytes(self.integers + j))
    }

    /// `-1`.
    pub fn minus_one(&self) -> Place {
        (Base::Pool, bytes(self.pool.len() - 1))
    }
}
