//! `nacre bake`: recipes, the default table set, and manifests.
//!
//! # Recipe format (TOML), table kind `film-lut`
//!
//! ```toml
//! kind = "film-lut"                 # required
//! description = "film on glass"     # optional, copied to the manifest
//!
//! [colour]                          # optional; these are the defaults
//! observer = "1931"                 # 1931 | 1964
//! illuminant = "d65"                # d65 | d50 | a | e
//! space = "srgb"                    # xyz | srgb | rec2020 | p3 | acescg (linear)
//!
//! [stack]
//! ambient = "1.0"                   # constant, non-absorbing
//! film = "thin film"                # optional label; the film index is an axis
//! base = "1.5"                      # any material spec (number, n+ki, bundled, file)
//! under = [ { material = "water", thickness_nm = 50.0 } ]   # optional fixed layers under the film
//!
//! [axes]
//! cos_theta_count = 32              # texels along cos θ (square mapping)
//! thickness_nm = [0.0, 1200.0]      # film thickness range
//! opd_count = 384                   # texels along the optical path difference
//! film_ior = [1.0, 2.5]             # film index range (≥ ambient index)
//! film_ior_count = 32
//!
//! [output]                          # optional; these are the defaults
//! precision = "half"                # half | float (OpenEXR)
//! png = true                        # also a 16-bit PNG when every value is in [0, 1]
//! transmittance = "auto"            # auto (when the base transmits) | true | false
//! ```
//!
//! The table is named after the recipe file (`film-gold.toml` → `film-gold`). Outputs in
//! the output folder: `NAME.json` (the manifest: the only thing the runtime reads),
//! `NAME.reflectance.exr` (+ `.png`) and, when baked, `NAME.transmittance.exr` (+ `.png`),
//! and beside each EXR the same table as a KTX 2.0 texture, `NAME.QUANTITY.ktx2` (3-D
//! `RGBA16F`; a `fourier` table gives one `NAME.ktx2`, a 2-D array `RGBA32F` texture with
//! every mip level: see [`crate::ktx2`]). Every file is written atomically; the manifest last.

