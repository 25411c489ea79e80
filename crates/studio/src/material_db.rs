//! The material database browser's model: where the local refractiveindex.info database
//! is, the pages its catalog lists ([`nacre_format::materials::MaterialDb::pages`]) and the
//! search over them. A page picked becomes a material specification `shelf/book/page`,
//! which the stack's parser ([`crate::StackDoc::build`], the CLI's) loads from the database
//! [`nacre_format::materials::set_database`] names, as `nacre --material-db DIR` does.

use nacre_format::materials::{CatalogPage, MaterialDb, set_database};
use std::path::{Path, PathBuf};

/// The environment variable that names the database folder (as for `nacre`).
pub const DB_ENV: &str = "NACRE_MATERIAL_DB";

/// Where the database is looked for when [`DB_ENV`] is unset: `../shared/` beside the
/// repository the studio was built from (the copy the project's machines keep).
pub fn shared_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/refractiveindex.info-database")
}

/// The database folder the studio starts with: [`DB_ENV`] when set, else
/// [`shared_folder`] when it exists, else None (the browser's folder field is empty).
pub fn default_folder() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os(DB_ENV).filter(|v| !v.is_empty()) {
        return Some(PathBuf::from(dir));
    }
    // Canonical, so that the folder field shows `/…/shared/…` rather than `crates/studio/../../..`.
    let shared = shared_folder();
    shared.canonicalize().ok().filter(|d| d.is_dir())
}

/// A database opened for browsing: its folder and its catalog's pages.
#[derive(Clone, Debug)]
pub struct Catalog {
    /// The database, as the stack's parser reads it.
    pub db: MaterialDb,
    /// Every page of its catalog, in the catalog's order.
    pub pages: Vec<CatalogPage>,
    /// Each page's `shelf/book/page` and title, lower case, for the search.
    haystack: Vec<String>,
}

impl Catalog {
    /// Opens the database at `folder` (the repository root or its `database/` folder) and
    /// reads its catalog; an error names the folder.
    pub fn open(folder: &Path) -> Result<Catalog, String> {
        let db = MaterialDb::new(folder, "the studio's material database folder");
        let pages = db.pages().map_err(|e| {
            format!(
                "{} is not a refractiveindex.info database (no catalog-nk.yml there or in its database/ folder): {e}",
                folder.display()
            )
        })?;
        let haystack = pages
            .iter()
            .map(|p| format!("{} {}", p.spec(), p.name).to_lowercase())
            .collect();
        Ok(Catalog {
            db,
            pages,
            haystack,
        })
    }

    /// The pages whose `shelf/book/page` or title contains every whitespace-separated
    /// word of `query` (case-insensitive), in the catalog's order: at most `limit` of them,
    /// and how many match in all.
    pub fn search(&self, query: &str, limit: usize) -> (Vec<&CatalogPage>, usize) {
        let words: Vec<String> = query.split_whitespace().map(str::to_lowercase).collect();
        let mut found = Vec::new();
        let mut total = 0;
        for (page, text) in self.pages.iter().zip(&self.haystack) {
            if words.iter().all(|w| text.contains(w.as_str())) {
                total += 1;
                if found.len() < limit {
                    found.push(page);
                }
            }
        }
        (found, total)
    }

    /// Makes this database the one `shelf/book/page` materials are read from (the stack,
    /// its plots, bakes and recipes).
    pub fn make_current(&self) {
        set_database(Some(self.db.clone()));
    }
}
