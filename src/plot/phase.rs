//! Phase portraits of the mechanism (the paper's Figs. 3-9): level sets of
//! its first integrals drawn from the formulas, overlaid with trajectories
//! the engine simulates. Where the two do not coincide, something is wrong;
//! [`Portrait::largest_mismatch`] says by how much.
//!
//! Planes:
//! - `strain`: `(eps, eps')`, level sets of `H0` (32); the constraint
//!   `eps >= 0` and the flip `eps' -> -eps'` (dashed) at impacts (Figs. 6, 9).
//! - `canonical`: `(theta, p0)` with `p0` from (29), level sets of (26)
//!   (Figs. 5, 7).
//! - `theta`: `(theta, theta')`, where `theta'` diverges at `theta = 0`.
//! - `linear`: `(theta1, theta1')` near the critical load with
//!   `eta = 1 + e^2 f1` (Figs. 3, 4): with `b = theta1^2`,
//!   `b'' = -omega^2 (b - 2 f1)` keeps `K = b'^2 + omega^2 (b - 2 f1)^2`;
//!   the paper's `h1` is `sqrt(K)` for `f1 > 0` (13) and
//!   `sqrt(K - 4 omega^2 f1^2)` for `f1 < 0` (24). Passing `theta1 = 0` is
//!   an impact of `b` at zero, so the strain model simulates it.

use crate::engine::{HybridModel, Mode, Options, Sample, simulate_sampled};
use crate::models::mechanism::angle::{AngleMechanism, Charts};
use crate::models::mechanism::strain::FLIGHT;
use crate::models::mechanism::{Mechanism, Phase, StrainMechanism};
use crate::plot::draw::{Curve, Figure, Style};

/// Which phase plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Plane {
    /// `(eps, eps')`, level sets of `H0` (32), with the constraint and the
    /// flips at impacts.
    Strain,
    /// `(theta, p0)` with `p0` from (29), level sets of (26).
    Canonical,
    /// `(theta, theta')`, where `theta'` diverges at `theta = 0`.
    Theta,
    /// The linearised plane, with `f1` (`eta = 1 + e^2 f1`).
    Linear {
        /// The linearised load parameter.
        f1: f64,
    },
}

/// A figure and the trajectories drawn on it, each with the level it
/// started on.
#[derive(Debug, Clone)]
pub struct Portrait {
    /// The figure: level sets and trajectories, ready to draw.
    pub figure: Figure,
    /// `(level, points)` of each drawn level-set curve (a set split at
    /// `theta = 0` gives two), the same points as in the figure, with the
    /// level at full precision (labels round it).
    pub level_sets: Vec<(f64, Vec<(f64, f64)>)>,
    /// `(level, points)` of each simulated trajectory.
    pub trajectories: Vec<(f64, Vec<(f64, f64)>)>,
    plane: Plane,
    mechanism: Mechanism,
}

/// Points per level-set branch.
const SAMPLES: usize = 240;