use crate::error::{Error, Result};
use crate::film_lut::{FilmLut, FilmLutAxes, FilmLutJob, validate_axes};
use crate::fourier_table::{FourierAxes, FourierTable};
use crate::materials::resolve;
use crate::rough_lut::{RoughLutAxes, RoughRecipe};
use crate::stack_spec::{line_of, toml_error};
use crate::table_io::{self, Precision, Table3};
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace};
use nacre_optics::{Layer, Material};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Most texels one table may have (2²⁴ ≈ 16.8 million: 96 MiB of half-float RGB per
/// quantity). Larger recipes are refused before any work.
pub const MAX_TEXELS: u64 = 1 << 24;

/// Manifest format identifier.
pub const MANIFEST_FORMAT: &str = "nacre-table/1";

/// The `quantity` of a `fourier` table's KTX2 file (every level in one file).
pub const FOURIER_KTX2_QUANTITY: &str = "all levels";

/// The `tables/` folder: `./tables` when it exists (running from a checkout), else the
/// checkout this binary was built from.
pub fn tables_dir() -> PathBuf {
    let here = PathBuf::from("tables");
    if here.join("recipes").is_dir() || here.join("baked").is_dir() {
        return here;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables")
}

/// The default recipes folder.
pub fn default_recipes_dir() -> PathBuf {
    tables_dir().join("recipes")
}

/// The default output folder.
pub fn default_baked_dir() -> PathBuf {
    tables_dir().join("baked")
}

/// Resolves a table reference: a manifest path, or the name of a default-set table.
pub fn resolve_table(name_or_path: &str) -> PathBuf {
    let p = Path::new(name_or_path);
    if name_or_path.ends_with(".json") || p.components().count() > 1 {
        return p.to_path_buf();
    }
    default_baked_dir().join(format!("{name_or_path}.json"))
}

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
#[serde(deny_unknown_fields)]
struct RawAxes {
    cos_theta_count: usize,
    thickness_nm: [f64; 2],
    opd_count: usize,
    film_ior: [f64; 2],
    film_ior_count: usize,
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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRecipe {
    #[allow(dead_code)] // checked before the full parse
    kind: Spanned<String>,
    description: Option<String>,
    colour: Option<RawColour>,
    stack: RawStack,
    axes: Spanned<RawAxes>,
    output: Option<RawOutput>,
}

/// A parsed `film-lut` recipe.
pub struct Recipe {
    /// Table name (the recipe's file stem).
    pub name: String,
    /// The recipe file.
    pub path: PathBuf,
    /// The recipe's text, recorded in the manifest.
    pub text: String,
    /// Description.
    pub description: String,
    /// Colour settings.
    pub colorimeter: Colorimeter,
    /// Material specs as written.
    pub ambient_spec: String,
    /// Film label.
    pub film_label: String,
    /// Base spec.
    pub base_spec: String,
    /// Fixed layers under the film (spec, thickness).
    pub under_specs: Vec<(String, f64)>,
    /// The job.
    pub job: FilmLutJob,
    /// Output precision.
    pub precision: Precision,
    /// Also write PNGs.
    pub png: bool,
}

fn parse_name<T: std::str::FromStr<Err = nacre_optics::Error>>(
    path: &Path,
    text: &str,
    value: &Option<Spanned<String>>,
    default: T,
) -> Result<T> {
    match value {
        None => Ok(default),
        Some(s) => s
            .get_ref()
            .parse()
            .map_err(|e: nacre_optics::Error| Error::Recipe {
                path: path.to_path_buf(),
                line: line_of(text, s.span().start),
                message: e.to_string(),
            }),
    }
}

impl Recipe {
    /// Reads and validates a recipe (nothing is computed yet).
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, text)
    }

    /// Parses recipe text; `path` names it and anchors relative material paths.
    pub fn parse(path: &Path, text: String) -> Result<Self> {
        // The kind decides the schema: check it first for a precise message.
        #[derive(Deserialize)]
        struct KindOnly {
            kind: Spanned<String>,
        }
        let kind: KindOnly = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        if kind.kind.get_ref() != "film-lut" {
            return Err(Error::Recipe {
                path: path.to_path_buf(),
                line: line_of(&text, kind.kind.span().start),
                message: format!(
                    "unknown table kind `{}`: expected `film-lut`, `rough-film-lut`, `fourier` or `diffraction`",
                    kind.kind.get_ref()
                ),
            });
        }
        let raw: RawRecipe = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let at = |span: std::ops::Range<usize>| {
            format!("{}:{}", path.display(), line_of(&text, span.start))
        };
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .filter(|s| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_'))
            .ok_or_else(|| Error::Recipe {
                path: path.to_path_buf(),
                line: 1,
                message: "the recipe's file name (the table name) must use only letters, digits, `-` and `_`".into(),
            })?
            .to_string();
        let colour = raw.colour.unwrap_or(RawColour {
            observer: None,
            illuminant: None,
            space: None,
        });
        let observer = parse_name(path, &text, &colour.observer, Observer::Cie1931_2Deg)?;
        let illuminant = parse_name(path, &text, &colour.illuminant, Illuminant::D65)?;
        let space = parse_name(
            path,
            &text,
            &colour.space,
            OutputSpace::Rgb(nacre_optics::colour::RgbSpace::Srgb),
        )?;
        let RecipeStack {
            ambient,
            ambient_index,
            base,
            under,
            under_specs,
        } = RecipeStack::parse(path, &text, &raw.stack, "film-lut")?;
        let ax = raw.axes.get_ref();
        let axes = FilmLutAxes {
            cos_theta_count: ax.cos_theta_count,
            opd_count: ax.opd_count,
            ior_count: ax.film_ior_count,
            thickness_min_nm: ax.thickness_nm[0],
            thickness_max_nm: ax.thickness_nm[1],
            ior_min: ax.film_ior[0],
            ior_max: ax.film_ior[1],
            ambient_index,
        };
        validate_axes(&axes, &at(raw.axes.span()), MAX_TEXELS)?;
        let output = raw.output.unwrap_or(RawOutput {
            precision: None,
            png: None,
            transmittance: None,
        });
        let transmits = under
            .iter()
            .map(|l| &l.material)
            .chain(std::iter::once(&base))
            .all(is_transparent);
        let transmittance = match output.transmittance {
            None => transmits,
            Some(Toggle::Bool(b)) => b,
            Some(Toggle::Word(w)) if w == "auto" => transmits,
            Some(Toggle::Word(w)) => {
                return Err(Error::Invalid {
                    context: path.display().to_string(),
                    message: format!(
                        "[output] transmittance = \"{w}\": expected \"auto\", true or false"
                    ),
                });
            }
        };
        Ok(Recipe {
            name,
            path: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            colorimeter: Colorimeter::new(observer, illuminant, space),
            ambient_spec: raw.stack.ambient.get_ref().clone(),
            film_label: raw.stack.film.unwrap_or_else(|| "film".into()),
            base_spec: raw.stack.base.get_ref().clone(),
            under_specs,
            job: FilmLutJob {
                axes,
                ambient,
                under,
                base,
                colorimeter: Colorimeter::new(observer, illuminant, space),
                transmittance,
            },
            precision: output.precision.unwrap_or(Precision::Half),
            png: output.png.unwrap_or(true),
            text,
        })
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
}

impl RecipeStack {
    /// Resolves `stack` of the recipe `path` (text `text`) for a table of `kind`.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the file and line of an ambient without a constant real
    /// index or a material that cannot be resolved; [`Error::Recipe`] for a negative or
    /// non-finite layer thickness.
    pub(crate) fn parse(path: &Path, text: &str, stack: &RawStack, kind: &str) -> Result<Self> {
        let at = |span: std::ops::Range<usize>| {
            format!("{}:{}", path.display(), line_of(text, span.start))
        };
        let base_dir = path.parent();
        let ambient = resolve(stack.ambient.get_ref(), &at(stack.ambient.span()), base_dir)?;
        let ambient_index = constant_real_index(&ambient).ok_or_else(|| Error::Invalid {
            context: at(stack.ambient.span()),
            message: format!(
                "the ambient of a {kind} must have a constant real index (e.g. \"1.0\"), not `{}`",
                stack.ambient.get_ref()
            ),
        })?;
        let base = resolve(stack.base.get_ref(), &at(stack.base.span()), base_dir)?;
        let mut under = Vec::new();
        let mut under_specs = Vec::new();
        for l in &stack.under {
            let d = *l.thickness_nm.get_ref();
            if !(d >= 0.0 && d.is_finite()) {
                return Err(Error::Recipe {
                    path: path.to_path_buf(),
                    line: line_of(text, l.thickness_nm.span().start),
                    message: format!("thickness_nm = {d}: must be finite and non-negative"),
                });
            }
            under.push(Layer {
                material: resolve(l.material.get_ref(), &at(l.material.span()), base_dir)?,
                thickness_nm: d,
            });
            under_specs.push((l.material.get_ref().clone(), d));
        }
        Ok(RecipeStack {
            ambient,
            ambient_index,
            base,
            under,
            under_specs,
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

/// One axis as the manifest describes it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisRecord {
    /// Axis name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Texels.
    pub count: usize,
    /// Smallest value (at t = 0).
    pub min: f64,
    /// Largest value (at t = 1).
    pub max: f64,
    /// Mapping name.
    pub mapping: String,
    /// Physical value → t.
    pub forward: String,
    /// t → physical value.
    pub inverse: String,
}

/// One file of a table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FileRecord {
    /// `reflectance` or `transmittance` (film-lut); `level K` or, for the KTX2 file,
    /// [`FOURIER_KTX2_QUANTITY`] (fourier).
    pub quantity: String,
    /// `exr`, `png16` or `ktx2`.
    pub format: String,
    /// File name, relative to the manifest.
    pub path: String,
    /// `half`, `float` or `unorm16`.
    pub encoding: String,
    /// Channel names.
    pub channels: Vec<String>,
    /// Atlas width in pixels (KTX2: the texture's level-0 width).
    pub width: usize,
    /// Atlas height in pixels (KTX2: the texture's level-0 height; its depth, layers and
    /// levels follow from the axes).
    pub height: usize,
    /// SHA-256 of the file.
    pub sha256: String,
}

/// The JSON manifest written beside every table: the runtime loads tables only through it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`MANIFEST_FORMAT`].
    pub format: String,
    /// Do-not-edit notice with the command that regenerates the table.
    pub generated_by: String,
    /// Table name.
    pub name: String,
    /// Table kind (`film-lut`).
    pub kind: String,
    /// Description from the recipe.
    pub description: String,
    /// nacre version that baked it.
    pub nacre_version: String,
    /// Recipe file name (no folder).
    pub recipe_file: String,
    /// SHA-256 of the recipe text.
    pub recipe_sha256: String,
    /// The recipe text.
    pub recipe: String,
    /// Observer (`1931` or `1964`).
    pub observer: String,
    /// Illuminant (`d65`, `d50`, `a`, `e`).
    pub illuminant: String,
    /// Output space (`xyz`, `srgb`, …), linear.
    pub space: String,
    /// Convention of the colour values.
    pub colour_convention: String,
    /// Ambient material spec (film-lut).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub ambient: String,
    /// Film label (film-lut).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub film: String,
    /// Fixed layers under the film: (material spec, thickness nm) (film-lut).
    #[serde(default)]
    pub under: Vec<(String, f64)>,
    /// Base material spec (film-lut).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub base: String,
    /// The axes in x, y, z order.
    pub axes: Vec<AxisRecord>,
    /// Machine-readable axes of a `film-lut`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub film_lut: Option<FilmLutAxes>,
    /// Machine-readable axes of a `fourier` table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fourier: Option<FourierAxes>,
    /// Machine-readable axes of a `rough-film-lut` ([`crate::rough_lut`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rough_film_lut: Option<RoughLutAxes>,
    /// Sampling, Taylor order and conventions of a `diffraction` table
    /// ([`crate::diffraction`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffraction: Option<crate::diffraction::DiffractionRecord>,
    /// Texel-centre convention.
    pub texel_centres: String,
    /// Atlas layout of the files.
    pub atlas: String,
    /// How a shader rebuilds the result from the channels.
    pub reconstruction: String,
    /// The files.
    pub files: Vec<FileRecord>,
}

impl Manifest {
    /// The fields every table's manifest shares — format, provenance (the recipe's file
    /// name, SHA-256 and text) and colour settings — for a table of `kind` baked from the
    /// recipe at `recipe_path`; the baker fills in the rest.
    pub(crate) fn for_recipe(
        kind: &str,
        name: &str,
        description: &str,
        recipe_path: &Path,
        recipe_text: &str,
        colorimeter: &Colorimeter,
    ) -> Manifest {
        let file_name = recipe_path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Manifest {
            format: MANIFEST_FORMAT.into(),
            generated_by: format!(
                "generated by `nacre bake` from the recipe {file_name} (in tables/recipes/ for the default set, which `nacre bake` with no arguments regenerates); do not edit"
            ),
            name: name.to_string(),
            kind: kind.to_string(),
            description: description.to_string(),
            nacre_version: env!("CARGO_PKG_VERSION").into(),
            recipe_file: file_name,
            recipe_sha256: sha256_text(recipe_text),
            recipe: recipe_text.to_string(),
            observer: colorimeter.observer().to_string(),
            illuminant: colorimeter.illuminant().to_string(),
            space: colorimeter.space().to_string(),
            ..Manifest::default()
        }
    }

    /// Reads and validates a manifest file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, &text)
    }

    /// Parses and validates manifest text; `path` names it in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        let m: Manifest = serde_json::from_str(text).map_err(|e| Error::Recipe {
            path: path.to_path_buf(),
            line: e.line(),
            message: format!("not a nacre table manifest: {e}"),
        })?;
        if m.format != MANIFEST_FORMAT {
            return Err(Error::Invalid {
                context: path.display().to_string(),
                message: format!("manifest format `{}` is not `{MANIFEST_FORMAT}`", m.format),
            });
        }
        // Axes a bake could not have written are refused here, before any file is sized
        // from them.
        if let Some(a) = &m.film_lut {
            validate_axes(a, &format!("{}: film_lut", path.display()), MAX_TEXELS)?;
        }
        if let Some(f) = &m.fourier {
            let consistent = f.level_samples.first() == Some(&f.samples)
                && f.level_samples.len() == f.level_sigma_nm.len()
                && f.level_samples
                    .iter()
                    .all(|n| (1..=MAX_FOURIER_SAMPLES).contains(n))
                && f.max_opd_nm > 0.0
                && f.max_opd_nm.is_finite();
            if !consistent {
                return Err(Error::Invalid {
                    context: format!("{}: fourier", path.display()),
                    message: format!(
                        "samples = {}, level_samples = {:?}, {} level_sigma_nm, max_opd_nm = {}: expected level 0 of `samples` texels, every level 1 to {MAX_FOURIER_SAMPLES} texels with one sigma each, and a positive finite max_opd_nm",
                        f.samples,
                        f.level_samples,
                        f.level_sigma_nm.len(),
                        f.max_opd_nm
                    ),
                });
            }
        }
        Ok(m)
    }

    /// The manifest as embedded in its KTX2 files (key [`crate::ktx2::MANIFEST_KEY`]):
    /// pretty JSON without `files`, whose checksums would include the KTX2 files themselves.
    pub fn embedded_json(&self) -> String {
        let mut v = serde_json::to_value(self).expect("manifest serialises");
        if let Some(o) = v.as_object_mut() {
            o.remove("files");
        }
        serde_json::to_string_pretty(&v).expect("manifest serialises")
    }

    /// Loads the table of `quantity` listed by this manifest (at `manifest_path`): from its
    /// EXR file when the manifest lists one, else from its KTX2 file; `None` when neither
    /// is listed.
    pub fn load_table(&self, manifest_path: &Path, quantity: &str) -> Result<Option<Table3>> {
        let find = |format: &str| {
            self.files
                .iter()
                .find(|f| f.quantity == quantity && f.format == format)
        };
        let Some(f) = find("exr").or_else(|| find("ktx2")) else {
            return Ok(None);
        };
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        let a = self.film_lut.as_ref().ok_or_else(|| Error::Invalid {
            context: manifest_path.display().to_string(),
            message: format!(
                "table `{}` is a `{}` table, not a film-lut",
                self.name, self.kind
            ),
        })?;
        let path = dir.join(&f.path);
        verify_sha256(manifest_path, &path, f)?;
        let (nx, ny, nz) = (a.cos_theta_count, a.opd_count, a.ior_count);
        if f.format == "ktx2" {
            return crate::ktx2::read_film_lut_ktx2(&path, nx, ny, nz).map(Some);
        }
        let (table, _) = table_io::read_exr_table(&path, nx, ny, nz)?;
        Ok(Some(table))
    }

    /// The colorimeter the table was baked with.
    pub fn colorimeter(&self, manifest_path: &Path) -> Result<Colorimeter> {
        let bad = |e: nacre_optics::Error| Error::Invalid {
            context: manifest_path.display().to_string(),
            message: e.to_string(),
        };
        Ok(Colorimeter::new(
            self.observer.parse().map_err(bad)?,
            self.illuminant.parse().map_err(bad)?,
            self.space.parse().map_err(bad)?,
        ))
    }
}

