//! Tests of material reading: formulas, tables, the repairs of imperfect pages, CSV and
//! index literals.

use super::*;

const SILICA: &str = "\
# test file
REFERENCES: \"Malitson 1965\"
DATA:
  - type: formula 1
    wavelength_range: 0.21 6.7
    coefficients: 0 0.6961663 0.0684043 0.4079426 0.1162414 0.8974794 9.896161
";

const METAL: &str = "\
REFERENCES: test
DATA:
  - type: tabulated nk
    data: |
        0.40 1.5 1.9
        0.50 1.0 2.0
        0.60 0.5 3.0
";

#[test]
fn sellmeier_fused_silica_at_sodium_d() {
    let m = Material::from_refractiveindex_yaml("silica", "s.yml", SILICA).unwrap();
    let n = m.index_at(587.56).unwrap();
    assert!((n.re - 1.4585).abs() < 1e-4, "{n}");
    assert_eq!(n.im, 0.0);
    assert_eq!(m.range_nm(), (210.0, 6700.0));
    let e = m.index_at(200.0).unwrap_err();
    assert!(matches!(e, Error::WavelengthOutOfRange { .. }), "{e}");
    assert!(e.to_string().contains("silica") && e.to_string().contains("210"));
}

#[test]
fn tabulated_interpolates_linearly_and_refuses_extrapolation() {
    let m = Material::from_refractiveindex_yaml("m", "m.yml", METAL).unwrap();
    let n = m.index_at(450.0).unwrap();
    assert!((n.re - 1.25).abs() < 1e-15 && (n.im - 1.95).abs() < 1e-15);
    assert_eq!(m.index_at(600.0).unwrap(), C64::new(0.5, 3.0));
    assert_eq!(m.index_at(400.0).unwrap(), C64::new(1.5, 1.9));
    assert!(m.index_at(600.0001).is_err());
    assert!(m.index_at(399.9).is_err());
}

/// The table walk of `indices_at` gives `index_at`'s bits and errors in any order of
/// wavelengths: ascending (walked), descending and shuffled (searched), repeated,
/// on the samples, between them, and outside the range.
#[test]
fn indices_at_is_index_at_in_any_order() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tables/materials/au.yml"
    ))
    .unwrap();
    let gold = Material::from_refractiveindex_yaml("au", "au.yml", &text).unwrap();
    let metal = Material::from_refractiveindex_yaml("m", "m.yml", METAL).unwrap();
    let silica = Material::from_refractiveindex_yaml("s", "s.yml", SILICA).unwrap();
    let ascending: Vec<f64> = (0..2000).map(|k| 200.0 + 0.37 * k as f64).collect();
    let mut shuffled = ascending.clone();
    // A fixed permutation (multiplicative, 2000 and 1237 coprime).
    for (k, w) in shuffled.iter_mut().enumerate() {
        *w = ascending[(k * 1237) % ascending.len()];
    }
    let descending: Vec<f64> = ascending.iter().rev().copied().collect();
    let mut sparse: Vec<f64> = vec![400.0, 400.0, 400.0, 450.0, 500.0, 500.0, 600.0];
    sparse.extend([401.0, 599.9, 600.0, 1e-3, 0.0, -5.0, f64::NAN, 800.0, 430.0]);
    for m in [&gold, &metal, &silica] {
        for list in [&ascending, &shuffled, &descending, &sparse] {
            // Every prefix: the values' bits, or the first wavelength's error.
            let one: Vec<Result<C64>> = list.iter().map(|&w| m.index_at(w)).collect();
            for k in 0..list.len() {
                let want: Result<Vec<C64>> = one[..=k].iter().cloned().collect();
                let bits = |v: Vec<C64>| -> Vec<(u64, u64)> {
                    v.iter().map(|n| (n.re.to_bits(), n.im.to_bits())).collect()
                };
                let got = m.indices_at(&list[..=k]);
                assert_eq!(
                    want.map(bits).map_err(|e| e.to_string()),
                    got.map(bits).map_err(|e| e.to_string()),
                    "{} at {} nm",
                    m.name(),
                    list[k]
                );
            }
        }
    }
}

