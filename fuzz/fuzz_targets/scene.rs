//! The scene parser and validator on arbitrary text: an error or a scene,
//! never a panic. A valid scene is also checked with `flicker check`'s
//! closed form (energy, regime) and run briefly (chains up to 10^4 units).
#![no_main]

use flicker::runner::Control;
use flicker::models::{self as scene, ChainScene};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(mut scene) = scene::parse(text) else {
        return;
    };
    // Keep runs short: the fuzzer is after panics, not long simulations.
    if let Some(c) = scene.downcast_ref::<ChainScene>()
        && c.units > 10_000
    {
        return;
    }
    let t_end = scene.t_end().min(10.0);
    if scene.set_t_end(t_end).is_ok() {
        let control = Control {
            max_wall_seconds: Some(0.05),
            ..Control::default()
        };
        let _ = scene.run(&control, &mut ());
    }
});
