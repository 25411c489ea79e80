//! The one error type of `nacre-bake`. Only the `nacre` binary turns it into a message
//! and an exit status.
//!
//! Errors name the inputs that went wrong with [`Param`] and [`Origin`] values (re-exported
//! from [`nacre_format::param`]), never a command-line flag: `Display` writes the
//! parameters' neutral names, [`Render`] takes any [`Naming`] (the `nacre` binary's writes
//! its flags).

use std::fmt;
use std::path::PathBuf;

pub use nacre_format::param::{Msg, Naming, Neutral, Origin, Param, Piece, Render};

/// Everything that can go wrong while reading recipes, resolving materials, computing and
/// writing tables. Files, lines, unknown materials, limits and unacceptable values named by
/// file or line come from the table format ([`nacre_format::Error`]); this type adds the
/// values of the commands' parameters.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An error from the table format: reading or writing files and tables, recipes and
    /// CSV files malformed at a line ([`nacre_format::Error::Parse`]), materials, limits,
    /// values unacceptable where they came from ([`nacre_format::Error::Invalid`]).
    Format(#[from] nacre_format::Error),
    /// An error from the physics core.
    Optics(#[from] nacre_optics::Error),
    /// A parameter's value is malformed or not acceptable: `ORIGIN `VALUE`: MESSAGE`.
    Value {
        /// The parameter the value came from (or a recipe line).
        origin: Origin,
        /// The value given.
        value: String,
        /// What was expected.
        message: Msg,
    },
    /// An angle, one of the values of `origin`, outside (−90°, 90°).
    Angle {
        /// The parameter the angles came from.
        origin: Origin,
        /// The value given (a range or list).
        value: String,
        /// The first angle outside, degrees.
        angle: f64,
    },
    /// A number outside its accepted range `low..=high`.
    OutOfRange {
        /// The parameter.
        param: Param,
        /// The value given.
        value: f64,
        /// The smallest accepted value.
        low: f64,
        /// The largest accepted value.
        high: f64,
    },
    /// A bake stopped because its caller cancelled it (nothing was written).
    Cancelled {
        /// The table being baked.
        table: String,
    },
}

impl Error {
    /// [`Error::Value`].
    pub fn value(
        origin: impl Into<Origin>,
        value: impl Into<String>,
        message: impl Into<Msg>,
    ) -> Self {
        Error::Value {
            origin: origin.into(),
            value: value.into(),
            message: message.into(),
        }
    }

    /// A [`nacre_format::Error::Invalid`]: a value unacceptable where it came from.
    pub fn invalid(context: impl Into<Origin>, message: impl Into<Msg>) -> Self {
        nacre_format::Error::invalid(context, message).into()
    }

    /// A [`nacre_format::Error::OpticsIn`]: the physics core rejected a value of `context`.
    pub fn optics_in(context: impl Into<Origin>, source: nacre_optics::Error) -> Self {
        nacre_format::Error::OpticsIn {
            context: context.into(),
            source,
        }
        .into()
    }

    /// A [`nacre_format::Error::Parse`]: a recipe or CSV file malformed at a 1-based line.
    pub fn recipe(path: impl Into<PathBuf>, line: usize, message: impl Into<String>) -> Self {
        nacre_format::Error::Parse {
            path: path.into(),
            line,
            message: message.into(),
        }
        .into()
    }
}

impl Render for Error {
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result {
        match self {
            Error::Format(e) => e.render(f, naming),
            Error::Optics(e) => fmt::Display::fmt(e, f),
            Error::Value {
                origin,
                value,
                message,
            } => write!(
                f,
                "{} `{value}`: {}",
                origin.named(naming),
                message.named(naming)
            ),
            Error::Angle {
                origin,
                value,
                angle,
            } => write!(
                f,
                "{} `{value}`: angle {angle} must lie strictly between -90 and 90 degrees",
                origin.named(naming)
            ),
            Error::OutOfRange {
                param,
                value,
                low,
                high,
            } => write!(
                f,
                "{} `{value}`: expected {low} to {high}",
                naming.name(*param)
            ),
            Error::Cancelled { table } => {
                write!(
                    f,
                    "the bake of `{table}` was cancelled: nothing was written"
                )
            }
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.render(f, &Neutral)
    }
}

/// Shorthand for `Result<T, nacre_bake::Error>`.
pub type Result<T, E = Error> = std::result::Result<T, E>;
