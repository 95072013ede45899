//! Written-out references for one mechanism (docs/physics.md s.2), so that tests
//! check the engine without going through `src/models/mechanism`, whose
//! model and closed form share `flow`, `time_to_closing` and
//! `impact_period`: the energy, both forms of the impact period, the cosine
//! arc between impacts, and a fixed-step RK4 integration of the ODE with the
//! elastic reset, written here from the equations alone.

use std::f64::consts::TAU;

/// One mechanism's load ratio and frequency.
#[derive(Debug, Clone, Copy)]
pub struct Unit {
    pub eta: f64,
    pub omega: f64,
}

impl Unit {
    /// `H0 = eps'^2 / (2 omega^2) + eps (eps + 2 (1 - eta)) / 2`.
    pub fn energy(&self, eps: f64, rate: f64) -> f64 {
        rate * rate / (2.0 * self.omega * self.omega) + eps * (eps + 2.0 * (1.0 - self.eta)) / 2.0
    }

    /// `A = sqrt(2 H0 + (eta - 1)^2)`, the arc's amplitude.
    pub fn amplitude(&self, h0: f64) -> f64 {
        (2.0 * h0 + (self.eta - 1.0).powi(2)).sqrt()
    }

    /// `T_imp = 2 arccos(-(eta - 1) / A) / omega`.
    pub fn period_arccos(&self, h0: f64) -> f64 {
        2.0 * (-(self.eta - 1.0) / self.amplitude(h0)).acos() / self.omega
    }

    /// `T_imp = (2 / omega) atan2(sqrt(2 H0), 1 - eta)`.
    pub fn period_atan2(&self, h0: f64) -> f64 {
        2.0 / self.omega * (2.0 * h0).sqrt().atan2(1.0 - self.eta)
    }

    /// The impact speed `|eps'| = omega sqrt(2 H0)`.
    pub fn impact_speed(&self, h0: f64) -> f64 {
        self.omega * (2.0 * h0).sqrt()
    }

    /// The largest strain of an orbit of energy `h0`, at rest:
    /// `(eta - 1) + A`.
    pub fn apex(&self, h0: f64) -> (f64, f64) {
        (self.eta - 1.0 + self.amplitude(h0), 0.0)
    }

    /// The cosine arc `eps = (eta - 1) + A cos(omega t + phi)` through
    /// `(eps0, rate0)` at `t = 0`, constraint ignored: `(eps, eps')` at `t`.
    pub fn arc(&self, (eps0, rate0): (f64, f64), t: f64) -> (f64, f64) {
        let c = self.eta - 1.0;
        let (u, w) = (eps0 - c, rate0 / self.omega);
        let a = u.hypot(w);
        // u = A cos(phi), w = eps'/omega = -A sin(phi).
        let psi = self.omega * t + (-w).atan2(u);
        (c + a * psi.cos(), -a * self.omega * psi.sin())
    }

    /// Time from `(eps0, rate0)` to the arc's next closing crossing of
    /// `eps = 0`, or `None` if it has none (`H0 < 0`, or the separatrix
    /// `H0 = 0` at `eta >= 1`, which touches zero at zero speed). The
    /// crossing phase `psi*` has `cos = -(eta - 1) / A` and `sin > 0` (the
    /// rate `-A omega sin` is negative there): `psi* = atan2(sqrt(2 H0),
    /// -(eta - 1))`; the phase runs to it from `phi`, within one turn.
    pub fn first_closing(&self, (eps0, rate0): (f64, f64)) -> Option<f64> {
        let h0 = self.energy(eps0, rate0);
        let c = self.eta - 1.0;
        if h0 < 0.0 || (h0 == 0.0 && c >= 0.0) {
            return None;
        }
        let target = (2.0 * h0).sqrt().atan2(-c);
        let phi = (-rate0 / self.omega).atan2(eps0 - c);
        Some((target - phi).rem_euclid(TAU) / self.omega)
    }

