//! Running a chain scene: the exact event-local flow by default, or the
//! chain as an ODE under a numerical method (the independent path), with
//! profiles at the snapshot times and the trace at the sample times.

use crate::engine::Limits;
use crate::engine::{
    HybridModel, LocalModel, Method, Name, Observer, Options, Outcome, Sample, Status,
    simulate_local, simulate_sampled,
};
use crate::models::chain::scene::ChainScene;
use crate::models::chain::{Chain, TaylorChain};
use crate::runner::{CLASSICAL_MAX_UNITS, Classical, FieldOutputs, Profile, Report, TraceRow};
use crate::scene::SceneError;
use crate::time::Time;

/// The chain's state at one time, in gaps and velocities.
struct State {
    gaps: Vec<f64>,
    velocities: Vec<f64>,
}

/// The profiles and trace rows that fall due as the run passes time `t`.
struct Sampler<'s> {
    scene: &'s ChainScene,
    chain: &'s Chain,
    snapshots: std::iter::Peekable<std::slice::Iter<'s, f64>>,
    samples: std::iter::Peekable<std::vec::IntoIter<f64>>,
    profiles: Vec<Profile>,
    trace: Vec<TraceRow>,
}

impl<'s> Sampler<'s> {
    fn new(scene: &'s ChainScene, chain: &'s Chain) -> Self {
        Sampler {
            scene,
            chain,
            snapshots: scene.snapshots.iter().peekable(),
            samples: scene.sample_times().into_iter().peekable(),
            profiles: Vec::new(),
            trace: Vec::new(),
        }
    }

    /// Record what is due at `t` from the exact flow.
    fn sample(&mut self, model: &TaylorChain, t: f64) {
        self.at(t, || {
            let at = Time::new(t);
            let (gaps, velocities) = model.state_at(at);
            (State { gaps, velocities }, model.energy(at))
        })
    }

    /// Record what is due at `t`, given the state and energy there.
    fn at(&mut self, t: f64, state: impl FnOnce() -> (State, Option<f64>)) {
        let snapshot = self.snapshots.next_if(|&&s| s <= t).is_some();
        let sample = self.samples.next_if(|&s| s <= t).is_some();
        if !(snapshot || sample) {
            return;
        }
        let (state, energy) = state();
        let c = self.chain;
        let momentum = c.mass * state.velocities.iter().sum::<f64>();
        let displacement: Vec<f64> = state
            .gaps
            .iter()
            .scan(0.0, |y, d| {
                *y += d;
                Some(*y)
            })
            .collect();
        let right_end = displacement.last().copied().unwrap_or(0.0);
        if sample {
            self.trace.push(TraceRow {
                t,
                energy: energy.unwrap_or(f64::NAN),
                momentum,
                right_end,
            });
        }
        if snapshot {
            let n = c.units as f64;
            let cell = self.scene.length / n;
            // Unit length 2l = F_cr / k: strain = Delta / 2l.
            let unit_length = c.unit_length();
            self.profiles.push(Profile {
                t,
                x: (0..c.units)
                    .map(|i| -0.5 * self.scene.length + (i as f64 + 0.5) * cell)
                    .collect(),
                strain: state.gaps.iter().map(|d| d / unit_length).collect(),
                displacement,
                velocity: state.velocities,
            });
        }
    }
}

pub(crate) fn run(
    scene: &ChainScene,
    limits: &Limits,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let chain = scene.chain(scene.constraint);
    let options = limits.options(
        scene.t_end,
        scene.max_events,
        scene.method,
        scene.tolerances,
    );
    let unit_length = chain.unit_length();
    let gaps: Vec<f64> = scene.strain.iter().map(|e| e * unit_length).collect();
    let mut report = match scene.method {
        Method::Auto | Method::Exact => run_exact(scene, &chain, &gaps, &options, observer)?,
        numerical => run_ode(scene, &chain, &gaps, &options, numerical, observer)?,
    };
    if scene.constraint
        && scene.units <= CLASSICAL_MAX_UNITS
        && report.outcome.status == Status::Completed
    {
        let classical = scene.chain(false);
        let mut model = TaylorChain::new(classical.clone(), &gaps, &scene.velocity)
            .map_err(|why| SceneError::field("initial", why))?;
        let mut sampler = Sampler::new(scene, &classical);
        let times = scene.due_times();
        let companion = simulate_local(
            &mut model,
            &options,
            &times,
            &mut |m: &TaylorChain, t| sampler.sample(m, t),
            &mut (),
        );
        // A companion cut short (interrupted) is left out, not shown half.
        if let Some(outputs) = report.fields.as_mut()
            && companion.status == Status::Completed
        {
            outputs.classical = Some(Classical {
                profiles: sampler.profiles,
                trace: sampler.trace,
            });
        }
    }
    Ok(report)
}

