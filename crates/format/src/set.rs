//! The default table set: where the `tables/` folder, its recipes and its baked tables are,
//! and how a table is named on the command line.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

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
