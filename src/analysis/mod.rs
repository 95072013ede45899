//! The tools that answer what comes after a run, on any model: periodic
//! orbits, their continuation and the brute-force diagram drawn under it
//! ([`orbit`]), bifurcation diagrams of any parameter ([`diagram`]),
//! basins of attraction ([`basins`]),
//! Lyapunov spectra ([`lyapunov`]), sensitivities ([`sensitivities`]),
//! sweeps over parameters and initial values ([`sweep`]); and those that
//! measure methods and models against exact answers: the stress suite
//! ([`stress`]), the work-precision chart ([`work_precision`]) and a
//! release as chains and continua ([`release_convergence`]).

pub mod basins;
pub mod diagram;
pub mod lyapunov;
pub mod orbit;
pub mod release_convergence;
pub mod section_records;
pub mod sensitivities;
pub mod spacing;
pub mod started_at;
pub mod stress;
pub mod sweep;
pub mod work_precision;
