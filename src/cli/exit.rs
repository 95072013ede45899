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
    pub code: Code,
    pub message: String,
}

impl Failure {
    pub fn bad_input(message: impl ToString) -> Self {
        Failure {
            code: Code::BadInput,
            message: message.to_string(),
        }
    }

    pub fn untrusted(message: impl ToString) -> Self {
        Failure {
            code: Code::Untrusted,
            message: message.to_string(),
        }
    }
}
