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
