//! Where an enclosure keeps its matrices: fixed arrays up to [`TRACKED`]
//! components, vectors beyond (up to [`CARRIED`]).
//!
//! The small sizes are the common case (a degree of freedom or a few), and
//! their maps run at every step: fixed arrays copy without calls and their
//! loops unroll. A large automaton (a chain of impacting units written
//! out) needs the same arithmetic on `n x n` matrices that no array of a
//! fixed size holds; the enclosures are written once over [`Storage`], and
//! each kind of storage gets its own copy of the code.
//!
//! [`CARRIED`]: super::CARRIED

use std::fmt::Debug;

use super::TRACKED;

/// Scratch and state of an enclosure: row- or column-major `n x n`
/// matrices, vectors of `n`, and an order of `n` indices.
pub(crate) trait Storage: Clone + Debug {
    type Matrix: AsRef<[f64]> + AsMut<[f64]> + Clone + Debug;
    type Vector: AsRef<[f64]> + AsMut<[f64]> + Clone + Debug;
    type Order: AsRef<[usize]> + AsMut<[usize]> + Clone + Debug;

    /// A zero matrix with room for `n x n`.
    fn matrix(n: usize) -> Self::Matrix;
    /// A zero vector with room for `n`.
    fn vector(n: usize) -> Self::Vector;
    /// `0, 1, ..., n - 1` (and maybe more).
    fn order(n: usize) -> Self::Order;
}

/// Fixed arrays of [`TRACKED`] components.
#[derive(Debug, Clone)]
pub(crate) struct Fixed;

impl Storage for Fixed {
    type Matrix = [f64; TRACKED * TRACKED];
    type Vector = [f64; TRACKED];
    type Order = [usize; TRACKED];

    #[inline(always)]
    fn matrix(_: usize) -> Self::Matrix {
        [0.0; TRACKED * TRACKED]
    }

    #[inline(always)]
    fn vector(_: usize) -> Self::Vector {
        [0.0; TRACKED]
    }

    #[inline(always)]
    fn order(_: usize) -> Self::Order {
        std::array::from_fn(|i| i)
    }
}

/// Vectors of exactly the size asked for.
#[derive(Debug, Clone)]
pub(crate) struct Heap;

impl Storage for Heap {
    type Matrix = Vec<f64>;
    type Vector = Vec<f64>;
    type Order = Vec<usize>;

    fn matrix(n: usize) -> Self::Matrix {
        vec![0.0; n * n]
    }

    fn vector(n: usize) -> Self::Vector {
        vec![0.0; n]
    }

    fn order(n: usize) -> Self::Order {
        (0..n).collect()
    }
}
