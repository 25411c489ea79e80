//! `lut` on any stack: the stack's own `film-lut` table, baked in the background.
//!
//! The bundled `film-dielectric` table holds one film in air on glass of index 1.5. A stack
//! it does not hold (another ambient or base, films under the top one, a film index or
//! thickness outside its axes) needs a table of its own: the export panel's recipe
//! ([`crate::bake::film_lut_recipe`]: film 1 varies in thickness and index, the films under
//! it and the base are fixed), baked by `nacre bake`'s code on a background thread
//! ([`BakeJob`]). Until it is loaded the view draws the stack exactly (`stack`), so a
//! change that needs a new table shows at once; then `lut` draws from the new table.
//!
//! The tables live in a cache folder (`$XDG_CACHE_HOME/nacre/studio-luts` by default), one
//! sub-folder per table named by a 64-bit FNV-1a hash of its [`key`]: a stack met before
//! (in this session or an earlier one) loads without a bake. Edits that keep the key (film
//! 1's thickness inside the axis, its index inside the index axis) reuse the table and redraw
//! in one frame. The folder keeps the [`KEPT_TABLES`] most recently baked tables.

use crate::bake::{
    BakeJob, BakeOutcome, BakeSettings, film_ior_range, thickness_max_nm, top_indices,
};
use crate::doc::StackDoc;
use crate::folders::user_folder;
use crate::view::View;
use nacre_optics::Stack;
use std::path::{Path, PathBuf};

/// Tables the cache folder keeps (the oldest are removed after a bake).
pub const KEPT_TABLES: usize = 16;

/// The table's name inside its sub-folder (`studio-lut.json` and its files).
const TABLE_NAME: &str = "studio-lut";

/// What decides a stack's table: the ambient, the films under the top one (material and
/// thickness), the base, the folder relative materials resolve from, film 1's index axis
/// ([`film_ior_range`]), the thickness axis ([`thickness_max_nm`]) and the texel counts.
/// Two stacks with the same key draw from the same table.
pub fn key(doc: &StackDoc, stack: &Stack, counts: &BakeSettings) -> Result<String, String> {
    let Some(top) = doc.films.first() else {
        return Err("a bare interface has no film".into());
    };
    let [ambient, film] = top_indices(stack)?;
    let under: Vec<String> = doc.films[1..]
        .iter()
        .map(|f| format!("{}@{}", f.material.trim(), f.thickness_nm))
        .collect();
    Ok(format!(
        "film-lut v1|ambient {}|under {}|base {}|dir {:?}|ior {:?}|thickness {}|texels {}x{}x{}",
        doc.ambient.trim(),
        under.join(","),
        doc.substrate.trim(),
        doc.base_dir,
        film_ior_range(ambient, film),
        thickness_max_nm(top),
        counts.cos_theta_count,
        counts.opd_count,
        counts.film_ior_count
    ))
}

/// The 64-bit FNV-1a hash of `text` (Fowler, Noll & Vo; offset basis 0xcbf29ce484222325,
/// prime 0x100000001b3): the cache sub-folder's name, the same on every machine.
pub fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The default cache folder: `$XDG_CACHE_HOME/nacre/studio-luts`, else
/// `~/.cache/nacre/studio-luts`; None when neither is known.
pub fn default_folder() -> Option<PathBuf> {
    Some(
        user_folder("XDG_CACHE_HOME", ".cache")?
            .join("nacre")
            .join("studio-luts"),
    )
}

/// The stack tables: the cache folder, the bake running, and how the last one went.
pub struct LiveLut {
    /// The cache folder; None: `lut` draws every stack with the bundled table (and says so).
    pub folder: Option<PathBuf>,
    /// The tables' texel counts (the bundled table's by default: 24 × 384 × 32).
    pub counts: BakeSettings,
    job: Option<(String, BakeJob)>,
    /// A key whose bake failed, and why: not tried again until the key changes.
    failed: Option<(String, String)>,
}

/// What [`LiveLut::update`] decided.
#[derive(Clone, Debug, PartialEq)]
pub struct LutState {
    /// The key `lut` draws with ([`crate::view::ViewSettings::lut_key`]).
    pub key: Option<String>,
    /// Whether a table was loaded this frame (the view must redraw).
    pub loaded: bool,
}

