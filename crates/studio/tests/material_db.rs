//! The material database browser driven by its accessible labels (`egui_kittest`), on the
//! local refractiveindex.info database (`../shared/refractiveindex.info-database`, or
//! `$NACRE_MATERIAL_DB`): skipped, saying so, when it is missing outside CI; a failure in
//! CI (`CI` set).
//!
//! * A folder that holds no database shows why and leaves the stack as it was.
//! * Searching "Au Johnson" lists `main/Au/Johnson` (and only pages whose name or title
//!   holds both words); clicking it makes it film 1's material: the stack builds, and its
//!   film's index at 550 nm is the page's own, read straight from the database.
//! * With "base" chosen, picking `main/SiO2/Malitson` makes it the base's material.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use nacre_format::materials::MaterialDb;
use nacre_studio::Studio;
use nacre_studio::app::MaterialTarget;
use nacre_studio::doc::StackDoc;
use nacre_studio::material_db::{DB_ENV, shared_folder};
use std::path::PathBuf;

mod support;

/// The database folder, or None (the test skips) outside CI.
fn database() -> Option<PathBuf> {
    let dir = std::env::var_os(DB_ENV)
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(shared_folder);
    if dir.join("database/catalog-nk.yml").is_file() || dir.join("catalog-nk.yml").is_file() {
        return Some(dir);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "{} is missing: CI must provide the refractiveindex.info database (../shared/DATA.md)",
        dir.display()
    );
    eprintln!(
        "skipped: the refractiveindex.info database is not at {} (../shared/DATA.md, or set {DB_ENV})",
        dir.display()
    );
    None
}

fn harness() -> Harness<'static, Studio> {
    support::harness_of(
        support::new_studio(StackDoc::default(), [64, 48]),
        [1400.0, 1000.0],
    )
}

fn index_550(db: &MaterialDb, spec: &str) -> (f64, f64) {
    let m = db.load(spec, "test").unwrap();
    let i = m.index_at(550.0).unwrap();
    (i.re, i.im)
}

#[test]
fn search_and_pick_set_the_films_and_the_bases_material() {
    let Some(dir) = database() else {
        return;
    };
    let mut h = harness();
    h.run_steps(2);
    let before = h.state().doc.clone();

    // A folder without a database: an error, the stack untouched.
    let missing = tempfile::tempdir().unwrap();
    h.get_by_label("Database folder")
        .set_text_value_accesskit(missing.path().to_str().unwrap());
    h.run_steps(1);
    h.get_by_label("Open database").click();
    h.run_steps(2);
    let error = h.state().materials.error.clone().expect("an error shown");
    assert!(
        error.contains("is not a refractiveindex.info database"),
        "{error}"
    );
    h.get_by_label_contains("is not a refractiveindex.info database");
    assert_eq!(h.state().doc, before);

    // The real database.
    h.get_by_label("Database folder")
        .set_text_value_accesskit(dir.to_str().unwrap());
    h.run_steps(1);
    h.get_by_label("Open database").click();
    h.run_steps(2);
    assert_eq!(h.state().materials.error, None);
    let pages = h.state().materials.catalog.as_ref().unwrap().pages.len();
    assert!(pages > 1000, "{pages} pages in the catalog");

    h.get_by_label("Search materials")
        .set_text_value_accesskit("Au Johnson");
    h.run_steps(2);
    let (found, total) = h
        .state()
        .materials
        .catalog
        .as_ref()
        .unwrap()
        .search("Au Johnson", usize::MAX);
    assert!(
        (1..pages).contains(&total),
        "{total} of {pages} pages match"
    );
    assert!(found.iter().any(|p| p.spec() == "main/Au/Johnson"));
    for p in &found {
        let text = format!("{} {}", p.spec(), p.name).to_lowercase();
        assert!(text.contains("au") && text.contains("johnson"), "{text}");
    }
    h.get_by_label_contains(&format!("{total} of {pages} pages match"));
    assert_eq!(h.state().materials.target, MaterialTarget::Film(0));
    h.get_by_label("main/Au/Johnson").click();
    h.run_steps(3);
    let s = h.state();
    assert_eq!(s.doc.films[0].material, "main/Au/Johnson");
    assert_eq!(s.stack_error, None);
    assert_eq!(s.stack().0.films[0].material, "main/Au/Johnson");
    let db = MaterialDb::new(&dir, "test");
    let (n, k) = index_550(&db, "main/Au/Johnson");
    let film = s.stack().1.layers()[0].material.index_at(550.0).unwrap();
    assert!(
        (film.re - n).abs() < 1e-12 && (film.im - k).abs() < 1e-12,
        "film 1 at 550 nm: {film}, the page: {n}+{k}i"
    );
    assert!(k > 1.0, "gold absorbs: k = {k}");

    // The base.
    h.get_by_label("base").click();
    h.run_steps(1);
    assert_eq!(h.state().materials.target, MaterialTarget::Base);
    h.get_by_label("Search materials")
        .set_text_value_accesskit("SiO2 Malitson");
    h.run_steps(2);
    h.get_by_label("main/SiO2/Malitson").click();
    h.run_steps(3);
    let s = h.state();
    assert_eq!(s.doc.substrate, "main/SiO2/Malitson");
    assert_eq!(s.stack_error, None);
    let (n, _) = index_550(&db, "main/SiO2/Malitson");
    let base = s.stack().1.substrate().index_at(550.0).unwrap();
    assert!((base.re - n).abs() < 1e-12, "base {base}, page {n}");
    assert!((n - 1.46).abs() < 0.01, "fused silica at 550 nm: {n}");
    // Film 1 kept its gold.
    assert_eq!(s.stack().0.films[0].material, "main/Au/Johnson");
}
