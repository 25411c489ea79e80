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
//!
//! # Templates: ranges mark free parameters
//!
//! A fit template ([`TemplateSpec`], what `nacre fit` reads) is the same stack where a range
//! marks a free parameter. On the command line a thickness range is `LO:HI`
//! (`sio2@50:400`, units allowed: `sio2@0.5um:2um`) and a constant real index range is
//! `NLO:NHI` in place of the material (`1.3:1.7@100:600`: index free in 1.3–1.7, thickness
//! free in 100–600 nm). In a recipe:
//!
//! ```toml
//! [[layers]]
//! material = "1.3:1.7"         # a constant index free in 1.3–1.7
//! thickness_nm = [100, 600]    # thickness free in 100–600 nm
//! ```
//!
//! A fit writes the recipe back with the fitted values and their 1σ uncertainties beside
//! them (`thickness_sigma_nm`, `index_sigma`) and a `[fit]` table; every reader accepts
//! those keys and ignores them. A stack recipe (not a template) refuses ranges.

use crate::commands::grid::parse_thickness_nm;
use crate::error::{Error, Origin, Param, Result};
use crate::recipe::{line_of, toml_error};
use nacre_format::materials::{MaterialDb, database, resolve_with};
use nacre_optics::fit::{Free, FreeKind};
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

/// One `--layer` value, parsed.
struct LayerFlag {
    /// The material spec (for a free index, the middle of its range as text).
    material: String,
    /// A free constant index's bounds.
    index: Option<(f64, f64)>,
    /// The thickness (nm), or a range's lower bound, and a range's upper bound.
    thickness_nm: (f64, Option<f64>),
    incoherent: bool,
}

/// `Some((lo, hi))` when `text` is `A:B` with both numbers.
fn number_pair(text: &str) -> Option<(f64, f64)> {
    let (a, b) = text.split_once(':')?;
    Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
}

/// Refuses bounds `lo:hi` of `what` that are inverted or (for an index) not positive.
fn check_bounds(lo: f64, hi: f64, what: &str) -> std::result::Result<(), String> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(format!("{what} bounds {lo}:{hi} must be finite"));
    }
    if lo > hi {
        return Err(format!(
            "{what} bounds {lo}:{hi} are inverted: write the lower bound first ({hi}:{lo})"
        ));
    }
    if what == "index" && lo <= 0.0 {
        return Err(format!("index bounds {lo}:{hi}: an index must be positive"));
    }
    Ok(())
}

/// Parses `MATERIAL@THICKNESS[:incoherent]`; with `ranges`, also `MATERIAL@LO:HI` and
/// `NLO:NHI@…` (a template's free parameters). `context` names the input in messages
/// (`--layer`, or Python's `layers[i]`).
fn parse_layer_flag(context: &Origin, text: &str, ranges: bool) -> Result<LayerFlag> {
    let bad = |message: String| Error::value(context.clone(), text.to_string(), message);
    let (m, d) = text.rsplit_once('@').ok_or_else(|| {
        Error::value(
            context.clone(),
            text.to_string(),
            "expected MATERIAL@THICKNESS, e.g. `water@400nm`",
        )
    })?;
    if m.trim().is_empty() {
        return Err(bad("the material before `@` is empty".into()));
    }
    let index = match number_pair(m) {
        Some((lo, hi)) if ranges => {
            check_bounds(lo, hi, "index").map_err(bad)?;
            Some((lo, hi))
        }
        _ => None,
    };
    let thickness = |d: &str| {
        let d = parse_thickness_nm(context.clone(), d).map_err(|e| match e {
            Error::Value { message, .. } => {
                Error::value(context.clone(), text.to_string(), message)
            }
            other => other,
        })?;
        if d >= MAX_THICKNESS_NM {
            return Err(bad(format!(
                "thickness {d} nm is a metre or more: a layer must be thinner than 1 m (units: `nm`, `um`, `mm`)"
            )));
        }
        Ok(d)
    };
    let (d, suffix) = match d.split_once(':') {
        Some((d, suffix)) => (d, Some(suffix)),
        None => (d, None),
    };
    let (thickness_nm, incoherent) = match suffix {
        None => ((thickness(d)?, None), false),
        Some(s) if s.trim() == INCOHERENT_SUFFIX => ((thickness(d)?, None), true),
        Some(s) if ranges => {
            let (lo, hi) = (thickness(d)?, thickness(s)?);
            check_bounds(lo, hi, "thickness").map_err(bad)?;
            ((lo, Some(hi)), false)
        }
        Some(s) => {
            return Err(bad(format!(
                "unknown suffix `:{s}`: the one suffix a layer takes is `:incoherent`, e.g. `bk7@2mm:incoherent`"
            )));
        }
    };
    Ok(LayerFlag {
        material: match index {
            Some((lo, hi)) => format!("{}", 0.5 * (lo + hi)),
            None => m.to_string(),
        },
        index,
        thickness_nm,
        incoherent,
    })
}

