//! The `nacre` binary's error: the libraries' errors side by side, displayed as
//! `nacre: error: …` with exit status 2 by `main`.

use std::fmt;

/// Everything a command can fail with.
#[derive(Debug)]
pub enum CliError {
    /// Recipes, commands, materials, tables through nacre-bake.
    Bake(nacre_bake::Error),
    /// Reading or writing tables and files directly.
    Format(nacre_format::Error),
    /// The GPU runtime (`render`, `bench-gpu`).
    Runtime(nacre_runtime::Error),
}

/// Shorthand for the commands' results.
pub type Result<T, E = CliError> = std::result::Result<T, E>;

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Bake(e) => e.fmt(f),
            CliError::Format(e) => e.fmt(f),
            // Table, physics and file errors name their file or value themselves; the
            // runtime's own errors are said to come from the render.
            CliError::Runtime(
                e @ (nacre_runtime::Error::Table(_)
                | nacre_runtime::Error::Optics(_)
                | nacre_runtime::Error::Io { .. }),
            ) => e.fmt(f),
            CliError::Runtime(e) => write!(f, "render: {e}"),
        }
    }
}

impl std::error::Error for CliError {}

impl From<nacre_bake::Error> for CliError {
    fn from(e: nacre_bake::Error) -> Self {
        CliError::Bake(e)
    }
}

impl From<nacre_format::Error> for CliError {
    fn from(e: nacre_format::Error) -> Self {
        CliError::Format(e)
    }
}

impl From<nacre_runtime::Error> for CliError {
    fn from(e: nacre_runtime::Error) -> Self {
        CliError::Runtime(e)
    }
}
