//! Dormand and Prince's 8th-order pair DOP853 with its 7th-order dense output.
//!
//! Same contract as [`crate::engine::step::dopri5`]: one call to
//! [`Dop853::step`] takes one accepted step and leaves a polynomial (here of
//! degree seven) in the normalised step time through the step's start and
//! end states, on which event location runs. It pays 12 stages per step
//! (the first reused from the last step's end) and three more for the dense
//! output, against Dormand-Prince 5(4)'s six: it earns its place once the
//! tolerance is tight enough that its steps are more than twice as long.
//! Error control is Hairer's: the 5th-order estimate, damped by the 3rd-order
//! one where the two disagree, which behaves as an 8th-order estimate.
//!
//! Coefficients from Hairer, Norsett and Wanner, "Solving Ordinary
//! Differential Equations I" (2nd ed.), section II.10, and their code DOP853;
//! the tests check them against the order conditions they must satisfy.

// Stage sums read several arrays at one index: an index loop says it plainly.
#![allow(clippy::needless_range_loop)]

use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::adaptive::{EmbeddedPair, StepControl, Tolerances, TrialError};

/// The order of the error estimate in the step size.
const ORDER: i32 = 8;
/// Stages per step, and stages including those of the dense output.
const STAGES: usize = 12;
const ALL_STAGES: usize = 16;
/// The stage that evaluates `f` at the step's end.
const END: usize = 12;

