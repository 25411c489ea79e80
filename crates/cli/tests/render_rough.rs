//! `nacre render --film-eval` and `--scene rough-row` (issue 6): the split-sum paths render
//! through the CLI (GPU: lavapipe without one; fails, never skips, without an adapter), and
//! bad values exit with status 2 without writing the output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn nacre(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(repo_root())
        .output()
        .expect("nacre runs")
}

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

#[test]
fn every_film_eval_renders_and_bad_values_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    for eval in ["classic", "nv", "exact"] {
        let out = dir.path().join(format!("{eval}.png"));
        let o = nacre(&[
            "render",
            "--film-eval",
            eval,
            "--width",
            "24",
            "--height",
            "16",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(
            o.status.success(),
            "{eval}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert_eq!(png_size(&out), (24, 16));
    }
    let out = dir.path().join("bad.png");
    for args in [
        &["--film-eval", "fresnel"][..],
        &["--scene", "rough-row", "--reference-samples", "8"][..],
        // The exact path without a rough-film-lut in the table set.
        &["--film-eval", "exact", "--tables", "film-dielectric"][..],
    ] {
        let mut v = vec!["render", "--width", "8", "--height", "8"];
        v.extend_from_slice(args);
        v.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = nacre(&v);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!out.exists(), "{args:?} wrote its output");
    }
}
