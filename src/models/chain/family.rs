//! A chain as the tools see it ([`Family`]): the chain as a linear
//! second-order ODE in positions and velocities ([`super::ode`]), which
//! carries its derivatives exactly (a linear flow stays linear with
//! them), started where the scene starts, with the parameters `load` (the
//! end load over `F_cr` after the release) and `wave_speed`.
//!
//! The exact event-local flow has no state a tool can differentiate; the
//! ODE is the same chain, and for the sizes a tool's dense derivatives
//! make sense at (tens of units), as fast.

use crate::engine::model::with_parameters::{WithParameters, positions};
use crate::engine::{Family, HybridModel, Mode, Promoted};
use crate::models::chain::Chain;
use crate::models::chain::scene::ChainScene;

const PARAMETERS: [&str; 2] = ["load", "wave_speed"];

/// A chain scene's ODE and start.
#[derive(Debug, Clone)]
pub struct ChainFamily {
    chain: Chain,
    length: f64,
    wave_speed: f64,
    load: f64,
    start: Vec<f64>,
    names: Vec<String>,
}

impl ChainFamily {
    /// The family of `scene`.
    pub fn new(scene: &ChainScene) -> Self {
        let chain = scene.chain(scene.constraint);
        let unit_length = chain.unit_length();
        let positions = scene.strain.iter().scan(0.0, |y, e| {
            *y += e * unit_length;
            Some(*y)
        });
        let start = positions.chain(scene.velocity.iter().copied()).collect();
        let names = (1..=scene.units)
            .map(|n| format!("y_{n}"))
            .chain((1..=scene.units).map(|n| format!("v_{n}")))
            .collect();
        ChainFamily {
            chain,
            length: scene.length,
            wave_speed: scene.wave_speed,
            load: scene.load_after,
            start,
            names,
        }
    }

    /// The chain with the parameters `which` (indices into `PARAMETERS`)
    /// at `values`.
    fn at(&self, which: &[usize], values: &[f64]) -> Chain {
        let (mut load, mut wave_speed) = (self.load, self.wave_speed);
        for (&k, &v) in which.iter().zip(values) {
            if k == 0 { load = v } else { wave_speed = v }
        }
        Chain::in_scene_units(
            self.chain.units,
            self.length,
            wave_speed,
            load,
            self.chain.constraint,
        )
    }
}

impl Family for ChainFamily {
    fn model(&self) -> &(dyn HybridModel + Sync) {
        &self.chain
    }

    fn modes(&self) -> usize {
        1
    }

    fn start(&self) -> (Mode, Vec<f64>) {
        (0, self.start.clone())
    }

    fn state_names(&self) -> Vec<String> {
        self.names.clone()
    }

    fn parameters(&self) -> Vec<String> {
        PARAMETERS.iter().map(|p| p.to_string()).collect()
    }

    fn promoted(&self, names: &[String]) -> Result<Promoted, String> {
        let which = positions(names, &PARAMETERS)?;
        let values: Vec<f64> = which
            .iter()
            .map(|&k| if k == 0 { self.load } else { self.wave_speed })
            .collect();
        // The start is given in strains, which the unit length (F_cr / k =
        // L / N) turns into positions whatever the parameters: it does not
        // move with them.
        let n = self.start.len();
        let slopes = (0..which.len())
            .map(|j| {
                let mut s = vec![0.0; n + which.len()];
                s[n + j] = 1.0;
                s
            })
            .collect();
        let mut start = self.start.clone();
        start.extend_from_slice(&values);
        let family = self.clone();
        let build_which = which.clone();
        let model = WithParameters::new(self.chain.clone(), 1, names, move |p: &[f64]| {
            family.at(&build_which, p)
        });
        Ok(Promoted {
            model: Box::new(model),
            mode: 0,
            start,
            parameters: (n..n + which.len()).collect(),
            slopes,
        })
    }
}
