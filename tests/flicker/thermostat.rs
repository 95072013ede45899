//! The from-scratch example (examples/thermostat.rs): an ODE flow with mode
//! switches, its cycle against the closed form of exponential relaxation.

#[allow(dead_code)]
#[path = "../../examples/thermostat.rs"]
mod example;

#[test]
fn the_heater_cycles_with_the_closed_form_period() {
    let times = example::switches(100.0);
    let period = example::period();
    assert_eq!(
        times.len() as f64,
        (100.0f64 / period * 2.0).floor(),
        "{times:?}"
    );
    for pair in times.windows(3) {
        assert!(
            (pair[2] - pair[0] - period).abs() < 1e-8,
            "cycle {} vs {period}",
            pair[2] - pair[0]
        );
    }
}
