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

pub use color::{
    ColourFit, ColourSettings, ColourSolution, ColourTarget, fit_colour, fit_colour_watched,
};
pub use spectrum::{
    Baseline, Loss, Measurement, Quantity, Settings, SpectrumFit, fit_spectrum,
    fit_spectrum_watched,
};
pub use template::{Free, FreeKind, Template};

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The hooks a long fit reports to and is stopped by (the studio's background fits): after
/// every step of work (a chunk of search samples, a local polish, a start of the global
/// search) `progress` is called with (steps done, steps in all), and before every step
/// `cancel` is read; once it is set the fit stops with [`crate::Error::FitCancelled`].
/// Neither changes a fit that runs to the end: its result is the same with any watch.
#[derive(Clone, Copy)]
pub struct Watch<'a> {
    /// Called with (steps done, steps in all) after each step, from any thread.
    pub progress: &'a (dyn Fn(usize, usize) + Sync),
    /// Read before each step; set: the fit stops.
    pub cancel: &'a AtomicBool,
}

/// Never set: the cancel flag of [`Watch::none`].
static NEVER: AtomicBool = AtomicBool::new(false);

impl Watch<'static> {
    /// No progress report and no cancel (the plain fits).
    pub fn none() -> Watch<'static> {
        Watch {
            progress: &|_, _| {},
            cancel: &NEVER,
        }
    }
}

/// A fit's step counter over a [`Watch`].
pub(crate) struct Steps<'a> {
    watch: Watch<'a>,
    done: AtomicUsize,
    total: AtomicUsize,
}

impl<'a> Steps<'a> {
    pub(crate) fn new(watch: Watch<'a>, total: usize) -> Self {
        Steps {
            watch,
            done: AtomicUsize::new(0),
            total: AtomicUsize::new(total),
        }
    }

    /// Errs with [`crate::Error::FitCancelled`] once the watch's cancel flag is set.
    pub(crate) fn check(&self) -> crate::Result<()> {
        if self.watch.cancel.load(Ordering::Relaxed) {
            return Err(crate::Error::FitCancelled {
                done: self.done.load(Ordering::Relaxed),
                total: self.total.load(Ordering::Relaxed),
            });
        }
        Ok(())
    }

    /// One more step done.
    pub(crate) fn step(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let total = self.total.load(Ordering::Relaxed).max(done);
        (self.watch.progress)(done, total);
    }

    /// Sets the steps in all (once the work is known).
    pub(crate) fn set_total(&self, total: usize) {
        self.total.store(total, Ordering::Relaxed);
    }

    /// All steps done (a search that stops early).
    pub(crate) fn finish(&self) {
        let total = self.total.load(Ordering::Relaxed);
        self.done.store(total, Ordering::Relaxed);
        (self.watch.progress)(total, total);
    }
}

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
