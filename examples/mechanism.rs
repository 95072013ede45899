//! The paper's mechanism through the library, in both formulations: the
//! strain formulation with its exact flow and impacts, the angle formulation
//! integrated numerically across theta = 0, and the closed form they must
//! both reproduce.
//!
//! Run: `cargo run --release --example mechanism`

use flicker::engine::{Options, Recorder, simulate};
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{
    AngleMechanism, Charts, ExactOrbit, Mechanism, Phase, StrainMechanism,
};

fn main() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let (eps, rate) = m
        .state_with_energy(0.05, Phase::Apex)
        .expect("an admissible energy");
    let t_end = 100.0;

    let mut strain_log = Recorder::default();
    let strain = simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[eps, rate],
        &Options::until(t_end),
        &mut strain_log,
    );

    let angle_model = AngleMechanism {
        mechanism: m,
        charts: Charts::Switch,
    };
    let (mode, x0) = angle_model
        .start_from_strain(eps, rate)
        .expect("a state off theta = 0");
    let angle = simulate(&angle_model, mode, &x0, &Options::until(t_end), &mut ());
    let angle_strain = angle_model.strain(angle.final_mode, &angle.final_state);

    let exact = ExactOrbit::new(m, eps, rate);
    let (eps_exact, _) = exact.state_at(t_end);
    println!(
        "impacts up to t = {t_end}: strain {}, angle {}, closed form {}",
        strain.events,
        angle.events,
        exact.impacts_until(t_end)
    );
    println!(
        "final strain: strain {:.12}, angle {:.12}, closed form {eps_exact:.12}",
        strain.final_state[0], angle_strain.0
    );
    println!(
        "first impacts at t = {:?}",
        strain_log
            .events
            .iter()
            .take(3)
            .map(|e| e.t)
            .collect::<Vec<_>>()
    );
    println!(
        "period in closed form: {}",
        m.impact_period(m.energy(eps, rate))
    );
}
