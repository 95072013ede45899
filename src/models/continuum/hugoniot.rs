//! Shocks of the homogenized string at its ends: the state a compressive
//! shock leaves at the loaded end (where the load is less than the force
//! the string carries) or at the wall (where the string runs into it).
//!
//! Across a shock of speed `s` between the state ahead `A` and the state
//! behind `B` (`rho = 1`), mass, momentum and energy give
//!
//! ```text
//! v_B - v_A = -s (e_B - e_A),   sigma_B - sigma_A = s^2 (e_B - e_A),
//! E_B - E_A = -(sigma_B v_B - sigma_A v_A) / s,
//! ```
//!
//! and the state behind must carry the force its equation of state
//! ([`super::rattle`]) gives. At the end `sigma_B` is the load, at the wall
//! `v_B = 0`; either leaves one unknown, the strain behind, found on
//! `(0, e_A)` by regula falsi. States are `[e, v, E]` with `E`
//! the energy per unit length, forces over `F_cr`, speeds over `c_b`
//! (scene units with `c_b = 1`: the caller scales).

use super::rattle;

/// A state behind a shock and the shock's speed (negative: towards the wall).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shock {
    /// The state behind, `[e, v, E]`.
    pub behind: [f64; 3],
    /// The shock's speed, over `c_b`.
    pub speed: f64,
}

/// The shock that leaves the loaded end into `ahead` (force `sigma_ahead`)
/// when the end carries `load < sigma_ahead`.
pub fn from_end(ahead: [f64; 3], sigma_ahead: f64, load: f64) -> Result<Shock, String> {
    let [ea, va, energy_a] = ahead;
    let behind = |e: f64| {
        let s = -((load - sigma_ahead) / (e - ea)).sqrt();
        let v = va - s * (e - ea);
        let energy = energy_a - (load * v - sigma_ahead * va) / s;
        (s, [e, v, energy])
    };
    solve(ea, behind, |_| load, "the loaded end")
}

/// The shock that leaves the wall into `ahead` (force `sigma_ahead`),
/// which runs into the wall (`v < 0`), stopping it.
pub fn from_wall(ahead: [f64; 3], sigma_ahead: f64) -> Result<Shock, String> {
    let [ea, va, energy_a] = ahead;
    let behind = |e: f64| {
        let s = va / (e - ea);
        let energy = energy_a + sigma_ahead * va / s;
        (s, [e, 0.0, energy])
    };
    let force = |e: f64| sigma_ahead + va * va / (e - ea);
    solve(ea, behind, force, "the wall")
}

/// The strain behind in `(0, ahead)` at which the state `behind(e)` carries
/// the force `force(e)` its equation of state gives.
fn solve(
    ahead: f64,
    behind: impl Fn(f64) -> (f64, [f64; 3]),
    force: impl Fn(f64) -> f64,
    at: &str,
) -> Result<Shock, String> {
    let residual = |e: f64| {
        let (_, [e, v, energy]) = behind(e);
        match rattle::stress(e, energy - 0.5 * v * v) {
            Ok(sigma) => sigma - force(e),
            // Below the law's range the state would need negative rattling.
            Err(_) => f64::NEG_INFINITY,
        }
    };
    let hi = ahead * (1.0 - 1e-9);
    let f_hi = residual(hi);
    let mut lo = 0.5 * ahead;
    let mut f_lo = residual(lo);
    while f_lo > 0.0 && lo > 1e-12 * ahead {
        lo *= 0.5;
        f_lo = residual(lo);
    }
    if !(f_hi > 0.0 && f_lo < 0.0) {
        return Err(format!(
            "no shock from {at} into strain {ahead:e} keeps mass, momentum and energy under the equation of state"
        ));
    }
    let e = rattle::root(&residual, lo, f_lo, hi, f_hi);
    // The residual jumps to minus infinity where the law's range ends: a
    // sign change there is an edge, not a root.
    let miss = residual(e).abs();
    if !(miss <= 1e-9 * (1.0 + force(e).abs())) {
        return Err(format!(
            "no shock from {at} into strain {ahead:e} keeps mass, momentum and energy under the equation of state (the nearest misses its force by {miss:e})"
        ));
    }
    let (speed, behind) = behind(e);
    Ok(Shock { behind, speed })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_free_end_shock_of_the_release_keeps_its_jump_conditions() {
        // docs/physics.md s.6, traction-free: eps 0.1 at rest, force 1.1; the
        // end carries nothing. Worked by hand from the same law: a front at
        // about 4.7 c_b, the end at about -0.235.
        let ahead = [0.1, 0.0, 0.1 + 0.005];
        let shock = from_end(ahead, 1.1, 0.0).unwrap();
        let [e, v, energy] = shock.behind;
        let s = shock.speed;
        assert!((-4.75..-4.6).contains(&s), "{s}");
        assert!((-0.24..-0.23).contains(&v), "{v}");
        assert!((v - 0.0 + s * (e - 0.1)).abs() < 1e-12);
        assert!((0.0 - 1.1 - s * s * (e - 0.1)).abs() < 1e-9);
        // No flux of energy through a traction-free end or the still string.
        assert!((energy - ahead[2]).abs() < 1e-12);
        assert!(rattle::stress(e, energy - 0.5 * v * v).unwrap().abs() < 1e-9);
    }

    #[test]
    fn the_wall_stops_a_string_that_runs_into_it() {
        // A rattling string (hidden energy 0.02 per length) at v = -0.2.
        let ahead = [0.05, -0.2, 0.05 + 0.5 * 0.0025 + 0.02 + 0.5 * 0.04];
        let sigma = rattle::stress(0.05, ahead[2] - 0.02).unwrap();
        let shock = from_wall(ahead, sigma).unwrap();
        let ([e, v, energy], s) = (shock.behind, shock.speed);
        assert!(s > 0.0 && v == 0.0 && e < 0.05);
        // The three jump conditions, and the law's force behind.
        let sigma_behind = rattle::stress(e, energy).unwrap();
        assert!((v - ahead[1] + s * (e - ahead[0])).abs() < 1e-12);
        assert!((sigma_behind - sigma - s * s * (e - ahead[0])).abs() < 1e-8);
        assert!((s * (energy - ahead[2]) + (sigma_behind * v - sigma * ahead[1])).abs() < 1e-12);
    }
}
