//! Exit codes, in one place.

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

    /// A failure for a run that cannot be trusted, or output that could not
    /// be written ([`Code::Untrusted`]).
    pub fn untrusted(message: impl ToString) -> Self {
        Failure {
            code: Code::Untrusted,
            message: message.to_string(),
        }
    }
}
