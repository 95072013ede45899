//! A Lyapunov spectrum as `flicker lyapunov` (and Python's `lyapunov()`)
//! asks it, its unset settings following the scene, resolved and run.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::analysis::lyapunov::{self, Spectrum};
use crate::engine::Family;
use crate::scene::{Scene, SceneError};
use crate::session::Prepared;

/// A Lyapunov spectrum as asked (`flicker lyapunov`'s flags, the keywords
/// of Python's `lyapunov()`): what is not given follows the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumRequest {
    /// How many exponents; all of them (the state's dimension) if unset.
    pub exponents: Option<usize>,
    /// Time run first, for a transient to die out.
    pub transient: f64,
    /// Time averaged over; the scene's `t_end` if unset.
    pub t_end: Option<f64>,
    /// Time between re-orthonormalisations; a quarter of the scene's time
    /// scale (at most the span) if unset.
    pub interval: Option<f64>,
    /// Seconds of wall time for the whole spectrum.
    pub wall: f64,
}

impl SpectrumRequest {
    /// The spectrum's settings for `scene`'s `family`, checked before
    /// anything runs, stopped by `stop` where given; the error names the
    /// field it is about (`exponents`, `interval`, `wall`...).
    pub fn resolve(
        &self,
        scene: &Scene,
        family: &dyn Family,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<lyapunov::Request, SceneError> {
        let span = self.t_end.unwrap_or_else(|| scene.t_end());
        let request = lyapunov::Request {
            exponents: self.exponents.unwrap_or_else(|| family.model().dimension()),
            transient: self.transient,
            span,
            interval: self
                .interval
                .unwrap_or_else(|| (scene.time_scale() / 4.0).min(span)),
            stop,
            deadline: super::deadline(self.wall)?,
        };
        lyapunov::check(family, &request).map_err(|(field, why)| SceneError::field(field, why))?;
        Ok(request)
    }

    /// The spectrum asked of `scene`, ready to run: its model's family
    /// (refused in one line, field `model`, for a scene without a finite
    /// state) and the settings resolved against it.
    pub fn on(
        &self,
        scene: &Scene,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<Prepared<lyapunov::Request>, SceneError> {
        let family = scene.family()?;
        let request = self.resolve(scene, &*family, stop)?;
        Ok(Prepared {
            family,
            request,
            t_max: scene.t_end(),
        })
    }
}

impl Prepared<lyapunov::Request> {
    /// The spectrum (see [`crate::analysis::lyapunov::spectrum`]); `progress` hears
    /// of the time reached and the events so far.
    pub fn spectrum(&self, progress: &mut dyn FnMut(f64, u64)) -> Spectrum {
        lyapunov::spectrum(&*self.family, &self.request, progress)
    }
}