/// Checks that the file at `path`, listed in the manifest at `manifest_path` as `f`, has
/// the SHA-256 the manifest records: a table whose files were replaced or damaged after the
/// bake is refused rather than read.
fn verify_sha256(manifest_path: &Path, path: &Path, f: &FileRecord) -> Result<()> {
    let sha = table_io::sha256_hex(path)?;
    if sha != f.sha256 {
        return Err(Error::Table {
            path: path.to_path_buf(),
            message: format!(
                "does not match its manifest {} (SHA-256 {sha}, the manifest says {}): re-bake the table or restore the file",
                manifest_path.display(),
                f.sha256
            ),
        });
    }
    Ok(())
}

pub(crate) fn sha256_text(text: &str) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn axis_records(a: &FilmLutAxes) -> Vec<AxisRecord> {
    vec![
        AxisRecord {
            name: "cos_theta".into(),
            unit: "1".into(),
            count: a.cos_theta_count,
            min: 0.0,
            max: 1.0,
            mapping: "square".into(),
            forward: "t = sqrt(cos_theta)".into(),
            inverse: "cos_theta = t * t".into(),
        },
        AxisRecord {
            name: "opd_nm".into(),
            unit: "nm".into(),
            count: a.opd_count,
            min: 0.0,
            max: a.opd_max_nm(),
            mapping: "linear in optical path difference".into(),
            forward: format!(
                "t = 2 * thickness_nm * sqrt(film_ior^2 - {}^2 * (1 - cos_theta^2)) / {}",
                a.ambient_index,
                a.opd_max_nm()
            ),
            inverse: format!("opd_nm = t * {}", a.opd_max_nm()),
        },
        AxisRecord {
            name: "film_ior".into(),
            unit: "1".into(),
            count: a.ior_count,
            min: a.ior_min,
            max: a.ior_max,
            mapping:
                "square root in the film's normal component q = sqrt(film_ior^2 - n0^2 sin^2 theta)"
                    .into(),
            forward: format!(
                "q(n) = sqrt(n^2 - {n0}^2 (1 - cos_theta^2)); t = sqrt((q(film_ior) - q({lo})) / (q({hi}) - q({lo})))",
                n0 = a.ambient_index,
                lo = a.ior_min,
                hi = a.ior_max
            ),
            inverse: format!(
                "q = q({lo}) + t^2 (q({hi}) - q({lo})); film_ior = sqrt(q^2 + {n0}^2 (1 - cos_theta^2))",
                n0 = a.ambient_index,
                lo = a.ior_min,
                hi = a.ior_max
            ),
        },
    ]
}

