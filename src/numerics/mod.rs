//! Numerics that serve the models and the engine alike, kept out of both:
//! polynomials in one variable (one evaluator, [`polynomial`]), fused
//! multiply-adds ([`fused`]), and the certified first crossing of zero of a
//! Taylor polynomial ([`first_crossing`]), which the chain's exact flow is made of.

pub mod first_crossing;
pub mod fused;
pub mod polynomial;
