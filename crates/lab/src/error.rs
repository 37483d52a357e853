//! What can go wrong in the lab, as a type: a caller can tell a bad file from a failed write
//! from a run that was refused.

use std::path::{Path, PathBuf};

use simlod::config::ConfigError;

/// An error of the recorder, the bench or an experiment. Each says what and where in its message.
#[derive(Debug, thiserror::Error)]
pub enum LabError {
    /// A file of the assets or of an experiment's settings that did not load or did not pass
    /// its checks: it names the file and the field.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A file or folder that could not be made, read or written.
    #[error("cannot {action} {}: {source}", path.display())]
    Io {
        /// What was being done: `create`, `read`, `write` or `open`.
        action: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// What a run was asked does not fit its files, or a file of an earlier run is not what it
    /// should be, or the model did not do what the run needs: the message says which and why.
    #[error("{0}")]
    Invalid(String),
}

/// Turns an I/O error at `path` into a [`LabError::Io`].
pub fn io_error(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> LabError + use<> {
    let path = path.to_owned();
    move |source| LabError::Io { action, path, source }
}
