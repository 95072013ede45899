//! The method policy, in one place: the methods' names, how a name and its
//! keys become a [`Method`], how each describes itself in a summary, what a
//! run takes when it names none ([`cheapest`]), and what a tool runs a
//! model by ([`tightest`]).
//!
//! Whether a method can run a given mode, and how that mode then moves,
//! is the integrator's rule ([`motion`](crate::engine::step::integrator::motion)).

use crate::engine::model::{Flow, HybridModel};
use crate::engine::step::adaptive::Tolerances;
use crate::engine::step::taylor_method;

/// How to advance the flows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// The cheapest exact description each mode offers: its closed form
    /// where it has one, Dormand-Prince otherwise. A scene resolves it
    /// further (see [`cheapest`]).
    Auto,
    /// The model's closed forms only; a mode without one fails.
    Exact,
    /// The exact propagator of linear flows.
    Linear,
    /// Dormand-Prince 5(4) with these tolerances.
    Dopri5(Tolerances),
    /// Dormand and Prince's 8th-order pair DOP853 with these tolerances.
    Dop853(Tolerances),
    /// Taylor's method with these tolerances (order and step from them).
    Taylor(Tolerances),
    /// Stormer-Verlet with this fixed step.
    Verlet {
        /// The fixed step.
        step: f64,
    },
    /// Finite volumes: the homogenized continuum's own solver, which no
    /// other model runs by (the engine's integrators refuse it).
    FiniteVolume,
}

/// The method names a scene's `solver.method` or `--method` may give.
pub const NAMES: [&str; 6] = ["exact", "linear", "taylor", "dopri5", "dop853", "verlet"];

/// What a method named in [`NAMES`] is set by besides its name: the keys
/// [`Method::parse`] takes for it, the settings `flicker compare` sweeps
/// and the stress suite fixes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// Nothing: the closed form, the linear propagator.
    None,
    /// `rtol` and `atol`: the adaptive methods.
    Tolerances,
    /// `step`: the fixed-step method.
    Step,
}

/// How the method `name` is set, or `None` for a name not in [`NAMES`].
pub fn setting(name: &str) -> Option<Setting> {
    match name {
        "exact" | "linear" => Some(Setting::None),
        "taylor" | "dopri5" | "dop853" => Some(Setting::Tolerances),
        "verlet" => Some(Setting::Step),
        _ => None,
    }
}

/// A method named with a key that does not belong to it, or without one it
/// needs: the key (`method`, `rtol`, `atol` or `step`) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Refused {
    /// The offending key.
    pub key: &'static str,
    /// Why.
    pub reason: String,
}

