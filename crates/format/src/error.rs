//! The error type of `nacre-format`: reading and writing table files and manifests, and
//! resolving material references. Each variant carries the values that went wrong; only the
//! `nacre` binary turns it into a message and an exit status.

use crate::param::{Msg, Naming, Neutral, Origin, Param, Render};
use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong while reading or writing tables and resolving materials.
/// Each message names the file (and line) or the parameter concerned; `Display`
/// names parameters neutrally ([`crate::param::Neutral`]), [`Render`] with any naming.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An error from the physics core.
    #[error(transparent)]
    Optics(#[from] nacre_optics::Error),
    /// The physics core rejected something that came from a parameter or recipe key.
    #[error("{}", self.named(&Neutral))]
    OpticsIn {
        /// The parameter or `file:line` the value came from.
        context: Origin,
        /// What the core said.
        source: nacre_optics::Error,
    },
    /// A text file (manifest, material data) is malformed at a line.
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was wrong and what was expected.
        message: String,
    },
    /// A material name that is neither a number, a bundled material nor a data file.
    #[error("{}", self.named(&Neutral))]
    UnknownMaterial {
        /// The parameter or `file:line` the name came from.
        context: Origin,
        /// The name given.
        name: String,
        /// The bundled names, comma-separated.
        bundled: String,
    },
    /// A refractiveindex.info page (`shelf/book/page`) that the material database does not
    /// have, or that was asked for with no database set.
    #[error("{}", self.named(&Neutral))]
    MaterialDb {
        /// The parameter or `file:line` the spec came from.
        context: Origin,
        /// The spec given.
        spec: String,
        /// The paths looked at, in order.
        tried: Vec<PathBuf>,
        /// What was wrong, with the paths tried and how to set the database.
        message: Msg,
    },
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A request larger than the documented limits.
    #[error("{}", self.named(&Neutral))]
    TooLarge {
        /// What was counted (it may name parameters).
        what: Msg,
        /// The requested count.
        count: u64,
        /// The limit.
        limit: u64,
    },
    /// A lookup-table image (OpenEXR or PNG atlas) is malformed, does not match the
    /// expected dimensions, or a table cannot be written in the requested format.
    #[error("{}: {message}", path.display())]
    Table {
        /// The image file.
        path: PathBuf,
        /// What was wrong and what was expected.
        message: String,
    },
    /// A table file whose SHA-256 differs from the one its manifest records: replaced or
    /// damaged after the bake.
    #[error(
        "{}: does not match its manifest {} (SHA-256 {actual}, the manifest says {expected}): re-bake the table or restore the file",
        path.display(),
        manifest.display()
    )]
    Checksum {
        /// The table file.
        path: PathBuf,
        /// The manifest that lists it.
        manifest: PathBuf,
        /// The file's SHA-256.
        actual: String,
        /// The SHA-256 the manifest records.
        expected: String,
    },
    /// A manifest of another table kind (or diffraction layout) than the reader expects.
    #[error("{}: table `{name}` is a `{kind}` table, not {expected}", manifest.display())]
    WrongKind {
        /// The manifest.
        manifest: PathBuf,
        /// The table's name.
        name: String,
        /// Its kind.
        kind: crate::kind::TableKind,
        /// What the reader expected, e.g. "a film-lut".
        expected: &'static str,
    },
    /// A value (usually from a recipe or manifest) that is well-formed but not acceptable.
    #[error("{}", self.named(&Neutral))]
    Invalid {
        /// File, `file:line`, parameter or table name concerned.
        context: Origin,
        /// What was wrong and what was expected.
        message: Msg,
    },
}

impl Error {
    /// [`Error::Invalid`] with `context` and `message`.
    pub fn invalid(context: impl Into<Origin>, message: impl Into<Msg>) -> Self {
        Error::Invalid {
            context: context.into(),
            message: message.into(),
        }
    }
}

impl Render for Error {
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result {
        match self {
            Error::OpticsIn { context, source } => {
                write!(f, "{}: {source}", context.named(naming))
            }
            Error::UnknownMaterial {
                context,
                name,
                bundled,
            } => write!(
                f,
                "{}: unknown material `{name}`: expected a number (`1.5`), a complex index (`0.27+2.9i`), a bundled material ({bundled}), a path to a `.yml`/`.csv` file or a refractiveindex.info page SHELF/BOOK/PAGE (with {})",
                context.named(naming),
                naming.name(Param::MaterialDb)
            ),
            Error::TooLarge { what, count, limit } => write!(
                f,
                "{}: {count} exceeds the limit of {limit}",
                what.named(naming)
            ),
            Error::MaterialDb {
                context, message, ..
            }
            | Error::Invalid { context, message } => {
                write!(f, "{}: {}", context.named(naming), message.named(naming))
            }
            other => fmt::Display::fmt(other, f),
        }
    }
}

/// Shorthand for `Result<T, nacre_format::Error>`.
pub type Result<T, E = Error> = std::result::Result<T, E>;
