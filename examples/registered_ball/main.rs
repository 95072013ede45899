//! A kind of scene from outside the crate, registered and run by every tool
//! of the command line: a ball bouncing on the floor.
//!
//! This file is the whole of it: the scene's keys, what it offers the tools
//! ([`SceneModel`]), and a `main` that is `flicker` with one more model;
//! the model (free flight, exact landing times, restitution `e`, settling
//! on the floor at its Zeno point) is `examples/bouncing_ball.rs`'s. Beside
//! it, `ball.json` (a scene) and `ball_sweep.json` (a sweep over
//! restitution and height).
//!
//! ```text
//! cargo run --release --example registered_ball -- check examples/registered_ball/ball.json
//! cargo run --release --example registered_ball -- run examples/registered_ball/ball.json
//! cargo run --release --example registered_ball -- sweep examples/registered_ball/ball_sweep.json
//! cargo run --release --example registered_ball -- schema
//! ```

use flicker::engine::Limits;
use flicker::engine::{Method, Name, Observer, Options, Tolerances, simulate};
use flicker::runner::Report;
use flicker::scene::fields::Fields;
use flicker::scene::solver::SolverSpec;
use flicker::scene::{Kind, Registry, Scene, SceneError, SceneModel};

// The ball itself is examples/bouncing_ball.rs's model; this file adds
// only what makes it a kind of scene.
#[path = "../bouncing_ball.rs"]
#[allow(dead_code)]
mod bouncing_ball;

use bouncing_ball::{BouncingBall, FLYING};

/// A ball scene: `{"model": "ball", "gravity": 9.81, "restitution": 0.8,
/// "height": 1.0, "t_end": 10.0}` (`gravity` optional, the ball dropped
/// from rest).
#[derive(Debug, Clone)]
pub struct BallScene {
    gravity: f64,
    restitution: f64,
    height: f64,
    t_end: f64,
    solver: SolverSpec,
}

fn validate(mut f: Fields) -> Result<Scene, SceneError> {
    let gravity = f.optional_number("gravity")?.unwrap_or(9.81);
    let gravity = f.check("gravity", gravity, "> 0", |g| g > 0.0)?;
    let restitution = f.number_where("restitution", "in [0, 1)", |e| (0.0..1.0).contains(&e))?;
    let height = f.number_where("height", "> 0", |h| h > 0.0)?;
    let t_end = f.number_where("t_end", "> 0", |t| t > 0.0)?;
    let mut scene = BallScene {
        gravity,
        restitution,
        height,
        t_end,
        solver: SolverSpec::default(),
    };
    if let Some(solver) = f.optional("solver") {
        scene.set_solver(SolverSpec::from_json(solver)?)?;
    }
    f.finish()?;
    Ok(Scene::new(scene))
}

impl SceneModel for BallScene {
    fn model(&self) -> &'static str {
        "ball"
    }
    fn t_end(&self) -> f64 {
        self.t_end
    }
    fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError> {
        self.t_end = t_end;
        Ok(())
    }
    fn solver(&self) -> &SolverSpec {
        &self.solver
    }
    fn set_solver(&mut self, spec: SolverSpec) -> Result<(), SceneError> {
        match spec.resolve()?.0 {
            Method::Auto | Method::Exact => Ok(self.solver = spec),
            other => Err(SceneError::field(
                "solver.method",
                format!("a ball flies exactly: not {}", other.name()),
            )),
        }
    }
    fn methods(&self) -> Vec<&'static str> {
        vec!["exact"]
    }
    /// The first fall's duration.
    fn time_scale(&self) -> f64 {
        (2.0 * self.height / self.gravity).sqrt()
    }
    fn describe(&self) -> Vec<String> {
        let first = self.time_scale();
        let zeno = first * (1.0 + self.restitution) / (1.0 - self.restitution);
        vec![
            format!("restitution {}, exact flight", self.restitution),
            format!(
                "dropped from {} under gravity {}, t_end {}",
                self.height, self.gravity, self.t_end
            ),
            format!("first bounce at t = {first:e}, bounces pile up at t = {zeno:e}"),
        ]
    }
    fn run(&self, limits: &Limits, observer: &mut dyn Observer) -> Result<Report, SceneError> {
        let ball = BouncingBall {
            gravity: self.gravity,
            restitution: self.restitution,
        };
        let options: Options =
            limits.options(self.t_end, 1_000_000, Method::Auto, Tolerances::default());
        let outcome = simulate(&ball, FLYING, &[self.height, 0.0], &options, observer);
        let final_state = vec![
            (Name::new("height"), outcome.final_state[0]),
            (Name::new("velocity"), outcome.final_state[1]),
        ];
        Ok(Report {
            outcome,
            method: Method::Exact,
            description: "free flight in closed form, exact landing times".into(),
            final_state,
            fields: None,
            sensitivities: None,
        })
    }
    fn clone_box(&self) -> Box<dyn SceneModel> {
        Box::new(self.clone())
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The JSON Schema of a ball scene (`flicker schema` includes it).
const SCHEMA: &str = r##"{
 "type": "object",
 "required": ["model", "restitution", "height", "t_end"],
 "additionalProperties": false,
 "description": "A ball dropped from rest, bouncing with restitution e.",
 "properties": {
  "model": {"const": "ball"},
  "gravity": {"$ref": "#/$defs/positive"},
  "restitution": {"type": "number", "minimum": 0, "exclusiveMaximum": 1},
  "height": {"$ref": "#/$defs/positive"},
  "t_end": {"$ref": "#/$defs/positive"},
  "solver": {"type": "object"}
 }
}"##;

/// The scene models `flicker` ships, and the ball.
pub fn registry() -> Registry {
    Registry::builtin().with(Kind {
        model: "ball",
        validate,
        schema: SCHEMA,
    })
}

#[cfg_attr(test, allow(dead_code))]
fn main() {
    std::process::exit(flicker::cli::main(registry()));
}
