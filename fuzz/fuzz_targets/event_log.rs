//! The event-log reader used by `flicker events` on arbitrary lines: an
//! error or an event, never a panic; events feed the summary.
#![no_main]

use flicker::log::inspect::{Filter, Summary};
use flicker::log::reader::parse_line;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut summary = Summary::default();
    let filter = Filter {
        guard: Some("impact".into()),
        from: Some(0.0),
        to: Some(1e300),
    };
    for line in text.lines() {
        if let Ok(event) = parse_line(line) {
            let _ = filter.keeps(&event);
            summary.add(&event);
        }
    }
    // `flicker events --summary` prints it as JSON.
    let _ = serde_json::to_string_pretty(&summary);
});
