//! The exact solution of the unconstrained chain by its normal modes: the
//! reference the other paths are checked against with the constraint off.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::Chain;

/// The exact solution of the unconstrained chain, by its normal modes:
/// `M y'' = -K y + f` with `K` the fixed-free stiffness matrix, solved as
/// the static deflection plus independent oscillations of the modes.
pub fn modal(chain: &Chain, x0: &[f64], t: f64) -> Vec<f64> {
    let n = chain.units;
    let w = chain.stiffness / chain.mass;
    let mut k = DMatrix::zeros(n, n);
    for i in 0..n {
        k[(i, i)] = if i + 1 < n { 2.0 * w } else { w };
        if i + 1 < n {
            k[(i, i + 1)] = -w;
            k[(i + 1, i)] = -w;
        }
    }
    let mut f = DVector::zeros(n);
    f[n - 1] = (chain.load - chain.critical_load) / chain.mass;
    let eigen = SymmetricEigen::new(k);
    // Static deflection: K y_s = f, solved in the modal basis.
    let q = &eigen.eigenvectors;
    let fq = q.transpose() * f;
    let y0 = DVector::from_row_slice(&x0[..n]);
    let v0 = DVector::from_row_slice(&x0[n..]);
    let statics = fq.zip_map(&eigen.eigenvalues, |fi, l| fi / l);
    let a0 = q.transpose() * y0 - &statics;
    let b0 = q.transpose() * v0;
    let (mut position, mut velocity) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let omega = eigen.eigenvalues[j].sqrt();
        let (s, c) = (omega * t).sin_cos();
        position[j] = statics[j] + a0[j] * c + b0[j] * s / omega;
        velocity[j] = -a0[j] * omega * s + b0[j] * c;
    }
    let y = q * position;
    let v = q * velocity;
    y.iter().chain(v.iter()).copied().collect()
}
