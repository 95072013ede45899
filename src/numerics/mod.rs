//! Numerics that serve the models and the engine alike, kept out of both:
//! polynomials in one variable (one evaluator, [`polynomial`]), fused
//! multiply-adds ([`fused`]), and the two root searches: the certified
//! first crossing of zero of a Taylor polynomial ([`first_crossing`]),
//! which Taylor's method and the chain's exact flow are made of, and every
//! real root of a step's low-degree dense output on `(0, 1)`
//! ([`real_roots`]), which the scan of a numerical step is made of.

pub mod central_difference;
pub mod double_double;
pub mod first_crossing;
pub mod fused;
pub mod polynomial;
pub mod real_roots;
