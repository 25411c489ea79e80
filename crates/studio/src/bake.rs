//! Baking the designed stack into a table set from the export panel: a `film-lut` recipe
//! written from the stack ([`film_lut_recipe`]), baked by `nacre bake`'s own code
//! ([`nacre_bake::kinds::film_lut`]) on a background thread ([`BakeJob`]) with its progress
//! (rows done of rows) and a cancel flag, into a folder the runtime loads as a table set
//! (`NAME.json` and its files, the manifest last; `nacre info NAME.json` reads it).
//!
//! The table's film is the stack's top film, its index an axis around the film's index at
//! [`INDEX_WAVELENGTH_NM`]; the films under it are the recipe's fixed `under` layers and
//! the base is the stack's. A cancelled bake writes nothing: every row checks the flag
//! before it starts, and the files are written only once the whole table is computed (each
//! atomically, the manifest last: [`nacre_format::stage`]).

use crate::doc::{Film, StackDoc};
use crate::view::INDEX_WAVELENGTH_NM;
use nacre_bake::kinds::TableRecipe;
use nacre_bake::kinds::film_lut::{FilmLutRecipe, bake_recipe_cancellable};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;

/// What the export panel bakes: where, under which name, and the table's texel counts.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeSettings {
    /// The output folder (created when missing).
    pub folder: String,
    /// The table's name: its manifest is `NAME.json` (letters, digits, `-`, `_`).
    pub name: String,
    /// Texels along cos θ.
    pub cos_theta_count: usize,
    /// Texels along the optical path difference.
    pub opd_count: usize,
    /// Texels along the film index.
    pub film_ior_count: usize,
}

impl Default for BakeSettings {
    /// `tables/studio/studio-stack`, with `film-dielectric`'s resolution (24 × 384 × 32).
    fn default() -> Self {
        BakeSettings {
            folder: "tables/studio".into(),
            name: "studio-stack".into(),
            cos_theta_count: 24,
            opd_count: 384,
            film_ior_count: 32,
        }
    }
}

/// The thinnest thickness range the table spans, nm (`film-dielectric`'s).
pub const MIN_THICKNESS_RANGE_NM: f64 = 1200.0;

/// The film-index range of the table around the top film's index n (real part at
/// [`INDEX_WAVELENGTH_NM`]): from the ambient index n₀ (the axis's floor: a film-lut's
/// films are at least as dense as the ambient) to max(2.5, n + 0.1), so that the default
/// set's range (1.0 to 2.5 in air) is kept and the film lies inside with room to edit.
pub fn film_ior_range(ambient_index: f64, film_index: f64) -> [f64; 2] {
    let lo = ambient_index.max(1.0);
    let hi = (film_index + 0.1).max(2.5);
    [lo, (hi * 100.0).ceil() / 100.0]
}

/// The top of the table's thickness axis for a top film `d ± r` thick: max(1200 nm, d + r
/// rounded up to 100 nm), nm.
pub fn thickness_max_nm(top: &Film) -> f64 {
    (((top.thickness_nm + top.relative_nm.abs()) / 100.0).ceil() * 100.0)
        .max(MIN_THICKNESS_RANGE_NM)
}

/// The real indices of the ambient and of film 1 at [`INDEX_WAVELENGTH_NM`]: the table's
/// ambient and the centre of its film-index axis ([`film_ior_range`]).
pub fn top_indices(stack: &nacre_optics::Stack) -> Result<[f64; 2], String> {
    let index = |m: &nacre_optics::Material, what: &str| {
        m.index_at(INDEX_WAVELENGTH_NM)
            .map(|n| n.re)
            .map_err(|e| format!("{what}: {e}"))
    };
    let Some(top) = stack.layers().first() else {
        return Err("a bare interface has no film: add a film".into());
    };
    Ok([
        index(stack.ambient(), "ambient")?,
        index(&top.material, "film 1")?,
    ])
}

/// The `film-lut` recipe TOML of `doc` with `settings`' texel counts: the ambient, the top
/// film's index range ([`film_ior_range`]), the films under it as fixed layers, the base;
/// thicknesses 0 to max(1200 nm, the top film's d + r rounded up to 100 nm).
pub fn film_lut_recipe(doc: &StackDoc, settings: &BakeSettings) -> Result<String, String> {
    let stack = doc.build().map_err(|e| e.to_string())?;
    let Some(top) = doc.films.first() else {
        return Err("a bare interface has no film to bake: add a film".into());
    };
    let [ambient, film] = top_indices(&stack)?;
    let thickness_max_nm = thickness_max_nm(top);
    #[derive(Serialize)]
    struct Under<'a> {
        material: &'a str,
        thickness_nm: f64,
    }
    #[derive(Serialize)]
    struct Stack<'a> {
        ambient: &'a str,
        film: String,
        base: &'a str,
        under: Vec<Under<'a>>,
    }
    #[derive(Serialize)]
    struct Axes {
        cos_theta_count: usize,
        thickness_nm: [f64; 2],
        opd_count: usize,
        film_ior: [f64; 2],
        film_ior_count: usize,
    }
    #[derive(Serialize)]
    struct Recipe<'a> {
        kind: &'static str,
        description: String,
        stack: Stack<'a>,
        axes: Axes,
    }
    let recipe = Recipe {
        kind: "film-lut",
        description: format!(
            "nacre studio: film 1 ({}, index axis around {:.3}) over {} fixed layer(s) on {}",
            top.material.trim(),
            film,
            doc.films.len() - 1,
            doc.substrate.trim()
        ),
        stack: Stack {
            ambient: doc.ambient.trim(),
            film: format!("film 1 ({})", top.material.trim()),
            base: doc.substrate.trim(),
            under: doc.films[1..]
                .iter()
                .map(|f| Under {
                    material: f.material.trim(),
                    thickness_nm: f.thickness_nm,
                })
                .collect(),
        },
        axes: Axes {
            cos_theta_count: settings.cos_theta_count,
            thickness_nm: [0.0, thickness_max_nm],
            opd_count: settings.opd_count,
            film_ior: film_ior_range(ambient, film),
            film_ior_count: settings.film_ior_count,
        },
    };
    let text = toml::to_string(&recipe).map_err(|e| e.to_string())?;
    Ok(format!(
        "# A film-lut table of a nacre studio stack (nacre bake RECIPE.toml bakes it again).\n{text}"
    ))
}

