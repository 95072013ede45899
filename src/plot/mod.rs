//! Pictures: phase portraits of the mechanism ([`phase`]), any two states
//! of a run against each other ([`plane`]), a chain's or a continuum's
//! fields ([`fields`]), drawn
//! with a bundled font ([`draw`]), so a machine without system fonts draws
//! text.

pub mod draw;
pub mod fields;
pub mod phase;
pub mod plane;

use std::sync::Once;

use plotters::style::{FontStyle, register_font};

/// Register the bundled DejaVu Sans as the `sans-serif` family, once.
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font shipped by the dejavu crate.
        let _ = register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}