/// Bakes one recipe into `out_dir`; returns the manifest path.
pub fn bake_recipe(
    recipe: &Recipe,
    out_dir: &Path,
    progress: &(dyn Fn() + Sync),
) -> Result<PathBuf> {
    let lut: FilmLut = recipe.job.bake(progress)?;
    // Every file goes to a staging folder first; `commit` moves them in, the manifest last.
    let stage = crate::output::StagedTable::new(out_dir)?;
    let dir = stage.path();
    let mut stale = Vec::new();
    let a = &lut.axes;
    let mut files = Vec::new();
    let channels: Vec<String> = recipe
        .colorimeter
        .space()
        .channel_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let c = &recipe.colorimeter;
    let mut manifest = Manifest {
        colour_convention: format!(
            "linear {} ({:?} channels {:?}); colour = integral of R(lambda) or T(lambda) x illuminant x CMF over 360-830 nm, normalised so that a perfect reflector has Y = 1 (RGB (1,1,1) after Bradford adaptation to the space's white); unpolarised (mean of s and p)",
            c.space(), c.space(), channels
        ),
        ambient: recipe.ambient_spec.clone(),
        film: recipe.film_label.clone(),
        under: recipe.under_specs.clone(),
        base: recipe.base_spec.clone(),
        axes: axis_records(a),
        film_lut: Some(a.clone()),
        fourier: None,
        diffraction: None,
        rough_film_lut: None,
        texel_centres: "texel i of an axis with count n holds t = i / (n - 1); a sampler reaches t at u = (t * (n - 1) + 0.5) / n; clamp to edge".into(),
        atlas: "width = count(cos_theta); height = count(opd_nm) * count(film_ior); slice k (film_ior index) occupies rows [k * count(opd_nm), (k + 1) * count(opd_nm)), row j of the slice is opd_nm index j, top row first (EXR, PNG); the KTX2 files hold the same texels as a 3-D RGBA16F texture, width = count(cos_theta), height = count(opd_nm), depth = count(film_ior), alpha 1".into(),
        reconstruction: "cos_t = dot(N, V); opd = 2 d sqrt(n_f^2 - n0^2 (1 - cos_t^2)); q(n) = sqrt(n^2 - n0^2 (1 - cos_t^2)); t = (sqrt(cos_t), opd / opd_max, sqrt((q(n_f) - q(ior_min)) / (q(ior_max) - q(ior_min)))); colour = trilinear sample at u = (t (n - 1) + 0.5) / n per axis; specular = colour (replaces the Fresnel term)".into(),
        files: Vec::new(),
        ..Manifest::for_recipe(
            "film-lut",
            &recipe.name,
            &recipe.description,
            &recipe.path,
            &recipe.text,
            c,
        )
    };
    let embedded = manifest.embedded_json();
    let quantities = [
        ("reflectance", Some(&lut.reflectance)),
        ("transmittance", lut.transmittance.as_ref()),
    ];
    for (quantity, table) in quantities {
        let Some(table) = table else { continue };
        let exr = format!("{}.{quantity}.exr", recipe.name);
        table_io::write_exr(&dir.join(&exr), table, recipe.precision)?;
        files.push(FileRecord {
            quantity: quantity.into(),
            format: "exr".into(),
            path: exr.clone(),
            encoding: match recipe.precision {
                Precision::Half => "half",
                Precision::Float => "float",
            }
            .into(),
            channels: vec!["R".into(), "G".into(), "B".into()],
            width: table.nx,
            height: table.ny * table.nz,
            sha256: table_io::sha256_hex(&dir.join(&exr))?,
        });
        if recipe.png {
            let png = format!("{}.{quantity}.png", recipe.name);
            if table_io::write_png16(&dir.join(&png), table)? {
                files.push(FileRecord {
                    quantity: quantity.into(),
                    format: "png16".into(),
                    path: png.clone(),
                    encoding: "unorm16".into(),
                    channels: vec!["R".into(), "G".into(), "B".into()],
                    width: table.nx,
                    height: table.ny * table.nz,
                    sha256: table_io::sha256_hex(&dir.join(&png))?,
                });
            } else {
                // A stale PNG from an earlier bake would contradict the manifest.
                stale.push(png);
            }
        }
        let ktx2 = format!("{}.{quantity}.ktx2", recipe.name);
        let ktx2_path = dir.join(&ktx2);
        let (ktx2_format, ktx2_encoding) = match recipe.precision {
            Precision::Half => (crate::ktx2::Ktx2Format::Rgba16Float, "half"),
            Precision::Float => (crate::ktx2::Ktx2Format::Rgba32Float, "float"),
        };
        crate::ktx2::write_ktx2(
            &ktx2_path,
            &crate::ktx2::film_lut_image_as(&ktx2_path, table, &embedded, ktx2_format)?,
        )?;
        files.push(FileRecord {
            quantity: quantity.into(),
            format: "ktx2".into(),
            path: ktx2,
            encoding: ktx2_encoding.into(),
            channels: vec!["R".into(), "G".into(), "B".into(), "A".into()],
            width: table.nx,
            height: table.ny,
            sha256: table_io::sha256_hex(&ktx2_path)?,
        });
    }
    manifest.files = files;
    stage.commit_manifest(&manifest, &stale)
}

