//! Each integrator shows its order on a smooth problem (a loose orbit of the
//! mechanism, no events): Stormer-Verlet's error falls as h^2, Dormand-Prince's
//! as (work)^-5, DOP853's as (work)^-8, and the linear propagator is exact
//! to round-off.

use flicker::engine::{Method, Options, Tolerances, simulate};
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{Mechanism, Phase, StrainMechanism};

const T_END: f64 = 20.0;

/// Final-state error against the closed form, and the flow evaluations spent.
fn error_and_cost(method: Method) -> (f64, f64) {
    let m = Mechanism {
        eta: 1.5,
        omega: 1.0,
    };
    let x0 = m.state_with_energy(-0.1, Phase::Apex).unwrap();
    let mut options = Options::until(T_END);
    options.method = method;
    let o = simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[x0.0, x0.1],
        &options,
        &mut (),
    );
    assert_eq!(o.events, 0, "the loose orbit must not impact");
    let (eps, rate) = m.flow(x0.0, x0.1, T_END);
    let error = (o.final_state[0] - eps)
        .abs()
        .max((o.final_state[1] - rate).abs());
    (error, o.flow_evaluations as f64)
}

/// Least-squares slope of `log y` against `log x`.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let cov: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let var: f64 = lx.iter().map(|x| (x - mx).powi(2)).sum();
    cov / var
}

#[test]
fn stormer_verlet_is_second_order() {
    let points: Vec<(f64, f64)> = [0.1, 0.05, 0.025, 0.0125, 0.00625]
        .iter()
        .map(|&h| (h, error_and_cost(Method::Verlet { step: h }).0))
        .collect();
    let order = slope(&points);
    println!("Stormer-Verlet measured order {order:.3}");
    assert!(
        (order - 2.0).abs() < 0.3,
        "measured order {order}: {points:?}"
    );
}

/// The order an adaptive pair shows: the slope of error against flow
/// evaluations over `tolerances` (rtol = atol), log-log.
fn adaptive_order(pair: fn(Tolerances) -> Method, tolerances: [f64; 5]) -> f64 {
    let points: Vec<(f64, f64)> = tolerances
        .iter()
        .map(|&tol| {
            let (error, cost) = error_and_cost(pair(Tolerances {
                rtol: tol,
                atol: tol,
            }));
            (cost, error)
        })
        .collect();
    let order = -slope(&points);
    println!(
        "{}: measured order {order:.3}: {points:?}",
        pair(Tolerances::default()).name()
    );
    order
}

#[test]
fn dormand_prince_is_fifth_order() {
    let order = adaptive_order(Method::Dopri5, [1e-6, 1e-7, 1e-8, 1e-9, 1e-10]);
    assert!((order - 5.0).abs() < 0.3, "measured order {order}");
}

#[test]
fn dop853_is_eighth_order() {
    // Tighter: at looser tolerances its few long steps are not yet in the
    // asymptotic regime.
    let order = adaptive_order(Method::Dop853, [1e-8, 1e-9, 1e-10, 1e-11, 1e-12]);
    assert!((order - 8.0).abs() < 0.3, "measured order {order}");
}

#[test]
fn the_linear_propagator_is_exact_to_round_off() {
    let (error, _) = error_and_cost(Method::Linear);
    assert!(error < 1e-13, "error {error}");
}
