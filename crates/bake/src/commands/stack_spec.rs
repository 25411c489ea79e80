//! Stack descriptions, from parameters (`ambient`, `layer` `M@THICKNESS`, `substrate`) or
//! from a recipe file.
//!
//! # Stack recipe format (TOML)
//!
//! ```toml
//! # A quarter-wave MgF2 anti-reflection coating on BK7.
//! ambient = "air"            # material spec; default "1.0" (vacuum)
//! substrate = "bk7"          # material spec; default "1.0"
//! angles = "0:89:1"          # optional, degrees in the ambient (flags override)
//! wavelengths = "380:780:5"  # optional, vacuum nm (flags override)
//!
//! [[layers]]                 # films, top first; none for a bare interface
//! material = "mgf2"          # material spec (number, n+ki, bundled name, .yml/.csv path)
//! thickness_nm = 99.75       # physical thickness in nm, ≥ 0 and below 1 m
//!
//! [[layers]]                 # a 2 mm glass slab whose reflections add in intensity
//! material = "bk7"
//! thickness_nm = 2e6
//! incoherent = true          # optional, default false (nacre_optics::incoherent)
//! ```
//!
//! On the command line a layer is `MATERIAL@THICKNESS[:incoherent]`, the thickness in nm
//! (`400`, `400nm`) or with a unit (`1.2um`, `2mm`): `bk7@2mm:incoherent`.
//!
//! Relative material paths are resolved from the recipe's folder. Unknown keys are errors.

use crate::commands::grid::parse_thickness_nm;
use crate::error::{Error, Origin, Param, Result};
use crate::recipe::{line_of, toml_error};
use nacre_format::materials::{MaterialDb, database, resolve_with};
use nacre_optics::{Layer, Stack};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Material used for the ambient and the substrate when none is given: vacuum, a constant
/// index that every wavelength accepts (air differs from it by 3×10⁻⁴; the bundled `air` has
/// data over 230–1690 nm only).
pub const DEFAULT_MEDIUM: &str = "1.0";

/// The default example stack: a 400 nm soap film of constant index 1.33 in vacuum (usable
/// at every wavelength, unlike the bundled `water`, 182–1129 nm).
pub const DEFAULT_LAYER: (&str, f64) = ("1.33", 400.0);

/// A material spec and where it came from (for messages).
#[derive(Clone, Debug)]
pub struct MaterialRef {
    /// The spec text.
    pub spec: String,
    /// The parameter or `file:line`.
    pub context: Origin,
}

/// A stack described by material specs, before the materials are loaded.
#[derive(Clone, Debug)]
pub struct StackSpec {
    /// Ambient medium.
    pub ambient: MaterialRef,
    /// Films, top first, with thickness in nm.
    pub layers: Vec<(MaterialRef, f64)>,
    /// Substrate.
    pub substrate: MaterialRef,
    /// Folder that relative material paths are resolved from.
    pub base_dir: Option<PathBuf>,
    /// Per layer: incoherent (a thick slab, [`nacre_optics::incoherent`]). Empty when every
    /// layer is coherent.
    pub incoherent: Vec<bool>,
}

/// The suffix that marks a layer incoherent: `bk7@2mm:incoherent`.
pub const INCOHERENT_SUFFIX: &str = "incoherent";

/// The thickness from which a layer is refused as absurd: 1 m, in nm.
pub const MAX_THICKNESS_NM: f64 = 1e9;

/// `Some(message)` when `spec` (an ambient or substrate) carries the incoherent suffix.
fn suffix_on_medium(spec: &str) -> Option<&'static str> {
    spec.trim()
        .strip_suffix(INCOHERENT_SUFFIX)
        .is_some_and(|m| m.ends_with(':'))
        .then_some(
            "the ambient and the substrate are semi-infinite and always add their reflections in intensity: `:incoherent` marks a layer (a slab with air behind it is a layer `bk7@2mm:incoherent` on an air substrate)",
        )
}