/// The recipes of the default set, sorted by name.
pub fn default_recipes() -> Result<Vec<PathBuf>> {
    let dir = default_recipes_dir();
    let entries = std::fs::read_dir(&dir).map_err(|source| Error::Io {
        path: dir.clone(),
        source,
    })?;
    let mut out: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    out.sort();
    Ok(out)
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
        .ok_or_else(|| Error::Recipe {
            path: path.to_path_buf(),
            line: 1,
            message:
                "the recipe's file name (the table name) must use only letters, digits, `-` and `_`"
                    .into(),
        })
}

/// Most texels of level 0 of a `fourier` table.
pub const MAX_FOURIER_SAMPLES: usize = 1 << 20;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFourier {
    samples: Spanned<usize>,
    max_opd_nm: Spanned<f64>,
    levels: Spanned<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFourierRecipe {
    #[allow(dead_code)] // checked before the full parse
    kind: Spanned<String>,
    description: Option<String>,
    colour: Option<RawColour>,
    fourier: RawFourier,
}

/// A parsed `fourier` recipe.
///
/// ```toml
/// kind = "fourier"
/// description = "..."
/// [colour]                 # as for film-lut
/// space = "srgb"
/// [fourier]
/// samples = 8192           # texels of level 0 (each level halves it)
/// max_opd_nm = 160000.0    # D_max: the μ range, nm
/// levels = 8               # mip levels (level k prefiltered with σ_k = D_max / N_k)
/// ```
pub struct FourierRecipe {
    /// Table name.
    pub name: String,
    /// Recipe file.
    pub path: PathBuf,
    /// Recipe text.
    pub text: String,
    /// Description.
    pub description: String,
    /// Colour settings.
    pub colorimeter: Colorimeter,
    /// Axes.
    pub axes: FourierAxes,
}

impl FourierRecipe {
    fn parse(path: &Path, text: String) -> Result<Self> {
        let raw: RawFourierRecipe =
            toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let colorimeter = parse_colour(path, &text, raw.colour)?;
        let f = &raw.fourier;
        let bad = |span: std::ops::Range<usize>, message: String| Error::Recipe {
            path: path.to_path_buf(),
            line: line_of(&text, span.start),
            message,
        };
        let samples = *f.samples.get_ref();
        if !(64..=MAX_FOURIER_SAMPLES).contains(&samples) {
            return Err(bad(
                f.samples.span(),
                format!("samples = {samples}: expected 64 to {MAX_FOURIER_SAMPLES}"),
            ));
        }
        let max_opd = *f.max_opd_nm.get_ref();
        if !(max_opd > 0.0 && max_opd <= 1e7) {
            return Err(bad(
                f.max_opd_nm.span(),
                format!("max_opd_nm = {max_opd}: expected a positive length up to 1e7 nm"),
            ));
        }
        let levels = *f.levels.get_ref();
        // checked_shr: `levels` of 65 or more must give this error, not a shift overflow.
        let last_level = u32::try_from(levels.wrapping_sub(1))
            .ok()
            .and_then(|shift| samples.checked_shr(shift))
            .unwrap_or(0);
        if levels == 0 || last_level < 2 {
            return Err(bad(
                f.levels.span(),
                format!(
                    "levels = {levels}: expected 1 or more, leaving at least 2 texels in the last level"
                ),
            ));
        }
        Ok(FourierRecipe {
            name: table_name(path)?,
            path: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            axes: FourierAxes::new(&colorimeter, samples, max_opd, levels),
            colorimeter,
            text,
        })
    }

    /// Bakes and writes the table; returns the manifest path.
    pub fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        let table = FourierTable::bake(&self.colorimeter, self.axes.clone());
        // Every file goes to a staging folder first; `commit` moves them in, the manifest last.
        let stage = crate::output::StagedTable::new(out_dir)?;
        let dir = stage.path();
        let a = &self.axes;
        let c = &self.colorimeter;
        let mut manifest = Manifest {
            colour_convention: format!(
                "sensitivities s_j of linear {} (channels {:?}): perfect reflector = white {:?}; Ŝ_j(μ) = ∫ s_j(λ) exp(-2πiμ/λ) dλ / ∫ s_j dλ (forward transform in ν = 1/λ with a negative exponent; Ŝ_j(0) = 1)",
                c.space(),
                c.space().channel_names(),
                a.white
            ),
            ambient: String::new(),
            film: String::new(),
            under: Vec::new(),
            base: String::new(),
            axes: vec![AxisRecord {
                name: "opd_nm".into(),
                unit: "nm".into(),
                count: a.samples,
                min: 0.0,
                max: a.max_opd_nm,
                mapping: "linear".into(),
                forward: format!("u = opd_nm / {}", a.max_opd_nm),
                inverse: format!("opd_nm = u * {}", a.max_opd_nm),
            }],
            film_lut: None,
            fourier: Some(a.clone()),
            diffraction: None,
            rough_film_lut: None,
            texel_centres: "texel i of level k (N_k = level_samples[k] texels) holds μ = (i + 0.5) D_max / N_k: the usual mip-map convention, u = μ / D_max at every level; clamp to edge".into(),
            atlas: "one OpenEXR file per mip level, width N_k, height 2: row 0 holds Re A_j, row 1 holds Im A_j for the channels R, G, B (the output space's channels in order); the KTX2 file holds every level as one 2-D array RGBA32F texture, width N, height 1, layer 0 = Re, layer 1 = Im, mip level k = level k, alpha 0".into(),
            reconstruction: "A = trilinear sample at (u = μ / D_max, lod), lod = σ_μ < σ_1 ? σ_μ / σ_1 : 1 + log2(σ_μ / σ_1); Ŝ_j(μ) = A_j exp(-2πi μ carrier_nu_per_nm[j]); colour_j = white_j [c0 + 2 Σ_m Re(c_m conj Ŝ_j(m D, m τ σ_d))] (Belcour & Barla 2017 Eq. 10; nacre_optics::fourier)".into(),
            files: Vec::new(),
            ..Manifest::for_recipe(
                "fourier",
                &self.name,
                &self.description,
                &self.path,
                &self.text,
                c,
            )
        };
        let embedded = manifest.embedded_json();
        let mut files = Vec::new();
        for k in 0..table.levels.len() {
            let file = format!("{}.level{k}.exr", self.name);
            let path = dir.join(&file);
            table.write_level(k, &path)?;
            files.push(FileRecord {
                quantity: format!("level {k}"),
                format: "exr".into(),
                path: file,
                encoding: "float".into(),
                channels: vec!["R".into(), "G".into(), "B".into()],
                width: table.levels[k].len(),
                height: 2,
                sha256: table_io::sha256_hex(&path)?,
            });
            progress();
        }
        let ktx2 = format!("{}.ktx2", self.name);
        let ktx2_path = dir.join(&ktx2);
        crate::ktx2::write_ktx2(
            &ktx2_path,
            &crate::ktx2::fourier_image(&ktx2_path, &table, &embedded)?,
        )?;
        files.push(FileRecord {
            quantity: FOURIER_KTX2_QUANTITY.into(),
            format: "ktx2".into(),
            path: ktx2,
            encoding: "float".into(),
            channels: vec!["R".into(), "G".into(), "B".into(), "A".into()],
            width: a.samples,
            height: 1,
            sha256: table_io::sha256_hex(&ktx2_path)?,
        });
        manifest.files = files;
        stage.commit_manifest(&manifest, &[])
    }
}

