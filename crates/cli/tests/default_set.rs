//! The committed default table set (`tables/baked/`) is exactly what `nacre bake` produces
//! from `tables/recipes/`, byte for byte, whatever the thread count.

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn rebaking_the_defaults_reproduces_the_committed_files() {
    let committed = repo().join("tables/baked");
    for threads in ["1", "2"] {
        let out = tempfile::tempdir().unwrap();
        let status = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args(["bake", "--out"])
            .arg(out.path())
            .current_dir(repo())
            .env("RAYON_NUM_THREADS", threads)
            .status()
            .unwrap();
        assert!(status.success());
        assert_eq!(files(out.path()), files(&committed));
        for name in files(&committed) {
            let a = std::fs::read(committed.join(&name)).unwrap();
            let b = std::fs::read(out.path().join(&name)).unwrap();
            assert!(
                a == b,
                "{name} differs from the committed file (RAYON_NUM_THREADS={threads}); re-run `nacre bake` and commit"
            );
        }
    }
}