/// Stage `i` evaluates `f` at `y0 + h sum_j a_ij k_j`, `(j, a_ij)` listed.
/// Stage 12 is the step's end `y1` (its weights are the 8th-order ones)
/// and stages 13 to 15 serve the dense output only.
const A: [&[(usize, f64)]; 16] = [
    &[],
    &[(0, 0.05260015195876773)],
    &[(0, 0.0197250569845379), (1, 0.0591751709536137)],
    &[(0, 0.02958758547680685), (2, 0.08876275643042054)],
    &[
        (0, 0.2413651341592667),
        (2, -0.8845494793282861),
        (3, 0.924834003261792),
    ],
    &[
        (0, 0.037037037037037035),
        (3, 0.17082860872947386),
        (4, 0.12546768756682242),
    ],
    &[
        (0, 0.037109375),
        (3, 0.17025221101954405),
        (4, 0.06021653898045596),
        (5, -0.017578125),
    ],
    &[
        (0, 0.03709200011850479),
        (3, 0.17038392571223998),
        (4, 0.10726203044637328),
        (5, -0.015319437748624402),
        (6, 0.008273789163814023),
    ],
    &[
        (0, 0.6241109587160757),
        (3, -3.3608926294469414),
        (4, -0.868219346841726),
        (5, 27.59209969944671),
        (6, 20.154067550477894),
        (7, -43.48988418106996),
    ],
    &[
        (0, 0.47766253643826434),
        (3, -2.4881146199716677),
        (4, -0.590290826836843),
        (5, 21.230051448181193),
        (6, 15.279233632882423),
        (7, -33.28821096898486),
        (8, -0.020331201708508627),
    ],
    &[
        (0, -0.9371424300859873),
        (3, 5.186372428844064),
        (4, 1.0914373489967295),
        (5, -8.149787010746927),
        (6, -18.52006565999696),
        (7, 22.739487099350505),
        (8, 2.4936055526796523),
        (9, -3.0467644718982196),
    ],
    &[
        (0, 2.273310147516538),
        (3, -10.53449546673725),
        (4, -2.0008720582248625),
        (5, -17.9589318631188),
        (6, 27.94888452941996),
        (7, -2.8589982771350235),
        (8, -8.87285693353063),
        (9, 12.360567175794303),
        (10, 0.6433927460157636),
    ],
    &[
        (0, 0.054293734116568765),
        (5, 4.450312892752409),
        (6, 1.8915178993145003),
        (7, -5.801203960010585),
        (8, 0.3111643669578199),
        (9, -0.1521609496625161),
        (10, 0.20136540080403034),
        (11, 0.04471061572777259),
    ],
    &[
        (0, 0.056167502283047954),
        (6, 0.25350021021662483),
        (7, -0.2462390374708025),
        (8, -0.12419142326381637),
        (9, 0.15329179827876568),
        (10, 0.00820105229563469),
        (11, 0.007567897660545699),
        (12, -0.008298),
    ],
    &[
        (0, 0.03183464816350214),
        (5, 0.028300909672366776),
        (6, 0.053541988307438566),
        (7, -0.05492374857139099),
        (10, -0.00010834732869724932),
        (11, 0.0003825710908356584),
        (12, -0.00034046500868740456),
        (13, 0.1413124436746325),
    ],
    &[
        (0, -0.42889630158379194),
        (5, -4.697621415361164),
        (6, 7.683421196062599),
        (7, 4.06898981839711),
        (8, 0.3567271874552811),
        (12, -0.0013990241651590145),
        (13, 2.9475147891527724),
        (14, -9.15095847217987),
    ],
];
/// The third-order weights `bhh` of the second error estimate.
const BHH: [(usize, f64); 3] = [
    (0, 0.2440944881889764),
    (8, 0.7338466882816118),
    (11, 0.022058823529411766),
];
/// Weights of the fifth-order error estimate.
const E5: [(usize, f64); 8] = [
    (0, 0.01312004499419488),
    (5, -1.2251564463762044),
    (6, -0.4957589496572502),
    (7, 1.6643771824549864),
    (8, -0.35032884874997366),
    (9, 0.3341791187130175),
    (10, 0.08192320648511571),
    (11, -0.022355307863886294),
];
/// The dense output's last four coefficients, as weights of the 16 stages.
const D: [[(usize, f64); 12]; 4] = [
    [
        (0, -8.428938276109013),
        (5, 0.5667149535193777),
        (6, -3.0689499459498917),
        (7, 2.38466765651207),
        (8, 2.117034582445028),
        (9, -0.871391583777973),
        (10, 2.2404374302607883),
        (11, 0.6315787787694688),
        (12, -0.08899033645133331),
        (13, 18.148505520854727),
        (14, -9.194632392478356),
        (15, -4.436036387594894),
    ],
    [
        (0, 10.427508642579134),
        (5, 242.28349177525817),
        (6, 165.20045171727028),
        (7, -374.5467547226902),
        (8, -22.113666853125306),
        (9, 7.733432668472264),
        (10, -30.674084731089398),
        (11, -9.332130526430229),
        (12, 15.697238121770845),
        (13, -31.139403219565178),
        (14, -9.35292435884448),
        (15, 35.81684148639408),
    ],
    [
        (0, 19.985053242002433),
        (5, -387.0373087493518),
        (6, -189.17813819516758),
        (7, 527.8081592054236),
        (8, -11.57390253995963),
        (9, 6.8812326946963),
        (10, -1.0006050966910838),
        (11, 0.7777137798053443),
        (12, -2.778205752353508),
        (13, -60.19669523126412),
        (14, 84.32040550667716),
        (15, 11.99229113618279),
    ],
    [
        (0, -25.69393346270375),
        (5, -154.18974869023643),
        (6, -231.5293791760455),
        (7, 357.6391179106141),
        (8, 93.40532418362432),
        (9, -37.45832313645163),
        (10, 104.0996495089623),
        (11, 29.8402934266605),
        (12, -43.53345659001114),
        (13, 96.32455395918828),
        (14, -39.17726167561544),
        (15, -149.72683625798564),
    ],
];

/// The dense output of one accepted step, as a function of `tau in [0, h]`:
/// `y0 + s (r0 + (1-s) (r1 + s (r2 + (1-s) (r3 + s (r4 + (1-s) (r5 + s r6))))))`
/// with `s = tau / h`.
#[derive(Debug, Clone, Default)]
pub struct DenseStep {
    /// The step's size.
    pub h: f64,
    y0: Vec<f64>,
    r: [Vec<f64>; 7],
    /// The step's end state as the integrator computed it.
    y1: Vec<f64>,
}

impl DenseStep {
    /// The interpolated state at `tau` into the step.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        let s = tau / self.h;
        let s1 = 1.0 - s;
        let r = &self.r;
        for i in 0..x.len() {
            let mut v = r[6][i];
            for (k, rk) in r[..6].iter().enumerate().rev() {
                v = rk[i] + if k % 2 == 1 { s } else { s1 } * v;
            }
            x[i] = self.y0[i] + s * v;
        }
    }

    /// The state at the end of the step, exactly as the integrator computed it.
    pub fn end(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.y1);
    }
}

/// The integrator's working storage and step-size memory.
#[derive(Debug, Clone)]
pub struct Dop853 {
    control: StepControl,
    k: [Vec<f64>; ALL_STAGES],
    y1: Vec<f64>,
    scratch: Vec<f64>,
    dense: DenseStep,
}

