//! `nacre conformance`: the `--quick` grid (2 080 rows, about a second) checked for its
//! format and against `nacre color`, atomic replacement of an existing folder, and the
//! committed `docs/conformance/` equal, byte for byte, to what the command writes.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BASES: [&str; 10] = [
    "1", "1.25", "1.5", "1.75", "2", "2.5", "au", "ag", "cu", "al",
];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn nacre(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(dir)
        .env_remove("NACRE_MATERIAL_DB")
        .output()
        .expect("run nacre")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The rows of a CSV text, header included, read as CSV.
fn csv_rows(text: &str) -> Vec<Vec<String>> {
    nacre_optics::csv_rows::rows("output", text)
        .unwrap()
        .into_iter()
        .map(|r| r.fields)
        .collect()
}

/// Rows of a CSV keyed by their first four fields (base, angle, thickness, film index).
fn rows_by_point(text: &str) -> HashMap<String, Vec<f64>> {
    csv_rows(text)
        .into_iter()
        .skip(1)
        .map(|f| {
            let key = f[..4].join(",");
            let values = f[4..].iter().map(|x| x.parse::<f64>().unwrap()).collect();
            (key, values)
        })
        .collect()
}

#[test]
fn quick_grid_is_well_formed_and_agrees_with_nacre_color() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(&["conformance", "--quick", "-o", "out"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("out");

    let csv = std::fs::read_to_string(out.join("conformance.csv")).unwrap();
    assert_eq!(
        csv.lines().next(),
        Some("base_ior,angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B")
    );
    let mut count = 0;
    for f in csv_rows(&csv).into_iter().skip(1) {
        let line = f.join(",");
        assert_eq!(f.len(), 10, "{line}");
        assert!(BASES.contains(&f[0].as_str()), "{line}");
        let v: Vec<f64> = f[1..].iter().map(|x| x.parse().unwrap()).collect();
        assert!(v.iter().all(|x| x.is_finite()), "{line}");
        let (angle, d, n) = (v[0], v[1], v[2]);
        assert!(
            (0.0..90.0).contains(&angle) && (0.0..=1200.0).contains(&d),
            "{line}"
        );
        assert!((1.0..=2.333).contains(&n), "{line}");
        // A reflectance colour: 0 ≤ Y ≤ 1; at least 8 significant digits.
        assert!((0.0..=1.0).contains(&v[4]), "{line}");
        let y = &f[5];
        assert!(
            v[4] == 0.0 || y.trim_start_matches("0.").len() >= 8,
            "{line}"
        );
        count += 1;
    }
    assert_eq!(count, 10 * 4 * 13 * 4);

    // A few points against `nacre color` (spectral), and the glTF column against
    // `nacre color --method gaussian`.
    let reference = rows_by_point(&csv);
    let gltf_csv = std::fs::read_to_string(out.join("gltf-reference-error.csv")).unwrap();
    assert!(gltf_csv.starts_with("base_ior,angle_deg,thickness_nm,film_ior,R,G,B,delta_e_2000\n"));
    let gltf = rows_by_point(&gltf_csv);
    assert_eq!(gltf.len(), count);
    for (base, angle, d, n) in [
        ("1.5", "30", "300", "1.3"),
        ("au", "60", "500", "2.333"),
        ("1", "0", "400", "1.3"),
        ("cu", "85", "1200", "1.5"),
        ("2.5", "0", "0", "1"),
        ("al", "30", "700", "1.5"),
    ] {
        let key = format!("{base},{angle},{d},{n}");
        for (method, table, columns) in [("spectral", &reference, 0..6), ("gaussian", &gltf, 3..6)]
        {
            let o = nacre(
                &[
                    "color",
                    "--ambient",
                    "1.0",
                    "--layer",
                    &format!("{n}@{d}"),
                    "--substrate",
                    base,
                    "--angles",
                    angle,
                    "--method",
                    method,
                ],
                dir.path(),
            );
            assert!(o.status.success(), "{}", stderr(&o));
            let text = String::from_utf8(o.stdout).unwrap();
            let row: Vec<f64> = csv_rows(&text)[1]
                .iter()
                .map(|x| x.parse().unwrap())
                .collect();
            let ours = &table[&key];
            for (i, c) in columns.enumerate() {
                let want = row[3 + c];
                assert!(
                    (ours[i] - want).abs() <= 1e-11 * want.abs().max(1e-3),
                    "{key} {method}: column {c}: {} vs nacre color {want}",
                    ours[i]
                );
            }
        }
    }

    let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
    for needle in [
        "Do not edit",
        "CIE 1931 2° observer",
        "illuminant D65",
        "Y = 1",
        "(R_s(λ) + R_p(λ)) / 2",
        "measured in the ambient",
        "iridescenceThicknessMinimum",
        "iridescenceIor",
        "KHR_materials_ior",
        "CIEDE2000",
        "| `au` |",
        "nacre conformance --quick -o DIR",
    ] {
        assert!(readme.contains(needle), "README lacks `{needle}`");
    }
    for base in BASES {
        let png = std::fs::read(out.join(format!("swatches-{base}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "{base}");
    }
    assert_eq!(files(&out).len(), 3 + BASES.len());
}

#[test]
fn existing_files_are_replaced_only_on_success() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("conformance.csv"), "old").unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let o = nacre(&["conformance", "--quick", "-o", "out"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("conformance.csv")).unwrap();
    assert!(csv.starts_with("base_ior,"));
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(files(&out).iter().all(|n| !n.starts_with(".nacre-")));

    // A folder in the way of one file: nothing is replaced, nothing is left behind.
    std::fs::remove_file(out.join("swatches-au.png")).unwrap();
    std::fs::create_dir(out.join("swatches-au.png")).unwrap();
    std::fs::write(out.join("conformance.csv"), "old").unwrap();
    let o = nacre(&["conformance", "--quick", "-o", "out"], dir.path());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("swatches-au.png"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(out.join("conformance.csv")).unwrap(),
        "old"
    );
    assert!(files(&out).iter().all(|n| !n.starts_with(".nacre-")));

    // -o naming a file, a folder under a file, conflicting grids: status 2, no output.
    std::fs::write(dir.path().join("plain"), "").unwrap();
    for (args, message) in [
        (
            &["conformance", "--quick", "-o", "plain"][..],
            "is not a folder",
        ),
        (
            &["conformance", "--quick", "-o", "plain/sub"][..],
            "plain/sub",
        ),
        (
            &["conformance", "--quick", "--fine", "-o", "x"][..],
            "--fine",
        ),
        (&["conformance"][..], "--output"),
    ] {
        let o = nacre(args, dir.path());
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
    assert!(!dir.path().join("x").exists());
    assert!(
        nacre(&["conformance", "--help"], dir.path())
            .status
            .success()
    );
}

/// `docs/conformance/` is what `nacre conformance -o docs/conformance` writes (the default
/// grid, about 10 s), so it never goes stale.
#[test]
fn committed_docs_match_the_command() {
    let committed = repo().join("docs/conformance");
    let out = tempfile::tempdir().unwrap();
    let o = nacre(
        &["conformance", "-o", out.path().to_str().unwrap()],
        &repo(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(files(out.path()), files(&committed));
    for name in files(&committed) {
        let a = std::fs::read(committed.join(&name)).unwrap();
        let b = std::fs::read(out.path().join(&name)).unwrap();
        assert!(
            a == b,
            "docs/conformance/{name} differs from what the command writes; re-run `nacre conformance -o docs/conformance` and commit"
        );
    }
    let csv = std::fs::metadata(committed.join("conformance.csv"))
        .unwrap()
        .len();
    assert!(csv <= 10_000_000, "the committed CSV is {csv} bytes");
}
