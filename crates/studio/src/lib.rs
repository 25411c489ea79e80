//! nacre studio: design a thin-film stack by eye. The stack editor (ambient, up to eight
//! films, base; the CLI's material parser), the runtime's renderer drawing it live on a
//! sphere, a bubble or a plane, its spectra and its exact colour against angle beside it,
//! and the recipe TOML the CLI reads.
//!
//! Files: `bake.rs` (the export panel's table bake on a background thread), `compare.rs` (the ΔE2000 map against the exact technique), `doc.rs` (the stack as edited, presets, undo, the recipe), `engine.rs` (the engine export: the closest glTF film, the stack JSON, Bevy and three.js snippets), `fit.rs` (the fit panel's colour design and spectrum fit on a background thread), `material_db.rs` (the refractiveindex.info database's catalog and its search, for the browser), `view.rs` (the live
//! view on the runtime's `Renderer`), `curves.rs` (spectra and colours for the plots, on a
//! background thread), `app/` (the window's panels, one file each), `main.rs` (the `nacre-studio`
//! binary: its flags, eframe, `--screenshot`).

pub mod app;
pub mod bake;
pub mod compare;
pub mod curves;
pub mod doc;
pub mod engine;
pub mod fit;
pub mod folders;
pub mod live_lut;
pub mod material_db;
pub mod view;

pub use app::Studio;
pub use doc::StackDoc;
pub use view::{View, ViewSettings};