/// A recipe of any table kind.
pub enum AnyRecipe {
    /// `film-lut`.
    FilmLut(Box<Recipe>),
    /// `fourier`.
    Fourier(Box<FourierRecipe>),
    /// `rough-film-lut` ([`crate::rough_lut`]).
    RoughFilmLut(Box<RoughRecipe>),
    /// `diffraction` ([`crate::diffraction`]).
    Diffraction(Box<crate::diffraction::DiffractionRecipe>),
}

impl AnyRecipe {
    /// Reads a recipe, dispatching on its `kind`.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, text)
    }

    /// Parses recipe text of any kind; `path` names it and anchors relative material paths.
    pub fn parse(path: &Path, text: String) -> Result<Self> {
        #[derive(Deserialize)]
        struct KindOnly {
            kind: Spanned<String>,
        }
        let kind: KindOnly = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        match kind.kind.get_ref().as_str() {
            "fourier" => Ok(AnyRecipe::Fourier(Box::new(FourierRecipe::parse(
                path, text,
            )?))),
            "rough-film-lut" => Ok(AnyRecipe::RoughFilmLut(Box::new(RoughRecipe::parse(
                path, text,
            )?))),
            "diffraction" => {
                #[derive(Deserialize)]
                struct ColourOnly {
                    colour: Option<RawColour>,
                }
                let c: ColourOnly =
                    toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
                let colorimeter = parse_colour(path, &text, c.colour)?;
                Ok(AnyRecipe::Diffraction(Box::new(
                    crate::diffraction::DiffractionRecipe::parse(
                        path,
                        text,
                        table_name(path)?,
                        colorimeter,
                    )?,
                )))
            }
            _ => Ok(AnyRecipe::FilmLut(Box::new(Recipe::parse(path, text)?))),
        }
    }

    /// The table name.
    pub fn name(&self) -> &str {
        match self {
            AnyRecipe::FilmLut(r) => &r.name,
            AnyRecipe::Fourier(r) => &r.name,
            AnyRecipe::RoughFilmLut(r) => &r.name,
            AnyRecipe::Diffraction(r) => &r.name,
        }
    }

    /// Units of work (for progress bars).
    pub fn work(&self) -> u64 {
        match self {
            AnyRecipe::FilmLut(r) => (r.job.axes.cos_theta_count * r.job.axes.ior_count) as u64,
            AnyRecipe::Fourier(r) => r.axes.level_samples.len() as u64,
            AnyRecipe::RoughFilmLut(r) => r.work(),
            AnyRecipe::Diffraction(_) => 1,
        }
    }

    /// Bakes into `out_dir`; returns the manifest path.
    pub fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        match self {
            AnyRecipe::FilmLut(r) => bake_recipe(r, out_dir, progress),
            AnyRecipe::Fourier(r) => r.bake(out_dir, progress),
            AnyRecipe::RoughFilmLut(r) => r.bake(out_dir, progress),
            AnyRecipe::Diffraction(r) => r.bake(out_dir, progress),
        }
    }
}