impl Portrait {
    /// The portrait of `mechanism` in `plane`.
    pub fn new(mechanism: Mechanism, plane: Plane) -> Self {
        let (levels, separatrix) = levels(mechanism, plane);
        let mut curves = Vec::new();
        if plane == Plane::Strain {
            let top = levels
                .iter()
                .map(|h| mechanism.omega * (2.0 * h.max(0.0)).sqrt())
                .fold(0.0, f64::max);
            curves.push(Curve {
                label: Some("constraint eps = 0".into()),
                points: vec![(0.0, -1.1 * top), (0.0, 1.1 * top)],
                style: Style::Constraint,
            });
        }
        let mut level_sets = Vec::new();
        for &level in &levels {
            let style = if Some(level) == separatrix {
                Style::Separatrix
            } else {
                Style::Level
            };
            let value = match plane {
                Plane::Linear { f1 } => format!("h1 = {:.3}", h1_of(level, f1, mechanism.omega)),
                _ => format!("H0 = {level:.4}"),
            };
            let label = Some(if style == Style::Separatrix {
                format!("separatrix, {value}")
            } else {
                value
            });
            for curve in level_set(mechanism, plane, level, label, style) {
                if curve.style != Style::Jump {
                    level_sets.push((level, curve.points.clone()));
                }
                curves.push(curve);
            }
        }
        let trajectories: Vec<(f64, Vec<(f64, f64)>)> = simulated_levels(mechanism, plane, &levels)
            .into_iter()
            .map(|h| (h, trajectory(mechanism, plane, h)))
            .collect();
        for (_, points) in &trajectories {
            curves.push(Curve {
                label: None,
                points: points.clone(),
                style: Style::Simulated,
            });
        }
        let (x_label, y_label) = match plane {
            Plane::Strain => ("strain eps (dimensionless)", "strain rate eps' (1/time)"),
            Plane::Canonical => ("angle theta (rad)", "momentum p0 (dimensionless, (27))"),
            Plane::Theta => ("angle theta (rad)", "angle rate theta' (rad/time)"),
            Plane::Linear { .. } => ("theta1 = theta / e (rad)", "theta1' (rad/time)"),
        };
        let title = match plane {
            Plane::Linear { f1 } => format!(
                "linearised phase plane, f1 = {f1}, omega = {}",
                mechanism.omega
            ),
            _ => format!(
                "phase portrait, eta = {}, omega = {}",
                mechanism.eta, mechanism.omega
            ),
        };
        let y_limit =
            matches!(plane, Plane::Theta | Plane::Linear { .. }).then(|| rate_limit(&curves));
        Portrait {
            figure: Figure {
                title,
                x_label: x_label.into(),
                y_label: y_label.into(),
                curves,
                y_limit,
            },
            level_sets,
            trajectories,
            plane,
            mechanism,
        }
    }

    /// The largest difference, relative to the scale of the levels, between
    /// the first integral at a simulated point and the level its trajectory
    /// started on.
    pub fn largest_mismatch(&self) -> f64 {
        let (levels, _) = levels(self.mechanism, self.plane);
        let scale = levels.iter().fold(f64::MIN_POSITIVE, |m, h| m.max(h.abs()));
        self.trajectories
            .iter()
            .flat_map(|(level, points)| points.iter().map(move |&(x, y)| (level, x, y)))
            .map(|(level, x, y)| {
                (first_integral(self.mechanism, self.plane, x, y) - level).abs() / scale
            })
            .fold(0.0, f64::max)
    }
}

/// Where to cut rates that diverge at the axis: three times the largest
/// rate on the level sets away from it (beyond a quarter of the width).
fn rate_limit(curves: &[Curve]) -> f64 {
    let points = curves
        .iter()
        .filter(|c| c.style != Style::Simulated)
        .flat_map(|c| c.points.iter());
    let width = points.clone().fold(0.0, |m: f64, (x, _)| m.max(x.abs()));
    3.0 * points
        .filter(|(x, _)| x.abs() >= 0.25 * width)
        .fold(0.0, |m: f64, (_, y)| m.max(y.abs()))
}

/// The levels drawn, and which one is the separatrix.
fn levels(m: Mechanism, plane: Plane) -> (Vec<f64>, Option<f64>) {
    if let Plane::Linear { f1 } = plane {
        let w = m.omega;
        return if f1 > 0.0 {
            // h1 around the separatrix h_sep = 2 omega f1 (18); K = h1^2.
            let h_sep = 2.0 * w * f1;
            let levels = [0.3, 0.6, 1.0, 1.5, 2.2]
                .iter()
                .map(|k| (k * h_sep).powi(2))
                .collect();
            (levels, Some(h_sep * h_sep))
        } else {
            let unit = 2.0 * w * f1.abs().max(0.05);
            let levels = [0.3, 0.6, 1.0, 1.5]
                .iter()
                .map(|k| (k * unit).powi(2) + 4.0 * w * w * f1 * f1)
                .collect();
            (levels, None)
        };
    }
    let c = m.centre();
    let scale = (0.5 * c * c).max(0.02);
    let mut levels = Vec::new();
    let mut separatrix = None;
    if c > 0.0 {
        levels.extend([-0.75 * 0.5 * c * c, -0.35 * 0.5 * c * c, 0.0]);
        separatrix = Some(0.0);
    }
    levels.extend([0.5 * scale, 1.5 * scale, 3.0 * scale]);
    (levels, separatrix)
}

/// The levels that get a simulated trajectory: one loose orbit (if any) and
/// one impacting orbit.
fn simulated_levels(m: Mechanism, plane: Plane, levels: &[f64]) -> Vec<f64> {
    match plane {
        Plane::Linear { .. } => vec![levels[1], levels[levels.len() - 1]],
        _ if m.centre() > 0.0 => vec![levels[0], levels[levels.len() - 2]],
        _ => vec![levels[1]],
    }
}

