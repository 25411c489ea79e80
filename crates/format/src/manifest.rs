//! The JSON manifest written beside every table: the runtime and engine integrations load
//! tables only through it. Its keys are stable (`nacre-table/1`): every manifest the
//! default set ships loads unchanged.
//!
//! A manifest names its [`TableKind`]; the kind's own axes are one [`KindRecord`] (under the
//! JSON key `film_lut`, `fourier`, `rough_film_lut`, `diffraction` or another kind's
//! [`TableKind::record_key`]); its files are
//! [`FileRecord`]s with a SHA-256 checked before any file is read.

use crate::diffraction::DiffractionRecord;
use crate::error::{Error, Result};
use crate::film_lut::{FilmLutAxes, validate_axes};
use crate::fourier::FourierAxes;
pub use crate::kind::TableKind;
use crate::rough_film_lut::RoughLutAxes;
use crate::table_io;
use nacre_optics::colour::Colorimeter;
use serde::de::{DeserializeOwned, IgnoredAny, MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::path::{Path, PathBuf};

/// Most texels one table may have (2²⁴ ≈ 16.8 million: 96 MiB of half-float RGB per
/// quantity). Larger recipes are refused before any work.
pub const MAX_TEXELS: u64 = 1 << 24;

/// Manifest format identifier.
pub const MANIFEST_FORMAT: &str = "nacre-table/1";

/// The `quantity` of a `fourier` table's KTX2 file (every level in one file).
pub const FOURIER_KTX2_QUANTITY: &str = "all levels";

/// The axes and records of one table kind, as the manifest stores them: one JSON key (the
/// kind's [`TableKind::record_key`]) beside the common fields.
#[derive(Clone, Debug, PartialEq)]
pub enum KindRecord {
    /// Machine-readable axes of a `film-lut` (key `film_lut`).
    FilmLut(FilmLutAxes),
    /// Machine-readable axes of a `fourier` table (key `fourier`).
    Fourier(FourierAxes),
    /// Machine-readable axes of a `rough-film-lut` (key `rough_film_lut`).
    RoughFilmLut(RoughLutAxes),
    /// Sampling, Taylor order and conventions of a `diffraction` table (key `diffraction`).
    Diffraction(Box<DiffractionRecord>),
    /// The record of a kind this crate does not type: a kind the CPU alone reads, whose
    /// module in `nacre-bake` writes it ([`KindRecord::data`]) and reads it back
    /// ([`Manifest::data_record`]) as its own serde type. (JSON objects keep their keys
    /// sorted here.)
    Data {
        /// The kind.
        kind: TableKind,
        /// The record.
        value: serde_json::Value,
    },
}

impl KindRecord {
    /// The kind this record belongs to.
    pub fn kind(&self) -> TableKind {
        match self {
            KindRecord::FilmLut(_) => TableKind::FILM_LUT,
            KindRecord::Fourier(_) => TableKind::FOURIER,
            KindRecord::RoughFilmLut(_) => TableKind::ROUGH_FILM_LUT,
            KindRecord::Diffraction(_) => TableKind::DIFFRACTION,
            KindRecord::Data { kind, .. } => *kind,
        }
    }

    /// The record of a kind without a typed variant: `record` as JSON.
    ///
    /// # Errors
    /// [`Error::Invalid`] when `record` does not serialise to JSON (a map with non-string
    /// keys, say).
    pub fn data(kind: TableKind, record: &impl Serialize) -> Result<KindRecord> {
        let value = serde_json::to_value(record).map_err(|e| Error::Invalid {
            context: format!("the {kind} record").into(),
            message: e.to_string().into(),
        })?;
        Ok(KindRecord::Data { kind, value })
    }
}

/// Reads a [`KindRecord`] from a map: the record under the first key that is the record key of
/// one of its kinds (other keys are skipped). [`KindRecord`]'s `Deserialize` uses
/// [`TableKind::ALL`].
struct RecordVisitor<'k>(&'k [TableKind]);

