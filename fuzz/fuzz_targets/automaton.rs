//! Automaton files with arbitrary expressions: the input's lines are the
//! rates, the guard, the reset, the energy and an initial value of a
//! two-state, two-mode automaton. Each must be refused with an error or
//! compiled and run briefly (every method that applies), never a panic.
//! The default rate switches by `sign()` (dry friction), so that flows
//! with switching surfaces, their sliding and their refusals are fuzzed
//! from the first input on.
#![no_main]

use flicker::runner::Control;
use flicker::scene::Registry;
use libfuzzer_sys::fuzz_target;
use serde_json::json;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut parts = text.split('\n');
    let mut next = |default: &str| parts.next().unwrap_or(default).to_string();
    let (rate_x, rate_v, guard, reset, energy, initial) = (
        next("v"),
        next("-x - a * sign(v)"),
        next("x"),
        next("-v"),
        next("v^2 + x^2"),
        next("1"),
    );
    let scene = json!({
        "model": "automaton",
        "parameters": {"a": 0.5, "b": 2.0},
        "states": ["x", "v"],
        "initial": {"x": initial, "v": 0.0},
        "initial_mode": "one",
        "modes": {
            "one": {"flow": {"x": rate_x, "v": rate_v},
                    "transitions": [{"name": "g", "guard": guard, "direction": "falling",
                                     "barrier": true, "reset": {"v": reset}, "to": "two"}]},
            "two": {"flow": {"x": rate_v, "v": rate_x},
                    "transitions": [{"name": "h", "guard": guard, "to": "one", "priority": 1}]}},
        "energy": energy,
        "t_end": 2.0,
        "max_events": 10000
    });
    let Ok(scene) = Registry::builtin().from_value(&scene) else {
        return;
    };
    let control = Control {
        max_wall_seconds: Some(0.05),
        ..Control::default()
    };
    for method in scene.methods() {
        let mut run = scene.clone();
        let spec = flicker::scene::solver::SolverSpec {
            method: Some(method.to_string()),
            rtol: None,
            atol: None,
            step: (method == "verlet").then_some(0.01),
        };
        if run.set_solver(spec).is_ok() {
            let _ = run.run(&control, &mut ());
        }
    }
});
