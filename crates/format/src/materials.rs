//! The bundled material library and the resolution of material specifications.
//!
//! A material specification `M` (an `ambient`/`layer`/`substrate` value or a recipe's
//! `material` string) is, in this order:
//!
//! 1. a real index (`1.33`) or a complex index `n+κi` (`0.27+2.9i`);
//! 2. a bundled material name, case-insensitive (see [`BUNDLED`]; a few common aliases
//!    such as `gold` or `sio2` are accepted);
//! 3. a path to a refractiveindex.info `.yml`/`.yaml` file or a `wavelength_nm,n,k` `.csv`
//!    file (relative paths in a recipe are taken relative to the recipe's folder);
//! 4. a refractiveindex.info page `shelf/book/page` (`main/Au/Johnson`, also on shelves
//!    whose name starts with a digit, `3d/metals/aluminium`), looked up in a local copy of
//!    the database ([`MaterialDb`]; the parameter [`Param::MaterialDb`] or the environment
//!    variable `NACRE_MATERIAL_DB` sets it with [`set_database`]).
//!
//! What the readers repaired or set aside in a file or page (docs/materials.md) is kept for
//! [`take_warnings`], each warning once per process.
//!
//! # The refractiveindex.info database layout
//!
//! The database repository (<https://github.com/polyanskiy/refractiveindex.info-database>)
//! keeps its files under `database/`: the library catalog `catalog-nk.yml` (shelves, books,
//! pages, each page with a `data:` path relative to the data folder) and the data files.
//! Their layout changed over time, and [`MaterialDb`] accepts each:
//!
//! | versions | page `main/Au/Johnson` |
//! |---|---|
//! | older | `database/data-nk/main/Au/Johnson.yml` |
//! | 2024 | `database/data/main/Au/Johnson.yml` |
//! | 2025 on | `database/data/main/Au/nk/Johnson.yml` |
//!
//! The folder given may be the repository root or its `database/` folder. A page is looked
//! for at those paths first, then through the catalog's `data:` entry (some page names
//! differ from their file names, e.g. `Walling-α` → `Walling-alpha.yml`).
//!
//! The bundled data files live in `tables/materials/` with their sources and licences;
//! they are embedded into the binary at build time so that `nacre` works from any folder.

use crate::error::{Error, Result};
use crate::msg;
use crate::param::{Origin, Param};
use nacre_optics::{Material, MaterialWarning};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, RwLock};

/// A bundled material: its name, what it is, and its data file's text.
pub struct Bundled {
    /// Name used on the command line and in recipes.
    pub name: &'static str,
    /// One-line description with the data source.
    pub description: &'static str,
    /// File name under `tables/materials/`.
    pub file: &'static str,
    /// The file's contents.
    pub text: &'static str,
}

macro_rules! bundled {
    ($( $name:literal, $file:literal, $desc:literal; )*) => {
        /// Every bundled material.
        pub const BUNDLED: &[Bundled] = &[
            $( Bundled {
                name: $name,
                description: $desc,
                file: $file,
                text: include_str!(concat!("../../../tables/materials/", $file)),
            }, )*
        ];
    };
}

bundled! {
    "air", "air.yml", "dry air, 15 °C, 450 ppm CO2 (Ciddor 1996)";
    "water", "water.yml", "liquid water, 20 °C (Daimon & Masumura 2007)";
    "fused-silica", "fused-silica.yml", "fused silica SiO2 (Malitson 1965)";
    "bk7", "bk7.yml", "SCHOTT N-BK7 optical glass";
    "mgf2", "mgf2.yml", "magnesium fluoride, ordinary ray (Dodge 1984)";
    "tio2", "tio2.yml", "titanium dioxide ALD thin film (Siefke et al. 2016)";
    "si", "si.yml", "crystalline silicon, 300 K (Green 2008)";
    "au", "au.yml", "gold (Johnson & Christy 1972)";
    "ag", "ag.yml", "silver (Johnson & Christy 1972)";
    "cu", "cu.yml", "copper (Johnson & Christy 1972)";
    "al", "al.yml", "aluminium (Rakić 1995)";
    "cr", "cr.yml", "chromium (Johnson & Christy 1974)";
    "oil", "oil.yml", "biodiesel fuel oil, 20 °C, a gasoline/oil-like dispersive dielectric (Wang et al. 2015)";
}

