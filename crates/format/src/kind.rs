//! The kinds of table nacre bakes, named as recipes and manifests name them.

use serde::{Deserialize, Serialize};
use std::fmt;

/// The kinds of table nacre bakes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TableKind {
    /// Pre-integrated film colour over cos θ × optical path × film index
    /// ([`crate::film_lut`]).
    FilmLut,
    /// Fourier transforms of the colour sensitivities, mip-mapped ([`crate::fourier`]).
    Fourier,
    /// Directional albedo of the iridescent GGX lobe ([`crate::rough_film_lut`]).
    RoughFilmLut,
    /// Stam's diffraction terms or their wavelength-integrated colours
    /// ([`crate::diffraction`]).
    Diffraction,
}

impl TableKind {
    /// Every kind.
    pub const ALL: [TableKind; 4] = [
        TableKind::FilmLut,
        TableKind::Fourier,
        TableKind::RoughFilmLut,
        TableKind::Diffraction,
    ];

    /// The name recipes and manifests use (`film-lut`, …).
    pub fn name(self) -> &'static str {
        match self {
            TableKind::FilmLut => "film-lut",
            TableKind::Fourier => "fourier",
            TableKind::RoughFilmLut => "rough-film-lut",
            TableKind::Diffraction => "diffraction",
        }
    }

    /// The kind named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl fmt::Display for TableKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