    /// Impacts in `(0, t]` from `x0`: `t1 + (n - 1) T <= t`.
    pub fn impacts_until(&self, x0: (f64, f64), t: f64) -> u64 {
        let h0 = self.energy(x0.0, x0.1);
        match self.first_closing(x0) {
            Some(t1) if t1 <= t && h0 > 0.0 => {
                ((t - t1) / self.period_atan2(h0)).floor() as u64 + 1
            }
            _ => 0,
        }
    }

    /// The hybrid state at `t` from `x0`: the arc from the last impact
    /// `t1 + (n - 1) T` before `t`, which leaves `eps = 0` at the impact
    /// speed (or the arc from `x0` before the first impact).
    pub fn state_at(&self, x0: (f64, f64), t: f64) -> (f64, f64) {
        let h0 = self.energy(x0.0, x0.1);
        match self.impacts_until(x0, t) {
            0 => self.arc(x0, t),
            n => {
                let last = self.first_closing(x0).unwrap() + (n - 1) as f64 * self.period_atan2(h0);
                self.arc((0.0, self.impact_speed(h0)), t - last)
            }
        }
    }
}

/// What [`rk4`] found.
#[derive(Debug, Clone)]
pub struct Rk4Run {
    pub impacts: Vec<f64>,
    pub state: (f64, f64),
    pub steps: u64,
}

/// `eps'' = -omega^2 (eps - (eta - 1))` from `x0` to `t_end` by classical
/// fourth-order Runge-Kutta with the fixed step `h`, with `eps' -> -eps'`
/// where `eps` reaches zero while closing. A step that would end below zero
/// is cut at the crossing: the RK4 step from the same start is a smooth
/// function of its length `s`, whose zero Newton finds (with the stepped
/// rate as its slope, exact to O(s^4), so Newton still converges). Time is
/// counted as the last event's time plus whole steps, so no rounding
/// accumulates in the clock.
pub fn rk4(unit: Unit, x0: (f64, f64), t_end: f64, h: f64) -> Rk4Run {
    let (c, w2) = (unit.eta - 1.0, unit.omega * unit.omega);
    let field = |(e, r): (f64, f64)| (r, -w2 * (e - c));
    let step = |x: (f64, f64), s: f64| {
        let at = |k: (f64, f64), f: f64| (x.0 + f * s * k.0, x.1 + f * s * k.1);
        let k1 = field(x);
        let k2 = field(at(k1, 0.5));
        let k3 = field(at(k2, 0.5));
        let k4 = field(at(k3, 1.0));
        (
            x.0 + s / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
            x.1 + s / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
        )
    };
    let (mut x, mut since, mut k, mut steps) = (x0, 0.0, 0u64, 0u64);
    let mut impacts = Vec::new();
    loop {
        let t = since + k as f64 * h;
        let s = (t_end - t).min(h);
        if s <= 0.0 {
            break;
        }
        steps += 1;
        let y = step(x, s);
        if y.0 < 0.0 {
            // Secant start, then Newton on the step length.
            let mut sigma = s * x.0 / (x.0 - y.0);
            let mut z = step(x, sigma);
            for _ in 0..60 {
                let next = sigma - z.0 / z.1;
                let done = (next - sigma).abs() <= 1e-17 * h.max(sigma);
                sigma = next;
                z = step(x, sigma);
                if done {
                    break;
                }
            }
            impacts.push(t + sigma);
            (x, since, k) = ((0.0, -z.1), t + sigma, 0);
            continue;
        }
        x = y;
        if s < h {
            break;
        }
        k += 1;
    }
    Rk4Run {
        impacts,
        state: x,
        steps,
    }
}

/// A bound on the phase error of [`rk4`] after `steps` steps of `h` over
/// time `t`: RK4's amplification for `y' = i omega y` has the phase
/// `theta - theta^5 / 120 + ...` per step (`theta = omega h`), so
/// truncation gives `omega t (omega h)^4 / 120`; round-off adds at most a
/// few ulps per step, counted here as 4 ulps all of one sign.
pub fn rk4_phase_error(omega: f64, h: f64, t: f64, steps: u64) -> f64 {
    omega * t * (omega * h).powi(4) / 120.0 + 4.0 * f64::EPSILON * steps as f64
}
