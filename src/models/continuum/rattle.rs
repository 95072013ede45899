//! The equation of state of a rattling string, from the single mechanism's
//! closed form (docs/physics.md s.2): what a unit does on average when it
//! carries an axial force `sigma = eta F_cr` and holds an energy it cannot
//! show as mean motion.
//!
//! A unit under a steady force oscillates as `eps = c + A cos(omega t)`
//! about its centre `c = eta - 1`, cut at `eps = 0` by elastic impacts. Over
//! its arc `|omega t| <= phi`, `cos(phi) = -c / A` (`phi = pi` when it never
//! reaches zero), the mean strain is
//!
//! ```text
//! e = c + A sin(phi) / phi
//! ```
//!
//! and its energy per unit length, `F_cr (eps'^2 / 2 omega^2 + eps^2 / 2 +
//! eps)` with the load's share `-eta eps` taken out of (32), averages to
//!
//! ```text
//! g = u / F_cr = (A^2 - c^2) / 2 + (1 + c) e.
//! ```
//!
//! Given a cell's mean strain `e` and internal energy `g`, the two fix `c`
//! and `A`, hence the mean force `sigma = F_cr (1 + c)` the cell carries:
//! the constitutive law of the homogenized string. Without rattling
//! (`g = e + e^2 / 2`) it is the elastic law `sigma = F_cr (1 + e)`; an
//! oscillation that never reaches zero leaves the force elastic too. No
//! number here is fitted to a chain.
//!
//! Where the hidden energy `g - e - e^2 / 2` is at most `e^2 / 2`, an
//! oscillation clear of zero about `c = e` has the same mean and energy as
//! some impacting ones under a smaller force: `(e, g)` does not say which.
//! The law takes the oscillation clear of zero (the string's state before
//! any impact); above `e^2 / 2` only impacting orbits remain. Orbits under
//! a force at most `F_cr` (`c <= 0`: the rattling behind a release) lie
//! there: their arcs are short enough that `A^2 (1 - (sin phi / phi)^2)`
//! exceeds `e^2`.

/// The centre `c = eta - 1` of the oscillation a unit with mean strain `e`
/// and internal energy `g` (per unit length, over `F_cr`) makes, or why
/// there is none.
pub fn centre(e: f64, g: f64) -> Result<f64, String> {
    centre_near(e, g, None).map(|(c, _)| c)
}

/// [`centre`], by Newton's method from `hint` (a nearby state's centre)
/// when it converges there (with the derivatives Newton used), else from a
/// bracket.
fn centre_near(e: f64, g: f64, hint: Option<f64>) -> Result<(f64, Option<Parts>), String> {
    if !(e.is_finite() && g.is_finite() && e > 0.0) {
        return Err(format!(
            "no unit has mean strain {e:e} and energy {g:e}: the mean strain must be positive"
        ));
    }
    let hidden = g - e - 0.5 * e * e;
    if hidden < -1e-12 * g.abs().max(e) {
        return Err(format!(
            "no unit has mean strain {e:e} and energy {g:e}: the energy is below the elastic energy of its mean strain"
        ));
    }
    // An oscillation of amplitude at most e about e never reaches zero.
    if hidden <= 0.5 * e * e {
        return Ok((e, None));
    }
    if let Some((c, parts)) = hint.and_then(|h| newton(e, g, h)) {
        return Ok((c, Some(parts)));
    }
    let mean = |c: f64| c + amplitude(c, e, g) * arc_mean(c, amplitude(c, e, g)) - e;
    // mean(e) > 0 (the arc lies above its centre); far below, the arc
    // shrinks to the top of the cosine and mean(c) -> -e / 3.
    let (mut lo, hi) = (e - 1.0, e);
    let mut f_lo = mean(lo);
    let mut widen = 0;
    while f_lo > 0.0 {
        lo = e - 2.0 * (e - lo);
        f_lo = mean(lo);
        widen += 1;
        if widen > 60 {
            return Err(format!(
                "no oscillation has mean strain {e:e} and energy {g:e}"
            ));
        }
    }
    Ok((root(mean, lo, f_lo, hi, mean(hi)), None))
}