/// One layer in the command line's syntax `MATERIAL@THICKNESS[:incoherent]` (`water@400`,
/// `mgf2@99.75nm`, `bk7@2mm:incoherent`; no ranges): the material spec, the thickness in nm
/// (below [`MAX_THICKNESS_NM`]) and whether the layer is incoherent, with the messages of
/// `--layer`. `context` names the input (Python's `layers[i]`).
pub fn parse_layer(context: impl Into<Origin>, text: &str) -> Result<(String, f64, bool)> {
    let l = parse_layer_flag(&context.into(), text, false)?;
    Ok((l.material, l.thickness_nm.0, l.incoherent))
}

/// A free parameter of a template and where it was given.
#[derive(Clone, Debug)]
pub struct FreeSpec {
    /// The parameter and its bounds.
    pub free: Free,
    /// The flag or `file:line` that set it free.
    pub origin: Origin,
}

/// A fit template before the materials are loaded: a stack whose thicknesses and constant
/// indices may be ranges (the module's documentation gives the syntax).
#[derive(Clone, Debug)]
pub struct TemplateSpec {
    /// The stack, each free parameter at the middle of its range.
    pub stack: StackSpec,
    /// The free parameters, films top first, a film's index before its thickness.
    pub free: Vec<FreeSpec>,
    /// `angles` range text of a recipe, if given.
    pub angles: Option<String>,
    /// `wavelengths` range text of a recipe, if given.
    pub wavelengths: Option<String>,
}

/// The free parameters of film `layer` (1-based): its index range, its thickness range.
fn free_of(
    layer: usize,
    index: Option<(f64, f64)>,
    thickness_nm: (f64, Option<f64>),
    origin: &Origin,
) -> impl Iterator<Item = FreeSpec> {
    let index = index.map(|(lo, hi)| Free {
        layer,
        kind: FreeKind::Index,
        lo,
        hi,
    });
    let thickness = thickness_nm.1.map(|hi| Free {
        layer,
        kind: FreeKind::ThicknessNm,
        lo: thickness_nm.0,
        hi,
    });
    index
        .into_iter()
        .chain(thickness)
        .map(move |free| FreeSpec {
            free,
            origin: origin.clone(),
        })
}

impl TemplateSpec {
    /// From command-line values (`--layer` values may hold ranges). With no value at all,
    /// the default soap film with nothing free.
    pub fn from_flags(
        ambient: Option<&str>,
        layers: &[String],
        substrate: Option<&str>,
    ) -> Result<Self> {
        let plain: Vec<String> = Vec::new();
        let mut stack = StackSpec::from_flags(ambient, &plain, substrate)?;
        if layers.is_empty() {
            return Ok(TemplateSpec {
                stack,
                free: Vec::new(),
                angles: None,
                wavelengths: None,
            });
        }
        let mut free = Vec::new();
        let mut incoherent = Vec::new();
        stack.layers.clear();
        for (i, text) in layers.iter().enumerate() {
            let l = parse_layer_flag(&Param::Layer.into(), text, true)?;
            let origin = Param::Layer.given(text.clone());
            free.extend(free_of(i + 1, l.index, l.thickness_nm, &origin));
            let d = match l.thickness_nm {
                (lo, Some(hi)) => 0.5 * (lo + hi),
                (d, None) => d,
            };
            incoherent.push(l.incoherent);
            stack.layers.push((
                MaterialRef {
                    spec: l.material,
                    context: Param::Layer.into(),
                },
                d,
            ));
        }
        if incoherent.contains(&true) {
            stack.incoherent = incoherent;
        }
        Ok(TemplateSpec {
            stack,
            free,
            angles: None,
            wavelengths: None,
        })
    }

    /// Reads a template recipe file (a stack recipe whose values may be ranges).
    pub fn read(path: &Path) -> Result<Self> {
        let text = read_text(path)?;
        Self::parse(path, &text)
    }