fn h1_of(k: f64, f1: f64, omega: f64) -> f64 {
    if f1 > 0.0 {
        k.sqrt()
    } else {
        (k - 4.0 * omega * omega * f1 * f1).max(0.0).sqrt()
    }
}

/// The first integral of `plane` at `(x, y)`.
pub fn first_integral(m: Mechanism, plane: Plane, x: f64, y: f64) -> f64 {
    match plane {
        Plane::Strain => m.energy(x, y),
        Plane::Canonical => {
            let (s, c) = x.sin_cos();
            let eps = 1.0 / c - 1.0;
            0.5 * y * y * c.powi(4) / (s * s) - (m.centre() - 0.5 * eps) * eps
        }
        Plane::Theta => {
            let (eps, rate) = crate::models::mechanism::angle::strain_of_angle(x, y);
            m.energy(eps, rate)
        }
        Plane::Linear { f1 } => {
            let b = x * x;
            let b_rate = 2.0 * x * y;
            b_rate * b_rate + (m.omega * (b - 2.0 * f1)).powi(2)
        }
    }
}

/// Cosine-spaced samples of `[lo, hi]`, dense at both ends where level sets
/// turn.
fn spaced(lo: f64, hi: f64) -> impl Iterator<Item = f64> {
    (0..=SAMPLES).map(move |k| {
        lo + (hi - lo) * 0.5 * (1.0 - (std::f64::consts::PI * k as f64 / SAMPLES as f64).cos())
    })
}

/// The level set `level` of `plane`, as curves (upper and lower branches
/// joined; one per side of `theta = 0` where the set splits).
fn level_set(
    m: Mechanism,
    plane: Plane,
    level: f64,
    label: Option<String>,
    style: Style,
) -> Vec<Curve> {
    let c = m.centre();
    let w = m.omega;
    let closed = |upper: Vec<(f64, f64)>| {
        let mut points = upper.clone();
        points.extend(upper.iter().rev().map(|&(x, y)| (x, -y)));
        points
    };
    match plane {
        Plane::Strain => {
            let amplitude = (2.0 * level + c * c).max(0.0).sqrt();
            let (lo, hi) = ((c - amplitude).max(0.0), c + amplitude);
            let rate = |e: f64| w * (2.0 * level - e * (e - 2.0 * c)).max(0.0).sqrt();
            let upper: Vec<(f64, f64)> = spaced(lo, hi).map(|e| (e, rate(e))).collect();
            let mut curves = vec![Curve {
                label,
                points: closed(upper),
                style,
            }];
            if level > 0.0 {
                let v = rate(0.0);
                curves.push(Curve {
                    label: None,
                    points: vec![(0.0, -v), (0.0, v)],
                    style: Style::Jump,
                });
            }
            curves
        }
        Plane::Canonical | Plane::Theta => {
            let amplitude = (2.0 * level + c * c).max(0.0).sqrt();
            let (lo, hi) = ((c - amplitude).max(0.0), c + amplitude);
            let theta_of = |e: f64| (1.0 / (1.0 + e)).acos();
            let y_of = |theta: f64| {
                let eps = 1.0 / theta.cos() - 1.0;
                let eps_rate = w * (2.0 * level - eps * (eps - 2.0 * c)).max(0.0).sqrt();
                let (s, co) = theta.sin_cos();
                match plane {
                    Plane::Canonical => eps_rate * s.abs() / (co * co) / w,
                    _ => eps_rate * co * co / s.abs(),
                }
            };
            // On orbits through theta = 0, theta' diverges there: stop where
            // it reaches 4x its value at 5% of the largest strain.
            let cap = if lo > 0.0 {
                f64::INFINITY
            } else {
                4.0 * y_of(theta_of(0.05 * hi))
            };
            [1.0, -1.0]
                .into_iter()
                .map(|side| {
                    let upper: Vec<(f64, f64)> = spaced(theta_of(lo), theta_of(hi))
                        .map(|t| (side * t, y_of(t)))
                        .filter(|(_, y)| plane == Plane::Canonical || *y <= cap)
                        .collect();
                    Curve {
                        label: if side > 0.0 { label.clone() } else { None },
                        points: closed(upper),
                        style,
                    }
                })
                .collect()
        }
        Plane::Linear { f1 } => {
            let reach = level.sqrt() / w;
            let (lo, hi) = ((2.0 * f1 - reach).max(0.0), 2.0 * f1 + reach);
            let y_of =
                |b: f64| (level - (w * (b - 2.0 * f1)).powi(2)).max(0.0).sqrt() / (2.0 * b.sqrt());
            let cap = if lo > 0.0 {
                f64::INFINITY
            } else {
                4.0 * y_of(0.05 * hi)
            };
            [1.0, -1.0]
                .into_iter()
                .map(|side| {
                    let upper: Vec<(f64, f64)> = spaced(lo, hi)
                        .map(|b| (side * b.sqrt(), y_of(b)))
                        .filter(|(_, y)| *y <= cap)
                        .collect();
                    Curve {
                        label: if side > 0.0 { label.clone() } else { None },
                        points: closed(upper),
                        style,
                    }
                })
                .collect()
        }
    }
}

