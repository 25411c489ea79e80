//! The policy for imperfect refractiveindex.info pages (docs/materials.md), on small
//! extracts of real pages committed in `tests/fixtures/refractiveindex/` (CC0 1.0; source
//! and licence in its LICENSE.md): one page per case, looked up through its catalog as
//! `--material-db DIR SHELF/BOOK/PAGE` does. Runs everywhere, with or without the whole
//! database (`refractiveindex_database.rs` tests that).

use nacre_format::materials::{MaterialDb, resolve_with, take_warnings};
use nacre_format::param::Param;
use nacre_optics::{C64, Error, Material, WarningKind};
use std::path::{Path, PathBuf};

fn db_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/refractiveindex")
}

fn load(spec: &str) -> nacre_format::Result<Material> {
    let db = MaterialDb::new(db_dir(), Param::MaterialDb);
    resolve_with(spec, Param::Substrate, None, Some(&db))
}

/// The data file of a page (its path under `database/data`).
fn file(rel: &str) -> String {
    db_dir()
        .join("database/data")
        .join(rel)
        .display()
        .to_string()
}

/// The 1-based line of the fixture `rel` whose text, trimmed, is `row`.
fn line_of(rel: &str, row: &str) -> usize {
    let text = std::fs::read_to_string(file(rel)).unwrap();
    1 + text
        .lines()
        .position(|l| l.trim() == row)
        .unwrap_or_else(|| panic!("{rel}: no line `{row}`"))
}

fn kinds(m: &Material) -> Vec<(usize, WarningKind)> {
    m.warnings()
        .iter()
        .map(|w| (w.line, w.kind.clone()))
        .collect()
}

#[test]
fn a_shelf_named_with_a_digit_is_a_page() {
    let m = load("3d/metals/aluminium").unwrap();
    let direct = load("main/Al/Rakic-BB").unwrap();
    assert_eq!(m.index_at(550.0).unwrap(), direct.index_at(550.0).unwrap());
    assert!(m.warnings().is_empty());
    // A number is still a number.
    assert_eq!(
        load("3.5").unwrap().index_at(500.0).unwrap(),
        C64::new(3.5, 0.0)
    );
}

#[test]
fn repeated_wavelengths_are_merged() {
    let rel = "main/Ag/nk/Yang.yml";
    let m = load("main/Ag/Yang").unwrap();
    // 1.32 µm twice with the same values: merged silently. 1.46 µm twice with other
    // values: their mean, named.
    let first = line_of(rel, "1.460E+00 2.300E-01 1.025E+01");
    let second = line_of(rel, "1.460E+00 2.301E-01 1.026E+01");
    assert_eq!(
        kinds(&m),
        [(
            second,
            WarningKind::Repeated {
                wavelength_um: 1.46,
                first_line: first
            }
        )]
    );
    assert_eq!(m.warnings()[0].source_name, file(rel));
    let at = m.index_at(1460.0).unwrap();
    assert!((at - C64::new(0.23005, 10.255)).norm() < 1e-12, "{at}");
    assert_eq!(m.index_at(1320.0).unwrap(), C64::new(0.1897, 9.243));
    assert_eq!(m.range_nm(), (270.0, 24920.0));
}

#[test]
fn negative_k_is_skipped_and_rows_out_of_order_are_sorted() {
    let rel = "main/Al2O3/nk/Querry-o.yml";
    let m = load("main/Al2O3/Querry-o").unwrap();
    let w = kinds(&m);
    let negative: Vec<usize> = w
        .iter()
        .filter(|(_, k)| matches!(k, WarningKind::NegativeK { .. }))
        .map(|(l, _)| *l)
        .collect();
    let first = line_of(rel, "0.2100 1.831 -0.052");
    assert_eq!(negative, (first..first + 8).collect::<Vec<_>>());
    assert!(w.contains(&(
        line_of(rel, "3.8911 1.683 0.021"),
        WarningKind::OutOfOrder {
            wavelength_um: 3.8911,
            previous_um: 3.8976
        }
    )));
    // k's table now starts at 3.861 µm at k = 0.021: k = 0 below it, named.
    assert!(w.contains(&(
        line_of(rel, "3.8610 1.684 0.021"),
        WarningKind::KTableEnds {
            wavelength_nm: 3861.0,
            lower: true,
            k: 0.021,
            n_range_nm: (210.0, 55555.6)
        }
    )));
    assert_eq!(m.range_nm(), (210.0, 55555.6));
    // n of the rows whose k was skipped is kept.
    assert_eq!(m.index_at(210.0).unwrap(), C64::new(1.831, 0.0));
    let sorted = m.index_at(3891.1).unwrap();
    assert_eq!(sorted, C64::new(1.683, 0.021));
}