fn run_exact(
    scene: &ChainScene,
    chain: &Chain,
    gaps: &[f64],
    options: &Options,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let mut model = TaylorChain::new(chain.clone(), gaps, &scene.velocity)
        .map_err(|why| SceneError::field("initial", why))?;
    let (order, reach) = model.order_and_reach();
    let mut sampler = Sampler::new(scene, chain);
    let times = scene.due_times();
    let outcome = simulate_local(
        &mut model,
        options,
        &times,
        &mut |m: &TaylorChain, t| sampler.sample(m, t),
        observer,
    );
    let end = Time::new(outcome.t_reached);
    let momentum = model.momentum(end);
    let expected = model.momentum_by_impulses(end);
    let scale = momentum
        .abs()
        .max(((chain.load - chain.critical_load) * end.value()).abs())
        .max(chain.mass * scene.wave_speed);
    let right_end = model.right_end(end);
    let description = format!(
        "chain of {} units: exact event-local flow (Taylor series of order {order} in windows of omega t = {}; \
         each impact re-expands the {} units within its certified reach), impacts as the first roots of the series",
        scene.units,
        crate::models::chain::event_local::WINDOW,
        2 * reach + 1
    );
    Ok(report(
        outcome,
        Method::Exact,
        description,
        FieldOutputs {
            momentum,
            momentum_balance_error: Some((momentum - expected).abs() / scale),
            right_end,
            profiles: sampler.profiles,
            trace: sampler.trace,
            classical: None,
        },
    ))
}

/// The chain as an ODE, sampled for the profiles and the trace as it runs.
fn run_ode(
    scene: &ChainScene,
    chain: &Chain,
    gaps: &[f64],
    options: &Options,
    method: Method,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let n = chain.units;
    let x: Vec<f64> = gaps
        .iter()
        .scan(0.0, |y, d| {
            *y += d;
            Some(*y)
        })
        .chain(scene.velocity.iter().copied())
        .collect();
    let mut sampler = Sampler::new(scene, chain);
    let times = scene.due_times();
    let outcome = simulate_sampled(
        chain,
        0,
        &x,
        options,
        &times,
        &mut |sample: &Sample| {
            let (ys, vs) = sample.state.split_at(n);
            sampler.at(sample.t, || {
                let gaps = (0..n)
                    .map(|i| ys[i] - if i > 0 { ys[i - 1] } else { 0.0 })
                    .collect();
                let state = State {
                    gaps,
                    velocities: vs.to_vec(),
                };
                (state, chain.energy(0, sample.state))
            })
        },
        observer,
    );
    let (momentum, right_end) = (
        chain.momentum(&outcome.final_state),
        outcome.final_state[n - 1],
    );
    let description =
        format!("chain of {n} units as a linear ODE in positions and velocities, by {method}");
    Ok(report(
        outcome,
        method,
        description,
        FieldOutputs {
            momentum,
            momentum_balance_error: None,
            right_end,
            profiles: sampler.profiles,
            trace: sampler.trace,
            classical: None,
        },
    ))
}

fn report(outcome: Outcome, method: Method, description: String, fields: FieldOutputs) -> Report {
    Report {
        outcome,
        method,
        description,
        final_state: vec![
            (Name::new("momentum"), fields.momentum),
            (Name::new("right_end"), fields.right_end),
        ],
        fields: Some(fields),
        sensitivities: None,
    }
}
