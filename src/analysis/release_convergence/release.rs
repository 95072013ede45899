//! The release a chain or continuum scene describes, as the continuum
//! scene the comparison runs every model from: a chain's string without
//! its units, or a continuum scene itself, on the comparison's cells.

use crate::analysis::release_convergence::DEFAULT_CELLS;
use crate::models::chain::scene::ChainScene;
use crate::models::continuum::scene::ContinuumScene;
use crate::models::continuum::{Piece, Variant};
use crate::scene::{Scene, SceneError};

/// What a chain or continuum scene says of the release it describes.
#[derive(Debug, Clone)]
pub struct Release {
    /// The release as a continuum scene (a chain's string without its
    /// units), its homogenized string on [`DEFAULT_CELLS`].
    pub string: ContinuumScene,
    /// The chain's units, for a chain scene.
    pub units: Option<usize>,
    /// Whether the string starts uniform and at rest.
    pub uniform: bool,
}

/// The release `scene` describes, if it is a chain or a continuum scene.
pub fn described(scene: &Scene) -> Option<Release> {
    if let Some(chain) = scene.downcast_ref::<ChainScene>() {
        return Some(of_chain(chain));
    }
    scene
        .downcast_ref::<ContinuumScene>()
        .map(|string| Release {
            string: ContinuumScene {
                resolution: DEFAULT_CELLS,
                ..string.clone()
            },
            units: None,
            uniform: string.cells.len() == 1,
        })
}

/// The string without its units, at the strain every unit starts at.
fn of_chain(chain: &ChainScene) -> Release {
    let rest = chain.load_before - 1.0;
    let uniform =
        chain.strain.iter().all(|e| *e == rest) && chain.velocity.iter().all(|v| *v == 0.0);
    let string = ContinuumScene {
        variant: Variant::Paper,
        length: chain.length,
        wave_speed: chain.wave_speed,
        load_before: chain.load_before,
        load_after: chain.load_after,
        constraint: chain.constraint,
        t_end: chain.t_end,
        snapshots: chain.snapshots.clone(),
        samples: chain.samples,
        resolution: DEFAULT_CELLS,
        cells: vec![Piece {
            strain: rest,
            velocity: 0.0,
        }],
        max_events: chain.max_events,
        description: None,
    };
    Release {
        string,
        units: Some(chain.units),
        uniform,
    }
}

/// The release a scene describes, as a continuum scene. Scenes with an
/// `initial` profile are refused: the models would not start alike.
pub fn release(scene: &Scene) -> Result<Release, SceneError> {
    let release = described(scene).ok_or_else(|| {
        SceneError::field(
            "model",
            "compares a chain with its continuum: give a chain or continuum scene".into(),
        )
    })?;
    if !release.uniform || release.string.cells[0].velocity != 0.0 {
        return Err(SceneError::field(
            "initial",
            "the models are compared from the release of a uniform string at rest; leave `initial` out".into(),
        ));
    }
    Ok(release)
}
