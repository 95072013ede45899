//! Exit codes, in one place: what each means, and which a run's status
//! or a tool's stop gives.

use crate::session::{SceneError, Status};

/// What the process tells its caller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Code {
    /// Completed, or a Zeno accumulation recognised and handled.
    Ok = 0,
    /// Bad input: a scene, a flag or a log that cannot be used.
    BadInput = 2,
    /// The run cannot be trusted: a method failed.
    Untrusted = 3,
    /// Stopped by a signal.
    Interrupted = 130,
}

impl Code {
    /// The code of a run that ended with `status`: a completed run and a
    /// recognised Zeno point are fine, a failed run cannot be trusted.
    pub fn of(status: Status) -> Code {
        match status {
            Status::Completed | Status::Zeno => Code::Ok,
            Status::Failed => Code::Untrusted,
            Status::Interrupted => Code::Interrupted,
        }
    }

    /// The code of a tool that stopped short: interrupted (the stop flag
    /// was set), else its result cannot be trusted.
    pub fn stopped(interrupted: bool) -> Code {
        if interrupted {
            Code::Interrupted
        } else {
            Code::Untrusted
        }
    }
}

/// An error with its exit code and a one-line message.
#[derive(Debug)]
pub struct Failure {
    /// The exit code the process ends with.
    pub code: Code,
    /// What went wrong, in one line (printed after `flicker: `).
    pub message: String,
}

impl Failure {
    /// A failure for input that cannot be used ([`Code::BadInput`]).
    pub fn bad_input(message: impl ToString) -> Self {
        Failure {
            code: Code::BadInput,
            message: message.to_string(),
        }
    }

    /// A request refused for one of its flags: `--{field}: {reason}`
    /// (the field's underscores written as the flag's dashes).
    pub fn flag(e: SceneError) -> Self {
        let field = e.field.unwrap_or_default().replace('_', "-");
        Failure::bad_input(format!("--{field}: {}", e.reason))
    }

    /// A tool's request refused: its scene's model, which the tool cannot
    /// apply to (`SCENE: reason`), or a flag's value (`--field: reason`).
    pub fn refused(scene: &std::path::Path, e: SceneError) -> Self {
        match e.field.as_deref() {
            Some("model") => Failure::bad_input(format!("{}: {}", scene.display(), e.reason)),
            _ => Failure::flag(e),
        }
    }

    /// A failure for a run that cannot be trusted, or output that could not
    /// be written ([`Code::Untrusted`]).
    pub fn untrusted(message: impl ToString) -> Self {
        Failure {
            code: Code::Untrusted,
            message: message.to_string(),
        }
    }
}
