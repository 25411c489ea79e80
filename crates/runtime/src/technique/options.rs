//! The techniques' settings: [`TechniqueOptions`] and the setups of `film_spectral` and
//! `film_stack`.

use crate::error::{Error, Result};
use nacre_optics::Material;

/// What the spectral technique integrates over: N wavelengths with their weights and the
/// base's index at each (the `samples:N` method of `nacre color`).
#[derive(Clone, Debug)]
pub struct SpectralSetup {
    /// Wavelength count N.
    pub samples: usize,
    /// The base material (its index is sampled at each wavelength).
    pub base: Material,
}

/// What `film_stack` evaluates: a stack of 1 to 8 films whose top film takes the pixel's
/// thickness and whose other films vary as d_j + r_j s_c, s_c from their channel c of the
/// thickness map ([`nacre_optics::few_wavelengths::StackEvaluation`]).
#[derive(Clone, Debug)]
pub struct StackSetup {
    /// Ambient, films (their own thicknesses d_j⁰) and base.
    pub stack: nacre_optics::Stack,
    /// Relative thickness r_j of each film, nm (the top film's is unused).
    pub relative_nm: Vec<f64>,
    /// Each film's thickness-map channel (0 R or grey, 1 G, 2 B; the top film's is unused:
    /// it follows the material's thickness mapping of channel R); empty: every film follows
    /// channel R.
    pub channels: Vec<usize>,
    /// `None`: the rule ladder (counts from the pixel's OPD); `Some(N)`: N nodes everywhere.
    pub samples: Option<usize>,
}

impl Default for StackSetup {
    /// A two-film dielectric stack in air on glass (n 1.5): 100 nm of n 1.38 over 60 nm of
    /// n 2.3, the lower film varying by ±30 nm.
    fn default() -> Self {
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layers = vec![
            nacre_optics::Layer {
                material: constant(1.38),
                thickness_nm: 100.0,
            },
            nacre_optics::Layer {
                material: constant(2.3),
                thickness_nm: 60.0,
            },
        ];
        StackSetup {
            stack: nacre_optics::Stack::new(constant(1.0), layers, constant(1.5))
                .expect("finite thicknesses and a clear ambient"),
            relative_nm: vec![0.0, 30.0],
            channels: Vec::new(),
            samples: None,
        }
    }
}

impl StackSetup {
    /// A dielectric stack of `films` (1 to 8) films in air on glass (n 1.5), alternating
    /// n 1.38 (100 nm) and n 2.3 (60 nm), every film below the top varying by ±20 nm: the
    /// stacks `nacre bench-gpu` times.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a film count outside 1 to 8.
    pub fn alternating(films: usize) -> Result<StackSetup> {
        if !(1..=nacre_optics::few_wavelengths::MAX_STACK_FILMS).contains(&films) {
            return Err(Error::OutOfRange {
                what: "film_stack: films".into(),
                value: films as f64,
                unit: "",
                expected: format!("1 to {}", nacre_optics::few_wavelengths::MAX_STACK_FILMS),
            });
        }
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layers = (0..films)
            .map(|j| nacre_optics::Layer {
                material: constant(if j % 2 == 0 { 1.38 } else { 2.3 }),
                thickness_nm: if j % 2 == 0 { 100.0 } else { 60.0 },
            })
            .collect();
        Ok(StackSetup {
            stack: nacre_optics::Stack::new(constant(1.0), layers, constant(1.5))?,
            relative_nm: (0..films)
                .map(|j| if j == 0 { 0.0 } else { 20.0 })
                .collect(),
            channels: Vec::new(),
            samples: None,
        })
    }
}

impl StackSetup {
    /// A coated pane in air: [`StackSetup::alternating`]'s two films (n 1.38, 100 nm over
    /// n 2.3, 60 nm) on the front face of a clear incoherent slab of n 1.5, 2 mm thick, and
    /// the same two films mirrored on its back face — the pane `nacre bench-gpu` times with
    /// `film_glass` beside the four coherent films alone with `film_stack`.
    ///
    /// # Errors
    /// None in practice (the stack is valid); the stack's own errors otherwise.
    pub fn coated_pane() -> Result<StackSetup> {
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layer = |n: f64, thickness_nm: f64| nacre_optics::Layer {
            material: constant(n),
            thickness_nm,
        };
        let layers = vec![
            layer(1.38, 100.0),
            layer(2.3, 60.0),
            layer(1.5, 2e6),
            layer(2.3, 60.0),
            layer(1.38, 100.0),
        ];
        let stack = nacre_optics::Stack::new(constant(1.0), layers, constant(1.0))?
            .with_incoherent(vec![false, false, true, false, false])?;
        Ok(StackSetup {
            stack,
            relative_nm: vec![0.0, 20.0, 0.0, 20.0, 20.0],
            channels: Vec::new(),
            samples: None,
        })
    }
}

/// Options of a technique's group-1 bind group.
#[derive(Clone, Debug)]
pub struct TechniqueOptions {
    /// Harmonics M of `film_fourier`: 0 (the default) = automatic, as `nacre color --method
    /// fourier` (`fourier:auto`): per pixel, as many as the series' decay and the
    /// sensitivities' need for ΔE2000 p95 ≤ 0.1 (`nacre_optics::fourier` module docs, "How
    /// many harmonics"); a fixed M otherwise.
    pub harmonics: u32,
    /// Setup of `film_spectral`.
    pub spectral: SpectralSetup,
    /// Setup of `film_stack`.
    pub stack: StackSetup,
}

impl Default for TechniqueOptions {
    fn default() -> Self {
        TechniqueOptions {
            harmonics: 0,
            spectral: SpectralSetup {
                samples: 30,
                base: Material::constant("1.5", nacre_optics::C64::new(1.5, 0.0))
                    .expect("a real index above zero is a valid material"),
            },
            stack: StackSetup::default(),
        }
    }
}