/// A root of `f` in `[lo, hi]`, where `f(lo)` and `f(hi)` differ in sign,
/// by Illinois regula falsi (bisecting when a secant leaves the bracket),
/// to a few ulps of the bracket's scale.
pub(crate) fn root(
    f: impl Fn(f64) -> f64,
    mut lo: f64,
    mut f_lo: f64,
    mut hi: f64,
    mut f_hi: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..200 {
        if (hi - lo).abs() <= 4.0 * f64::EPSILON * hi.abs().max(lo.abs()).max(f64::MIN_POSITIVE) {
            break;
        }
        let mut x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        if !(x > lo.min(hi) && x < lo.max(hi)) {
            x = 0.5 * (lo + hi);
        }
        let fx = f(x);
        if fx == 0.0 {
            return x;
        }
        if (fx > 0.0) == (f_hi > 0.0) {
            (hi, f_hi) = (x, fx);
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        } else {
            (lo, f_lo) = (x, fx);
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        }
    }
    0.5 * (lo + hi)
}

/// Newton's iteration for the centre from `c`, if it settles within a few
/// steps on an impacting orbit (`c < e`).
/// With the derivatives at the last iterate but one: a step below `1e-8`
/// leaves an error of its square, and derivatives good to `1e-8`.
fn newton(e: f64, g: f64, mut c: f64) -> Option<(f64, Parts)> {
    for _ in 0..8 {
        if !(c < e) {
            return None;
        }
        let p = Parts::at(c, e, g)?;
        let step = p.f / p.f_c;
        c -= step;
        if step.abs() <= 1e-8 * (1.0 + c.abs()) {
            return (c < e).then_some((c, p));
        }
    }
    None
}

/// The mismatch `f = c + A sin(phi) / phi - e` of the mean strain about
/// centre `c`, and its derivatives in `c`, `e` and `g` (at fixed others).
struct Parts {
    f: f64,
    f_c: f64,
    f_e: f64,
    f_g: f64,
}

impl Parts {
    /// `None` at the ends of the arc's range (`sin(phi)` near zero), where
    /// the derivatives lose their digits.
    fn at(c: f64, e: f64, g: f64) -> Option<Parts> {
        let a = amplitude(c, e, g);
        let sin_phi = (a * a - c * c).max(0.0).sqrt() / a;
        if !(sin_phi > 1e-6) {
            return None;
        }
        let cos_phi = (-c / a).clamp(-1.0, 1.0);
        let phi = cos_phi.acos();
        let s = sin_phi / phi;
        let s_phi = (phi * cos_phi - sin_phi) / (phi * phi);
        let (phi_c, phi_a) = (1.0 / (a * sin_phi), -c / (a * a * sin_phi));
        let (a_c, a_e, a_g) = ((c - e) / a, -(1.0 + c) / a, 1.0 / a);
        let f_a = s + a * s_phi * phi_a;
        Some(Parts {
            f: c + a * s - e,
            f_c: 1.0 + a * s_phi * phi_c + f_a * a_c,
            f_e: -1.0 + f_a * a_e,
            f_g: f_a * a_g,
        })
    }
}

/// The amplitude that gives energy `g` about centre `c` at mean strain `e`.
fn amplitude(c: f64, e: f64, g: f64) -> f64 {
    (c * c + 2.0 * (g - (1.0 + c) * e)).max(0.0).sqrt()
}

/// `sin(phi) / phi` over the arc of `c + A cos` above zero.
fn arc_mean(c: f64, a: f64) -> f64 {
    if a <= 0.0 {
        return 0.0;
    }
    let phi = (-c / a).clamp(-1.0, 1.0).acos();
    if phi < 1e-4 {
        1.0 - phi * phi / 6.0
    } else {
        phi.sin() / phi
    }
}

/// The mean force over `F_cr` of a cell with mean strain `e` and energy `g`.
pub fn stress(e: f64, g: f64) -> Result<f64, String> {
    centre(e, g).map(|c| 1.0 + c)
}

/// What the law says of a cell: its centre `c` (force `F_cr (1 + c)`) and
/// its sound speed over `c_b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Law {
    /// The centre `c` of the oscillation: the cell carries `F_cr (1 + c)`.
    pub centre: f64,
    /// The sound speed, over `c_b`.
    pub speed: f64,
}

/// The law at `(e, g)`, starting from the centre `hint` of a nearby state
/// if there is one. The sound speed is `sqrt(d sigma / d e)` along
/// `dg = sigma de` (a cell stretched without exchanging energy with its
/// neighbours): from the derivatives of the mean-strain relation, or by
/// differences near the ends of the arc's range; never below the elastic
/// speed, as a bound for the flux.
pub fn law(e: f64, g: f64, hint: Option<f64>) -> Result<Law, String> {
    let (c, parts) = centre_near(e, g, hint)?;
    let parts = parts.or_else(|| (c < e).then(|| Parts::at(c, e, g)).flatten());
    let slope = match parts {
        Some(p) => (-p.f_e - (1.0 + c) * p.f_g) / p.f_c,
        None if c < e => slope_by_differences(e, g, 1.0 + c)?,
        None => 1.0,
    };
    Ok(Law {
        centre: c,
        speed: slope.max(1.0).sqrt(),
    })
}

