//! The mechanism in the angle formulation: the smooth equation (8) in
//! `theta`, integrated numerically (docs/physics.md s.3).
//!
//! `theta'' = [-omega^2 (sec theta - eta) - theta'^2 (1 + sin^2 theta) / cos^3 theta]
//!            * cos^2 theta / sin theta`
//!
//! The equation is singular at `theta = 0`, where `theta'` grows like
//! `1 / theta` while the strain rate stays finite. Integrated as it is
//! ([`Charts::Plain`]), the step size collapses there and the run fails,
//! saying why. With [`Charts::Switch`], the automaton changes chart: below
//! the strain `SWITCH_IN` it follows the same motion in the strain
//! `(eps, eps')` (the linear ODE (45), still integrated numerically), where
//! passing `theta = 0` is the crossing `eps = 0` with `eps'` changing sign
//! and `theta` changing side; above `SWITCH_OUT` it returns to the angle.
//! The gap between the two thresholds keeps the chart from flickering.
//! Below the critical load, chattering at `theta = 0` settles into the
//! `resting` mode, as in the strain formulation.

use crate::engine::{Direction, Flow, Guard, HybridModel, Jump, Mode, Name};
use crate::models::mechanism::closed_form::Mechanism;

/// The angle chart, `theta > 0`: state `[theta, theta']`.
pub const ANGLE_POSITIVE: Mode = 0;
/// The angle chart, `theta < 0`: state `[theta, theta']`.
pub const ANGLE_NEGATIVE: Mode = 1;
/// The strain chart near `theta = 0` on the side `theta > 0`: state
/// `[eps, eps']`.
pub const STRAIN_POSITIVE: Mode = 2;
/// The strain chart near `theta = 0` on the side `theta < 0`: state
/// `[eps, eps']`.
pub const STRAIN_NEGATIVE: Mode = 3;
/// The angle equation everywhere, without charts ([`Charts::Plain`]):
/// state `[theta, theta']`.
pub const PLAIN: Mode = 4;
/// Resting contact at `theta = 0` below the critical load, after chattering.
pub const RESTING: Mode = 5;

/// Strain below which the angle chart hands over to the strain chart.
pub const SWITCH_IN: f64 = 0.01;
/// Strain above which the strain chart hands back to the angle chart.
pub const SWITCH_OUT: f64 = 0.02;

const ANGLE_STATE: &[Name] = &[Name::new("angle"), Name::new("angle_rate")];
const STRAIN_STATE: &[Name] = &[Name::new("strain"), Name::new("strain_rate")];
const ANGLE_GUARDS: &[Guard] =
    &[Guard::affine("enter_strain_chart", Direction::Falling).as_internal()];
const STRAIN_GUARDS: &[Guard] = &[
    Guard::affine("impact", Direction::Falling),
    Guard::affine("leave_strain_chart", Direction::Rising).as_internal(),
];

/// Whether the model may change chart near `theta = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Charts {
    /// Integrate (8) everywhere; fails at `theta = 0`.
    Plain,
    /// Cross `theta = 0` in the strain chart.
    Switch,
}

/// State `[theta, theta']` in angle modes, `[eps, eps']` in strain modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleMechanism {
    /// The mechanism's load ratio and frequency.
    pub mechanism: Mechanism,
    /// Whether to change chart near `theta = 0`.
    pub charts: Charts,
}

fn side(mode: Mode) -> f64 {
    if mode == ANGLE_NEGATIVE || mode == STRAIN_NEGATIVE {
        -1.0
    } else {
        1.0
    }
}

fn is_strain_chart(mode: Mode) -> bool {
    mode == STRAIN_POSITIVE || mode == STRAIN_NEGATIVE || mode == RESTING
}

/// `(eps, eps')` from `(theta, theta')`: `eps = sec theta - 1`,
/// `eps' = theta' sin theta / cos^2 theta`.
pub fn strain_of_angle(theta: f64, rate: f64) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    (1.0 / c - 1.0, rate * s / (c * c))
}

/// `(theta, theta')` on side `side` (+1 or -1) from `(eps, eps')`.
pub fn angle_of_strain(eps: f64, rate: f64, side: f64) -> (f64, f64) {
    let theta = side * (1.0 / (1.0 + eps)).acos();
    let (s, c) = theta.sin_cos();
    (theta, rate * c * c / s)
}

impl AngleMechanism {
    /// The starting mode and state for a strain `eps >= 0` with rate `rate`,
    /// on the side `theta >= 0`.
    pub fn start_from_strain(&self, eps: f64, rate: f64) -> Result<(Mode, [f64; 2]), String> {
        match self.charts {
            Charts::Switch if eps < SWITCH_OUT => Ok((STRAIN_POSITIVE, [eps, rate])),
            Charts::Switch => {
                let (theta, theta_rate) = angle_of_strain(eps, rate, 1.0);
                Ok((ANGLE_POSITIVE, [theta, theta_rate]))
            }
            Charts::Plain if eps == 0.0 => Err(
                "the angle formulation cannot start at theta = 0 without chart switching (theta' is infinite there); set \"chart\": \"switch\""
                    .into(),
            ),
            Charts::Plain => {
                let (theta, theta_rate) = angle_of_strain(eps, rate, 1.0);
                Ok((PLAIN, [theta, theta_rate]))
            }
        }
    }