impl Manifest {
    /// Loads the `fourier` table this manifest (at `manifest_path`) describes: from its
    /// per-level EXR files when the manifest lists them all, else from its KTX2 file.
    pub fn load_fourier(&self, manifest_path: &Path) -> Result<FourierTable> {
        let axes = self.fourier.clone().ok_or_else(|| Error::Invalid {
            context: manifest_path.display().to_string(),
            message: format!(
                "table `{}` is a `{}` table, not a fourier table",
                self.name, self.kind
            ),
        })?;
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        let levels = axes.level_samples.len();
        let exr_level = |k: usize| {
            self.files
                .iter()
                .find(|f| f.quantity == format!("level {k}") && f.format == "exr")
        };
        if (0..levels).any(|k| exr_level(k).is_none())
            && let Some(f) = self.files.iter().find(|f| f.format == "ktx2")
        {
            let path = dir.join(&f.path);
            verify_sha256(manifest_path, &path, f)?;
            return crate::ktx2::read_fourier_ktx2(&path, axes);
        }
        let paths: Vec<PathBuf> = (0..levels)
            .map(|k| {
                let f = exr_level(k).ok_or_else(|| Error::Invalid {
                    context: manifest_path.display().to_string(),
                    message: format!("the manifest lists no file for level {k}"),
                })?;
                let path = dir.join(&f.path);
                verify_sha256(manifest_path, &path, f)?;
                Ok(path)
            })
            .collect::<Result<_>>()?;
        FourierTable::read(axes, &paths)
    }
}
