//! The inputs of nacre's commands, named neutrally, and message text that mentions them.
//!
//! The libraries never spell a command-line flag: an error says which input a value came
//! from with a [`Param`] (or an [`Origin`], which also covers `file:line` in a recipe or
//! manifest), and text that asks for another input ("needs a roughness", "add colours") is a
//! [`Msg`] of text and [`Param`] pieces. Rendering takes a [`Naming`]: [`Neutral`] (what
//! `Display` uses) writes the parameters' own names ([`Param::name`], the request fields,
//! `snake_case`), a front end such as the `nacre` binary writes its flags.
//!
//! ```
//! use nacre_format::msg;
//! use nacre_format::param::{Neutral, Param, Render};
//!
//! let m = msg!["needs ", Param::Roughness.arg(), " (GGX α, 0 < α ≤ 1)"];
//! assert_eq!(m.to_string(), "needs roughness (GGX α, 0 < α ≤ 1)");
//! assert_eq!(m.named(&Neutral).to_string(), m.to_string());
//! ```

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

macro_rules! params {
    ($( $(#[$doc:meta])* $variant:ident => $name:literal, )*) => {
        /// An input of nacre's commands: a field of a request, a flag of the `nacre` binary.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Param {
            $( $(#[$doc])* $variant, )*
        }

        impl Param {
            /// Every parameter.
            pub const ALL: &'static [Param] = &[$(Param::$variant),*];

            /// The neutral name: the request field, `snake_case` (`angles`, `fourier_table`).
            pub fn name(self) -> &'static str {
                match self {
                    $( Param::$variant => $name, )*
                }
            }
        }
    };
}

params! {
    /// Incidence angles, degrees (a range or a list).
    Angles => "angles",
    /// One incidence angle, degrees.
    Angle => "angle",
    /// A film thickness.
    Thickness => "thickness",
    /// Film thicknesses (a range).
    Thicknesses => "thicknesses",
    /// Vacuum wavelengths, nm (a range).
    Wavelengths => "wavelengths",
    /// The colour method (`spectral`, `lut:NAME`, …).
    Method => "method",
    /// Several colour methods, comma-separated.
    Methods => "methods",
    /// The CIE observer.
    Observer => "observer",
    /// The illuminant.
    Illuminant => "illuminant",
    /// The output colour space.
    Space => "space",
    /// The GGX roughness α.
    Roughness => "roughness",
    /// The baked `fourier` table.
    FourierTable => "fourier_table",
    /// The ambient medium.
    Ambient => "ambient",
    /// A film, `MATERIAL@THICKNESS`.
    Layer => "layer",
    /// The substrate.
    Substrate => "substrate",
    /// The local refractiveindex.info database.
    MaterialDb => "material_db",
    /// Points to evaluate (a CSV file).
    Points => "points",
    /// Reflectance or transmittance.
    Quantity => "quantity",
    /// Several quantities of a spectrum plot.
    Quantities => "quantities",
    /// Colours instead of spectra.
    Color => "color",
    /// A named reference case.
    Case => "case",
    /// Film indices of a table plot.
    FilmIors => "film_iors",
    /// The largest optical path difference of a Fourier plot.
    MaxOpd => "max_opd",
    /// Colour gamuts drawn on a chromaticity diagram.
    Gamut => "gamut",
    /// The output file.
    Output => "output",
    /// A height field: a file or a synthetic spec.
    Surface => "surface",
    /// A baked table (default-set name or manifest path).
    Table => "table",
    /// Baked tables to load.
    Tables => "tables",
    /// The diffraction table layout (`terms`, `integrated`).
    Layout => "layout",
    /// Texels along v of an in-memory integrated table.
    IntegratedSamples => "integrated_samples",
    /// Sample pitch of a height field, µm; or the orbit camera's elevation, degrees (no
    /// command takes both).
    Pitch => "pitch",
    /// Samples per axis of a synthetic height field.
    Samples => "samples",
    /// Height scale of a height-field file, µm.
    HeightScale => "height_scale",
    /// Coherence diameter of the light, µm.
    Coherence => "coherence",
    /// The index of the Fresnel factor.
    Fresnel => "fresnel",
    /// Light incidence angle, degrees.
    Incidence => "incidence",
    /// View angles, degrees.
    Views => "views",
    /// Largest view angle of a map, degrees.
    MaxView => "max_view",
    /// Cells across a map.
    Cells => "cells",
    /// Exposure: a factor or `auto`.
    Exposure => "exposure",
    /// Wavelength step of a GPU diffraction render, nm.
    WavelengthStep => "wavelength_step",
    /// Wavelength step of the GPU diffraction benchmark, nm.
    DiffractionStep => "diffraction_step",
    /// Environment samples of a GPU diffraction render.
    EnvSamples => "env_samples",
    /// Monte Carlo samples of a reference.
    ReferenceSamples => "reference_samples",
    /// Film index of the GPU benchmark's pixels.
    BenchFilmIor => "bench_film_ior",
    /// Base index of the GPU benchmark's pixels.
    BenchBaseIor => "bench_base_ior",
    /// The file an export writes.
    Out => "out",
    /// Relative thicknesses of a stack's films, nm.
    Relative => "relative",
    /// The thickness-map channel of each film of a stack.
    LayerChannel => "layer_channel",
    /// The glTF file's camera to render from.
    Camera => "camera",
    /// Orbit camera: rotation about the vertical, degrees.
    Yaw => "yaw",
    /// Orbit camera: distance from the scene's centre, world units.
    Distance => "distance",
    /// Derivatives of a spectrum by the films' thicknesses.
    Jacobian => "jacobian",
    /// A measured spectrum to fit: a CSV file or a folder of them.
    Measured => "measured",
    /// A fit's scale model (`1`, `free`, `poly:N`).
    Scale => "scale",
    /// A fit's offset model (`0`, `free`, `poly:N`).
    Offset => "offset",
    /// A fit's wavelength window, nm.
    FitRange => "fit_range",
    /// A fit's loss (`linear`, `cauchy`).
    Loss => "loss",
    /// The residuals file of a fit.
    Residuals => "residuals",
    /// The picture of a fit (PNG or SVG).
    FitPlot => "fit_plot",
    /// The target colours of a colour design: a CSV file.
    Targets => "targets",
    /// Most distinct stacks a colour design returns.
    Solutions => "solutions",
    /// The thickness tolerance below which two designed stacks are the same, nm.
    Distinct => "distinct",
}

impl Param {
    /// A message piece asking for this parameter with a value: `roughness` neutrally,
    /// `--roughness ALPHA` on nacre's command line.
    pub fn arg(self) -> Piece {
        Piece::Arg(self)
    }

    /// This parameter with the value it was given, as an [`Origin`].
    pub fn given(self, value: impl Into<String>) -> Origin {
        Origin::Given(self, value.into())
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How messages spell parameters.
pub trait Naming {
    /// The name of `param`: `angles` ([`Neutral`]) or a flag `--angles`.
    fn name(&self, param: Param) -> &'static str;

    /// `param` as a message asks for it with a value ([`Param::arg`]): by default its
    /// [`Naming::name`]; a command line may add a placeholder (`--roughness ALPHA`).
    fn arg(&self, param: Param) -> String {
        self.name(param).to_string()
    }

    /// `param` with the value it was given ([`Origin::Given`]): `NAME VALUE` by default.
    fn given(&self, param: Param, value: &str) -> String {
        format!("{} {value}", self.name(param))
    }
}

/// The neutral naming of `Display`: [`Param::name`], and `name = value` for given values.
#[derive(Clone, Copy, Debug, Default)]
pub struct Neutral;

impl Naming for Neutral {
    fn name(&self, param: Param) -> &'static str {
        param.name()
    }

    fn given(&self, param: Param, value: &str) -> String {
        format!("{} = {value}", param.name())
    }
}

/// Something that renders with a [`Naming`]: messages, origins and the libraries' errors.
pub trait Render: fmt::Debug {
    /// Writes `self` with parameters spelled by `naming`.
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result;

    /// `self` with `naming`, for `format!` and `to_string`.
    fn named<'a>(&'a self, naming: &'a dyn Naming) -> Named<'a, Self>
    where
        Self: Sized,
    {
        Named(self, naming)
    }
}

/// A [`Render`] value with its [`Naming`]: displays as [`Render::render`].
pub struct Named<'a, T: ?Sized>(&'a T, &'a dyn Naming);

impl<T: Render + ?Sized> fmt::Display for Named<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.render(f, self.1)
    }
}

/// A piece of a [`Msg`].
#[derive(Clone, Debug)]
pub enum Piece {
    /// Plain text.
    Text(String),
    /// A parameter's name: `angles` / `--angles`.
    Param(Param),
    /// A parameter asked for with a value: `roughness` / `--roughness ALPHA`.
    Arg(Param),
    /// Where a value came from.
    Origin(Origin),
    /// Another renderable value, e.g. an error quoted in a message.
    Nested(Arc<dyn Render + Send + Sync>),
}

impl PartialEq for Piece {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Piece::Text(a), Piece::Text(b)) => a == b,
            (Piece::Param(a), Piece::Param(b)) | (Piece::Arg(a), Piece::Arg(b)) => a == b,
            (Piece::Origin(a), Piece::Origin(b)) => a == b,
            // The same value, not an equal one: `Render` has no equality.
            (Piece::Nested(a), Piece::Nested(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

impl Eq for Piece {}

impl From<&str> for Piece {
    fn from(s: &str) -> Self {
        Piece::Text(s.to_string())
    }
}

impl From<String> for Piece {
    fn from(s: String) -> Self {
        Piece::Text(s)
    }
}

impl From<Param> for Piece {
    fn from(p: Param) -> Self {
        Piece::Param(p)
    }
}

impl From<Msg> for Piece {
    fn from(m: Msg) -> Self {
        Piece::Nested(Arc::new(m))
    }
}

impl From<Origin> for Piece {
    fn from(o: Origin) -> Self {
        Piece::Origin(o)
    }
}

/// Message text that may name parameters: text and [`Param`] pieces, rendered with a
/// [`Naming`]. Build one with [`crate::msg!`] or from a `String`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Msg(pub Vec<Piece>);

impl Msg {
    /// A message of `pieces`.
    pub fn from_pieces(pieces: Vec<Piece>) -> Self {
        Msg(pieces)
    }

    /// The parameters the message names, in order.
    pub fn params(&self) -> Vec<Param> {
        self.0
            .iter()
            .filter_map(|p| match p {
                Piece::Param(p) | Piece::Arg(p) => Some(*p),
                _ => None,
            })
            .collect()
    }
}

impl From<String> for Msg {
    fn from(s: String) -> Self {
        Msg(vec![Piece::Text(s)])
    }
}

impl From<&str> for Msg {
    fn from(s: &str) -> Self {
        Msg(vec![Piece::Text(s.to_string())])
    }
}

impl Render for Msg {
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result {
        for piece in &self.0 {
            match piece {
                Piece::Text(t) => f.write_str(t)?,
                Piece::Param(p) => f.write_str(naming.name(*p))?,
                Piece::Arg(p) => f.write_str(&naming.arg(*p))?,
                Piece::Origin(o) => o.render(f, naming)?,
                Piece::Nested(r) => r.render(f, naming)?,
            }
        }
        Ok(())
    }
}

impl fmt::Display for Msg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.render(f, &Neutral)
    }
}

/// A message of text, [`Param`] and other pieces: `msg!["give ", Param::Layer]`.
#[macro_export]
macro_rules! msg {
    ($($piece:expr),* $(,)?) => {
        $crate::param::Msg::from_pieces(vec![$($crate::param::Piece::from($piece)),*])
    };
}

/// Where a value came from, for messages.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A parameter: `layer` / `--layer`.
    Param(Param),
    /// A parameter with the value it was given: `method = fourier` / `--method fourier`.
    Given(Param, String),
    /// A line of a file (recipe, manifest, CSV): `recipe.toml:12`.
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
    },
    /// Anything else (a file, a table, a default, several parameters), as a message.
    Other(Msg),
}