const ALIASES: &[(&str, &str)] = &[
    ("sio2", "fused-silica"),
    ("silica", "fused-silica"),
    ("n-bk7", "bk7"),
    ("gold", "au"),
    ("silver", "ag"),
    ("copper", "cu"),
    ("aluminium", "al"),
    ("aluminum", "al"),
    ("chromium", "cr"),
    ("silicon", "si"),
    ("titania", "tio2"),
    ("h2o", "water"),
];

/// Comma-separated bundled names, for messages.
pub fn bundled_names() -> String {
    BUNDLED
        .iter()
        .map(|b| b.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Looks up a bundled material by name or alias (case-insensitive).
pub fn bundled(name: &str) -> Option<&'static Bundled> {
    let lower = name.trim().to_ascii_lowercase();
    let canonical = ALIASES
        .iter()
        .find(|(alias, _)| *alias == lower)
        .map_or(lower.as_str(), |(_, target)| target);
    BUNDLED.iter().find(|b| b.name == canonical)
}

/// Parses a bundled material.
pub fn load_bundled(b: &Bundled) -> Result<Material> {
    let source = format!("tables/materials/{}", b.file);
    Ok(parse_material_text(b.name, &source, b.text)?)
}

fn parse_material_text(name: &str, source: &str, text: &str) -> nacre_optics::Result<Material> {
    if source.to_ascii_lowercase().ends_with(".csv") {
        Material::from_nk_csv(name, source, text)
    } else {
        Material::from_refractiveindex_yaml(name, source, text)
    }
}

/// A local copy of the refractiveindex.info database (see the module docs for the layouts
/// it accepts).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MaterialDb {
    /// The folder given: the repository root or its `database/` folder.
    pub dir: PathBuf,
    /// Where the setting came from, for messages: the parameter [`Param::MaterialDb`] or an
    /// environment variable.
    pub origin: Origin,
}

/// Warnings of the materials [`resolve`] has loaded: every one seen (as text), and those
/// not yet taken.
struct WarningLog {
    seen: Option<HashSet<String>>,
    pending: Vec<MaterialWarning>,
}

static WARNINGS: Mutex<WarningLog> = Mutex::new(WarningLog {
    seen: None,
    pending: Vec::new(),
});

/// Keeps `m`'s warnings for [`take_warnings`] (each warning once per process) and returns
/// `m`.
fn noting_warnings(m: Material) -> Material {
    if m.warnings().is_empty() {
        return m;
    }
    let mut log = WARNINGS.lock().unwrap_or_else(|e| e.into_inner());
    let WarningLog { seen, pending } = &mut *log;
    let seen = seen.get_or_insert_with(HashSet::new);
    for w in m.warnings() {
        if seen.insert(w.to_string()) {
            pending.push(w.clone());
        }
    }
    m
}

/// The warnings of every material file or database page that [`resolve`] (or
/// [`MaterialDb::load`]) has read since the last call, in the order they were read, each
/// once per process: rows the reader repaired or set aside, see
/// [`nacre_optics::WarningKind`]. The materials are usable; a front end shows these to the
/// user (the `nacre` binary prints them as `nacre: warning: FILE:LINE: …`).
pub fn take_warnings() -> Vec<MaterialWarning> {
    std::mem::take(&mut WARNINGS.lock().unwrap_or_else(|e| e.into_inner()).pending)
}

/// The process-wide database used by [`resolve`]; None until [`set_database`].
static DATABASE: RwLock<Option<MaterialDb>> = RwLock::new(None);

/// Sets (or, with None, clears) the database that [`resolve`] looks `shelf/book/page`
/// specifications up in. The `nacre` binary calls it once, before any work.
pub fn set_database(db: Option<MaterialDb>) {
    *DATABASE.write().unwrap_or_else(|e| e.into_inner()) = db;
}

