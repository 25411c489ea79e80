//! Every page of the refractiveindex.info database, loaded in-process the way `nacre` loads
//! `--material-db DIR SHELF/BOOK/PAGE`, and probed over the whole wavelength range its data
//! states (docs/materials.md, "Pages of the refractiveindex.info database").
//!
//! Where it looks: `$NACRE_REFRACTIVEINDEX_DB` when set, else
//! `../shared/refractiveindex.info-database` beside the project root (the copy the project's
//! machines keep; `../shared/DATA.md`). Without it the test fails in CI (the `CI`
//! environment variable set to anything but `false`/`0`) and skips elsewhere with a message
//! (a user's clone does not have it).
//!
//! This test reads each data file itself (with yaml-rust2, not nacre's reader) to know the
//! range the page states: the wavelengths of the entry that gives n (its table's first and
//! last rows, or its formula's `wavelength_range`). A page passes when nacre loads it and
//! gives a physical index at every probe inside that range, except where nacre's warnings
//! say why a part of the range was set aside (rows with n ≤ 0 at a table's ends, a formula
//! that turns non-physical). Only pages that give no n at all (`tabulated k` alone) may be
//! refused.

use nacre_format::materials::{MaterialDb, resolve_with};
use nacre_format::param::Param;
use nacre_optics::{Error, WarningKind};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use yaml_rust2::{Yaml, YamlLoader};

fn database_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("NACRE_REFRACTIVEINDEX_DB") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/refractiveindex.info-database"),
    };
    if dir.join("database/catalog-nk.yml").is_file() {
        return Some(dir);
    }
    let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
    let message = format!(
        "the refractiveindex.info database is not at {} (set NACRE_REFRACTIVEINDEX_DB to a \
         clone of https://github.com/polyanskiy/refractiveindex.info-database; see ../shared/DATA.md)",
        dir.display()
    );
    if ci {
        panic!("{message}: CI must have it");
    }
    eprintln!("skipped: {message}");
    None
}

/// Every page of `catalog-nk.yml`: (`SHELF/BOOK/PAGE`, data path under `database/data`).
fn catalog(dir: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(dir.join("database/catalog-nk.yml")).unwrap();
    let docs = YamlLoader::load_from_str(&text).unwrap();
    let mut pages = Vec::new();
    fn walk(items: &Yaml, shelf: &str, book: &str, out: &mut Vec<(String, String)>) {
        for item in items.as_vec().into_iter().flatten() {
            let key = |k: &str| -> Option<String> {
                match &item[k] {
                    Yaml::String(s) => Some(s.clone()),
                    Yaml::Integer(i) => Some(i.to_string()),
                    Yaml::Real(r) => Some(r.clone()),
                    _ => None,
                }
            };
            if let Some(s) = key("SHELF") {
                walk(&item["content"], &s, "", out);
            } else if let Some(b) = key("BOOK") {
                walk(&item["content"], shelf, &b, out);
            } else if let (Some(p), Some(d)) = (key("PAGE"), key("data")) {
                out.push((format!("{shelf}/{book}/{p}"), d));
            }
        }
    }
    walk(&docs[0], "", "", &mut pages);
    let mut seen = std::collections::HashSet::new();
    pages.retain(|(spec, _)| seen.insert(spec.clone()));
    pages
}

/// A decimal number of micrometres in nanometres, correctly rounded (the test's own
/// conversion: the decimal point moved three places in the text).
fn um_text_to_nm(t: &str) -> f64 {
    let t = t.trim();
    let (mantissa, exponent) = match t.find(['e', 'E']) {
        Some(i) => (&t[..i], t[i + 1..].parse::<i32>().unwrap()),
        None => (t, 0),
    };
    format!("{mantissa}e{}", exponent + 3).parse().unwrap()
}

/// What the data file states about n: its range in nm, and the wavelengths to probe.
struct Stated {
    range_nm: (f64, f64),
    probes_nm: Vec<f64>,
    gives_n: bool,
}

fn stated(path: &Path) -> Stated {
    let text = std::fs::read_to_string(path).unwrap();
    let docs = YamlLoader::load_from_str(&text).unwrap();
    for entry in docs[0]["DATA"].as_vec().unwrap() {
        let ty = entry["type"].as_str().unwrap();
        if ty == "tabulated k" {
            continue;
        }
        if ty.starts_with("formula") {
            let range = match &entry["wavelength_range"] {
                Yaml::String(s) => s.clone(),
                Yaml::BadValue => "0.2 2".into(), // no range stated: probe the visible
                other => panic!("{}: wavelength_range {other:?}", path.display()),
            };
            let v: Vec<f64> = range.split_whitespace().map(um_text_to_nm).collect();
            let (lo, hi) = (v[0], v[1]);
            let mut probes: Vec<f64> = (0..=256)
                .map(|i| lo * (hi / lo).powf(i as f64 / 256.0))
                .collect();
            probes[0] = lo;
            probes[256] = hi;
            return Stated {
                range_nm: (lo, hi),
                probes_nm: probes,
                gives_n: true,
            };
        }
        let data = entry["data"].as_str().unwrap();
        let w: Vec<f64> = data
            .lines()
            .filter_map(|l| l.split_whitespace().next())
            .map(um_text_to_nm)
            .collect();
        let lo = w.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = w.iter().copied().fold(0.0, f64::max);
        return Stated {
            range_nm: (lo, hi),
            probes_nm: w,
            gives_n: true,
        };
    }
    Stated {
        range_nm: (0.0, 0.0),
        probes_nm: vec![],
        gives_n: false,
    }
}