impl LiveLut {
    /// Stack tables cached in `folder` (None: none), at the bundled table's texel counts.
    pub fn new(folder: Option<PathBuf>) -> LiveLut {
        LiveLut {
            folder,
            counts: BakeSettings::default(),
            job: None,
            failed: None,
        }
    }

    /// The table folder of `key`.
    fn table_folder(folder: &Path, key: &str) -> PathBuf {
        folder.join(format!("lut-{:016x}", fnv1a(key)))
    }

    /// Decides the table `lut` draws `doc` with: None (the bundled table) when it holds the
    /// stack or no cache folder is set; else the stack's key, loading the table into `view`
    /// when it is cached or its bake just ended, and starting its bake (cancelling one for
    /// an older stack) when it is neither. Call once per UI frame while `lut` is chosen.
    pub fn update(&mut self, view: &mut View, doc: &StackDoc, stack: &Stack) -> LutState {
        let none = LutState {
            key: None,
            loaded: false,
        };
        let Some(folder) = self.folder.clone() else {
            return none;
        };
        if view.bundled_lut_holds(doc, stack) {
            return none;
        }
        let Ok(key) = key(doc, stack, &self.counts) else {
            return none;
        };
        // A bake for a stack left behind stops (its drop cancels it).
        if self.job.as_ref().is_some_and(|(k, _)| *k != key) {
            self.job = None;
        }
        if view.stack_lut_key() == Some(key.as_str()) {
            return LutState {
                key: Some(key),
                loaded: false,
            };
        }
        if let Some((k, _)) = &self.failed
            && *k == key
        {
            return none;
        }
        // The finished bake of this key, or a table cached before.
        let finished = match &mut self.job {
            Some((k, job)) if *k == key => match job.poll() {
                None => {
                    return LutState {
                        key: Some(key),
                        loaded: false,
                    };
                }
                Some(outcome) => Some(outcome),
            },
            _ => None,
        };
        if finished.is_some() {
            self.job = None;
        }
        let manifest = Self::table_folder(&folder, &key).join(format!("{TABLE_NAME}.json"));
        match finished {
            Some(BakeOutcome::Failed(why)) => {
                self.failed = Some((key, why));
                return none;
            }
            Some(BakeOutcome::Cancelled) | None if !manifest.is_file() => {
                self.start(&folder, &key, doc);
                return match &self.failed {
                    Some((k, _)) if *k == key => none,
                    _ => LutState {
                        key: Some(key),
                        loaded: false,
                    },
                };
            }
            _ => {}
        }
        match view.set_stack_lut(key.clone(), &manifest) {
            Ok(()) => {
                if finished.is_some() {
                    prune(&folder, KEPT_TABLES);
                }
                LutState {
                    key: Some(key),
                    loaded: true,
                }
            }
            Err(_) if finished.is_none() => {
                // A cached table that no longer loads (an older format, a broken file):
                // baked again, atomically over it.
                self.start(&folder, &key, doc);
                LutState {
                    key: Some(key),
                    loaded: false,
                }
            }
            Err(e) => {
                self.failed = Some((key, format!("{}: {e}", manifest.display())));
                none
            }
        }
    }

    /// Starts baking `key`'s table (the previous bake, if any, is cancelled by its drop).
    fn start(&mut self, folder: &Path, key: &str, doc: &StackDoc) {
        let settings = BakeSettings {
            folder: Self::table_folder(folder, key).display().to_string(),
            name: TABLE_NAME.into(),
            ..self.counts.clone()
        };
        match BakeJob::start(doc, &settings) {
            Ok(job) => self.job = Some((key.to_string(), job)),
            Err(why) => {
                self.job = None;
                self.failed = Some((key.to_string(), why));
            }
        }
    }

    /// The running bake's rows done and rows in all, if one runs.
    pub fn progress(&self) -> Option<(u64, u64)> {
        self.job.as_ref().map(|(_, j)| j.progress())
    }

    /// Why the current stack's table could not be baked, if it could not.
    pub fn error(&self) -> Option<&str> {
        self.failed.as_ref().map(|(_, why)| why.as_str())
    }
}

/// Removes all but the `kept` most recently written table folders (`lut-*`) of `folder`.
fn prune(folder: &Path, kept: usize) {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    let mut tables: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with("lut-"))
        .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
        .collect();
    tables.sort();
    let excess = tables.len().saturating_sub(kept);
    for (_, path) in tables.into_iter().take(excess) {
        let _ = std::fs::remove_dir_all(path);
    }
}