/// The database set by [`set_database`], if any.
pub fn database() -> Option<MaterialDb> {
    DATABASE.read().unwrap_or_else(|e| e.into_inner()).clone()
}

/// `shelf/book/page` when `spec` has that form: three non-empty `/`-separated parts, none
/// `.` or `..`.
pub fn database_page(spec: &str) -> Option<(&str, &str, &str)> {
    let mut parts = spec.split('/');
    let (shelf, book, page) = (parts.next()?, parts.next()?, parts.next()?);
    let ok = |p: &str| !p.is_empty() && p != "." && p != ".." && !p.contains('\\');
    (parts.next().is_none() && ok(shelf) && ok(book) && ok(page)).then_some((shelf, book, page))
}

impl MaterialDb {
    /// A database at `dir`, set by `origin` (a parameter or variable name, for messages).
    pub fn new(dir: impl Into<PathBuf>, origin: impl Into<Origin>) -> Self {
        MaterialDb {
            dir: dir.into(),
            origin: origin.into(),
        }
    }

    /// The folder that holds `catalog-nk.yml` and the data folders: `DIR/database` when
    /// there is one (DIR is the repository), else DIR.
    fn root(&self) -> PathBuf {
        let inner = self.dir.join("database");
        if inner.is_dir() {
            inner
        } else {
            self.dir.clone()
        }
    }

    /// Every page the database's catalog (`catalog-nk.yml`) lists, in its order (see
    /// [`catalog_pages`]): what a front end offers to browse and search.
    pub fn pages(&self) -> Result<Vec<CatalogPage>> {
        let catalog = self.root().join("catalog-nk.yml");
        let text = std::fs::read_to_string(&catalog).map_err(|source| Error::Io {
            path: catalog,
            source,
        })?;
        Ok(catalog_pages(&text))
    }

    /// The data file of page `shelf/book/page`, and every path tried (in order) when
    /// there is none.
    pub fn locate(&self, shelf: &str, book: &str, page: &str) -> (Option<PathBuf>, Vec<PathBuf>) {
        let root = self.root();
        let file = format!("{page}.yml");
        let book_dir = |data: &str| root.join(data).join(shelf).join(book);
        let mut tried = Vec::new();
        for path in [
            book_dir("data").join("nk").join(&file),
            book_dir("data").join(&file),
            book_dir("data-nk").join(&file),
        ] {
            if path.is_file() {
                return (Some(path), tried);
            }
            tried.push(path);
        }
        let catalog = root.join("catalog-nk.yml");
        if let Ok(text) = std::fs::read_to_string(&catalog) {
            tried.push(catalog);
            if let Some(rel) = catalog_lookup(&text, shelf, book, page) {
                for data in ["data", "data-nk"] {
                    let path = root.join(data).join(&rel);
                    if path.is_file() {
                        return (Some(path), tried);
                    }
                    tried.push(path);
                }
            }
        }
        (None, tried)
    }

