//! The continuum limit of the chain (docs/physics.md s.5; paper (58)-(86)): the
//! incompressible string, `y_tt = c^2 y_xx` with the strain `eps = y_x >= 0`,
//! in the scene units of docs/physics.md s.4 (`rho = 1`, `F_cr = c^2`).
//!
//! The string lies on `x in [-L/2, L/2]`: the wall holds `y = 0` at
//! `x = -L/2`, the load acts at `x = L/2`. A state is a [`Piece`], a
//! constant strain and velocity; [`fronts::FrontTracking`] carries the
//! exact solution for piecewise-constant data as pieces between fronts
//! moving at `+-c`.
//!
//! The paper's variant ([`Variant::Paper`]) is the wave equation with the
//! constraint and energy kept across impacts, nothing more. Its loaded end
//! obeys the paper's boundary condition (74): `eps = eta - 1` there, which
//! the constraint allows only for `eta >= 1`; for a lighter load the end is
//! held at `eps = 0` (the paper's own reading of its release: "the right
//! end where eps = 0 on account of the absence of an applied tension"), so
//! the end carries `F_cr`, more than the scene's load. The model's energy
//! and momentum balance use the force its end carries
//! ([`Continuum::end_force`]); the scene's load is what it leaves out.

pub mod fronts;
pub mod homogenized;
pub mod hugoniot;
pub mod rattle;
pub(crate) mod run;
pub mod scene;
mod scene_model;

pub use fronts::FrontTracking;
pub use homogenized::Homogenized;

use crate::engine::LocalModel;
use crate::models::chain::coarse::Coarse;
use crate::time::Time;

/// What a run observes of a string, whichever description carries it.
pub trait StringModel: LocalModel {
    /// The state at `x` (the mean state, for a homogenized string).
    fn piece_at(&self, x: f64, t: Time) -> Piece;
    /// `y(x, t)`, the integral of the strain from the wall to `x`.
    fn displacement_at(&self, x: f64, t: Time) -> f64;
    /// Total momentum.
    fn momentum(&self, t: Time) -> f64;
    /// The initial momentum plus what the end force and the wall have
    /// given since: what [`StringModel::momentum`] must equal.
    fn momentum_by_impulses(&self, t: Time) -> f64;
    /// The coarse-grained fields of docs/physics.md s.6 at window centres.
    fn coarse(&self, centres: &[f64], t: Time) -> Coarse;
    /// The loaded end's displacement.
    fn right_end(&self, t: Time) -> f64 {
        self.displacement_at(f64::INFINITY, t)
    }
    /// The state and the displacement at each of `points` (in increasing
    /// order), in one pass along the string.
    fn profile(&self, points: &[f64], t: Time) -> Vec<(Piece, f64)>;
}

/// Which continuum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// The paper's: the wave equation, the constraint, energy kept.
    Paper,
    /// Mass, momentum and energy with the rattling kept, under the single
    /// mechanism's equation of state ([`homogenized`]).
    Homogenized,
}

impl Variant {
    /// The variant's name in scenes and output: `paper` or `homogenized`.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Paper => "paper",
            Variant::Homogenized => "homogenized",
        }
    }
}

/// The string's parameters, in scene units.
#[derive(Debug, Clone, PartialEq)]
pub struct Continuum {
    /// Length `L`; the string spans `[-L/2, L/2]`.
    pub length: f64,
    /// Wave speed `c` (`F_cr = c^2`, `rho = 1`).
    pub wave_speed: f64,
    /// End load after the release, over `F_cr`.
    pub load: f64,
    /// Whether `eps >= 0` is enforced (`false`: the classical string).
    pub constraint: bool,
}

/// A constant state of the string.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Strain `eps = y_x`.
    pub strain: f64,
    /// Velocity `y_t`.
    pub velocity: f64,
}

impl Continuum {
    /// The critical load `F_cr = c^2` (with `rho = 1`).
    pub fn critical_load(&self) -> f64 {
        self.wave_speed * self.wave_speed
    }

    /// The wall's position, `-L/2`.
    pub fn wall(&self) -> f64 {
        -0.5 * self.length
    }

    /// The loaded end's position, `L/2`.
    pub fn end(&self) -> f64 {
        0.5 * self.length
    }

