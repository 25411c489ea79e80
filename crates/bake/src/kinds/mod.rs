//! Table kinds: one module per kind behind one trait ([`TableRecipe`]) and one registry
//! ([`REGISTRY`]).
//!
//! Each kind's module parses its recipe (the shared sections through [`crate::recipe`]),
//! estimates the work and bakes the table through `nacre_format`'s writers and staging.
//! Adding a kind: one line in `nacre_format::TableKind::ALL`, one module here that exports a
//! [`KindEntry`], and one line in [`REGISTRY`] (a kind the GPU samples also has a typed
//! record and its axes in `nacre-format`: `docs/architecture.md`).

pub mod diffraction;
pub mod diffraction_integrated;
pub mod diffraction_recipe;
pub mod film_lut;
pub mod fourier;
pub mod height_field;
pub mod rough_film_lut;

use crate::error::{Error, Result};
use crate::recipe::{line_of, toml_error};
use nacre_format::TableKind;
use serde::Deserialize;
use std::any::Any;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// A parsed recipe of one table kind: validated and with its materials resolved, nothing
/// computed yet.
pub trait TableRecipe: Any + Send + Sync {
    /// The kind of table it bakes.
    fn kind(&self) -> TableKind;
    /// The table name (the recipe's file stem).
    fn name(&self) -> &str;
    /// Units of work, for progress bars (`progress` is called once per unit).
    fn work(&self) -> u64;
    /// Bakes and writes the table into `out_dir` (atomically, the manifest last); returns
    /// the manifest path.
    fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf>;
}

impl dyn TableRecipe {
    /// The concrete recipe, when it is a `T`.
    pub fn downcast_ref<T: TableRecipe>(&self) -> Option<&T> {
        (self as &dyn Any).downcast_ref()
    }
}

impl std::fmt::Debug for dyn TableRecipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} recipe `{}`", self.kind(), self.name())
    }
}

/// One registry entry: a kind, the parser of its recipes and when a bake of many starts it.
pub struct KindEntry {
    /// The kind.
    pub kind: TableKind,
    /// Parses recipe text (`path` names it and anchors relative material paths).
    pub parse: fn(&Path, String) -> Result<Box<dyn TableRecipe>>,
    /// Where `nacre bake` starts this kind's tables among others': the slowest kinds
    /// first (0), so that the quick ones fill the cores at the end. It changes the
    /// schedule only, never the bytes.
    pub start_rank: u8,
}

/// Every table kind `nacre bake` knows, in the order error messages list them.
pub const REGISTRY: &[KindEntry] = &[
    film_lut::ENTRY,
    rough_film_lut::ENTRY,
    fourier::ENTRY,
    diffraction::ENTRY,
];

/// The registry entry of `kind`, if `nacre bake` knows it.
pub fn entry(kind: TableKind) -> Option<&'static KindEntry> {
    REGISTRY.iter().find(|e| e.kind == kind)
}

/// Reads a recipe of any kind, dispatching on its `kind`.
pub fn read_recipe(path: &Path) -> Result<Box<dyn TableRecipe>> {
    let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_recipe(path, text)
}

/// Parses recipe text of any kind; `path` names it and anchors relative material paths.
///
/// # Errors
/// [`nacre_format::Error::Parse`] naming the line of a missing or unknown `kind`, else the kind's own
/// errors.
pub fn parse_recipe(path: &Path, text: String) -> Result<Box<dyn TableRecipe>> {
    #[derive(Deserialize)]
    struct KindOnly {
        kind: Spanned<String>,
    }
    let kind: KindOnly = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
    let name = kind.kind.get_ref();
    match REGISTRY.iter().find(|e| e.kind.name() == name) {
        Some(entry) => (entry.parse)(path, text),
        None => {
            let names: Vec<String> = REGISTRY
                .iter()
                .map(|e| format!("`{}`", e.kind.name()))
                .collect();
            let (last, rest) = names.split_last().expect("the registry is not empty");
            Err(Error::recipe(
                path.to_path_buf(),
                line_of(&text, kind.kind.span().start),
                format!(
                    "unknown table kind `{name}`: expected {} or {last}",
                    rest.join(", ")
                ),
            ))
        }
    }
}
