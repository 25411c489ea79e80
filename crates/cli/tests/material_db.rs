//! `--material-db DIR` / `NACRE_MATERIAL_DB`: refractiveindex.info pages `shelf/book/page`
//! read from a local copy of the database, here a tiny fake one in the real layouts.

use std::path::Path;
use std::process::{Command, Output};

fn nacre(args: &[&str], dir: &Path, env_db: Option<&Path>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_nacre"));
    c.args(args)
        .current_dir(dir)
        .env_remove("NACRE_MATERIAL_DB");
    if let Some(db) = env_db {
        c.env("NACRE_MATERIAL_DB", db);
    }
    c.output().expect("run nacre")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A page in the database's own form (header comments, block-scalar REFERENCES/COMMENTS).
const GOLD_LIKE: &str = "# this file is part of a test database\n\nREFERENCES: |\n    A. Author.\n    [*J. Test* **1**, 1 (2025)](https://doi.org/10.0/test)\nCOMMENTS: |\n    Room temperature\nDATA:\n  - type: tabulated nk\n    data: |\n        0.30 1.50 1.80\n        0.50 0.80 2.00\n        1.00 0.20 6.00\n";

/// A fake database: the repository root holding `database/` with the 2025 layout
/// (`data/SHELF/BOOK/nk/PAGE.yml`) for one page and the older one (`data-nk/...`) for another.
fn fake_db(root: &Path) {
    let write = |rel: &str, text: &str| {
        let p = root.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    };
    write("database/data/main/Au/nk/Test.yml", GOLD_LIKE);
    write("database/data-nk/main/Ag/Old.yml", GOLD_LIKE);
    write("page.yml", GOLD_LIKE);
}

#[test]
fn pages_resolve_through_the_flag_and_the_variable() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fake_db(&d.join("db"));
    let db = d.join("db");
    let args = |substrate: &str| {
        vec![
            "spectrum".to_string(),
            "--layer".into(),
            "1.5@300".into(),
            "--substrate".into(),
            substrate.into(),
            "--angles".into(),
            "0:60:30".into(),
            "--wavelengths".into(),
            "400:700:50".into(),
        ]
    };
    let run = |extra: &[&str], substrate: &str, env: Option<&Path>| {
        let mut a: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        a.extend(args(substrate));
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let o = nacre(&a, d, env);
        assert!(o.status.success(), "{a:?}: {}", stderr(&o));
        o.stdout
    };
    let direct = run(&[], "db/page.yml", None);
    let db_str = db.to_str().unwrap();
    // Before or after the subcommand, the repository root or its database/ folder, or the
    // environment variable: the same numbers as the file itself.
    assert_eq!(
        run(&["--material-db", db_str], "main/Au/Test", None),
        direct
    );
    let inner = db.join("database");
    assert_eq!(
        run(
            &["--material-db", inner.to_str().unwrap()],
            "main/Ag/Old",
            None
        ),
        direct
    );
    assert_eq!(run(&[], "main/Au/Test", Some(&db)), direct);
    // The flag wins over the variable.
    assert_eq!(
        run(
            &["--material-db", db_str],
            "main/Au/Test",
            Some(&d.join("nowhere"))
        ),
        direct
    );
    let mut after = args("main/Au/Test");
    after.extend(["--material-db".to_string(), db_str.to_string()]);
    let after: Vec<&str> = after.iter().map(String::as_str).collect();
    let o = nacre(&after, d, None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(o.stdout, direct);
    // Bundled names keep working with a database set.
    let o = nacre(
        &[
            "--material-db",
            db_str,
            "color",
            "--layer",
            "1.5@300",
            "--substrate",
            "au",
            "--angles",
            "0",
        ],
        d,
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // Recipes too.
    std::fs::write(
        d.join("r.toml"),
        "substrate = \"main/Au/Test\"\nangles = \"0:60:30\"\nwavelengths = \"400:700:50\"\n[[layers]]\nmaterial = \"1.5\"\nthickness_nm = 300\n",
    )
    .unwrap();
    let o = nacre(
        &["--material-db", db_str, "spectrum", "--recipe", "r.toml"],
        d,
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(o.stdout, direct);
}

#[test]
fn missing_pages_and_missing_databases_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fake_db(&d.join("db"));
    let db = d.join("db");
    let db_str = db.to_str().unwrap();
    let o = nacre(
        &[
            "--material-db",
            db_str,
            "spectrum",
            "--layer",
            "1.5@300",
            "--substrate",
            "main/Au/Nobody",
            "-o",
            "out.csv",
        ],
        d,
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.starts_with("nacre: error: --substrate: refractiveindex.info page `main/Au/Nobody` not found in the material database"),
        "{e}"
    );
    for needle in [
        "--material-db",
        "database/data/main/Au/Nobody.yml",
        "database/data/main/Au/nk/Nobody.yml",
        "database/data-nk/main/Au/Nobody.yml",
    ] {
        assert!(e.contains(needle), "lacks {needle}: {e}");
    }
    assert!(!d.join("out.csv").exists());
    // Through the variable, the message names the variable.
    let o = nacre(
        &["spectrum", "--layer", "main/Xx/Yy@300"],
        d,
        Some(&d.join("nowhere")),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("--layer") && e.contains("NACRE_MATERIAL_DB") && e.contains("does not exist"),
        "{e}"
    );
    // No database at all: how to set one.
    let o = nacre(&["spectrum", "--substrate", "main/Au/Test"], d, None);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("`main/Au/Test`")
            && e.contains("--material-db DIR")
            && e.contains("NACRE_MATERIAL_DB"),
        "{e}"
    );
}

/// Imperfect pages (docs/materials.md): repaired with a warning on stderr naming file and
/// line, the command succeeding; a shelf starting with a digit; a formula's non-physical
/// stretch refused naming the flag.
#[test]
fn imperfect_pages_work_with_warnings_and_name_their_lines() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |rel: &str, text: &str| {
        let p = d.join("db").join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    };
    // Line 13 repeats 0.50 µm (line 12) with other values; line 14 is out of order; line 15
    // has k < 0.
    write(
        "database/data/main/Au/nk/Messy.yml",
        &GOLD_LIKE.replace(
            "        1.00 0.20 6.00\n",
            "        0.50 0.90 2.20\n        0.40 1.10 1.90\n        0.70 0.40 -1.0\n        1.00 0.20 6.00\n",
        ),
    );
    // A formula with a pole at 2 µm: no physical n for √2 < λ < 2 µm.
    write(
        "database/data/main/X/nk/Pole.yml",
        "DATA:\n  - type: formula 2\n    wavelength_range: 0.5 5\n    coefficients: 0 1 4\n",
    );
    write(
        "database/catalog-nk.yml",
        "- SHELF: 3d\n  content:\n    - BOOK: metals\n      content:\n        - PAGE: gold\n          data: main/Au/nk/Messy.yml\n",
    );
    let db = d.join("db");
    let db = db.to_str().unwrap();
    let spectrum = |substrate: &str, wavelengths: &str| {
        nacre(
            &[
                "--material-db",
                db,
                "spectrum",
                "--substrate",
                substrate,
                "--angles",
                "0",
                "--wavelengths",
                wavelengths,
            ],
            d,
            None,
        )
    };
    for page in ["main/Au/Messy", "3d/metals/gold"] {
        let o = spectrum(page, "300:1000:100");
        let e = stderr(&o);
        assert!(o.status.success(), "{page}: {e}");
        let file = d.join("db/database/data/main/Au/nk/Messy.yml");
        let file = file.display();
        let lines: Vec<&str> = e.lines().collect();
        assert_eq!(
            lines,
            [
                format!("nacre: warning: {file}:13: wavelength 0.5 µm repeats line 12 with other values: their mean is used").as_str(),
                &format!("nacre: warning: {file}:14: wavelength 0.4 µm follows 0.5 µm: the rows are sorted by wavelength"),
                &format!("nacre: warning: {file}:15: k = -1 at 0.7 µm is negative (gain): this k is skipped"),
            ][..],
            "{page}"
        );
        assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 9);
    }
    // The formula: fine outside its gap, refused inside it naming the flag.
    let o = spectrum("main/X/Pole", "1000");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(
            "Pole.yml:3: the formula gives no physical n between 1414.213 and 2000.001 nm"
        ),
        "{}",
        stderr(&o)
    );
    let o = spectrum("main/X/Pole", "1700");
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("nacre: error: --wavelengths: material `main/X/Pole` has no physical index at 1700 nm: its formula gives none between 1414.213 and 2000.001 nm"),
        "{e}"
    );
    assert!(o.stdout.is_empty());
}
