//! The single bistable mechanism in closed form (docs/physics.md s.2; paper
//! (32), (45)-(47)).
//!
//! Between impacts the strain is a linear oscillator about `eta - 1`:
//! `eps = (eta - 1) + A cos(omega t + phi)`. Its energy
//! `H0 = eps'^2 / (2 omega^2) + eps (eps + 2 (1 - eta)) / 2` is conserved
//! along flows and across the elastic reset `eps' -> -eps'` at `eps = 0`.
//! Everything here is exact up to rounding; the hybrid models and the tests
//! both build on it.

use std::f64::consts::TAU;

/// Load ratio and frequency of one mechanism.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanism {
    /// `F / F_cr`.
    pub eta: f64,
    /// `sqrt(k / m) > 0`.
    pub omega: f64,
}

/// Where on its orbit a mechanism given by its energy starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// At `eps = 0`, opening (`eps' >= 0`).
    Impact,
    /// At the largest strain, at rest.
    Apex,
}

impl Mechanism {
    /// The centre of oscillation, `eta - 1` (the buckled strain when positive).
    pub fn centre(&self) -> f64 {
        self.eta - 1.0
    }

    /// `H0` at strain `eps` and strain rate `rate`.
    pub fn energy(&self, eps: f64, rate: f64) -> f64 {
        let w = rate / self.omega;
        0.5 * w * w + 0.5 * eps * (eps + 2.0 * (1.0 - self.eta))
    }

    /// The scale of relative energy errors: `max(|H0|, (eta - 1)^2 / 2)`, so
    /// that orbits with `H0 = 0` still have a meaningful one.
    pub fn energy_scale(&self, h0: f64) -> f64 {
        let c = self.centre();
        h0.abs().max(0.5 * c * c).max(f64::MIN_POSITIVE)
    }

    /// The state `tau` after `(eps, rate)` along the free (unconstrained) flow.
    pub fn flow(&self, eps: f64, rate: f64, tau: f64) -> (f64, f64) {
        let (s, c) = (self.omega * tau).sin_cos();
        let u = eps - self.centre();
        let w = rate / self.omega;
        (self.centre() + u * c + w * s, self.omega * (w * c - u * s))
    }

    /// Elapsed time from `(eps, rate)` until the strain next reaches zero
    /// while closing, or `None` if it never does (loose orbits and the
    /// grazing separatrix, which touches zero at zero speed).
    ///
    /// With `u = eps - (eta - 1)`, `w = rate / omega` and
    /// `s = sqrt(2 H0)`, the phase still to run before the closing crossing
    /// is the angle between the vectors `(u, -w)` and `(-(eta - 1), s)`,
    /// taken by one `atan2` so that no phase is computed from a difference of
    /// nearly equal angles.
    pub fn time_to_closing(&self, eps: f64, rate: f64) -> Option<f64> {
        let c = self.centre();
        let w = rate / self.omega;
        let u = eps - c;
        let two_h0 = eps * (eps - 2.0 * c) + w * w;
        if two_h0 < 0.0 || (two_h0 == 0.0 && c >= 0.0) {
            return None;
        }
        let s = two_h0.sqrt();
        let sin = s * u - c * w;
        let cos = -c * u - s * w;
        let mut phase = sin.atan2(cos);
        if phase < 0.0 {
            // On the closing side the crossing lies at most half a turn
            // ahead; a negative phase there is rounding of "now".
            phase = if rate < 0.0 || (rate == 0.0 && eps == 0.0) {
                0.0
            } else {
                phase + TAU
            };
        }
        Some(phase / self.omega)
    }

    /// Time between impacts of an orbit of energy `h0 > 0`:
    /// `(2 / omega) atan2(sqrt(2 h0), 1 - eta)`, accurate near grazing and
    /// near resting contact alike.
    pub fn impact_period(&self, h0: f64) -> f64 {
        2.0 / self.omega * (2.0 * h0).sqrt().atan2(1.0 - self.eta)
    }

    /// The state with energy `h0` at `phase`, or why there is none.
    pub fn state_with_energy(&self, h0: f64, phase: Phase) -> Result<(f64, f64), String> {
        let c = self.centre();
        match phase {
            Phase::Impact if h0 < 0.0 => Err(format!(
                "an orbit of energy {h0} never reaches eps = 0 (impacts need energy >= 0)"
            )),
            Phase::Impact => Ok((0.0, self.omega * (2.0 * h0).sqrt())),
            Phase::Apex => {
                let amplitude_sq = 2.0 * h0 + c * c;
                let apex = c + amplitude_sq.max(0.0).sqrt();
                if amplitude_sq < 0.0 || apex < 0.0 {
                    let least = if c > 0.0 { -0.5 * c * c } else { 0.0 };
                    return Err(format!(
                        "no admissible state (eps >= 0) has energy {h0} at eta = {}; the least energy is {least}",
                        self.eta
                    ));
                }
                // Exact for the separatrix: c + |c| is 2c or 0 without rounding.
                Ok((apex, 0.0))
            }
        }
    }
}

/// The exact hybrid trajectory of one mechanism, for reference: impacts at
/// `t1, t1 + T, t1 + 2T, ...` with `T` the impact period.
#[derive(Debug, Clone, Copy)]
pub struct ExactOrbit {
    mechanism: Mechanism,
    initial: (f64, f64),
    first_impact: Option<f64>,
    period: f64,
    impact_speed: f64,
    resting: bool,
}

