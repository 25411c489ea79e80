//! The runtime's error type.

use nacre_format::param::{Msg, Naming, Render};
use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong in `nacre-runtime`.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// wgpu found no adapter (no GPU and no software Vulkan driver such as Mesa's lavapipe).
    #[error(
        "no GPU adapter found: install a Vulkan driver (on Debian: `apt install mesa-vulkan-drivers` for the software rasteriser lavapipe) ({0})"
    )]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not create a device on {adapter}: {message}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// wgpu's message.
        message: String,
    },
    /// A table or manifest could not be read or does not describe what was asked for, or a
    /// material it names could not be resolved.
    #[error(transparent)]
    Table(#[from] nacre_format::Error),
    /// The physics core rejected a value (a material, a stack).
    #[error(transparent)]
    Optics(#[from] nacre_optics::Error),
    /// A manifest and its files disagree, or a manifest asks for something the runtime
    /// cannot upload.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A table exceeds what the device supports.
    #[error("{what} needs {needed}, but the device allows at most {limit} ({adapter})")]
    Limit {
        /// What was being created.
        what: String,
        /// The size needed.
        needed: u64,
        /// The device's limit.
        limit: u64,
        /// Adapter name.
        adapter: String,
    },
    /// wgpu reported a validation or out-of-memory error, or the device was lost.
    #[error("GPU error while {context}: {message}")]
    Gpu {
        /// What the runtime was doing.
        context: String,
        /// wgpu's message.
        message: String,
    },
    /// The device was lost (driver reset, GPU removed, or `wgpu::Device::destroy`): nothing
    /// more can run on it; create a new [`crate::GpuContext`].
    #[error(
        "the GPU device on {adapter} was lost while {context} ({reason}): create a new device and reload the tables"
    )]
    DeviceLost {
        /// Adapter name.
        adapter: String,
        /// What the runtime was doing.
        context: String,
        /// wgpu's reason and message.
        reason: String,
    },
    /// A request the runtime refuses (bad sizes, missing tables for a technique, …).
    #[error("{context}: {message}")]
    Invalid {
        /// Where.
        context: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A request the runtime refuses, with advice that names parameters (rendered by a
    /// [`Naming`]: `Display` names them neutrally).
    #[error("{context}: {message}")]
    Refused {
        /// Where.
        context: String,
        /// What is wrong and the way out.
        message: Msg,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

impl Render for Error {
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result {
        match self {
            Error::Table(e) => e.render(f, naming),
            Error::Refused { context, message } => {
                write!(f, "{context}: {}", message.named(naming))
            }
            other => fmt::Display::fmt(other, f),
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