impl Dop853 {
    /// An integrator for states of `dimension` components, at tolerances `tol`.
    pub fn new(dimension: usize, tol: Tolerances) -> Self {
        let v = || vec![0.0; dimension];
        Dop853 {
            control: StepControl::new(tol, ORDER, 6.0, 0.333),
            k: std::array::from_fn(|_| v()),
            y1: v(),
            scratch: v(),
            dense: DenseStep {
                h: 0.0,
                y0: v(),
                r: std::array::from_fn(|_| v()),
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
        (&self.k[END], &self.k[0])
    }

    /// `k[stage] = f(y)`.
    fn stage_at<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y: &[f64],
        stage: usize,
    ) {
        model.rhs(mode, y, &mut self.k[stage]);
        self.control.evaluations += 1;
    }

    /// Evaluate `stage` from `y0` and the stages before it.
    fn stage<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h: f64,
        stage: usize,
    ) {
        let row = A[stage];
        for i in 0..y0.len() {
            let sum: f64 = row.iter().map(|&(j, a)| a * self.k[j][i]).sum();
            self.scratch[i] = y0[i] + h * sum;
        }
        let y = std::mem::take(&mut self.scratch);
        self.stage_at(model, mode, &y, stage);
        self.scratch = y;
    }
}

impl EmbeddedPair for Dop853 {
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