#[test]
fn yaml_errors_name_the_line() {
    let bad = METAL.replace("0.50 1.0 2.0", "0.50 1.0 x2.0");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
    assert_eq!(e.to_string(), "m.yml:6: `x2.0` is not a finite number");
    let bad = METAL.replace("0.50 1.0 2.0", "0.50 1.0 2.0 7");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.yml:6: `tabulated nk` rows need 3 numbers, found 4"
    );
    let bad = METAL.replace("0.50 1.0 2.0", "-0.50 1.0 2.0");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.yml:6: wavelength -0.5 µm must be positive"
    );
    let bad = METAL.replace("data: |\n", "data: |\n\n");
    let bad = bad.replace("0.50 1.0 2.0", "0.50 1.0 x2.0");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
    assert_eq!(e.to_string(), "m.yml:7: `x2.0` is not a finite number");
    let bad = METAL
        .replace("1.5 1.9", "-1.5 1.9")
        .replace("1.0 2.0", "0 2.0");
    let bad = bad.replace("0.5 3.0", "-0.5 3.0");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.yml:5: `tabulated nk` entry has no row with n > 0"
    );
    let e = Material::from_refractiveindex_yaml("m", "m.yml", "DATA: [").unwrap_err();
    assert!(e.to_string().contains("malformed YAML"), "{e}");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", "FOO: 1").unwrap_err();
    assert!(e.to_string().contains("no `DATA` key"), "{e}");
    let bad = SILICA.replace("formula 1", "formula 12");
    let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
    assert!(
        e.to_string().starts_with("m.yml:4: unsupported type"),
        "{e}"
    );
}

#[test]
fn formula_with_tabulated_k_combines() {
    let text = "\
DATA:
  - type: formula 5
    wavelength_range: 0.3 0.9
    coefficients: 1.5 0.01 -2
  - type: tabulated k
    data: |
        0.35 0.1
        0.80 0.2
";
    let m = Material::from_refractiveindex_yaml("c", "c.yml", text).unwrap();
    // n's range; κ = 0 outside κ's table (its ends, 0.1 and 0.2, are named).
    assert_eq!(m.range_nm(), (300.0, 900.0));
    assert_eq!(m.index_at(300.0).unwrap().im, 0.0);
    assert_eq!(m.warnings().len(), 2);
    let n = m.index_at(500.0).unwrap();
    assert!((n.re - (1.5 + 0.01 / 0.25)).abs() < 1e-14);
    assert!((n.im - (0.1 + 0.1 * 150.0 / 450.0)).abs() < 1e-14);
}

fn warnings_of(m: &Material) -> Vec<String> {
    m.warnings().iter().map(ToString::to_string).collect()
}

#[test]
fn repeated_rows_are_merged_and_unordered_rows_sorted() {
    // Line 5 repeats line 4 exactly (merged silently); line 7 repeats line 6 with other
    // values (merged into their mean, named); line 9 is out of order (sorted, named).
    let text = "\
DATA:
  - type: tabulated nk
    data: |
        0.40 1.5 1.9
        0.40 1.5 1.9
        0.50 1.0 2.0
        0.50 1.2 2.2
        0.70 0.5 3.0
        0.60 0.7 2.5
";
    let m = Material::from_refractiveindex_yaml("m", "m.yml", text).unwrap();
    assert_eq!(
        warnings_of(&m),
        [
            "m.yml:7: wavelength 0.5 µm repeats line 6 with other values: their mean is used",
            "m.yml:9: wavelength 0.6 µm follows 0.7 µm: the rows are sorted by wavelength",
        ]
    );
    assert_eq!(m.range_nm(), (400.0, 700.0));
    let at = |w: f64| m.index_at(w).unwrap();
    assert!((at(500.0) - C64::new(1.1, 2.1)).norm() < 1e-15);
    assert_eq!(at(600.0), C64::new(0.7, 2.5));
    assert_eq!(at(400.0), C64::new(1.5, 1.9));
}

#[test]
fn unphysical_values_are_skipped_with_their_lines() {
    // k < 0 at line 4 (k skipped, n kept); n ≤ 0 at the last row (n skipped: the range
    // ends at the row before; k kept but beyond n's range unused).
    let text = "\
DATA:
  - type: tabulated nk
    data: |
        0.40 1.5 -0.2
        0.50 1.0 2.0
        0.60 0.5 3.0
        900 -256 1265
";
    let m = Material::from_refractiveindex_yaml("m", "m.yml", text).unwrap();
    assert_eq!(
        warnings_of(&m),
        [
            "m.yml:4: k = -0.2 at 0.4 µm is negative (gain): this k is skipped",
            "m.yml:5: k is tabulated only from 500 nm (k = 2 there) inside n's range 400–600 nm: k = 0 beyond its table",
            "m.yml:7: n = -256 at 900 µm is not positive: this n is skipped",
        ]
    );
    assert_eq!(m.range_nm(), (400.0, 600.0));
    // κ's table now starts at 500 nm (κ = 2, named): κ = 0 below it.
    assert_eq!(m.index_at(400.0).unwrap(), C64::new(1.5, 0.0));
    assert_eq!(m.index_at(550.0).unwrap(), C64::new(0.75, 2.5));
}