/// `d sigma / d e` along `dg = sigma de`, by central differences.
fn slope_by_differences(e: f64, g: f64, s: f64) -> Result<f64, String> {
    let h = 1e-6 * e;
    Ok((stress(e + h, g + s * h)? - stress(e - h, g - s * h)?) / (2.0 * h))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::mechanism::{ExactOrbit, Mechanism};

    /// The time average of a mechanism's strain and of its energy without
    /// the load's share, over many impact periods, from its closed form.
    fn averaged(eta: f64, eps: f64) -> (f64, f64) {
        let m = Mechanism { eta, omega: 1.0 };
        let orbit = ExactOrbit::new(m, eps, 0.0);
        let h0 = m.energy(eps, 0.0);
        let span = if h0 > 0.0 {
            m.impact_period(h0) * 50.0
        } else {
            std::f64::consts::TAU * 50.0
        };
        let n = 200_000;
        let (mut e, mut g) = (0.0, 0.0);
        for k in 0..n {
            let (x, rate) = orbit.state_at(span * (k as f64 + 0.5) / n as f64);
            e += x / n as f64;
            g += (0.5 * rate * rate + 0.5 * x * x + x) / n as f64;
        }
        (e, g)
    }

    #[test]
    fn the_law_returns_the_load_of_a_rattling_mechanism() {
        // Impacting orbits below, at and above the critical load, and a
        // loose one: the time averages of the closed form give back eta.
        for (eta, eps) in [
            (0.0, 0.3),
            (0.5, 0.05),
            (1.0, 0.08),
            (1.2, 1.0),
            (1.3, 0.45),
        ] {
            let (e, g) = averaged(eta, eps);
            let s = stress(e, g).unwrap();
            assert!((s - eta).abs() < 2e-4, "eta {eta}: law gives {s}");
        }
    }

    #[test]
    fn a_small_hidden_energy_is_read_as_an_oscillation_clear_of_zero() {
        // eta 1.2 from eps 0.5: impacts (c = 0.2, A = 0.3), but an
        // oscillation about its own mean, clear of zero, has the same mean
        // strain and energy; the law takes that one.
        let (e, g) = averaged(1.2, 0.5);
        assert!(g - e - 0.5 * e * e < 0.5 * e * e);
        assert!((stress(e, g).unwrap() - (1.0 + e)).abs() < 1e-12);
    }

    #[test]
    fn the_sound_speed_from_derivatives_matches_differences_and_newton_the_bracket() {
        for (eta, eps) in [(0.0, 0.3), (0.5, 0.05), (1.0, 0.08), (1.2, 1.0)] {
            let (e, g) = averaged(eta, eps);
            let exact = law(e, g, None).unwrap();
            let s = 1.0 + exact.centre;
            let by_differences = slope_by_differences(e, g, s).unwrap().max(1.0).sqrt();
            assert!(
                (exact.speed - by_differences).abs() < 1e-6 * exact.speed,
                "eta {eta}: {} against {by_differences}",
                exact.speed
            );
            let near = law(e, g, Some(exact.centre - 0.01)).unwrap();
            assert!((near.centre - exact.centre).abs() < 1e-13, "eta {eta}");
        }
    }

    #[test]
    fn without_rattling_the_law_is_elastic() {
        for e in [1e-3, 0.1, 2.0] {
            let g = e + 0.5 * e * e;
            assert!((stress(e, g).unwrap() - (1.0 + e)).abs() < 1e-15);
            assert!((law(e, g, None).unwrap().speed - 1.0).abs() < 1e-6);
        }
        assert!(stress(0.0, 1.0).is_err());
        assert!(stress(0.1, 0.0).is_err());
    }

    #[test]
    fn rattling_makes_the_string_stiffer_and_the_arc_mean_exact() {
        // At eta = 1 the arc is half a cosine: e = 2 A / pi.
        let a = 0.1;
        let (e, g) = (
            2.0 * a / std::f64::consts::PI,
            0.5 * a * a + 2.0 * a / std::f64::consts::PI,
        );
        assert!((stress(e, g).unwrap() - 1.0).abs() < 1e-12);
        assert!(law(e, g, None).unwrap().speed > 1.0);
    }
}