    /// One trial step of size `h`, and its error.
    fn attempt<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h: f64,
    ) -> TrialError {
        for stage in 1..STAGES {
            self.stage(model, mode, y0, h, stage);
        }
        let k = &self.k;
        let (mut err5, mut err3) = (0.0, 0.0);
        let (mut largest, mut allowed) = (0.0_f64, 0.0_f64);
        for i in 0..y0.len() {
            let high: f64 = A[END].iter().map(|&(j, b)| b * k[j][i]).sum();
            self.y1[i] = y0[i] + h * high;
            let e5: f64 = E5.iter().map(|&(j, e)| e * k[j][i]).sum();
            let e3 = high - BHH.iter().map(|&(j, b)| b * k[j][i]).sum::<f64>();
            let scale = self.control.tol.scale(y0[i].abs().max(self.y1[i].abs()));
            err5 += (e5 / scale).powi(2);
            err3 += (e3 / scale).powi(2);
            if i < self.control.bounded {
                largest = largest.max(e5.abs());
                allowed = allowed.max(scale);
            }
        }
        if self.y1.iter().any(|v| !v.is_finite()) || !(err5.is_finite() && err3.is_finite()) {
            return TrialError {
                norm: f64::NAN,
                largest: f64::NAN,
                allowed: f64::NAN,
            };
        }
        let allowed = allowed * (y0.len() as f64).sqrt();
        if err5 == 0.0 && err3 == 0.0 {
            return TrialError {
                norm: 0.0,
                largest: 0.0,
                allowed,
            };
        }
        // Hairer's combination: |e5|^2 / sqrt(|e5|^2 + 0.01 |e3|^2) scales
        // like h^8 where both estimates are in their asymptotic regime.
        let damping = err5.sqrt() / (err5 + 0.01 * err3).sqrt();
        TrialError {
            norm: h * err5 / ((err5 + 0.01 * err3) * y0.len() as f64).sqrt(),
            largest: h * largest * damping,
            allowed,
        }
    }

    /// Evaluate `f(y1)` (carried over to the next step) and the dense
    /// output's extra stages, and store the dense output.
    fn finish<M: HybridModel + ?Sized>(&mut self, model: &M, mode: Mode, y0: &[f64], h: f64) {
        let y1 = std::mem::take(&mut self.y1);
        self.stage_at(model, mode, &y1, END);
        self.y1 = y1;
        for stage in END + 1..ALL_STAGES {
            self.stage(model, mode, y0, h, stage);
        }
        let k = &self.k;
        let r = &mut self.dense.r;
        for i in 0..y0.len() {
            let dy = self.y1[i] - y0[i];
            let bspl = h * k[0][i] - dy;
            r[0][i] = dy;
            r[1][i] = bspl;
            r[2][i] = dy - h * k[END][i] - bspl;
            for (m, weights) in D.iter().enumerate() {
                r[3 + m][i] = h * weights.iter().map(|&(j, d)| d * k[j][i]).sum::<f64>();
            }
        }
        self.dense.h = h;
        self.dense.y0.copy_from_slice(y0);
        self.dense.y1.copy_from_slice(&self.y1);
        self.k.swap(0, END);
        self.control.fsal = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::mechanism::strain::FLIGHT;
    use crate::models::mechanism::{Mechanism, StrainMechanism};

    /// The nodes `c_i`, transcribed independently of `A`: row sums must
    /// reproduce them.
    const C: [f64; 16] = [
        0.0,
        0.05260015195876773,
        0.0789002279381516,
        0.1183503419072274,
        0.2816496580927726,
        0.3333333333333333,
        0.25,
        0.3076923076923077,
        0.6512820512820513,
        0.6,
        0.8571428571428571,
        1.0,
        1.0,
        0.1,
        0.2,
        0.7777777777777778,
    ];

    fn weights(entries: &[(usize, f64)]) -> [f64; ALL_STAGES] {
        let mut w = [0.0; ALL_STAGES];
        for &(j, v) in entries {
            w[j] += v;
        }
        w
    }

    /// `sum_j w_j c_j^q`.
    fn moment(w: &[f64; ALL_STAGES], q: i32) -> f64 {
        w.iter().zip(C).map(|(w, c)| w * c.powi(q)).sum()
    }

    #[test]
    fn rows_sum_to_their_nodes() {
        for (i, row) in A.iter().enumerate() {
            let sum: f64 = row.iter().map(|(_, a)| a).sum();
            assert!((sum - C[i]).abs() < 1e-14, "row {i}: {sum} vs {}", C[i]);
        }
    }

    #[test]
    fn the_weights_integrate_polynomials_to_their_orders() {
        // b: order 8, so c^q for q < 8 exactly (1 / (q + 1)).
        let b = weights(A[END]);
        for q in 0..8 {
            let want = 1.0 / f64::from(q + 1);
            assert!((moment(&b, q) - want).abs() < 1e-14, "b, q = {q}");
        }
        // The third-order weights bhh: q < 3.
        let bhh = weights(&BHH);
        for q in 0..3 {
            let want = 1.0 / f64::from(q + 1);
            assert!((moment(&bhh, q) - want).abs() < 1e-14, "bhh, q = {q}");
        }
        // E5 is b minus a fifth-order rule: it annihilates c^q for q < 5 and
        // not c^5.
        let e5 = weights(&E5);
        for q in 0..5 {
            assert!(moment(&e5, q).abs() < 1e-14, "e5, q = {q}");
        }
        assert!(moment(&e5, 5).abs() > 1e-6);
    }

    #[test]
    fn the_dense_output_is_seventh_order_inside_the_step() {
        // Halving the step divides the interpolant's error at a fixed
        // fraction of it by about 2^8 (local error of a 7th-degree interpolant).
        // The mechanism's strain flow is a harmonic oscillator with a
        // closed form to compare with.
        let model = StrainMechanism {
            mechanism: Mechanism {
                eta: 1.5,
                omega: 1.0,
            },
        };
        let (eps, rate) = (0.3, 0.2);
        let error = |h_max: f64| {
            let mut m = Dop853::new(
                2,
                Tolerances {
                    rtol: 1.0,
                    atol: 1.0,
                },
            );
            m.step(&model, FLIGHT, &[eps, rate], h_max, 0.0).unwrap();
            let h = m.dense().h;
            let mut x = [0.0; 2];
            let tau = 0.37 * h;
            m.dense().eval(tau, &mut x);
            let exact = model.mechanism.flow(eps, rate, tau);
            (h, (x[0] - exact.0).abs().max((x[1] - exact.1).abs()))
        };
        let ((h1, coarse), (h2, fine)) = (error(0.4), error(0.2));
        let order = (coarse / fine).ln() / (h1 / h2).ln();
        assert!(
            order > 7.5,
            "errors {coarse:e} (h {h1}), {fine:e} (h {h2}): order {order}"
        );
        assert!(fine < 1e-9, "error {fine:e}");
    }

    #[test]
    fn the_stage_order_conditions_hold() {
        // sum_j a_ij c_j = c_i^2 / 2 for every stage past the third (the
        // method's stage order conditions); a slip in one coefficient breaks it.
        for (i, row) in A.iter().enumerate().skip(3) {
            let sum: f64 = row.iter().map(|&(j, a)| a * C[j]).sum();
            assert!((sum - C[i] * C[i] / 2.0).abs() < 1e-13, "row {i}");
        }
    }
}
