//! flicker's integration tests: one binary, one module per behaviour.

mod bouncing_ball;
mod chain;
mod chain_cli;
mod chain_exact;
mod chain_invariants;
mod cli;
mod compare;
mod compare_models;
mod continuum;
mod convergence;
mod engine_generic;
mod event_location;
mod fuzz_regressions;
mod homogenized;
mod invariants;
mod mechanism_angle;
mod mechanism_strain;
mod oscillator;
mod phase;
mod reproducible;
mod scenes;
mod schemas;
mod stress;
mod support;
mod sweep;
mod thermostat;
