//! Fitting stacks to data: a stack with free parameters and their bounds
//! ([`template::Template`]), small bounded optimisers and the fits built on them.
//!
//! * [`template`] — a stack with free parameters and their bounds;
//! * [`nelder_mead`] — the bounded Nelder–Mead simplex for a few parameters;
//! * [`lm`] — a small box-bounded Levenberg–Marquardt;
//! * [`gltf`] — the closest `KHR_materials_iridescence` film to target colours;
//! * [`spectrum`] — the global fit of a measured spectrum;
//! * [`color`] — the design of a stack for target colours over angles.
//!
//! No I/O: the commands read the data and the template, this module fits.

pub mod color;
pub mod gltf;
pub mod lm;
pub mod nelder_mead;
pub mod spectrum;
pub mod template;

pub use color::{ColourFit, ColourSettings, ColourSolution, ColourTarget, fit_colour};
pub use spectrum::{Baseline, Loss, Measurement, Quantity, Settings, SpectrumFit, fit_spectrum};
pub use template::{Free, FreeKind, Template};

/// The Halton sequence's `i`-th value in base `b` (i ≥ 1), in (0, 1): the low-discrepancy
/// starts of the global searches (Halton 1960, *Numer. Math.* 2, 84).
pub(crate) fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// The Halton bases of the parameters, one prime per coordinate.
pub(crate) const PRIMES: [usize; 16] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];
