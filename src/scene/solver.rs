//! The `solver` key of a scene, and the command-line flags that override it.
//!
//! ```json
//! "solver": {"method": "dopri5", "rtol": 1e-9, "atol": 1e-9}
//! "solver": {"method": "dop853", "rtol": 1e-9, "atol": 1e-9}
//! "solver": {"method": "taylor", "rtol": 1e-15, "atol": 1e-15}
//! "solver": {"method": "verlet", "step": 0.01}
//! "solver": {"method": "linear"}
//! "solver": {"method": "exact"}
//! ```
//!
//! Without `method` (or without `solver`) a scene runs the cheapest exact
//! description its model offers; `rtol` and `atol` then set the tolerances
//! of the method it takes where a model has only an ODE. Each key belongs
//! to its methods: `step` to `verlet`, `rtol`/`atol` to `dopri5`, `dop853`
//! and `taylor` (default 1e-12 for the first two, machine epsilon for
//! `taylor`).

use serde_json::Value;

use crate::engine::{Method, Tolerances};
use crate::scene::SceneError;
use crate::scene::fields::Fields;

/// The solver as written, before it is checked against the model.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SolverSpec {
    /// `method`: one of [`NAMES`](crate::engine::step::method::NAMES); `None` for the model's cheapest exact
    /// description.
    pub method: Option<String>,
    /// `rtol`: relative tolerance, for `dopri5` and `dop853`.
    pub rtol: Option<f64>,
    /// `atol`: absolute tolerance, for `dopri5` and `dop853`.
    pub atol: Option<f64>,
    /// `step`: the fixed step, for `verlet`.
    pub step: Option<f64>,
}

impl SolverSpec {
    /// Read the `solver` object of a scene.
    pub fn from_json(value: &Value) -> Result<Self, SceneError> {
        let mut f = Fields::open(value, "solver")?;
        let spec = SolverSpec {
            method: f.optional_string("method")?.map(str::to_string),
            rtol: f.optional_number("rtol")?,
            atol: f.optional_number("atol")?,
            step: f.optional_number("step")?,
        };
        f.finish()?;
        Ok(spec)
    }

    /// This spec with the fields of `other` that are set taking precedence;
    /// a different method in `other` replaces this spec whole, since its
    /// keys belong to the old method.
    pub fn overridden_by(&self, other: &SolverSpec) -> SolverSpec {
        if other.method.is_some() && other.method != self.method {
            return other.clone();
        }
        SolverSpec {
            method: other.method.clone().or_else(|| self.method.clone()),
            rtol: other.rtol.or(self.rtol),
            atol: other.atol.or(self.atol),
            step: other.step.or(self.step),
        }
    }

    /// The method and tolerances this spec asks for ([`Method::parse`]),
    /// each number a finite number > 0.
    pub fn resolve(&self) -> Result<(Method, Tolerances), SceneError> {
        let positive = |key: &str, x: Option<f64>| match x {
            Some(x) if !(x.is_finite() && x > 0.0) => Err(SceneError::field(
                &format!("solver.{key}"),
                format!("must be a finite number > 0 (got {x})"),
            )),
            _ => Ok(x),
        };
        Method::parse(
            self.method.as_deref(),
            positive("rtol", self.rtol)?,
            positive("atol", self.atol)?,
            positive("step", self.step)?,
        )
        .map_err(|refused| SceneError::field(&format!("solver.{}", refused.key), refused.reason))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(method: Option<&str>, rtol: Option<f64>, step: Option<f64>) -> SolverSpec {
        SolverSpec {
            method: method.map(str::to_string),
            rtol,
            atol: None,
            step,
        }
    }

    #[test]
    fn resolves_each_method_with_its_own_keys() {
        assert_eq!(spec(None, None, None).resolve().unwrap().0, Method::Auto);
        let (m, _) = spec(Some("dopri5"), Some(1e-6), None).resolve().unwrap();
        assert_eq!(
            m,
            Method::Dopri5(Tolerances {
                rtol: 1e-6,
                atol: Tolerances::default().atol
            })
        );
        assert_eq!(
            spec(Some("verlet"), None, Some(0.1)).resolve().unwrap().0,
            Method::Verlet { step: 0.1 }
        );
        assert_eq!(
            spec(Some("linear"), None, None).resolve().unwrap().0,
            Method::Linear
        );
    }

    #[test]
    fn refuses_keys_that_belong_to_other_methods() {
        let message = |s: SolverSpec| s.resolve().unwrap_err().to_string();
        assert!(message(spec(Some("verlet"), Some(1e-6), Some(0.1))).contains("solver.rtol"));
        assert!(message(spec(Some("dopri5"), None, Some(0.1))).contains("solver.step"));
        assert!(message(spec(Some("verlet"), None, None)).contains("is required"));
        assert!(message(spec(Some("rk4"), None, None)).contains("unknown method"));
        assert!(message(spec(Some("dopri5"), Some(-1.0), None)).contains("> 0"));
    }

    #[test]
    fn later_fields_override_earlier_ones() {
        let scene = spec(Some("dopri5"), Some(1e-6), None);
        let flags = spec(None, Some(1e-9), None);
        assert_eq!(
            scene.overridden_by(&flags),
            spec(Some("dopri5"), Some(1e-9), None)
        );
        // Another method drops the old one's keys.
        let verlet = spec(Some("verlet"), None, Some(0.01));
        let flags = spec(Some("dopri5"), None, None);
        assert_eq!(verlet.overridden_by(&flags), flags);
        assert!(verlet.overridden_by(&flags).resolve().is_ok());
    }
}

/// Fixed steps a run may take: beyond this it would run for minutes.
const MAX_FIXED_STEPS: f64 = 1e9;

/// Refuse a fixed step that would need more than 10^9 steps to reach `t_end`.
pub fn check_steps(method: Method, t_end: f64) -> Result<(), SceneError> {
    match method {
        Method::Verlet { step } if t_end / step > MAX_FIXED_STEPS => Err(SceneError::field(
            "solver.step",
            format!(
                "{step:e} needs {:.1e} steps to reach t_end = {t_end}, more than 1e9; take a larger step",
                t_end / step
            ),
        )),
        _ => Ok(()),
    }
}