    /// Loads page `spec` = `shelf/book/page`; `context` names where the spec came from.
    pub fn load(&self, spec: &str, context: impl Into<Origin>) -> Result<Material> {
        let context = context.into();
        let Some((shelf, book, page)) = database_page(spec) else {
            return Err(Error::MaterialDb {
                context,
                spec: spec.to_string(),
                tried: vec![],
                message:
                    "expected a refractiveindex.info page SHELF/BOOK/PAGE, e.g. main/Au/Johnson"
                        .into(),
            });
        };
        let (found, tried) = self.locate(shelf, book, page);
        let Some(path) = found else {
            let dir = self.dir.display();
            let origin = self.origin.clone();
            let message = if !self.dir.is_dir() {
                msg![
                    format!("the material database folder {dir} ("),
                    origin,
                    ") does not exist"
                ]
            } else {
                msg![
                    format!(
                        "refractiveindex.info page `{spec}` not found in the material database {dir} ("
                    ),
                    origin,
                    format!(
                        ", the database repository or its database/ folder); tried {}",
                        tried
                            .iter()
                            .map(|p| p.display().to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                ]
            };
            return Err(Error::MaterialDb {
                context,
                spec: spec.to_string(),
                tried,
                message,
            });
        };
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Io {
            path: path.clone(),
            source,
        })?;
        let shown = path.display().to_string();
        Ok(noting_warnings(Material::from_refractiveindex_yaml(
            spec, &shown, &text,
        )?))
    }
}

/// One page of the database's catalog (`catalog-nk.yml`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CatalogPage {
    /// The shelf (`main`).
    pub shelf: String,
    /// The book (`Au`).
    pub book: String,
    /// The page (`Johnson`).
    pub page: String,
    /// The page's title in the catalog (`Johnson and Christy 1972: n,k 0.188–1.94 µm`).
    pub name: String,
    /// Its data file, relative to the data folder (`main/Au/nk/Johnson.yml`).
    pub data: String,
}

impl CatalogPage {
    /// The page as a material specification: `shelf/book/page`.
    pub fn spec(&self) -> String {
        format!("{}/{}/{}", self.shelf, self.book, self.page)
    }
}

/// Every page of a `catalog-nk.yml` text that names a data file, in the catalog's order.
/// The catalog is read line by line (its `SHELF`/`BOOK`/`PAGE`, `name` and `data` keys), not
/// as general YAML.
pub fn catalog_pages(text: &str) -> Vec<CatalogPage> {
    fn value<'a>(line: &'a str, key: &str) -> Option<&'a str> {
        let v = line.strip_prefix(key)?.strip_prefix(':')?.trim();
        let v = v
            .strip_prefix('"')
            .and_then(|v| v.strip_suffix('"'))
            .or_else(|| v.strip_prefix('\'').and_then(|v| v.strip_suffix('\'')))
            .unwrap_or(v);
        Some(v)
    }
    let (mut s, mut b, mut p, mut name) = ("", "", "", "");
    let mut pages = Vec::new();
    for line in text.lines() {
        let t = line.trim();
        let t = t.strip_prefix("- ").unwrap_or(t).trim_start();
        if let Some(v) = value(t, "SHELF") {
            (s, b, p, name) = (v, "", "", "");
        } else if let Some(v) = value(t, "BOOK") {
            (b, p, name) = (v, "", "");
        } else if let Some(v) = value(t, "PAGE") {
            (p, name) = (v, "");
        } else if let Some(v) = value(t, "name") {
            name = v;
        } else if let Some(v) = value(t, "data") {
            pages.push(CatalogPage {
                shelf: s.to_string(),
                book: b.to_string(),
                page: p.to_string(),
                name: name.to_string(),
                data: v.to_string(),
            });
        }
    }
    pages
}

/// The data path the catalog gives page `shelf/book/page`, if any.
fn catalog_lookup(text: &str, shelf: &str, book: &str, page: &str) -> Option<String> {
    catalog_pages(text)
        .into_iter()
        .find(|c| (c.shelf.as_str(), c.book.as_str(), c.page.as_str()) == (shelf, book, page))
        .map(|c| c.data)
}

/// Resolves a material specification (see module docs) with the database set by
/// [`set_database`]. `context` names where it came from (a parameter or `recipe.toml:12`)
/// for messages; `base_dir` anchors relative paths.
pub fn resolve(
    spec: &str,
    context: impl Into<Origin>,
    base_dir: Option<&Path>,
) -> Result<Material> {
    resolve_with(spec, context, base_dir, database().as_ref())
}