#[test]
fn n_not_positive_far_outside_the_range_asked_for_does_not_matter() {
    let rel = "main/Lu/nk/Garcia-Cortes.yml";
    let m = load("main/Lu/Garcia-Cortes").unwrap();
    assert_eq!(
        kinds(&m),
        [(
            line_of(rel, "700475.6352 -256.29294 1265.305"),
            WarningKind::NonPositiveN {
                wavelength_um: 700475.6352,
                n: -256.29294
            }
        )]
    );
    assert_eq!(m.range_nm(), (8.26561e-5, 635816345.8));
    m.index_at(550.0).unwrap();
}

#[test]
fn a_pages_own_endpoints_are_accepted_and_printed_as_written() {
    let m = load("main/Ag/Werner").unwrap();
    assert_eq!(m.range_nm(), (17.586, 2479.684));
    m.index_at(17.586).unwrap();
    m.index_at(2479.684).unwrap();
    let e = m.index_at(17.5).unwrap_err().to_string();
    assert!(e.ends_with("its data covers 17.586–2479.684 nm"), "{e}");
    assert!(m.warnings().is_empty());
}

#[test]
fn formula_n_with_narrower_tabulated_k_covers_the_formula_range() {
    let m = load("main/ZnSe/Amotchkina").unwrap();
    assert_eq!(m.range_nm(), (400.0, 13900.0));
    assert_eq!(m.index_at(400.0).unwrap().im, 1.77e-3);
    for wl in [888.0, 889.0, 5000.0, 13900.0] {
        let n = m.index_at(wl).unwrap();
        assert!(n.re > 2.3 && n.re < 2.8, "{wl}: {n}");
        if wl > 888.0 {
            assert_eq!(n.im, 0.0, "{wl}");
        }
    }
    // k at the table's end is below 10⁻³: k = 0 beyond it without a warning.
    assert!(m.warnings().is_empty(), "{:?}", kinds(&m));
}

#[test]
fn a_formula_non_physical_inside_its_range_is_refused_there_by_name() {
    let rel = "main/CS2/nk/Chemnitz.yml";
    let m = load("main/CS2/Chemnitz").unwrap();
    let &[(from_nm, to_nm)] = m.gaps_nm() else {
        panic!("{:?}", m.gaps_nm())
    };
    // Formula 1 with a pole at C₅ = 6.591946 µm: n² < 0 just below it.
    assert!((6400.0..6591.946).contains(&from_nm) && (6591.946..6592.0).contains(&to_nm));
    assert_eq!(
        kinds(&m),
        [(
            line_of(rel, "wavelength_range: 0.3 12"),
            WarningKind::FormulaGap { from_nm, to_nm }
        )]
    );
    assert_eq!(m.range_nm(), (300.0, 12000.0));
    m.index_at(550.0).unwrap();
    m.index_at(from_nm).unwrap();
    m.index_at(12000.0).unwrap();
    let e = m.index_at(6500.0).unwrap_err();
    assert!(matches!(e, Error::NoPhysicalIndex { .. }), "{e}");
    // Through a parameter, the message names it.
    let named = nacre_format::Error::OpticsIn {
        context: Param::Wavelengths.into(),
        source: e,
    };
    assert!(
        named.to_string().starts_with(
            "wavelengths: material `main/CS2/Chemnitz` has no physical index at 6500 nm"
        ),
        "{named}"
    );
}

#[test]
fn a_second_entry_giving_n_is_ignored() {
    let rel = "organic/(C6H9NO)n - polyvinylpyrrolidone/nk/Konig.yml";
    let m = load("organic/polyvinylpyrrolidone/Konig").unwrap();
    assert_eq!(
        kinds(&m),
        [(
            line_of(rel, "- type: tabulated nk"),
            WarningKind::SecondEntry {
                quantity: 'n',
                first_line: line_of(rel, "- type: formula 5")
            }
        )]
    );
    // n from the formula, k from the table.
    let n = m.index_at(400.0).unwrap();
    assert!((n.re - (1.5151 + 0.00279 / 0.16 + 5.0756e-4 / 0.0256)).abs() < 1e-12);
    assert_eq!(n.im, 0.00397496253061592);
}

#[test]
fn a_page_without_n_stays_an_error() {
    let e = load("main/Si/Daub").unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}:{}: no `DATA` entry gives the real index n (only `tabulated k`): the page cannot be used alone",
            file("main/Si/nk/Daub.yml"),
            line_of("main/Si/nk/Daub.yml", "- type: tabulated k")
        )
    );
}

#[test]
fn warnings_are_collected_once_per_line() {
    // Another test of this binary may read the same pages: take what is there first.
    let _ = take_warnings();
    load("main/Ag/Yang").unwrap();
    load("main/Ag/Yang").unwrap();
    // Tests run in parallel and the warnings are collected globally: another test's pages may
    // add theirs meanwhile, so count only this page's.
    let yang = format!("{}:", file("main/Ag/nk/Yang.yml"));
    let taken: Vec<String> = take_warnings()
        .iter()
        .map(|w| w.to_string())
        .filter(|w| w.starts_with(&yang))
        .collect();
    assert!(taken.len() <= 1, "{taken:?}");
}