impl Method {
    /// The name used in summaries, `compare.csv` and `solver.method`
    /// (`auto` for the unresolved default, `finite_volume` for the
    /// homogenized continuum).
    pub fn name(&self) -> &'static str {
        match self {
            Method::Auto => "auto",
            Method::Exact => "exact",
            Method::Linear => "linear",
            Method::Dopri5(_) => "dopri5",
            Method::Dop853(_) => "dop853",
            Method::Taylor(_) => "taylor",
            Method::Verlet { .. } => "verlet",
            Method::FiniteVolume => "finite_volume",
        }
    }

    /// The method `name` (one of [`NAMES`], or `None` for [`Method::Auto`])
    /// with its keys: `rtol` and `atol` for the adaptive methods (default
    /// 1e-12; machine epsilon for Taylor's), `step` for Verlet (required).
    /// The tolerances are returned too: they also set those of the method
    /// `Auto` takes where a model has only an ODE.
    pub fn parse(
        name: Option<&str>,
        rtol: Option<f64>,
        atol: Option<f64>,
        step: Option<f64>,
    ) -> Result<(Method, Tolerances), Refused> {
        let default = Tolerances::default();
        let tolerances = Tolerances {
            rtol: rtol.unwrap_or(default.rtol),
            atol: atol.unwrap_or(default.atol),
        };
        let not_for = |key: &'static str, method: &str| Refused {
            key,
            reason: format!("does not apply to method {method:?}"),
        };
        let Some(name) = name else {
            return match step {
                Some(_) => Err(not_for("step", "auto")),
                None => Ok((Method::Auto, tolerances)),
            };
        };
        let refused = match setting(name) {
            None => {
                return Err(Refused {
                    key: "method",
                    reason: format!("unknown method {name:?} (known: {})", NAMES.join(", ")),
                });
            }
            Some(Setting::Tolerances) => step.map(|_| "step"),
            Some(Setting::Step) => rtol.map(|_| "rtol").or(atol.map(|_| "atol")),
            Some(Setting::None) => rtol
                .map(|_| "rtol")
                .or(atol.map(|_| "atol"))
                .or(step.map(|_| "step")),
        };
        if let Some(key) = refused {
            return Err(not_for(key, name));
        }
        let method = match name {
            "dopri5" => Method::Dopri5(tolerances),
            "dop853" => Method::Dop853(tolerances),
            "taylor" => Method::Taylor(Tolerances {
                rtol: rtol.unwrap_or(taylor_method::DEFAULT_TOLERANCE),
                atol: atol.unwrap_or(taylor_method::DEFAULT_TOLERANCE),
            }),
            "verlet" => Method::Verlet {
                step: step.ok_or_else(|| Refused {
                    key: "step",
                    reason: "is required by method \"verlet\"".into(),
                })?,
            },
            "linear" => Method::Linear,
            // "exact": the last name `setting` knows.
            _ => Method::Exact,
        };
        Ok((method, tolerances))
    }

    /// What the method is, for a summary's `method_description` (a model
    /// says what its own closed form is: `Exact` and `Auto` are its words).
    pub fn describe(&self) -> String {
        match self {
            Method::Auto => "the cheapest exact description of each mode".into(),
            Method::Exact => "closed form".into(),
            Method::Linear => "exact linear propagator, events located on it".into(),
            Method::Dopri5(t) => {
                format!("Dormand-Prince 5(4), rtol {:e}, atol {:e}", t.rtol, t.atol)
            }
            Method::Dop853(t) => format!(
                "DOP853 (Dormand-Prince 8(5,3)), rtol {:e}, atol {:e}",
                t.rtol, t.atol
            ),
            Method::Taylor(t) => format!(
                "Taylor's method of order {}, rtol {:e}, atol {:e}, events on each guard's series",
                taylor_method::order_for(*t),
                t.rtol,
                t.atol
            ),
            Method::Verlet { step } => format!("Stormer-Verlet, step {step:e}"),
            Method::FiniteVolume => "finite volumes".into(),
        }
    }
}