/// [`resolve`] with an explicit database (None: `shelf/book/page` specifications are an
/// error that says how to set one).
pub fn resolve_with(
    spec: &str,
    context: impl Into<Origin>,
    base_dir: Option<&Path>,
    db: Option<&MaterialDb>,
) -> Result<Material> {
    let context = context.into();
    let spec = spec.trim();
    // A number, unless it has the SHELF/BOOK/PAGE form (shelves such as `3d` start with a
    // digit; no index literal contains `/`).
    let looks_numeric = spec
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+'))
        && database_page(spec).is_none();
    if looks_numeric {
        return Material::parse_index(spec).map_err(|source| Error::OpticsIn { context, source });
    }
    if let Some(b) = bundled(spec) {
        return load_bundled(b);
    }
    let lower = spec.to_ascii_lowercase();
    if [".yml", ".yaml", ".csv"]
        .iter()
        .any(|ext| lower.ends_with(ext))
    {
        let path = match base_dir {
            Some(dir) if Path::new(spec).is_relative() => dir.join(spec),
            _ => Path::new(spec).to_path_buf(),
        };
        // Named with where the spec came from: a recipe line or a flag.
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Invalid {
            context,
            message: format!("cannot read the material file {}: {source}", path.display()).into(),
        })?;
        let shown = path.display().to_string();
        return Ok(noting_warnings(parse_material_text(spec, &shown, &text)?));
    }
    if database_page(spec).is_some() {
        return match db {
            Some(db) => db.load(spec, context),
            None => Err(Error::MaterialDb {
                context,
                spec: spec.to_string(),
                tried: vec![],
                message: msg![
                    format!(
                        "`{spec}` looks like a refractiveindex.info page (SHELF/BOOK/PAGE) but no material database is set: pass "
                    ),
                    Param::MaterialDb.arg(),
                    " or set NACRE_MATERIAL_DB to a local copy of https://github.com/polyanskiy/refractiveindex.info-database"
                ],
            }),
        };
    }
    Err(Error::UnknownMaterial {
        context,
        name: spec.to_string(),
        bundled: bundled_names(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bundled_material_parses_and_covers_the_visible() {
        for b in BUNDLED {
            let m = load_bundled(b).unwrap_or_else(|e| panic!("{}: {e}", b.name));
            let (lo, hi) = m.range_nm();
            assert!(lo <= 300.0 && hi >= 1000.0, "{}: {lo}–{hi} nm", b.name);
            for wl in [300.0, 380.0, 555.5, 780.0, 1000.0] {
                m.index_at(wl).unwrap();
            }
        }
    }

    #[test]
    fn resolution_order_and_messages() {
        assert_eq!(
            resolve("1.5", Param::Substrate, None).unwrap().name(),
            "1.5"
        );
        assert_eq!(
            resolve("Gold", Param::Substrate, None).unwrap().name(),
            "au"
        );
        let e = resolve("unobtainium", Param::Layer, None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("layer: unknown material `unobtainium`"),
            "{e}"
        );
        let e = resolve("1.5-0.2i", Param::Layer, None)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("layer: invalid refractive index"), "{e}");
        let e = resolve("missing.yml", Param::Layer, None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("layer: cannot read the material file missing.yml: "),
            "{e}"
        );
    }

    /// A refractiveindex.info page with constant n and κ over 0.3–1.0 µm.
    fn page(n: f64, k: f64) -> String {
        format!(
            "DATA:\n  - type: tabulated nk\n    data: |\n        0.3 {n} {k}\n        1.0 {n} {k}\n"
        )
    }

    fn write(path: &Path, text: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }

    #[test]
    fn database_pages_in_every_layout() {
        let dir = tempfile::tempdir().unwrap();
        let db = dir.path().join("database");
        // 2025 on: data/SHELF/BOOK/nk/PAGE.yml; 2024: data/SHELF/BOOK/PAGE.yml; older:
        // data-nk/SHELF/BOOK/PAGE.yml; a page whose file name differs, via the catalog.
        write(&db.join("data/main/Au/nk/Johnson.yml"), &page(0.5, 2.0));
        write(&db.join("data/main/Ag/Johnson.yml"), &page(0.1, 3.0));
        write(&db.join("data-nk/main/Cu/Johnson.yml"), &page(0.9, 2.5));
        write(
            &db.join("data-nk/main/BeAl2O4/Walling-alpha.yml"),
            &page(1.7, 0.0),
        );
        write(
            &db.join("catalog-nk.yml"),
            "- DIVIDER: \"Research data\"\n- SHELF: main\n  name: \"MAIN\"\n  content:\n    - BOOK: BeAl2O4\n      content:\n        - PAGE: Walling-α\n          name: \"Walling et al. 1980\"\n          data: \"main/BeAl2O4/Walling-alpha.yml\"\n",
        );
        // The repository root and its database/ folder both work.
        for root in [dir.path().to_path_buf(), db.clone()] {
            let db = MaterialDb::new(&root, Param::MaterialDb);
            for (spec, n, k) in [
                ("main/Au/Johnson", 0.5, 2.0),
                ("main/Ag/Johnson", 0.1, 3.0),
                ("main/Cu/Johnson", 0.9, 2.5),
                ("main/BeAl2O4/Walling-α", 1.7, 0.0),
            ] {
                let m = resolve_with(spec, Param::Substrate, None, Some(&db))
                    .unwrap_or_else(|e| panic!("{spec}: {e}"));
                assert_eq!(m.name(), spec);
                let i = m.index_at(550.0).unwrap();
                assert!(
                    (i.re - n).abs() < 1e-12 && (i.im - k).abs() < 1e-12,
                    "{spec}: {i}"
                );
            }
            // The catalog lists its pages with their titles and data files.
            assert_eq!(
                db.pages().unwrap(),
                vec![CatalogPage {
                    shelf: "main".into(),
                    book: "BeAl2O4".into(),
                    page: "Walling-α".into(),
                    name: "Walling et al. 1980".into(),
                    data: "main/BeAl2O4/Walling-alpha.yml".into(),
                }]
            );
            assert_eq!(db.pages().unwrap()[0].spec(), "main/BeAl2O4/Walling-α");
            // Bundled names, numbers and paths come first.
            let au = resolve_with("au", Param::Substrate, None, Some(&db)).unwrap();
            assert_eq!(au.name(), "au");
            assert!((au.index_at(550.0).unwrap().re - 0.5).abs() > 1e-3);
        }
    }

    #[test]
    fn database_errors_name_the_spec_the_paths_and_the_flag() {
        let dir = tempfile::tempdir().unwrap();
        write(
            &dir.path().join("database/data/main/Au/nk/Johnson.yml"),
            &page(0.5, 2.0),
        );
        let db = MaterialDb::new(dir.path(), Param::MaterialDb);
        let e = resolve_with("main/Au/Nobody", Param::Layer, None, Some(&db)).unwrap_err();
        let Error::MaterialDb { spec, tried, .. } = &e else {
            panic!("{e:?}");
        };
        assert_eq!(spec, "main/Au/Nobody");
        assert!(tried.contains(&dir.path().join("database/data/main/Au/nk/Nobody.yml")));
        assert!(tried.contains(&dir.path().join("database/data-nk/main/Au/Nobody.yml")));
        let e = e.to_string();
        assert!(
            e.starts_with("layer: refractiveindex.info page `main/Au/Nobody` not found"),
            "{e}"
        );
        assert!(
            e.contains("(material_db,") && e.contains("Nobody.yml"),
            "{e}"
        );
        // No database set: say how to set one.
        let e = resolve_with("main/Au/Johnson", Param::Layer, None, None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("pass material_db or set NACRE_MATERIAL_DB"),
            "{e}"
        );
        // A database folder that does not exist.
        let gone = MaterialDb::new(dir.path().join("nope"), "NACRE_MATERIAL_DB");
        let e = resolve_with("main/Au/Johnson", Param::Layer, None, Some(&gone))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("does not exist") && e.contains("NACRE_MATERIAL_DB"),
            "{e}"
        );
        // Not a page: two parts, or `..`.
        assert!(database_page("main/Au").is_none());
        assert!(database_page("main/../x").is_none());
        assert!(database_page("a/b/c/d").is_none());
        assert_eq!(
            database_page("main/Au/Johnson"),
            Some(("main", "Au", "Johnson"))
        );
    }
}