    /// The starting mode and state for an angle and angle rate.
    pub fn start_from_angle(&self, theta: f64, rate: f64) -> (Mode, [f64; 2]) {
        let (eps, eps_rate) = strain_of_angle(theta, rate);
        match self.charts {
            Charts::Plain => (PLAIN, [theta, rate]),
            Charts::Switch if eps < SWITCH_OUT => {
                let mode = if theta < 0.0 {
                    STRAIN_NEGATIVE
                } else {
                    STRAIN_POSITIVE
                };
                (mode, [eps, eps_rate])
            }
            Charts::Switch => {
                let mode = if theta < 0.0 {
                    ANGLE_NEGATIVE
                } else {
                    ANGLE_POSITIVE
                };
                (mode, [theta, rate])
            }
        }
    }

    /// `(theta, theta')` of a state in any mode (infinite rate at
    /// `theta = 0`, which only the strain chart reaches).
    pub fn angle(&self, mode: Mode, x: &[f64]) -> (f64, f64) {
        if is_strain_chart(mode) {
            angle_of_strain(x[0], x[1], side(mode))
        } else {
            (x[0], x[1])
        }
    }

    /// `(eps, eps')` of a state in any mode.
    pub fn strain(&self, mode: Mode, x: &[f64]) -> (f64, f64) {
        if is_strain_chart(mode) {
            (x[0], x[1])
        } else {
            strain_of_angle(x[0], x[1])
        }
    }
}

impl HybridModel for AngleMechanism {
    fn dimension(&self) -> usize {
        2
    }

    fn state_names(&self, mode: Mode) -> &[Name] {
        if is_strain_chart(mode) {
            STRAIN_STATE
        } else {
            ANGLE_STATE
        }
    }

    fn mode_name(&self, mode: Mode) -> &str {
        match mode {
            ANGLE_POSITIVE => "angle_chart_positive",
            ANGLE_NEGATIVE => "angle_chart_negative",
            STRAIN_POSITIVE => "strain_chart_positive",
            STRAIN_NEGATIVE => "strain_chart_negative",
            RESTING => "resting",
            _ => "angle",
        }
    }

    fn guards(&self, mode: Mode) -> &[Guard] {
        match mode {
            ANGLE_POSITIVE | ANGLE_NEGATIVE => ANGLE_GUARDS,
            STRAIN_POSITIVE | STRAIN_NEGATIVE => STRAIN_GUARDS,
            _ => &[],
        }
    }

    fn guard(&self, mode: Mode, guard: usize, x: &[f64]) -> f64 {
        if is_strain_chart(mode) {
            if guard == 0 { x[0] } else { x[0] - SWITCH_OUT }
        } else {
            side(mode) * x[0] - (1.0 / (1.0 + SWITCH_IN)).acos()
        }
    }

    fn flow(&self, mode: Mode) -> Flow {
        if mode == RESTING {
            Flow::Frozen
        } else {
            Flow::Ode
        }
    }

    fn rhs(&self, mode: Mode, x: &[f64], dx: &mut [f64]) {
        let Mechanism { eta, omega } = self.mechanism;
        dx[0] = x[1];
        dx[1] = if is_strain_chart(mode) {
            -omega * omega * (x[0] - (eta - 1.0))
        } else {
            let (s, c) = x[0].sin_cos();
            let rate = x[1];
            (-omega * omega * (1.0 / c - eta) - rate * rate * (1.0 + s * s) / (c * c * c)) * c * c
                / s
        };
    }

    fn reset(&self, mode: Mode, guard: usize, x: &mut [f64]) -> Jump {
        let side = side(mode);
        match (mode, guard) {
            (ANGLE_POSITIVE | ANGLE_NEGATIVE, _) => {
                (x[0], x[1]) = strain_of_angle(x[0], x[1]);
                Jump::to(if side > 0.0 {
                    STRAIN_POSITIVE
                } else {
                    STRAIN_NEGATIVE
                })
            }
            (_, 0) => {
                // theta passes through zero: eps' changes sign, theta changes side.
                x[0] = 0.0;
                x[1] = -x[1];
                Jump::to(if side > 0.0 {
                    STRAIN_NEGATIVE
                } else {
                    STRAIN_POSITIVE
                })
            }
            _ => {
                (x[0], x[1]) = angle_of_strain(x[0], x[1], side);
                Jump::to(if side > 0.0 {
                    ANGLE_POSITIVE
                } else {
                    ANGLE_NEGATIVE
                })
            }
        }
    }

    fn energy(&self, mode: Mode, x: &[f64]) -> Option<f64> {
        let (eps, rate) = self.strain(mode, x);
        Some(self.mechanism.energy(eps, rate))
    }

    fn energy_scale(&self, initial_energy: f64) -> f64 {
        self.mechanism.energy_scale(initial_energy)
    }

    fn settle(&self, mode: Mode, x: &mut [f64]) -> Option<Mode> {
        (self.mechanism.eta < 1.0 && is_strain_chart(mode)).then(|| {
            x.copy_from_slice(&[0.0, 0.0]);
            RESTING
        })
    }

    fn diagnose(&self, mode: Mode, x: &[f64]) -> Option<String> {
        (mode == PLAIN && x[0].abs() < 0.2).then(|| {
            "the angle formulation (8) is singular at theta = 0, where theta' grows like 1/theta \
             while the strain rate stays finite; set \"chart\": \"switch\" to cross theta = 0 in \
             the strain chart, or use the strain formulation"
                .to_string()
        })
    }
}
