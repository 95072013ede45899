//! The event log (`events.jsonl`) and the run summary (`summary.json`).
//!
//! # `events.jsonl`
//! JSON Lines: one object per event, in the order the events happened
//! (non-decreasing `t`), written while the run goes. Only whole lines reach
//! the file, so a log cut short by an interrupted run still parses line by
//! line. Each line holds:
//!
//! | key | meaning |
//! |---|---|
//! | `seq` | 1-based position of the event |
//! | `t` | time of the event |
//! | `guard` | the guard that fired (`impact`, ...; `settle` when a Zeno accumulation is handed to resting contact) |
//! | `mode_before`, `mode_after` | the automaton's mode on either side |
//! | `energy_before`, `energy_after` | the model's energy on either side (`null` if it has none) |
//! | `before`, `after` | the state on either side, as an object of named components (empty for a chain, whose state is too large) |
//! | `unit` | chains only: the unit that closed (1 = next to the wall); with `rel_velocity` 0 it came to rest shut (resting contact); a `release` line names the unit pulled open from rest |
//! | `rel_velocity` | chains: `y'_{n-1} - y'_n` just before the impact (`-y'_1` for unit 1), positive when closing; continua: the speed at which a shut stretch strikes the wall |
//! | `x` | continua only: where the event happened (the wall at `-length / 2`, the loaded end at `+length / 2`) |
//!
//! A chain or continuum run also writes `profiles.json` and `trace.csv` ([`field_files`]);
//! a run asked for samples, `samples.csv` ([`samples`]).
//! The same events held in memory as arrays: [`columns`].
//!
//! ```json
//! {"seq":1,"t":2.2142,"guard":"impact","mode_before":"flight","mode_after":"flight","energy_before":0.025,"energy_after":0.025,"before":{"strain":0.0,"strain_rate":-0.2236},"after":{"strain":0.0,"strain_rate":0.2236}}
//! ```
//!
//! # `summary.json`
//! Written once at the end (to a temporary file, then renamed), with at
//! least `status`, `reason`, `events`, `events_by_guard`, `t_end`,
//! `t_reached`, `energy_initial`, `energy_final`, `max_energy_error`,
//! `final_state`, `zeno`, `method` and `wall_seconds`; see [`summary`].

pub mod columns;
pub mod field_files;
pub mod inspect;
pub mod reader;
pub mod samples;
pub mod size_notice;
pub mod summary;
pub mod writer;

pub use writer::JsonlWriter;