impl std::fmt::Display for Method {
    /// Its [`Method::name`].
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a scene of `model`'s modes `0..modes` runs by when it names no
/// method, and why, in the order "model no more than a scene needs": the
/// closed form where every mode has one (or is frozen); [`Method::Auto`]
/// where only some have (their closed forms, Dormand-Prince elsewhere, as
/// the engine runs `Auto`); the exact linear propagator where every flow
/// is affine; Taylor's method (at `taylor`) where every mode gives its
/// series; Dormand-Prince 5(4) (at `tolerances`) otherwise.
pub fn cheapest<M: HybridModel + ?Sized>(
    model: &M,
    modes: usize,
    tolerances: Tolerances,
    taylor: Tolerances,
) -> (Method, &'static str) {
    let all = |ok: &dyn Fn(usize) -> bool| (0..modes).all(ok);
    if all(&|m| matches!(model.flow(m), Flow::Frozen | Flow::Exact)) {
        (Method::Exact, "every mode has a closed form")
    } else if !all(&|m| model.flow(m) != Flow::Exact) {
        (Method::Auto, "some modes have a closed form")
    } else if all(&|m| model.flow(m) == Flow::Frozen || model.has_affine_flow(m)) {
        (Method::Linear, "every mode's flow is affine")
    } else if all(&|m| model.flow(m) == Flow::Frozen || model.has_series(m)) {
        (Method::Taylor(taylor), "a mode's flow is not affine")
    } else {
        (
            Method::Dopri5(tolerances),
            "a mode's flow is not affine and has no Taylor series",
        )
    }
}

/// The tightest method a tool can run `model`'s modes `0..modes` by
/// without Taylor series (which derivatives carried as states do not
/// have): the closed form where every mode has one (or is frozen), the
/// exact linear propagator where every mode is linear (or frozen), DOP853
/// at `tolerance` otherwise. What orbits, sensitivities and Lyapunov
/// spectra run by.
pub fn tightest<M: HybridModel + ?Sized>(model: &M, modes: usize, tolerance: f64) -> Method {
    let tolerances = Tolerances {
        rtol: tolerance,
        atol: tolerance,
    };
    match cheapest(model, modes, tolerances, tolerances).0 {
        // Every mode exact: its closed forms, under the engine's own name.
        Method::Exact => Method::Auto,
        Method::Linear => Method::Linear,
        _ => Method::Dop853(tolerances),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::model::names::Name;
    use crate::engine::model::{Guard, Jump, Mode};
    use crate::names;

    /// A model whose modes are of the kinds given: `e` exact, `l` linear,
    /// `s` an ODE with Taylor series, `o` an ODE without.
    struct Kinds(&'static str);

    impl HybridModel for Kinds {
        fn dimension(&self) -> usize {
            1
        }
        fn state_names(&self, _: Mode) -> &[Name] {
            names!["x"]
        }
        fn mode_name(&self, _: Mode) -> &str {
            "m"
        }
        fn guards(&self, _: Mode) -> &[Guard] {
            &[]
        }
        fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
            x[0]
        }
        fn flow(&self, mode: Mode) -> Flow {
            if self.0.as_bytes()[mode] == b'e' {
                Flow::Exact
            } else {
                Flow::Ode
            }
        }
        fn is_linear(&self, mode: Mode) -> bool {
            self.0.as_bytes()[mode] == b'l'
        }
        fn has_series(&self, mode: Mode) -> bool {
            matches!(self.0.as_bytes()[mode], b'l' | b's')
        }
        fn reset(&self, mode: Mode, _: usize, _: &mut [f64]) -> Jump {
            Jump::to(mode)
        }
    }

    #[test]
    fn a_scene_that_names_no_method_runs_the_cheapest_exact_description() {
        let (tol, taylor) = (
            Tolerances::default(),
            Tolerances {
                rtol: 1e-15,
                atol: 1e-15,
            },
        );
        let pick = |kinds: &'static str| cheapest(&Kinds(kinds), kinds.len(), tol, taylor).0;
        assert_eq!(pick("ee"), Method::Exact);
        assert_eq!(pick("el"), Method::Auto);
        assert_eq!(pick("ll"), Method::Linear);
        assert_eq!(pick("ls"), Method::Taylor(taylor));
        assert_eq!(pick("lo"), Method::Dopri5(tol));
    }

    #[test]
    fn names_parse_to_their_methods_and_back() {
        for name in NAMES {
            let step = (name == "verlet").then_some(0.1);
            let (method, _) = Method::parse(Some(name), None, None, step).unwrap();
            assert_eq!(method.name(), name);
        }
        assert_eq!(
            Method::parse(None, None, None, None).unwrap().0,
            Method::Auto
        );
        let refused = Method::parse(Some("rk4"), None, None, None).unwrap_err();
        assert_eq!(refused.key, "method");
    }

    #[test]
    fn each_name_takes_exactly_the_keys_of_its_setting() {
        assert_eq!(setting("rk4"), None);
        for name in NAMES {
            let allowed: &[&str] = match setting(name).unwrap() {
                Setting::None => &[],
                Setting::Tolerances => &["rtol", "atol"],
                Setting::Step => &["step"],
            };
            // Every subset of the three keys, given or not.
            for given in 0..8 {
                let has = |bit: usize| given & (1 << bit) != 0;
                let keys = [("rtol", has(0)), ("atol", has(1)), ("step", has(2))];
                let value = |bit: usize| has(bit).then_some(0.1);
                let parsed = Method::parse(Some(name), value(0), value(1), value(2));
                let stray = keys.iter().find(|(k, on)| *on && !allowed.contains(k));
                let missing = allowed == ["step"] && !has(2);
                match (stray, parsed) {
                    (Some((key, _)), Err(refused)) => assert_eq!(refused.key, *key, "{name}"),
                    (None, Err(refused)) => assert!(missing && refused.key == "step", "{name}"),
                    (None, Ok((method, _))) => assert_eq!(method.name(), name),
                    (Some(_), Ok(_)) => panic!("{name} took a key of another method: {keys:?}"),
                }
            }
        }
    }
}