#[test]
fn micrometres_convert_to_the_decimal_nanometres() {
    assert_eq!(um_to_nm("0.017586"), Some(17.586));
    assert_eq!(um_to_nm("2.479684"), Some(2479.684));
    assert_eq!(um_to_nm("1.5E-2"), Some(15.0));
    assert_eq!(um_to_nm("2.36e-3"), Some(2.36));
    assert_eq!(um_to_nm("7e5"), Some(7e8));
    assert_eq!(um_to_nm("x"), None);
    assert_eq!(um_to_nm("inf"), None);
    let text = "DATA:\n  - type: tabulated nk\n    data: |\n        0.017586 0.9 0.3\n        2.479684 0.2 14\n";
    let m = Material::from_refractiveindex_yaml("m", "m.yml", text).unwrap();
    assert_eq!(m.range_nm(), (17.586, 2479.684));
    m.index_at(17.586).unwrap();
    m.index_at(2479.684).unwrap();
}

#[test]
fn formula_n_with_a_narrower_k_table_covers_the_formula_range() {
    // κ tabulated over 0.5–0.8 µm only: κ = 0 outside it (κ = 0.2 at its upper end is
    // not negligible: named); the formula's whole range is usable.
    let text = "\
DATA:
  - type: formula 5
    wavelength_range: 0.4 13.9
    coefficients: 2.4 0.01 -2
  - type: tabulated k
    data: |
        0.50 0.0001
        0.80 0.2
";
    let m = Material::from_refractiveindex_yaml("c", "c.yml", text).unwrap();
    assert_eq!(m.range_nm(), (400.0, 13900.0));
    assert_eq!(m.index_at(450.0).unwrap().im, 0.0);
    assert!((m.index_at(650.0).unwrap().im - 0.10005).abs() < 1e-12);
    assert_eq!(m.index_at(13900.0).unwrap().im, 0.0);
    assert_eq!(
        warnings_of(&m),
        [
            "c.yml:8: k is tabulated only up to 800 nm (k = 0.2 there) inside n's range 400–13900 nm: k = 0 beyond its table"
        ]
    );
}

#[test]
fn a_second_entry_giving_n_is_ignored() {
    let text = "\
DATA:
  - type: formula 5
    wavelength_range: 0.375 1
    coefficients: 1.5 0.002 -2
  - type: tabulated nk
    data: |
        0.375 1.9 0.004
        1.0 1.9 0.001
";
    let m = Material::from_refractiveindex_yaml("c", "c.yml", text).unwrap();
    assert_eq!(
        warnings_of(&m),
        ["c.yml:5: a second entry giving n: the entry of line 2 gives it, this one's n is ignored"]
    );
    let n = m.index_at(500.0).unwrap();
    assert!((n.re - 1.508).abs() < 1e-12 && n.im > 0.001, "{n}");
}

#[test]
fn a_formula_non_physical_inside_its_range_is_cut_or_refused_there() {
    // Formula 2 with a pole at λ² = 4 (2 µm): n² < 0 just above it, down to where
    // 1 + 1·λ²/(λ² − 4) = 0, i.e. λ² = 2 … 4: n is non-physical for √2 < λ < 2 µm.
    let text = "\
DATA:
  - type: formula 2
    wavelength_range: 0.5 5
    coefficients: 0 1 4
";
    let m = Material::from_refractiveindex_yaml("p", "p.yml", text).unwrap();
    assert_eq!(m.range_nm(), (500.0, 5000.0));
    let &[(a, b)] = m.gaps_nm() else {
        panic!("{:?}", m.gaps_nm())
    };
    assert!(
        a <= 2f64.sqrt() * 1e3 && a > 1414.2 && (2000.0..2000.01).contains(&b),
        "{a} {b}"
    );
    m.index_at(a).unwrap();
    m.index_at(b).unwrap();
    let e = m.index_at(1700.0).unwrap_err();
    assert!(matches!(e, Error::NoPhysicalIndex { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "material `p` has no physical index at 1700 nm: its formula gives none between {a} and {b} nm (choose wavelengths outside that interval or another page)"
        )
    );
    assert_eq!(
        warnings_of(&m),
        [format!(
            "p.yml:3: the formula gives no physical n between {a} and {b} nm, inside its wavelength_range: wavelengths there are refused"
        )]
    );
    // Non-physical at an end: the range is cut.
    let cut = text.replace("0.5 5", "1.5 5");
    let m = Material::from_refractiveindex_yaml("p", "p.yml", &cut).unwrap();
    assert_eq!(m.range_nm().0, b);
    assert!(m.gaps_nm().is_empty());
    assert!(warnings_of(&m)[0].contains("only"), "{:?}", warnings_of(&m));
    // Nowhere physical: an error naming the line.
    let none = text.replace("0.5 5", "1.5 1.9");
    let e = Material::from_refractiveindex_yaml("p", "p.yml", &none).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("p.yml:3: the formula gives no physical n"),
        "{e}"
    );
}

