//! What a run of a model with extent in space (a chain, a continuum)
//! reports besides the engine's outcome: profiles along the string at the
//! snapshot times, the trace at the sample times, and the classical string
//! beside them. `flicker run` writes them as `profiles.json` and
//! `trace.csv` ([`crate::log::field_files`]).

/// What a run of a model with extent (a chain, a continuum) reports besides
/// the engine's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldOutputs {
    /// Total momentum `sum m v` at the end.
    pub momentum: f64,
    /// `|P - P_impulses| / max(|P|, |F - F_cr| t, m c)` at the end, with
    /// `P_impulses` the momentum the end load and the wall gave (exact path).
    pub momentum_balance_error: Option<f64>,
    /// `y_N` at the end.
    pub right_end: f64,
    /// The string at each of the scene's snapshot times.
    pub profiles: Vec<Profile>,
    /// One row per sample time, for `trace.csv`.
    pub trace: Vec<TraceRow>,
    /// The classical string (same scene, constraint off) at the same times,
    /// for the pictures; for constrained chains of up to
    /// [`CLASSICAL_MAX_UNITS`] units.
    pub classical: Option<Classical>,
}

/// The classical chain's profiles and trace.
#[derive(Debug, Clone, PartialEq)]
pub struct Classical {
    /// Its profiles at the snapshot times.
    pub profiles: Vec<Profile>,
    /// Its trace at the sample times.
    pub trace: Vec<TraceRow>,
}

/// Largest chain the classical companion is computed for: it costs about
/// as much as the impacting run's flow without its impacts.
pub const CLASSICAL_MAX_UNITS: usize = 2000;

/// The chain at one time: entry `n` is unit `n + 1` (its centre `x`, its
/// strain) and node `n + 1` (its displacement and velocity).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// The profile's time.
    pub t: f64,
    /// Position of each entry along the string: a unit's centre (a cell's,
    /// for a continuum).
    pub x: Vec<f64>,
    /// Strain at each entry.
    pub strain: Vec<f64>,
    /// Displacement `y` at each entry.
    pub displacement: Vec<f64>,
    /// Velocity at each entry.
    pub velocity: Vec<f64>,
}

/// One row of `trace.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceRow {
    /// The sample's time.
    pub t: f64,
    /// Total energy (NaN where the model gives none).
    pub energy: f64,
    /// Total momentum.
    pub momentum: f64,
    /// The loaded end's displacement, `y_N`.
    pub right_end: f64,
}