impl<'de> Visitor<'de> for RecordVisitor<'_> {
    type Value = KindRecord;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a table kind's record")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<KindRecord, A::Error> {
        let mut record = None;
        while let Some(key) = map.next_key::<String>()? {
            let kind = match record {
                None => TableKind::from_record_key(self.0, &key),
                Some(_) => None,
            };
            record = Some(match kind {
                Some(TableKind::FILM_LUT) => KindRecord::FilmLut(map.next_value()?),
                Some(TableKind::FOURIER) => KindRecord::Fourier(map.next_value()?),
                Some(TableKind::ROUGH_FILM_LUT) => KindRecord::RoughFilmLut(map.next_value()?),
                Some(TableKind::DIFFRACTION) => KindRecord::Diffraction(map.next_value()?),
                Some(kind) => KindRecord::Data {
                    kind,
                    value: map.next_value()?,
                },
                None => {
                    map.next_value::<IgnoredAny>()?;
                    continue;
                }
            });
        }
        record.ok_or_else(|| {
            let keys: Vec<String> = self
                .0
                .iter()
                .map(|k| format!("`{}`", k.record_key()))
                .collect();
            serde::de::Error::custom(format_args!(
                "no table record: expected one of the keys {}",
                keys.join(", ")
            ))
        })
    }
}

impl Serialize for KindRecord {
    /// One entry: the kind's record key and its record.
    fn serialize<S: Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(1))?;
        let key = self.kind().record_key();
        match self {
            KindRecord::FilmLut(a) => map.serialize_entry(&key, a)?,
            KindRecord::Fourier(a) => map.serialize_entry(&key, a)?,
            KindRecord::RoughFilmLut(a) => map.serialize_entry(&key, a)?,
            KindRecord::Diffraction(r) => map.serialize_entry(&key, r)?,
            KindRecord::Data { value, .. } => map.serialize_entry(&key, value)?,
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for KindRecord {
    /// The first key that is the record key of a kind of [`TableKind::ALL`].
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        deserializer.deserialize_map(RecordVisitor(TableKind::ALL))
    }
}

/// The format of one table file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FileFormat {
    /// OpenEXR atlas ([`crate::table_io`]).
    #[serde(rename = "exr")]
    Exr,
    /// 16-bit PNG atlas, values in [0, 1] ([`crate::table_io`]).
    #[serde(rename = "png16")]
    Png16,
    /// KTX 2.0 texture ([`crate::ktx2`]).
    #[serde(rename = "ktx2")]
    Ktx2,
}

/// How a table file stores its values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// IEEE half floats.
    Half,
    /// IEEE single floats.
    Float,
    /// 16-bit unsigned normalised integers.
    Unorm16,
}