    /// The strain the loaded end is held at: `eta - 1`, not below zero
    /// under the constraint.
    pub fn end_strain(&self) -> f64 {
        let free = self.load - 1.0;
        if self.constraint { free.max(0.0) } else { free }
    }

    /// The force the model's loaded end carries, `F_cr (1 + end strain)`:
    /// the scene's load, or `F_cr` where the constraint holds the end shut.
    pub fn end_force(&self) -> f64 {
        self.critical_load() * (1.0 + self.end_strain())
    }

    /// Energy per unit length of `p`, `v^2 / 2 + F_cr (eps^2 / 2 + eps)`
    /// (paper (79) with `rho = 1`; the end load's share is `-F y(L/2)`).
    pub fn energy_density(&self, p: Piece) -> f64 {
        0.5 * p.velocity * p.velocity
            + self.critical_load() * (0.5 * p.strain * p.strain + p.strain)
    }

    /// The axial force in `p`, `F_cr (1 + eps)` (70).
    pub fn force(&self, p: Piece) -> f64 {
        self.critical_load() * (1.0 + p.strain)
    }

    /// The state between a left piece `l` and a right piece `r` once the
    /// jump between them has split into a left- and a right-moving front:
    /// it keeps `v - c eps` from the left and `v + c eps` from the right
    /// (the Riemann invariants carried across each front).
    pub fn between(&self, l: Piece, r: Piece) -> Piece {
        let c = self.wave_speed;
        Piece {
            strain: 0.5 * (l.strain + r.strain) + (r.velocity - l.velocity) / (2.0 * c),
            velocity: 0.5 * (l.velocity + r.velocity) + 0.5 * c * (r.strain - l.strain),
        }
    }

    /// The state a left-moving wave leaves at the wall (`v = 0`) when `p`
    /// arrives there: `v + c eps` is carried in.
    pub fn reflected_at_wall(&self, p: Piece) -> Piece {
        Piece {
            strain: p.strain + p.velocity / self.wave_speed,
            velocity: 0.0,
        }
    }

    /// The state at the loaded end (`eps` = [`Continuum::end_strain`]) when
    /// `p` arrives there: `v - c eps` is carried in.
    pub fn reflected_at_end(&self, p: Piece) -> Piece {
        let (c, e) = (self.wave_speed, self.end_strain());
        Piece {
            strain: e,
            velocity: p.velocity + c * (e - p.strain),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn string() -> Continuum {
        Continuum {
            length: 2.0,
            wave_speed: 2.0,
            load: 0.5,
            constraint: false,
        }
    }

    #[test]
    fn the_middle_state_satisfies_the_jump_conditions_of_both_fronts() {
        // Across a front moving at s: s [eps] = -[v] and s [v] = -c^2 [eps].
        let s = string();
        let (l, r) = (
            Piece {
                strain: 0.3,
                velocity: -0.2,
            },
            Piece {
                strain: 0.05,
                velocity: 0.7,
            },
        );
        let m = s.between(l, r);
        let c = s.wave_speed;
        // Left-moving front between l and m, right-moving between m and r.
        assert!((-c * (m.strain - l.strain) + (m.velocity - l.velocity)).abs() < 1e-15);
        assert!((c * (r.strain - m.strain) + (r.velocity - m.velocity)).abs() < 1e-15);
    }

    #[test]
    fn reflections_keep_the_incoming_invariant_and_the_boundary_condition() {
        let s = string();
        let p = Piece {
            strain: 0.1,
            velocity: 0.3,
        };
        let c = s.wave_speed;
        let w = s.reflected_at_wall(p);
        assert_eq!(w.velocity, 0.0);
        assert!((w.velocity + c * w.strain - (p.velocity + c * p.strain)).abs() < 1e-15);
        let e = s.reflected_at_end(p);
        assert_eq!(e.strain, -0.5);
        assert!((e.velocity - c * e.strain - (p.velocity - c * p.strain)).abs() < 1e-15);
        // Under the constraint a load below F_cr holds the end at zero strain.
        let held = Continuum {
            constraint: true,
            ..s
        };
        assert_eq!(held.end_strain(), 0.0);
        assert_eq!(held.end_force(), held.critical_load());
    }
}
