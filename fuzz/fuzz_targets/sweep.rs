//! The sweep file parser on arbitrary text: an error or a sweep, never a
//! panic; a valid sweep's first points are built.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(sweep) = flicker::analysis::sweep::parse_text(text, std::path::Path::new("/nonexistent"), &flicker::scene::Registry::builtin()) else {
        return;
    };
    for point in 0..sweep.points().min(4) {
        let _ = sweep
            .scene_at(point)
            .map(|v| flicker::models::from_value(&v));
    }
});