impl Origin {
    /// The parameter the value came from, if it came from one.
    pub fn param(&self) -> Option<Param> {
        match self {
            Origin::Param(p) | Origin::Given(p, _) => Some(*p),
            _ => None,
        }
    }
}

impl From<Param> for Origin {
    fn from(p: Param) -> Self {
        Origin::Param(p)
    }
}

impl From<String> for Origin {
    fn from(s: String) -> Self {
        Origin::Other(s.into())
    }
}

impl From<&String> for Origin {
    fn from(s: &String) -> Self {
        Origin::Other(s.as_str().into())
    }
}

impl From<&str> for Origin {
    fn from(s: &str) -> Self {
        Origin::Other(s.into())
    }
}

impl From<Msg> for Origin {
    fn from(m: Msg) -> Self {
        Origin::Other(m)
    }
}

impl Render for Origin {
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result {
        match self {
            Origin::Param(p) => f.write_str(naming.name(*p)),
            Origin::Given(p, value) => f.write_str(&naming.given(*p, value)),
            Origin::Line { path, line } => write!(f, "{}:{line}", path.display()),
            Origin::Other(m) => m.render(f, naming),
        }
    }
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.render(f, &Neutral)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Flags;

    impl Naming for Flags {
        fn name(&self, param: Param) -> &'static str {
            match param {
                Param::Roughness => "--roughness",
                _ => "--other",
            }
        }
        fn arg(&self, param: Param) -> String {
            format!("{} ALPHA", self.name(param))
        }
    }

    #[test]
    fn names_are_snake_case_and_unique() {
        let mut seen = std::collections::HashSet::new();
        for p in Param::ALL {
            let n = p.name();
            assert!(n.chars().all(|c| c.is_ascii_lowercase() || c == '_'), "{n}");
            assert!(seen.insert(n), "{n} twice");
        }
    }

    #[test]
    fn messages_render_with_a_naming() {
        let m = crate::msg!["needs ", Param::Roughness.arg(), ", see ", Param::Roughness];
        assert_eq!(m.to_string(), "needs roughness, see roughness");
        assert_eq!(
            m.named(&Flags).to_string(),
            "needs --roughness ALPHA, see --roughness"
        );
        let o = Param::Roughness.given("2");
        assert_eq!(o.to_string(), "roughness = 2");
        assert_eq!(o.named(&Flags).to_string(), "--roughness 2");
        let o = Origin::Line {
            path: "r.toml".into(),
            line: 3,
        };
        assert_eq!(o.named(&Flags).to_string(), "r.toml:3");
    }
}
