//! The stack being designed: ambient, films (top first) and base as the text a user types
//! (`1.45`, `0.27+2.9i`, `bk7`, a file), each film's thickness and relative thickness; its
//! presets, its undo history, and its recipe TOML (the format `nacre … --recipe` reads,
//! `nacre_bake::commands::stack_spec`).
//!
//! Materials are parsed by the CLI's own code: [`StackDoc::spec`] is a
//! [`StackSpec`] and [`StackDoc::build`] its [`StackSpec::build`], so every entry the
//! studio accepts is one `nacre color --layer` accepts, with the same messages.

use nacre_bake::commands::stack_spec::{MaterialRef, StackRecipe, StackSpec};
use nacre_format::atomic::write_atomic;
use nacre_optics::Stack;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The most films a stack holds (the `film_stack` technique's limit).
pub const MAX_FILMS: usize = 8;

/// The thickest film the sliders reach, nm (typed values may go beyond).
pub const SLIDER_MAX_NM: f64 = 1500.0;

/// One film: its material as typed, its thickness and its relative thickness (the film
/// spans `thickness_nm ± relative_nm` over the thickness map, as `nacre render --relative`).
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Material spec: a number, `n+ki`, a bundled name or a file.
    pub material: String,
    /// Physical thickness, nm.
    pub thickness_nm: f64,
    /// Relative thickness r over the thickness map, nm (0: uniform).
    pub relative_nm: f64,
}

impl Film {
    /// A uniform film of `material`, `thickness_nm` thick.
    pub fn new(material: &str, thickness_nm: f64) -> Film {
        Film {
            material: material.to_string(),
            thickness_nm,
            relative_nm: 0.0,
        }
    }
}

/// The stack as the user entered it.
#[derive(Clone, Debug, PartialEq)]
pub struct StackDoc {
    /// Ambient (incidence) medium.
    pub ambient: String,
    /// Films, top first (0 to [`MAX_FILMS`]).
    pub films: Vec<Film>,
    /// Base (substrate).
    pub substrate: String,
    /// Folder that relative material paths are resolved from (a loaded recipe's).
    pub base_dir: Option<PathBuf>,
}

impl Default for StackDoc {
    /// The first preset, the soap bubble.
    fn default() -> Self {
        PRESETS[0].doc()
    }
}

/// A named starting point.
pub struct Preset {
    /// Its name in the preset menu.
    pub name: &'static str,
    /// What it is, and where its numbers come from.
    pub description: &'static str,
    ambient: &'static str,
    films: &'static [(&'static str, f64)],
    substrate: &'static str,
}

impl Preset {
    /// The preset's stack.
    pub fn doc(&self) -> StackDoc {
        StackDoc {
            ambient: self.ambient.into(),
            films: self.films.iter().map(|(m, d)| Film::new(m, *d)).collect(),
            substrate: self.substrate.into(),
            base_dir: None,
        }
    }
}

/// The presets. Dispersive materials are the bundled ones (`nacre materials`); titanium,
/// iron and their oxides are constant indices near 550 nm (titanium 2.54 + 3.43i and iron
/// 2.87 + 3.35i: Johnson & Christy 1974; the anodic TiO₂ film is the bundled `tio2`; the
/// steel's temper oxide, a magnetite/haematite mix, ≈ 2.6 + 0.4i, an assumed value).
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "soap bubble",
        description: "a 380 nm water film in air",
        ambient: "1.0",
        films: &[("water", 380.0)],
        substrate: "1.0",
    },
    Preset {
        name: "oil slick",
        description: "300 nm of oil on water",
        ambient: "1.0",
        films: &[("oil", 300.0)],
        substrate: "water",
    },
    Preset {
        name: "AR-coated lens",
        description: "a quarter-wave MgF2 coating (550 nm) on BK7",
        ambient: "1.0",
        films: &[("mgf2", 99.75)],
        substrate: "bk7",
    },
    Preset {
        name: "anodised titanium",
        description: "70 nm of TiO2 on titanium (2.54+3.43i)",
        ambient: "1.0",
        films: &[("tio2", 70.0)],
        substrate: "2.54+3.43i",
    },
    Preset {
        name: "tempered steel",
        description: "a 60 nm temper oxide (2.6+0.4i) on iron (2.87+3.35i)",
        ambient: "1.0",
        films: &[("2.6+0.4i", 60.0)],
        substrate: "2.87+3.35i",
    },
];

/// What an entry names in messages: `studio film 2 material` and so on.
fn origin(what: &str) -> nacre_format::param::Origin {
    format!("studio {what}").into()
}

impl StackDoc {
    /// The stack as the CLI's [`StackSpec`] (materials not loaded yet).
    pub fn spec(&self) -> StackSpec {
        let reference = |spec: &str, what: &str| MaterialRef {
            spec: spec.trim().to_string(),
            context: origin(what),
        };
        StackSpec {
            ambient: reference(&self.ambient, "ambient"),
            layers: self
                .films
                .iter()
                .enumerate()
                .map(|(j, f)| {
                    (
                        reference(&f.material, &format!("film {}", j + 1)),
                        f.thickness_nm,
                    )
                })
                .collect(),
            substrate: reference(&self.substrate, "base"),
            base_dir: self.base_dir.clone(),
            incoherent: Vec::new(),
        }
    }