impl StackSpec {
    /// From command-line values. With no value at all, the default soap film.
    pub fn from_flags(
        ambient: Option<&str>,
        layers: &[String],
        substrate: Option<&str>,
    ) -> Result<Self> {
        let flag = |spec: &str, context: Origin| MaterialRef {
            spec: spec.to_string(),
            context,
        };
        for (param, spec) in [(Param::Ambient, ambient), (Param::Substrate, substrate)] {
            if let Some(message) = spec.and_then(suffix_on_medium) {
                return Err(Error::value(param, spec.unwrap_or_default(), message));
            }
        }
        let mut incoherent = Vec::new();
        let layers = if ambient.is_none() && layers.is_empty() && substrate.is_none() {
            vec![(
                flag(DEFAULT_LAYER.0, "default stack".into()),
                DEFAULT_LAYER.1,
            )]
        } else {
            layers
                .iter()
                .map(|text| {
                    let (m, d) = text.rsplit_once('@').ok_or_else(|| {
                        Error::value(
                            Param::Layer,
                            text.clone(),
                            "expected MATERIAL@THICKNESS, e.g. `water@400nm`",
                        )
                    })?;
                    if m.trim().is_empty() {
                        return Err(Error::value(
                            Param::Layer,
                            text.clone(),
                            "the material before `@` is empty",
                        ));
                    }
                    let (d, suffix) = match d.split_once(':') {
                        Some((d, suffix)) => (d, Some(suffix)),
                        None => (d, None),
                    };
                    let inc = match suffix {
                        None => false,
                        Some(s) if s.trim() == INCOHERENT_SUFFIX => true,
                        Some(s) => {
                            return Err(Error::value(
                                Param::Layer,
                                text.clone(),
                                format!(
                                    "unknown suffix `:{s}`: the one suffix a layer takes is `:incoherent`, e.g. `bk7@2mm:incoherent`"
                                ),
                            ));
                        }
                    };
                    let d = parse_thickness_nm(Param::Layer, d).map_err(|e| match e {
                        Error::Value { message, .. } => {
                            Error::value(Param::Layer, text.clone(), message)
                        }
                        other => other,
                    })?;
                    if d >= MAX_THICKNESS_NM {
                        return Err(Error::value(
                            Param::Layer,
                            text.clone(),
                            format!(
                                "thickness {d} nm is a metre or more: a layer must be thinner than 1 m (units: `nm`, `um`, `mm`)"
                            ),
                        ));
                    }
                    incoherent.push(inc);
                    Ok((flag(m, Param::Layer.into()), d))
                })
                .collect::<Result<_>>()?
        };
        Ok(StackSpec {
            ambient: flag(ambient.unwrap_or(DEFAULT_MEDIUM), Param::Ambient.into()),
            layers,
            substrate: flag(substrate.unwrap_or(DEFAULT_MEDIUM), Param::Substrate.into()),
            base_dir: None,
            incoherent: if incoherent.contains(&true) {
                incoherent
            } else {
                Vec::new()
            },
        })
    }

    /// The stack a baked film table (`film-lut`, `rough-film-lut`) at `path` was made for: its
    /// ambient, the default film ([`DEFAULT_LAYER`]), its fixed layers and its base, named
    /// by the manifest in messages. None when the manifest records no ambient or base.
    pub fn for_table(m: &nacre_format::Manifest, path: &Path) -> Option<Self> {
        if m.ambient.is_empty() || m.base.is_empty() {
            return None;
        }
        let from = |spec: &str, what: &str| MaterialRef {
            spec: spec.to_string(),
            context: format!("{} ({what} of table `{}`)", path.display(), m.name).into(),
        };
        let mut layers = vec![(
            MaterialRef {
                spec: DEFAULT_LAYER.0.into(),
                context: "default stack".into(),
            },
            DEFAULT_LAYER.1,
        )];
        layers.extend(
            m.under
                .iter()
                .map(|(spec, d)| (from(spec, "fixed layer"), *d)),
        );
        Some(StackSpec {
            ambient: from(&m.ambient, "ambient"),
            layers,
            substrate: from(&m.base, "base"),
            base_dir: path.parent().map(Path::to_path_buf),
            incoherent: Vec::new(),
        })
    }

