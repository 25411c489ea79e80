//! The recipe sections every table kind shares — `[colour]`, `[stack]`, `[output]` — and
//! the table name, each parsed once here for every kind (`crate::kinds`).

use crate::error::{Error, Origin, Result};
use nacre_format::materials::resolve;
use nacre_format::table_io::Precision;
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace};
use nacre_optics::{Layer, Material};
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawColour {
    observer: Option<Spanned<String>>,
    illuminant: Option<Spanned<String>>,
    space: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLayer {
    pub(crate) material: Spanned<String>,
    pub(crate) thickness_nm: Spanned<f64>,
    /// A thick slab whose reflections add in intensity ([`nacre_optics::incoherent`]);
    /// `film-lut` only.
    #[serde(default)]
    pub(crate) incoherent: Option<Spanned<bool>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStack {
    pub(crate) ambient: Spanned<String>,
    pub(crate) film: Option<String>,
    pub(crate) base: Spanned<String>,
    #[serde(default)]
    pub(crate) under: Vec<RawLayer>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, untagged)]
pub(crate) enum Toggle {
    Bool(bool),
    Word(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawOutput {
    pub(crate) precision: Option<Precision>,
    pub(crate) png: Option<bool>,
    pub(crate) transmittance: Option<Toggle>,
}

/// The `[output]` section of the table kinds that write film-like tables, resolved.
pub(crate) struct OutputSettings {
    /// OpenEXR precision (`half` unless the recipe says `float`).
    pub(crate) precision: Precision,
    /// Also write 16-bit PNGs (the kind's default unless the recipe says).
    pub(crate) png: bool,
    /// Bake the transmittance table (`auto`: when every layer under the film and the base
    /// are transparent).
    pub(crate) transmittance: bool,
}

impl OutputSettings {
    /// Resolves `[output]` of the recipe `path` for a stack whose layers `under` and `base`
    /// decide what `transmittance = "auto"` means; `png_default` is the kind's default for
    /// `png`.
    ///
    /// # Errors
    /// [`nacre_format::Error::Invalid`] for a `transmittance` that is not `"auto"`, true or false.
    pub(crate) fn parse(
        path: &Path,
        output: Option<RawOutput>,
        under: &[Layer],
        base: &Material,
        png_default: bool,
    ) -> Result<Self> {
        let output = output.unwrap_or(RawOutput {
            precision: None,
            png: None,
            transmittance: None,
        });
        let transmits = under
            .iter()
            .map(|l| &l.material)
            .chain(std::iter::once(base))
            .all(is_transparent);
        let transmittance = match output.transmittance {
            None => transmits,
            Some(Toggle::Bool(b)) => b,
            Some(Toggle::Word(w)) if w == "auto" => transmits,
            Some(Toggle::Word(w)) => {
                return Err(Error::invalid(
                    path.display().to_string(),
                    format!("[output] transmittance = \"{w}\": expected \"auto\", true or false"),
                ));
            }
        };
        Ok(OutputSettings {
            precision: output.precision.unwrap_or(Precision::Half),
            png: output.png.unwrap_or(png_default),
            transmittance,
        })
    }
}

fn parse_name<T: std::str::FromStr<Err = nacre_optics::Error>>(
    path: &Path,
    text: &str,
    value: &Option<Spanned<String>>,
    default: T,
) -> Result<T> {
    match value {
        None => Ok(default),
        Some(s) => s.get_ref().parse().map_err(|e: nacre_optics::Error| {
            Error::recipe(
                path.to_path_buf(),
                line_of(text, s.span().start),
                e.to_string(),
            )
        }),
    }
}

/// The materials of a table recipe's `[stack]` (shared by the `film-lut` and
/// `rough-film-lut` kinds): ambient, base and the layers under the film, resolved.
pub(crate) struct RecipeStack {
    pub(crate) ambient: Material,
    /// The ambient's constant real index n₀.
    pub(crate) ambient_index: f64,
    pub(crate) base: Material,
    pub(crate) under: Vec<Layer>,
    /// `(material spec, thickness_nm)` of each layer under the film, as written.
    pub(crate) under_specs: Vec<(String, f64)>,
    /// Per layer under the film: incoherent (`incoherent = true`, a thick slab). Empty when
    /// every layer is coherent.
    pub(crate) under_incoherent: Vec<bool>,
}

impl RecipeStack {
    /// Resolves `stack` of the recipe `path` (text `text`) for a table of `kind`.
    ///
    /// # Errors
    /// [`nacre_format::Error::Invalid`] naming the file and line of an ambient without a constant real
    /// index or a material that cannot be resolved; [`nacre_format::Error::Parse`] for a negative or
    /// non-finite layer thickness.
    pub(crate) fn parse(path: &Path, text: &str, stack: &RawStack, kind: &str) -> Result<Self> {
        let at = |span: std::ops::Range<usize>| Origin::Line {
            path: path.to_path_buf(),
            line: line_of(text, span.start),
        };
        let base_dir = path.parent();
        let ambient = resolve(stack.ambient.get_ref(), at(stack.ambient.span()), base_dir)?;
        let ambient_index = constant_real_index(&ambient).ok_or_else(|| Error::invalid(at(stack.ambient.span()), format!(
                "the ambient of a {kind} must have a constant real index (e.g. \"1.0\"), not `{}`",
                stack.ambient.get_ref()
            )))?;
        let base = resolve(stack.base.get_ref(), at(stack.base.span()), base_dir)?;
        let mut under = Vec::new();
        let mut under_specs = Vec::new();
        let mut under_incoherent = Vec::new();
        for l in &stack.under {
            let incoherent = l.incoherent.as_ref().is_some_and(|i| *i.get_ref());
            if incoherent && kind != "film-lut" {
                let span = l.incoherent.as_ref().expect("set").span();
                return Err(Error::recipe(
                    path.to_path_buf(),
                    line_of(text, span.start),
                    format!(
                        "incoherent = true: a {kind} takes coherent layers only; an incoherent slab under the film is a `film-lut`'s"
                    ),
                ));
            }
            under_incoherent.push(incoherent);
            let d = *l.thickness_nm.get_ref();
            if !(d >= 0.0 && d.is_finite()) {
                return Err(Error::recipe(
                    path.to_path_buf(),
                    line_of(text, l.thickness_nm.span().start),
                    format!("thickness_nm = {d}: must be finite and non-negative"),
                ));
            }
            under.push(Layer {
                material: resolve(l.material.get_ref(), at(l.material.span()), base_dir)?,
                thickness_nm: d,
            });
            under_specs.push((l.material.get_ref().clone(), d));
        }
        if !under_incoherent.contains(&true) {
            under_incoherent.clear();
        }
        Ok(RecipeStack {
            ambient,
            ambient_index,
            base,
            under,
            under_specs,
            under_incoherent,
        })
    }
}

/// The real index of a constant, non-absorbing material.
pub(crate) fn constant_real_index(m: &Material) -> Option<f64> {
    if !m.is_constant() {
        return None;
    }
    let n = m.index_at(550.0).ok()?;
    (n.im == 0.0).then_some(n.re)
}

/// True when the material is practically transparent (κ ≤ 1e-3) over 360–830 nm.
pub(crate) fn is_transparent(m: &Material) -> bool {
    (0..=94).all(|i| {
        m.index_at(360.0 + 5.0 * f64::from(i))
            .is_ok_and(|n| n.im <= 1e-3)
    })
}

/// Parses the `[colour]` section shared by every kind.
pub(crate) fn parse_colour(
    path: &Path,
    text: &str,
    colour: Option<RawColour>,
) -> Result<Colorimeter> {
    let colour = colour.unwrap_or(RawColour {
        observer: None,
        illuminant: None,
        space: None,
    });
    Ok(Colorimeter::new(
        parse_name(path, text, &colour.observer, Observer::Cie1931_2Deg)?,
        parse_name(path, text, &colour.illuminant, Illuminant::D65)?,
        parse_name(
            path,
            text,
            &colour.space,
            OutputSpace::Rgb(nacre_optics::colour::RgbSpace::Srgb),
        )?,
    ))
}

/// The table name of a recipe: its file stem, restricted to letters, digits, `-` and `_`.
pub(crate) fn table_name(path: &Path) -> Result<String> {
    path.file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| {
            !s.is_empty()
                && s.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        })
        .map(str::to_string)
        .ok_or_else(|| Error::recipe(path.to_path_buf(), 1, "the recipe's file name (the table name) must use only letters, digits, `-` and `_`"
                    ))
}

/// 1-based line of byte offset `at` in `text`.
pub fn line_of(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Converts a `toml` error into a recipe error with its line.
pub fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> Error {
    Error::recipe(
        path.to_path_buf(),
        e.span().map_or(1, |s| line_of(text, s.start)),
        e.message().trim().to_string(),
    )
}