#[test]
fn csv_reads_and_reports_lines() {
    let text = "# source: test\nwavelength_nm,n,k\n400,1.5,0\n500,1.6,0.1\n";
    let m = Material::from_nk_csv("c", "c.csv", text).unwrap();
    let n = m.index_at(450.0).unwrap();
    assert!((n.re - 1.55).abs() < 1e-15 && (n.im - 0.05).abs() < 1e-15);
    let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n400,1.5\n").unwrap_err();
    assert!(e.to_string().starts_with("c.csv:2: expected 3"), "{e}");
    let e = Material::from_nk_csv("c", "c.csv", "lambda,n,k\n").unwrap_err();
    assert!(
        e.to_string().starts_with("c.csv:1: expected the header"),
        "{e}"
    );
    let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n400,1.5,0\n300,1.5,0\n")
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("c.csv:3: wavelengths must strictly increase"),
        "{e}"
    );
    let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n400,1.5,nan\n").unwrap_err();
    assert!(e.to_string().starts_with("c.csv:2: k `nan`"), "{e}");
}

#[test]
fn csv_accepts_bom_crlf_comments_quotes_and_spaces() {
    let plain = "wavelength_nm,n,k\n400,1.5,0\n500,1.6,0.1\n650,1.7,0.25\n";
    let fancy = "\u{feff}# measured by hand\r\n\r\n  Wavelength_nm , \"n\", k \r\n\
                     # visible\r\n400, 1.5 ,0\r\n  # indented comment\r\n\
                     \"500\",\"1.6\" , \"0.1\"\r\n   \r\n 650 ,1.7,\t0.25";
    let a = Material::from_nk_csv("c", "c.csv", plain).unwrap();
    let b = Material::from_nk_csv("c", "c.csv", fancy).unwrap();
    assert_eq!(a, b);
    // Errors name the line the row is on, past the BOM, comments and CRLF.
    let e = Material::from_nk_csv("c", "c.csv", &fancy.replace("1.7", "1.7x")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "c.csv:9: n `1.7x` is not a finite number",
        "{fancy:?}"
    );
    let e = Material::from_nk_csv("c", "c.csv", &fancy.replace("1.6", "-1.6")).unwrap_err();
    assert!(e.to_string().starts_with("c.csv:7: n = -1.6"), "{e}");
    let e = Material::from_nk_csv("c", "c.csv", "\u{feff}#\r\nlambda,n,k\r\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "c.csv:2: expected the header `wavelength_nm,n,k`, found `lambda,n,k`"
    );
    let e = Material::from_nk_csv("c", "c.csv", "# nothing\n\n").unwrap_err();
    assert!(e.to_string().starts_with("c.csv:0: no header"), "{e}");
    let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n# none\n").unwrap_err();
    assert!(e.to_string().starts_with("c.csv:0: no data rows"), "{e}");
}

#[test]
fn index_literals() {
    assert_eq!(
        Material::parse_index("1.33")
            .unwrap()
            .index_at(500.0)
            .unwrap(),
        C64::new(1.33, 0.0)
    );
    for text in ["0.27+2.9i", "0.27 + 2.9i", "0.27+2.9j", "2.7e-1+2.9i"] {
        let m = Material::parse_index(text).unwrap();
        assert_eq!(m.index_at(500.0).unwrap(), C64::new(0.27, 2.9), "{text}");
    }
    assert_eq!(
        Material::parse_index("1.5+1e-2i")
            .unwrap()
            .index_at(1.0)
            .unwrap(),
        C64::new(1.5, 0.01)
    );
    for bad in [
        "", "abc", "1.5-0.1i", "-1.5", "0", "1.5+i", "inf", "nan", "1.5+2.0",
    ] {
        assert!(Material::parse_index(bad).is_err(), "{bad} accepted");
    }
    let e = Material::parse_index("1.5-0.1i").unwrap_err();
    assert!(e.to_string().contains("κ"), "{e}");
}