    /// `e` with the input named when it is a material's complaint about a wavelength (no
    /// data there, no physical index there, an absorbing ambient) about one of `stack`'s
    /// materials, `stack` built from `self`: the ambient's, a layer's or the substrate's
    /// origin. Other errors are returned as they are.
    pub fn attribute(&self, stack: &Stack, e: Error) -> Error {
        let Error::Optics(source) = e else { return e };
        let material = match &source {
            nacre_optics::Error::WavelengthOutOfRange { material, .. }
            | nacre_optics::Error::NonPhysicalIndex { material, .. }
            | nacre_optics::Error::NoPhysicalIndex { material, .. }
            | nacre_optics::Error::AbsorbingAmbient { material, .. } => material,
            _ => return Error::Optics(source),
        };
        let mut named = std::iter::once((stack.ambient(), &self.ambient))
            .chain(
                stack
                    .layers()
                    .iter()
                    .map(|l| &l.material)
                    .zip(self.layers.iter().map(|(m, _)| m)),
            )
            .chain(std::iter::once((stack.substrate(), &self.substrate)));
        match named.find(|(m, _)| m.name() == material) {
            Some((_, r)) => Error::optics_in(r.context.clone(), source),
            None => Error::Optics(source),
        }
    }

    /// Loads the materials and builds the stack, with the material database set by
    /// [`nacre_format::materials::set_database`].
    pub fn build(&self) -> Result<Stack> {
        self.build_with(database().as_ref())
    }