/// A parsed recipe for `doc`: named `settings.name`, relative material paths resolved
/// from the stack's folder (a loaded recipe's) or the working folder.
pub fn parse_recipe(doc: &StackDoc, settings: &BakeSettings) -> Result<FilmLutRecipe, String> {
    let text = film_lut_recipe(doc, settings)?;
    let dir = doc.base_dir.clone().unwrap_or_else(|| PathBuf::from("."));
    let path = dir.join(format!("{}.toml", settings.name.trim()));
    FilmLutRecipe::parse(&path, text).map_err(|e| e.to_string())
}

/// A bake running on its own thread.
pub struct BakeJob {
    done: Arc<AtomicU64>,
    total: u64,
    cancel: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<PathBuf, nacre_bake::Error>>>,
    /// The output folder.
    pub folder: PathBuf,
    /// The table's name.
    pub name: String,
}

/// How a bake ended.
#[derive(Clone, Debug, PartialEq)]
pub enum BakeOutcome {
    /// Baked: the manifest's path.
    Baked(PathBuf),
    /// Cancelled: nothing written.
    Cancelled,
    /// Failed: why (nothing written).
    Failed(String),
}

impl BakeJob {
    /// Parses the recipe of `doc` (errors come back at once) and starts baking it into
    /// `settings.folder`.
    pub fn start(doc: &StackDoc, settings: &BakeSettings) -> Result<BakeJob, String> {
        let recipe = parse_recipe(doc, settings)?;
        let folder = PathBuf::from(settings.folder.trim());
        if folder.as_os_str().is_empty() {
            return Err("the table folder is empty: name a folder".into());
        }
        if folder.is_file() {
            return Err(format!("{} is a file, not a folder", folder.display()));
        }
        let done = Arc::new(AtomicU64::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let total = recipe.work();
        let name = recipe.name.clone();
        // The bake's rows run on a pool of their own, one core short of the machine's, so
        // that the plots' worker (rayon's global pool) and the view are never queued behind
        // them. The bytes do not depend on the pool's size.
        let threads = std::thread::available_parallelism()
            .map_or(1, |n| n.get().saturating_sub(1))
            .max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|k| format!("nacre-studio bake {k}"))
            .build()
            .map_err(|e| format!("the bake threads did not start: {e}"))?;
        let thread = {
            let (done, cancel, folder) = (Arc::clone(&done), Arc::clone(&cancel), folder.clone());
            std::thread::Builder::new()
                .name("nacre-studio bake".into())
                .spawn(move || {
                    pool.install(|| {
                        bake_recipe_cancellable(
                            &recipe,
                            &folder,
                            &|| {
                                done.fetch_add(1, Ordering::Relaxed);
                            },
                            &cancel,
                        )
                    })
                })
                .map_err(|e| format!("the bake thread did not start: {e}"))?
        };
        Ok(BakeJob {
            done,
            total,
            cancel,
            thread: Some(thread),
            folder,
            name,
        })
    }

    /// Rows done and rows in all.
    pub fn progress(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed).min(self.total),
            self.total,
        )
    }

    /// Asks the bake to stop (rows already running finish; nothing is written).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Whether a cancel was asked.
    pub fn cancelling(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// The outcome once the thread has finished (None while it runs).
    pub fn poll(&mut self) -> Option<BakeOutcome> {
        if !self.thread.as_ref()?.is_finished() {
            return None;
        }
        let thread = self.thread.take()?;
        Some(match thread.join() {
            Ok(Ok(path)) => BakeOutcome::Baked(path),
            Ok(Err(nacre_bake::Error::Cancelled { .. })) => BakeOutcome::Cancelled,
            Ok(Err(e)) => BakeOutcome::Failed(e.to_string()),
            Err(_) => BakeOutcome::Failed("the bake thread stopped unexpectedly".into()),
        })
    }
}

impl Drop for BakeJob {
    /// A studio closed mid-bake stops the bake (and writes nothing).
    fn drop(&mut self) {
        self.cancel();
    }
}

/// The manifest a bake of `settings` writes.
pub fn manifest_path(settings: &BakeSettings) -> PathBuf {
    Path::new(settings.folder.trim()).join(format!("{}.json", settings.name.trim()))
}
