//! The loader's errors.

use crate::error::Error;
use std::path::Path;

/// An error about the glTF file at `path`.
pub(crate) fn invalid(path: &Path, message: impl Into<String>) -> Error {
    Error::Invalid {
        context: format!("glTF {}", path.display()),
        message: message.into(),
    }
}