    /// Loads the materials and builds the stack (the CLI's [`StackSpec::build`]); also
    /// refuses more than [`MAX_FILMS`] films and negative or non-finite thicknesses.
    pub fn build(&self) -> nacre_bake::Result<Stack> {
        if self.films.len() > MAX_FILMS {
            return Err(nacre_bake::Error::invalid(
                origin("films"),
                format!(
                    "{} films (the studio holds 1 to {MAX_FILMS})",
                    self.films.len()
                ),
            ));
        }
        for (j, f) in self.films.iter().enumerate() {
            for (what, v) in [("thickness", f.thickness_nm), ("relative", f.relative_nm)] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(nacre_bake::Error::invalid(
                        origin(&format!("film {} {what}", j + 1)),
                        format!("{v} nm (expected a finite thickness ≥ 0)"),
                    ));
                }
            }
        }
        self.spec().build()
    }

    /// Each film's relative thickness, nm (top first).
    pub fn relative_nm(&self) -> Vec<f64> {
        self.films.iter().map(|f| f.relative_nm).collect()
    }

    /// The recipe TOML of this stack: `ambient`, `substrate` and one `[[layers]]` per film
    /// (`material`, `thickness_nm`), the format `--recipe` reads. Relative thicknesses are
    /// not part of that format: a comment lists them when any is non-zero.
    pub fn to_recipe_toml(&self) -> String {
        #[derive(Serialize)]
        struct Layer<'a> {
            material: &'a str,
            thickness_nm: f64,
        }
        #[derive(Serialize)]
        struct Recipe<'a> {
            ambient: &'a str,
            substrate: &'a str,
            layers: Vec<Layer<'a>>,
        }
        let recipe = Recipe {
            ambient: self.ambient.trim(),
            substrate: self.substrate.trim(),
            layers: self
                .films
                .iter()
                .map(|f| Layer {
                    material: f.material.trim(),
                    thickness_nm: f.thickness_nm,
                })
                .collect(),
        };
        let mut text = String::from(
            "# A film stack from nacre studio: films top first (`nacre color --recipe FILE`).\n",
        );
        let relative = self.relative_nm();
        if relative.iter().any(|&r| r != 0.0) {
            text.push_str(&format!(
                "# relative thicknesses, nm, top first (nacre render --relative): {relative:?}\n"
            ));
        }
        text.push_str(&toml::to_string(&recipe).expect("strings and numbers serialise"));
        text
    }

    /// Writes [`StackDoc::to_recipe_toml`] to `path` atomically (nothing is left behind on
    /// failure).
    pub fn write_recipe(&self, path: &Path) -> nacre_format::Result<()> {
        let text = self.to_recipe_toml();
        write_atomic(path, |w| w.write_all(text.as_bytes()))
    }

    /// Reads a stack recipe (the CLI's [`StackRecipe::read`]); relative thicknesses start
    /// at 0. More than [`MAX_FILMS`] films, or an incoherent layer, are refused.
    pub fn read_recipe(path: &Path) -> nacre_bake::Result<StackDoc> {
        let recipe = StackRecipe::read(path)?;
        let s = recipe.stack;
        if s.incoherent.contains(&true) {
            return Err(nacre_bake::Error::invalid(
                path.display().to_string(),
                "an incoherent layer: the studio draws coherent films only (compute its colour with `nacre color --method spectral`)",
            ));
        }
        if s.layers.len() > MAX_FILMS {
            return Err(nacre_bake::Error::invalid(
                path.display().to_string(),
                format!(
                    "{} layers (the studio holds up to {MAX_FILMS})",
                    s.layers.len()
                ),
            ));
        }
        Ok(StackDoc {
            ambient: s.ambient.spec,
            films: s
                .layers
                .iter()
                .map(|(m, d)| Film::new(&m.spec, *d))
                .collect(),
            substrate: s.substrate.spec,
            base_dir: s.base_dir,
        })
    }
}

/// Undo and redo over committed stacks.
#[derive(Clone, Debug, Default)]
pub struct History {
    undo: Vec<StackDoc>,
    redo: Vec<StackDoc>,
}

/// The most steps kept for undo.
const MAX_UNDO: usize = 200;

impl History {
    /// Records `before`, the stack as it was before an edit (clears the redo list).
    pub fn record(&mut self, before: StackDoc) {
        if self.undo.last() == Some(&before) {
            return;
        }
        self.undo.push(before);
        if self.undo.len() > MAX_UNDO {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// The stack before the last edit, `current` kept for redo; None when there is none.
    pub fn undo(&mut self, current: &StackDoc) -> Option<StackDoc> {
        let previous = self.undo.pop()?;
        self.redo.push(current.clone());
        Some(previous)
    }

    /// The stack the last undo left; None when there is none.
    pub fn redo(&mut self, current: &StackDoc) -> Option<StackDoc> {
        let next = self.redo.pop()?;
        self.undo.push(current.clone());
        Some(next)
    }

    /// Whether there is an edit to undo.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether there is an undone edit to redo.
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }
}