    /// Loads the materials and builds the stack, reading `shelf/book/page` materials from
    /// `db` (None: such specs are an error that says how to set a database).
    pub fn build_with(&self, db: Option<&MaterialDb>) -> Result<Stack> {
        let base = self.base_dir.as_deref();
        let load = |m: &MaterialRef| resolve_with(&m.spec, m.context.clone(), base, db);
        let ambient = load(&self.ambient)?;
        let layers = self
            .layers
            .iter()
            .map(|(m, d)| {
                Ok(Layer {
                    material: load(m)?,
                    thickness_nm: *d,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let substrate = load(&self.substrate)?;
        let stack = Stack::new(ambient, layers, substrate)
            .map_err(|source| Error::optics_in(self.ambient.context.clone(), source))?;
        if self.incoherent.is_empty() {
            return Ok(stack);
        }
        stack
            .with_incoherent(self.incoherent.clone())
            .map_err(|source| Error::optics_in(self.ambient.context.clone(), source))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLayer {
    material: Spanned<String>,
    thickness_nm: Spanned<f64>,
    #[serde(default)]
    incoherent: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStackRecipe {
    ambient: Option<Spanned<String>>,
    substrate: Option<Spanned<String>>,
    #[serde(default)]
    layers: Vec<RawLayer>,
    angles: Option<String>,
    wavelengths: Option<String>,
}

/// A stack recipe file: the stack plus optional sampling ranges.
#[derive(Clone, Debug)]
pub struct StackRecipe {
    /// The stack.
    pub stack: StackSpec,
    /// `angles` range text, if given.
    pub angles: Option<String>,
    /// `wavelengths` range text, if given.
    pub wavelengths: Option<String>,
}

impl StackRecipe {
    /// Reads a stack recipe file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, &text)
    }

    /// Parses a stack recipe's text; `path` names it in messages and anchors relative
    /// material paths.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        let raw: RawStackRecipe = toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        let at = |span: std::ops::Range<usize>| Origin::Line {
            path: path.to_path_buf(),
            line: line_of(text, span.start),
        };
        let mref = |s: &Spanned<String>| MaterialRef {
            spec: s.get_ref().clone(),
            context: at(s.span()),
        };
        let default = |what: &str| MaterialRef {
            spec: DEFAULT_MEDIUM.into(),
            context: format!("{} ({what} default)", path.display()).into(),
        };
        let mut layers = Vec::with_capacity(raw.layers.len());
        for layer in &raw.layers {
            let d = *layer.thickness_nm.get_ref();
            if !(d >= 0.0 && d.is_finite()) {
                return Err(Error::recipe(
                    path.to_path_buf(),
                    line_of(text, layer.thickness_nm.span().start),
                    format!("thickness_nm = {d}: must be finite and non-negative"),
                ));
            }
            if d >= MAX_THICKNESS_NM {
                return Err(Error::recipe(
                    path.to_path_buf(),
                    line_of(text, layer.thickness_nm.span().start),
                    format!("thickness_nm = {d}: a layer must be thinner than 1 m (1e9 nm)"),
                ));
            }
            layers.push((mref(&layer.material), d));
        }
        for (what, medium) in [("ambient", &raw.ambient), ("substrate", &raw.substrate)] {
            if let Some(m) = medium
                && let Some(message) = suffix_on_medium(m.get_ref())
            {
                return Err(Error::recipe(
                    path.to_path_buf(),
                    line_of(text, m.span().start),
                    format!("{what} = \"{}\": {message}", m.get_ref()),
                ));
            }
        }
        let incoherent: Vec<bool> = raw.layers.iter().map(|l| l.incoherent).collect();
        Ok(StackRecipe {
            stack: StackSpec {
                ambient: raw
                    .ambient
                    .as_ref()
                    .map_or_else(|| default("ambient"), mref),
                layers,
                substrate: raw
                    .substrate
                    .as_ref()
                    .map_or_else(|| default("substrate"), mref),
                base_dir: path.parent().map(Path::to_path_buf),
                incoherent: if incoherent.contains(&true) {
                    incoherent
                } else {
                    Vec::new()
                },
            },
            angles: raw.angles,
            wavelengths: raw.wavelengths,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_and_defaults() {
        let s = StackSpec::from_flags(None, &[], None).unwrap();
        assert_eq!(s.layers.len(), 1);
        assert_eq!(s.layers[0].0.spec, "1.33");
        assert_eq!(s.ambient.spec, "1.0");
        assert_eq!(s.substrate.spec, "1.0");
        // The defaults work at every wavelength.
        let stack = s.build().unwrap();
        for wl in [100.0, 380.0, 2000.0, 20000.0] {
            stack.evaluate(0.0, wl).unwrap();
        }
        let s = StackSpec::from_flags(None, &[], Some("bk7")).unwrap();
        assert!(s.layers.is_empty());
        let s = StackSpec::from_flags(
            None,
            &["mgf2@99.75nm".into(), "1.5+0.1i@10".into()],
            Some("bk7"),
        )
        .unwrap();
        assert_eq!(s.layers[0].1, 99.75);
        assert_eq!(s.layers[1].0.spec, "1.5+0.1i");
        s.build().unwrap();
        for bad in ["water", "water@-3", "@5", "water@x"] {
            let e = StackSpec::from_flags(None, &[bad.into()], None)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("layer `"), "{bad}: {e}");
        }
    }

    #[test]
    fn recipe_errors_have_lines() {
        let p = Path::new("r.toml");
        let r = StackRecipe::parse(
            p,
            "substrate = \"bk7\"\n[[layers]]\nmaterial = \"mgf2\"\nthickness_nm = 100\n",
        )
        .unwrap();
        assert_eq!(r.stack.layers[0].1, 100.0);
        r.stack.build().unwrap();
        let e = StackRecipe::parse(
            p,
            "substrate = \"bk7\"\n[[layers]]\nmaterial = \"mgf2\"\nthickness_nm = -1\n",
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.toml:4: thickness_nm = -1: must be finite and non-negative"
        );
        let e = StackRecipe::parse(p, "substrate = \"bk7\"\ncolour = 3\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.toml:2: unknown field `colour`"), "{e}");
        let r = StackRecipe::parse(p, "\n\nsubstrate = \"nope\"\n").unwrap();
        let e = r.stack.build().unwrap_err().to_string();
        assert!(e.starts_with("r.toml:3: unknown material `nope`"), "{e}");
    }
}