impl From<table_io::Precision> for Encoding {
    fn from(p: table_io::Precision) -> Self {
        match p {
            table_io::Precision::Half => Encoding::Half,
            table_io::Precision::Float => Encoding::Float,
        }
    }
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
    /// The file's format.
    pub format: FileFormat,
    /// File name, relative to the manifest.
    pub path: String,
    /// How its values are stored.
    pub encoding: Encoding,
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`MANIFEST_FORMAT`].
    pub format: String,
    /// Do-not-edit notice with the command that regenerates the table.
    pub generated_by: String,
    /// Table name.
    pub name: String,
    /// Table kind.
    pub kind: TableKind,
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
    /// Per fixed layer: incoherent, a thick slab whose reflections add in intensity
    /// (film-lut; absent when every fixed layer is coherent, [`crate::film_lut`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub under_incoherent: Vec<bool>,
    /// Base material spec (film-lut).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub base: String,
    /// The axes in x, y, z order.
    pub axes: Vec<AxisRecord>,
    /// The kind's own axes and records (JSON key: the kind's [`TableKind::record_key`]).
    #[serde(flatten)]
    pub record: KindRecord,
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
    /// recipe at `recipe_path`, with the kind's `record`; the baker fills in the rest
    /// (left empty here).
    pub fn for_recipe(
        record: KindRecord,
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
            kind: record.kind(),
            description: description.to_string(),
            nacre_version: env!("CARGO_PKG_VERSION").into(),
            recipe_file: file_name,
            recipe_sha256: sha256_text(recipe_text),
            recipe: recipe_text.to_string(),
            observer: colorimeter.observer().to_string(),
            illuminant: colorimeter.illuminant().to_string(),
            space: colorimeter.space().to_string(),
            colour_convention: String::new(),
            ambient: String::new(),
            film: String::new(),
            under: Vec::new(),
            under_incoherent: Vec::new(),
            base: String::new(),
            axes: Vec::new(),
            record,
            texel_centres: String::new(),
            atlas: String::new(),
            reconstruction: String::new(),
            files: Vec::new(),
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
        let m: Manifest = serde_json::from_str(text).map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: e.line(),
            message: format!("not a nacre table manifest: {e}"),
        })?;
        if m.format != MANIFEST_FORMAT {
            return Err(Error::Invalid {
                context: path.display().to_string().into(),
                message: format!("manifest format `{}` is not `{MANIFEST_FORMAT}`", m.format)
                    .into(),
            });
        }
        if m.record.kind() != m.kind {
            return Err(Error::Invalid {
                context: path.display().to_string().into(),
                message: format!(
                    "a `{}` table whose manifest holds the axes of a `{}` table",
                    m.kind,
                    m.record.kind()
                )
                .into(),
            });
        }
        // Axes a bake could not have written are refused here, before any file is sized
        // from them.
        if let Some(a) = m.film_lut() {
            validate_axes(a, &format!("{}: film_lut", path.display()), MAX_TEXELS)?;
        }
        if let Some(f) = m.fourier() {
            let consistent = f.level_samples.first() == Some(&f.samples)
                && f.level_samples.len() == f.level_sigma_nm.len()
                && f.level_samples
                    .iter()
                    .all(|n| (1..=MAX_FOURIER_SAMPLES).contains(n))
                && f.max_opd_nm > 0.0
                && f.max_opd_nm.is_finite();
            if !consistent {
                return Err(Error::Invalid {
                    context: format!("{}: fourier", path.display()).into(),
                    message: format!(
                        "samples = {}, level_samples = {:?}, {} level_sigma_nm, max_opd_nm = {}: expected level 0 of `samples` texels, every level 1 to {MAX_FOURIER_SAMPLES} texels with one sigma each, and a positive finite max_opd_nm",
                        f.samples,
                        f.level_samples,
                        f.level_sigma_nm.len(),
                        f.max_opd_nm
                    ).into(),
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

    /// The axes of a `film-lut`, `None` for another kind.
    pub fn film_lut(&self) -> Option<&FilmLutAxes> {
        match &self.record {
            KindRecord::FilmLut(a) => Some(a),
            _ => None,
        }
    }

    /// The axes of a `fourier` table, `None` for another kind.
    pub fn fourier(&self) -> Option<&FourierAxes> {
        match &self.record {
            KindRecord::Fourier(a) => Some(a),
            _ => None,
        }
    }

    /// The axes of a `rough-film-lut`, `None` for another kind.
    pub fn rough_film_lut(&self) -> Option<&RoughLutAxes> {
        match &self.record {
            KindRecord::RoughFilmLut(a) => Some(a),
            _ => None,
        }
    }

    /// The record of a `diffraction` table, `None` for another kind.
    pub fn diffraction(&self) -> Option<&DiffractionRecord> {
        match &self.record {
            KindRecord::Diffraction(r) => Some(r),
            _ => None,
        }
    }

    /// The record of a kind without a typed [`KindRecord`] variant (a CPU-only kind's) as
    /// its module's type `T`; `None` for a table of another kind.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming `manifest_path` when the record is not a `T`.
    pub fn data_record<T: DeserializeOwned>(
        &self,
        kind: TableKind,
        manifest_path: &Path,
    ) -> Option<Result<T>> {
        match &self.record {
            KindRecord::Data { kind: k, value } if *k == kind => {
                Some(T::deserialize(value).map_err(|e| Error::Invalid {
                    context: format!("{}: {}", manifest_path.display(), kind.record_key()).into(),
                    message: e.to_string().into(),
                }))
            }
            _ => None,
        }
    }

    /// The file of `quantity` in `format`, if the manifest lists one.
    pub fn file(&self, quantity: &str, format: FileFormat) -> Option<&FileRecord> {
        self.files
            .iter()
            .find(|f| f.quantity == quantity && f.format == format)
    }

    /// The folder of the manifest at `manifest_path`, against which file paths resolve.
    pub fn dir(&self, manifest_path: &Path) -> PathBuf {
        manifest_path
            .parent()
            .unwrap_or(Path::new("."))
            .to_path_buf()
    }

    /// The error for a reader that expected `expected` (e.g. "a film-lut").
    pub fn wrong_kind(&self, manifest_path: &Path, expected: &'static str) -> Error {
        Error::WrongKind {
            manifest: manifest_path.to_path_buf(),
            name: self.name.clone(),
            kind: self.kind,
            expected,
        }
    }

    /// The colorimeter the table was baked with.
    pub fn colorimeter(&self, manifest_path: &Path) -> Result<Colorimeter> {
        let bad = |e: nacre_optics::Error| Error::Invalid {
            context: manifest_path.display().to_string().into(),
            message: e.to_string().into(),
        };
        Ok(Colorimeter::new(
            self.observer.parse().map_err(bad)?,
            self.illuminant.parse().map_err(bad)?,
            self.space.parse().map_err(bad)?,
        ))
    }
}

/// SHA-256 of a text, as lower-case hex ([`crate::checksum::sha256_text`]).
pub use crate::checksum::sha256_text;

/// Most texels of level 0 of a `fourier` table.
pub const MAX_FOURIER_SAMPLES: usize = 1 << 20;

#[cfg(test)]
mod tests {
    use super::*;

    /// A kind without a typed record, as a CPU-only kind's module would add it.
    const PROBE: TableKind = TableKind::new("probe-kind");

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct ProbeAxes {
        samples: usize,
        max_nm: f64,
    }

    #[test]
    fn a_kind_without_a_typed_record_writes_and_reads_its_own_type() {
        let axes = ProbeAxes {
            samples: 7,
            max_nm: 1200.5,
        };
        let record = KindRecord::data(PROBE, &axes).unwrap();
        assert_eq!(record.kind(), PROBE);
        assert_eq!(
            serde_json::to_string(&record).unwrap(),
            r#"{"probe_kind":{"max_nm":1200.5,"samples":7}}"#
        );
        // Read back with the kind known, skipping keys of no kind.
        let kinds = [TableKind::FILM_LUT, PROBE];
        let json = r#"{"other": [1, 2], "probe_kind": {"samples": 7, "max_nm": 1200.5}}"#;
        let back = serde_json::Deserializer::from_str(json)
            .deserialize_map(RecordVisitor(&kinds))
            .unwrap();
        assert_eq!(back, record);
        let err = serde_json::Deserializer::from_str(r#"{"other": 1}"#)
            .deserialize_map(RecordVisitor(&kinds))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("no table record: expected one of the keys `film_lut`, `probe_kind`"),
            "{err}"
        );

        let colorimeter = Colorimeter::new(
            "1931".parse().unwrap(),
            "d65".parse().unwrap(),
            "srgb".parse().unwrap(),
        );
        let path = Path::new("probe.json");
        let m = Manifest::for_recipe(
            record,
            "probe",
            "",
            Path::new("probe.toml"),
            "",
            &colorimeter,
        );
        assert_eq!(m.kind, PROBE);
        let read: ProbeAxes = m.data_record(PROBE, path).unwrap().unwrap();
        assert_eq!(read, axes);
        assert!(
            m.data_record::<ProbeAxes>(TableKind::FOURIER, path)
                .is_none()
        );
        let err = m.data_record::<Vec<f64>>(PROBE, path).unwrap().unwrap_err();
        assert!(err.to_string().contains("probe.json: probe_kind"), "{err}");
        // A manifest may name only the kinds of TableKind::ALL.
        let text = serde_json::to_string(&m).unwrap();
        let err = Manifest::parse(path, &text).unwrap_err().to_string();
        assert!(err.contains("unknown variant `probe-kind`"), "{err}");
    }

    #[test]
    fn the_typed_records_keep_their_keys() {
        for entry in std::fs::read_dir(crate::set::default_baked_dir()).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "json") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let m = Manifest::parse(&path, &text).unwrap();
            assert!(
                !matches!(m.record, KindRecord::Data { .. }),
                "{}",
                path.display()
            );
            // Written again, the manifest has the same top-level keys in the same order, its
            // record under the kind's key. (Its bytes are `nacre bake`'s:
            // `crates/cli/tests/default_set.rs`; serde_json's float parser may move a value
            // read back by an ulp, so values are not compared here.)
            let keys = |text: &str| -> Vec<String> {
                text.lines()
                    .filter_map(|l| l.strip_prefix("  \""))
                    .filter_map(|l| l.split_once("\": ").map(|(k, _)| k.to_string()))
                    .collect()
            };
            let again = serde_json::to_string_pretty(&m).unwrap();
            assert_eq!(keys(&again), keys(&text), "{}", path.display());
            assert!(
                keys(&text).contains(&m.kind.record_key()),
                "{}",
                path.display()
            );
        }
    }
}