#[derive(Debug)]
enum Outcome {
    /// Every probe of the stated range gives a physical index.
    Full,
    /// Loaded; some probes are refused, each explained by a warning: (refused, total).
    Part(usize, usize),
    /// Refused because the page gives no n.
    NoN,
    /// Not explained: what went wrong.
    Bad(String),
}

fn probe(spec: &str, data: &Path, db: &MaterialDb) -> (Stated, Outcome, usize) {
    let st = stated(data);
    let m = match resolve_with(spec, Param::Substrate, None, Some(db)) {
        Err(e) => {
            let e = e.to_string();
            let outcome = if !st.gives_n && e.contains("no `DATA` entry gives the real index n") {
                Outcome::NoN
            } else {
                Outcome::Bad(format!("refused: {e}"))
            };
            return (st, outcome, 0);
        }
        Ok(m) => m,
    };
    if !st.gives_n {
        return (st, Outcome::Bad("a page without n was loaded".into()), 0);
    }
    // Every warning names this file and a line of it.
    let lines = std::fs::read_to_string(data).unwrap().lines().count();
    if let Some(w) = m
        .warnings()
        .iter()
        .find(|w| w.source_name != data.display().to_string() || w.line == 0 || w.line > lines)
    {
        return (
            st,
            Outcome::Bad(format!("warning names no line of the page: {w}")),
            0,
        );
    }
    let warned = |pred: &dyn Fn(&WarningKind) -> bool| m.warnings().iter().any(|w| pred(&w.kind));
    let (lo, hi) = m.range_nm();
    let mut refused = 0;
    for &w in &st.probes_nm {
        match m.index_at(w) {
            Ok(_) => {}
            // Outside the range kept: rows with n ≤ 0 at a table's end, or a formula cut.
            Err(Error::WavelengthOutOfRange { .. })
                if (w < lo || w > hi)
                    && warned(&|k| {
                        matches!(
                            k,
                            WarningKind::NonPositiveN { .. } | WarningKind::FormulaRangeCut { .. }
                        )
                    }) =>
            {
                refused += 1
            }
            Err(Error::NoPhysicalIndex { from_nm, to_nm, .. })
                if warned(&|k| *k == WarningKind::FormulaGap { from_nm, to_nm }) =>
            {
                refused += 1
            }
            Err(e) => {
                return (
                    st,
                    Outcome::Bad(format!("at {w} nm: {e}")),
                    m.warnings().len(),
                );
            }
        }
    }
    let outcome = if refused == 0 {
        Outcome::Full
    } else {
        Outcome::Part(refused, st.probes_nm.len())
    };
    (st, outcome, m.warnings().len())
}

#[test]
fn every_page_is_usable_over_its_stated_range() {
    let Some(dir) = database_dir() else { return };
    let db = MaterialDb::new(&dir, Param::MaterialDb);
    let pages = catalog(&dir);
    assert!(
        pages.len() > 3000,
        "only {} pages in the catalog",
        pages.len()
    );
    let results: Vec<(String, Stated, Outcome, usize)> = pages
        .par_iter()
        .map(|(spec, data)| {
            let (st, outcome, warnings) = probe(spec, &dir.join("database/data").join(data), &db);
            (spec.clone(), st, outcome, warnings)
        })
        .collect();
    let count = |f: &dyn Fn(&Outcome) -> bool| results.iter().filter(|r| f(&r.2)).count();
    let full = count(&|o| matches!(o, Outcome::Full));
    let part = count(&|o| matches!(o, Outcome::Part(..)));
    let no_n = count(&|o| matches!(o, Outcome::NoN));
    let warned = results.iter().filter(|r| r.3 > 0).count();
    eprintln!(
        "refractiveindex.info: {} pages: {full} usable over their whole stated range, {part} in part \
         (the rest of their range refused with a warning), {no_n} refused (no n: `tabulated k` alone); \
         {warned} loaded with warnings",
        results.len(),
    );
    for (spec, st, o, _) in &results {
        if let Outcome::Part(refused, total) = o {
            eprintln!(
                "  in part: {spec} ({}–{} nm stated): {refused} of {total} probes refused",
                st.range_nm.0, st.range_nm.1
            );
        }
    }
    let bad: Vec<String> = results
        .iter()
        .filter_map(|(spec, _, o, _)| match o {
            Outcome::Bad(why) => Some(format!("{spec}: {why}")),
            _ => None,
        })
        .collect();
    assert!(
        bad.is_empty(),
        "{} page(s) not usable where their data are sound:\n{}",
        bad.len(),
        bad.join("\n")
    );
}
