//! Why a command did not finish, and the exit status that says so: usage errors (clap's, and the
//! checks [`Failure::Usage`] carries) exit with status 2, failures while working with status 1.

/// Why a command did not finish: a usage error (exit status 2) or a failure while working (1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Failure {
    /// The command line asks for something impossible: nothing was done.
    Usage(String),
    /// The work failed (a file that does not load, a write that fails, ...).
    Run(String),
}

impl Failure {
    /// The exit status of this failure.
    pub fn code(&self) -> i32 {
        match self {
            Failure::Usage(_) => 2,
            Failure::Run(_) => 1,
        }
    }

    /// The message.
    pub fn message(&self) -> &str {
        match self {
            Failure::Usage(m) | Failure::Run(m) => m,
        }
    }
}

impl From<String> for Failure {
    fn from(m: String) -> Self {
        Failure::Run(m)
    }
}

impl From<&str> for Failure {
    fn from(m: &str) -> Self {
        Failure::Run(m.to_string())
    }
}

/// What a command returns: its exit status when it finished (0, or 1 for a failed conformance
/// check), or why it did not.
pub type Outcome = Result<i32, Failure>;

/// A usage error.
pub fn usage<T>(m: impl Into<String>) -> Result<T, Failure> {
    Err(Failure::Usage(m.into()))
}
