//! Dormand-Prince 5(4) with Hairer's 4th-order dense output.
//!
//! One call to [`Dopri5::step`] takes one accepted step (retrying rejected
//! ones) and leaves a [`DenseStep`]: a quartic polynomial in the normalised
//! step time through the step's start and end states. Event location runs on
//! that polynomial, so a guard can be checked anywhere in the step without
//! more right-hand-side calls. Flows are autonomous, so the nodes `c_i` of
//! the tableau are not needed. Coefficients from Hairer, Norsett and Wanner,
//! "Solving Ordinary Differential Equations I", and their code DOPRI5.

// Stage sums read several arrays at one index: an index loop says it plainly.
#![allow(clippy::needless_range_loop)]

use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::adaptive::{EmbeddedPair, StepControl, Tolerances, TrialError};

/// The order of the error estimate in the step size.
const ORDER: i32 = 5;

const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// The dense output of one accepted step, as a function of `tau in [0, h]`.
#[derive(Debug, Clone, Default)]
pub struct DenseStep {
    /// The step's size.
    pub h: f64,
    r: [Vec<f64>; 5],
    /// The step's end state as the integrator computed it (the polynomial
    /// at `s = 1` may differ from it in the last bit).
    y1: Vec<f64>,
}

impl DenseStep {
    /// The interpolated state at `tau` into the step.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        let s = tau / self.h;
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5] = &self.r;
        for i in 0..x.len() {
            x[i] = r1[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * r5[i])));
        }
    }

    /// The state at the end of the step, exactly as the integrator computed it.
    pub fn end(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.y1);
    }
}

/// The integrator's working storage and step-size memory.
#[derive(Debug, Clone)]
pub struct Dopri5 {
    control: StepControl,
    k: [Vec<f64>; 7],
    y1: Vec<f64>,
    scratch: Vec<f64>,
    dense: DenseStep,
}

impl Dopri5 {
    /// An integrator for states of `dimension` components, at tolerances `tol`.
    pub fn new(dimension: usize, tol: Tolerances) -> Self {
        let v = || vec![0.0; dimension];
        Dopri5 {
            control: StepControl::new(tol, ORDER, 5.0, 0.2),
            k: [v(), v(), v(), v(), v(), v(), v()],
            y1: v(),
            scratch: v(),
            dense: DenseStep {
                h: 0.0,
                r: [v(), v(), v(), v(), v()],
                y1: v(),
            },
        }
    }

    /// The dense output of the last accepted step.
    pub fn dense(&self) -> &DenseStep {
        &self.dense
    }

    /// The flow at the start and at the end of the last accepted step: its
    /// first stage and the one it carries over to the next step (first
    /// same as last), until the next step's trial overwrites them.
    pub fn rates(&self) -> (&[f64], &[f64]) {
        (&self.k[6], &self.k[0])
    }

    fn eval<M: HybridModel + ?Sized>(&mut self, model: &M, mode: Mode, y: &[f64], stage: usize) {
        model.rhs(mode, y, &mut self.k[stage]);
        self.control.evaluations += 1;
    }
}

impl EmbeddedPair for Dopri5 {
    fn parts(&mut self) -> (&mut StepControl, &mut [Vec<f64>], &mut [f64]) {
        (&mut self.control, &mut self.k, &mut self.scratch)
    }

    fn control(&self) -> &StepControl {
        &self.control
    }

    fn dense_eval(&self, tau: f64, x: &mut [f64]) {
        self.dense.eval(tau, x);
    }

    fn dense_h(&self) -> f64 {
        self.dense.h
    }

    fn trial_end(&mut self) -> &mut Vec<f64> {
        &mut self.y1
    }

    fn attempt<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h: f64,
    ) -> TrialError {
        let stages: [(usize, &[f64]); 6] = [
            (1, &[A21]),
            (2, &[A31, A32]),
            (3, &[A41, A42, A43]),
            (4, &[A51, A52, A53, A54]),
            (5, &[A61, A62, A63, A64, A65]),
            (6, &[A71, 0.0, A73, A74, A75, A76]),
        ];
        for (stage, a) in stages {
            for i in 0..y0.len() {
                let mut sum = 0.0;
                for (j, aj) in a.iter().enumerate() {
                    sum += aj * self.k[j][i];
                }
                self.scratch[i] = y0[i] + h * sum;
            }
            if stage == 6 {
                self.y1.copy_from_slice(&self.scratch);
            }
            let y = std::mem::take(&mut self.scratch);
            self.eval(model, mode, &y, stage);
            self.scratch = y;
        }
        let k = &self.k;
        let (mut sum, mut largest, mut allowed) = (0.0, 0.0_f64, 0.0_f64);
        for i in 0..y0.len() {
            let e = h
                * (E1 * k[0][i]
                    + E3 * k[2][i]
                    + E4 * k[3][i]
                    + E5 * k[4][i]
                    + E6 * k[5][i]
                    + E7 * k[6][i]);
            let scale = self.control.tol.scale(y0[i].abs().max(self.y1[i].abs()));
            sum += (e / scale).powi(2);
            if i < self.control.bounded {
                largest = largest.max(e.abs());
                allowed = allowed.max(scale);
            }
        }
        let blew_up = self.y1.iter().any(|v| !v.is_finite()) || k[6].iter().any(|v| !v.is_finite());
        TrialError {
            norm: if blew_up {
                f64::NAN
            } else {
                (sum / y0.len() as f64).sqrt()
            },
            largest,
            allowed: allowed * (y0.len() as f64).sqrt(),
        }
    }

    /// Store the dense output of the accepted step and carry `f(y1)` over.
    fn finish<M: HybridModel + ?Sized>(&mut self, _: &M, _: Mode, y0: &[f64], h: f64) {
        let k = &self.k;
        let r = &mut self.dense.r;
        for i in 0..y0.len() {
            let dy = self.y1[i] - y0[i];
            let bspl = h * k[0][i] - dy;
            r[0][i] = y0[i];
            r[1][i] = dy;
            r[2][i] = bspl;
            r[3][i] = dy - h * k[6][i] - bspl;
            r[4][i] = h
                * (D1 * k[0][i]
                    + D3 * k[2][i]
                    + D4 * k[3][i]
                    + D5 * k[4][i]
                    + D6 * k[5][i]
                    + D7 * k[6][i]);
        }
        self.dense.h = h;
        self.dense.y1.copy_from_slice(&self.y1);
        self.k.swap(0, 6);
        self.control.fsal = true;
    }
}