/// The engine's trajectory from the apex of `level`, sampled over two
/// periods, in the plane's coordinates.
fn trajectory(m: Mechanism, plane: Plane, level: f64) -> Vec<(f64, f64)> {
    let t_end = 2.0 * std::f64::consts::TAU / m.omega;
    match plane {
        Plane::Strain => {
            let (eps, rate) = m
                .state_with_energy(level, Phase::Apex)
                .unwrap_or((0.0, 0.0));
            sample(
                &StrainMechanism { mechanism: m },
                FLIGHT,
                &[eps, rate],
                t_end,
            )
            .into_iter()
            .map(|(_, _, x)| (x[0], x[1]))
            .collect()
        }
        Plane::Canonical | Plane::Theta => {
            let model = AngleMechanism {
                mechanism: m,
                charts: Charts::Switch,
            };
            let (eps, rate) = m
                .state_with_energy(level, Phase::Apex)
                .unwrap_or((0.0, 0.0));
            let Ok((mode, x0)) = model.start_from_strain(eps, rate) else {
                return Vec::new();
            };
            sample(&model, mode, &x0, t_end)
                .into_iter()
                .map(|(mode, _, x)| {
                    let (theta, theta_rate) = model.angle(mode, &x);
                    let (e, e_rate) = model.strain(mode, &x);
                    match plane {
                        // (29), which stays finite where theta' does not.
                        Plane::Canonical => (
                            theta,
                            theta.signum() * (e + 1.0) * (e * (e + 2.0)).sqrt() * e_rate / m.omega,
                        ),
                        _ => (theta, theta_rate),
                    }
                })
                .filter(|(_, y)| y.is_finite())
                .collect()
        }
        Plane::Linear { f1 } => {
            // b = theta1^2 is the strain of a mechanism with eta = 1 + 2 f1.
            let b_model = Mechanism {
                eta: 1.0 + 2.0 * f1,
                omega: m.omega,
            };
            let apex = 2.0 * f1 + level.sqrt() / m.omega;
            let mut side = 1.0;
            let mut impacts = 0;
            sample(
                &StrainMechanism { mechanism: b_model },
                FLIGHT,
                &[apex, 0.0],
                t_end,
            )
            .into_iter()
            .filter_map(|(_, events, x)| {
                if events != impacts {
                    side = -side;
                    impacts = events;
                }
                let theta1 = side * x[0].max(0.0).sqrt();
                (theta1 != 0.0).then(|| (theta1, x[1] / (2.0 * theta1)))
            })
            .collect()
        }
    }
}

/// States at evenly spaced times over `[0, t_end]` of one run, with the
/// mode and the events so far.
fn sample<M: HybridModel>(
    model: &M,
    mode: Mode,
    x0: &[f64],
    t_end: f64,
) -> Vec<(Mode, u64, Vec<f64>)> {
    let mut out = vec![(mode, 0, x0.to_vec())];
    let dt = t_end / (2 * SAMPLES) as f64;
    let times: Vec<f64> = (1..=2 * SAMPLES).map(|k| k as f64 * dt).collect();
    simulate_sampled(
        model,
        mode,
        x0,
        &Options::until(t_end),
        &times,
        &mut |s: &Sample| out.push((s.mode, s.events, s.state.to_vec())),
        &mut (),
    );
    out
}