    /// Parses a template recipe's text; `path` names it in messages.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        parse_recipe(path, text, true)
    }
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
                    let l = parse_layer_flag(&Param::Layer.into(), text, false)?;
                    incoherent.push(l.incoherent);
                    Ok((flag(&l.material, Param::Layer.into()), l.thickness_nm.0))
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
            // The film is coherent; a slab under it keeps its flag (film-lut over a pane).
            incoherent: if m.under_incoherent.contains(&true) {
                std::iter::once(false)
                    .chain((0..m.under.len()).map(|j| m.under_incoherent.get(j) == Some(&true)))
                    .collect()
            } else {
                Vec::new()
            },
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

/// A thickness in a recipe: a number, or `[LO, HI]` in a template.
#[derive(Deserialize)]
#[serde(untagged)]
enum RawThickness {
    Fixed(f64),
    Range([f64; 2]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLayer {
    material: Spanned<String>,
    thickness_nm: Spanned<RawThickness>,
    #[serde(default)]
    incoherent: bool,
    /// A fit's 1σ uncertainty of the thickness (written by a fit, ignored here).
    #[allow(dead_code)]
    thickness_sigma_nm: Option<f64>,
    /// A fit's 1σ uncertainty of a constant index (written by a fit, ignored here).
    #[allow(dead_code)]
    index_sigma: Option<f64>,
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
    /// A fit's summary (written by a fit, ignored here).
    #[allow(dead_code)]
    fit: Option<toml::Table>,
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

/// The text of the file at `path`.
fn read_text(path: &Path) -> Result<String> {
    Ok(
        std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
            path: path.to_path_buf(),
            source,
        })?,
    )
}

/// Parses a stack recipe (`ranges` false: ranges are refused) or a template recipe.
fn parse_recipe(path: &Path, text: &str, ranges: bool) -> Result<TemplateSpec> {
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
    let mut free = Vec::new();
    for (i, layer) in raw.layers.iter().enumerate() {
        let line = line_of(text, layer.thickness_nm.span().start);
        let refuse = |message: String| Error::recipe(path.to_path_buf(), line, message);
        let check = |d: f64| {
            if !(d >= 0.0 && d.is_finite()) {
                return Err(refuse(format!(
                    "thickness_nm = {d}: must be finite and non-negative"
                )));
            }
            if d >= MAX_THICKNESS_NM {
                return Err(refuse(format!(
                    "thickness_nm = {d}: a layer must be thinner than 1 m (1e9 nm)"
                )));
            }
            Ok(d)
        };
        let thickness_nm = match layer.thickness_nm.get_ref() {
            RawThickness::Fixed(d) => (check(*d)?, None),
            RawThickness::Range([lo, hi]) if ranges => {
                let (lo, hi) = (check(*lo)?, check(*hi)?);
                check_bounds(lo, hi, "thickness")
                    .map_err(|m| refuse(format!("thickness_nm = [{lo}, {hi}]: {m}")))?;
                (lo, Some(hi))
            }
            RawThickness::Range([lo, hi]) => {
                return Err(refuse(format!(
                    "thickness_nm = [{lo}, {hi}] is a range: only a fit template takes ranges (a stack needs one thickness)"
                )));
            }
        };
        let mut material = mref(&layer.material);
        let index = match number_pair(&material.spec) {
            Some((lo, hi)) if ranges => {
                check_bounds(lo, hi, "index").map_err(|m| {
                    Error::recipe(
                        path.to_path_buf(),
                        line_of(text, layer.material.span().start),
                        format!("material = \"{}\": {m}", material.spec),
                    )
                })?;
                material.spec = format!("{}", 0.5 * (lo + hi));
                Some((lo, hi))
            }
            _ => None,
        };
        free.extend(free_of(
            i + 1,
            index,
            thickness_nm,
            &at(layer.thickness_nm.span()),
        ));
        let d = match thickness_nm {
            (lo, Some(hi)) => 0.5 * (lo + hi),
            (d, None) => d,
        };
        layers.push((material, d));
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
    Ok(TemplateSpec {
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
        free,
        angles: raw.angles,
        wavelengths: raw.wavelengths,
    })
}

impl StackRecipe {
    /// Reads a stack recipe file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = read_text(path)?;
        Self::parse(path, &text)
    }

    /// Parses a stack recipe's text; `path` names it in messages and anchors relative
    /// material paths.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        let t = parse_recipe(path, text, false)?;
        Ok(StackRecipe {
            stack: t.stack,
            angles: t.angles,
            wavelengths: t.wavelengths,
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