impl ExactOrbit {
    /// The orbit from strain `eps` and strain rate `rate` at `t = 0`.
    pub fn new(mechanism: Mechanism, eps: f64, rate: f64) -> Self {
        let h0 = mechanism.energy(eps, rate);
        // At H0 = 0 below critical load the unit rests shut: no impacts.
        let resting = h0 == 0.0 && mechanism.centre() < 0.0;
        let first_impact = mechanism.time_to_closing(eps, rate).filter(|_| !resting);
        ExactOrbit {
            mechanism,
            initial: (eps, rate),
            first_impact,
            period: if h0 > 0.0 {
                mechanism.impact_period(h0)
            } else {
                f64::INFINITY
            },
            impact_speed: mechanism.omega * (2.0 * h0.max(0.0)).sqrt(),
            resting,
        }
    }

    /// Impacts in `(0, t]`, counted from the closed form; saturates at
    /// `u64::MAX` for chattering orbits whose count no integer holds.
    pub fn impacts_until(&self, t: f64) -> u64 {
        match self.first_impact {
            // The float-to-integer cast saturates.
            Some(t1) if t1 <= t => (((t - t1) / self.period).floor() as u64).saturating_add(1),
            _ => 0,
        }
    }

    /// The time of impact number `k` (from 0), computed from the first
    /// impact and the period, with no accumulated rounding.
    pub fn impact_time(&self, k: u64) -> f64 {
        self.first_impact.unwrap_or(f64::INFINITY) + k as f64 * self.period
    }

    /// `(eps, eps')` at time `t`.
    pub fn state_at(&self, t: f64) -> (f64, f64) {
        let (eps, rate) = self.initial;
        if self.resting {
            return (0.0, 0.0);
        }
        match self.first_impact {
            Some(t1) if t1 <= t => {
                let since = (t - t1) % self.period;
                self.mechanism.flow(0.0, self.impact_speed, since)
            }
            _ => self.mechanism.flow(eps, rate, t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flow_conserves_energy_and_solves_the_oscillator() {
        let m = Mechanism {
            eta: 1.3,
            omega: 2.0,
        };
        let (e0, r0) = (0.4, -0.1);
        let h0 = m.energy(e0, r0);
        for k in 1..50 {
            let tau = 0.37 * k as f64;
            let (e, r) = m.flow(e0, r0, tau);
            assert!((m.energy(e, r) - h0).abs() < 1e-15);
            // eps'' = -omega^2 (eps - (eta - 1)), checked by a central difference.
            let d = 1e-4;
            let (ep, _) = m.flow(e0, r0, tau + d);
            let (em, _) = m.flow(e0, r0, tau - d);
            let second = (ep - 2.0 * e + em) / (d * d);
            assert!((second + m.omega.powi(2) * (e - m.centre())).abs() < 1e-6);
        }
    }

    #[test]
    fn closing_time_lands_on_zero_strain_while_closing() {
        let m = Mechanism {
            eta: 0.8,
            omega: 1.5,
        };
        for (e0, r0) in [(0.3, 0.2), (0.3, -0.2), (1e-3, 0.0), (0.0, 0.5)] {
            let tau = m.time_to_closing(e0, r0).unwrap();
            let (e, r) = m.flow(e0, r0, tau);
            assert!(e.abs() < 1e-15, "eps {e} at the crossing");
            assert!(r < 0.0);
            // No earlier crossing: the strain stays positive before it.
            for k in 1..100 {
                assert!(m.flow(e0, r0, tau * k as f64 / 100.0).0 > -1e-15);
            }
        }
    }

    #[test]
    fn period_matches_the_arccos_form_away_from_the_limits() {
        let m = Mechanism {
            eta: 1.2,
            omega: 1.0,
        };
        let h0 = 0.3;
        let a = (2.0 * h0 + 0.04f64).sqrt();
        let arccos_form = 2.0 * (-(m.eta - 1.0) / a).acos() / m.omega;
        assert!((m.impact_period(h0) - arccos_form).abs() < 1e-14);
        assert!(
            (m.time_to_closing(0.0, m.omega * (2.0 * h0).sqrt()).unwrap() - arccos_form).abs()
                < 1e-14
        );
    }

    #[test]
    fn loose_and_grazing_orbits_never_close() {
        let m = Mechanism {
            eta: 1.2,
            omega: 1.0,
        };
        let apex = m.state_with_energy(-0.01, Phase::Apex).unwrap();
        assert_eq!(m.time_to_closing(apex.0, apex.1), None);
        let separatrix = m.state_with_energy(0.0, Phase::Apex).unwrap();
        assert_eq!(m.energy(separatrix.0, separatrix.1), 0.0);
        assert_eq!(m.time_to_closing(separatrix.0, separatrix.1), None);
    }

    #[test]
    fn resting_contact_below_critical_load_closes_at_once() {
        let m = Mechanism {
            eta: 0.5,
            omega: 1.0,
        };
        assert_eq!(m.time_to_closing(0.0, 0.0), Some(0.0));
    }

    #[test]
    fn resting_contact_stays_shut_with_no_impacts() {
        let orbit = ExactOrbit::new(
            Mechanism {
                eta: 0.8,
                omega: 1.0,
            },
            0.0,
            0.0,
        );
        assert_eq!(orbit.impacts_until(100.0), 0);
        assert_eq!(orbit.state_at(37.0), (0.0, 0.0));
    }

    #[test]
    fn energy_below_the_minimum_is_refused() {
        let m = Mechanism {
            eta: 1.2,
            omega: 1.0,
        };
        assert!(m.state_with_energy(-0.03, Phase::Apex).is_err());
        assert!(m.state_with_energy(-0.1, Phase::Impact).is_err());
        let below = Mechanism {
            eta: 0.8,
            omega: 1.0,
        };
        assert!(below.state_with_energy(-0.01, Phase::Apex).is_err());
    }
}
