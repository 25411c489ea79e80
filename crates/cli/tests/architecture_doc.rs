//! `docs/architecture.md` tells where code lives: every repository path it names in
//! backticks (`crates/…`, `shaders/…`, `tests/…`, …) must exist, so that a file moved or
//! renamed without the document fails here. Placeholders (`NEW_KIND.rs`, `film_NEW.wgsl`,
//! `NAME`) stand for files a reader adds and are not checked.

use std::path::Path;

/// The top-level directories whose paths the document names.
const ROOTS: &[&str] = &[
    "crates/",
    "shaders/",
    "tests/",
    "integrations/",
    "docs/",
    "tables/",
    "python/",
    "fuzz/",
    ".ci/",
];

/// The backticked spans of `text` that are repository paths: a known root, then path
/// characters only (a `::item` or `(…)` after the path is cut off).
fn paths(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, span) in text.split('`').enumerate() {
        if i % 2 == 0 || !ROOTS.iter().any(|r| span.starts_with(r)) {
            continue;
        }
        let path: String = span
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || "/_.-".contains(*c))
            .collect();
        let path = path.trim_end_matches('.');
        let placeholder = path.contains("NEW") || path.contains("NAME");
        if !placeholder {
            out.push(path.to_string());
        }
    }
    out
}

#[test]
fn every_path_in_the_architecture_document_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
    let listed = paths(&doc);
    assert!(listed.len() > 30, "only {} paths found", listed.len());
    let missing: Vec<&String> = listed.iter().filter(|p| !root.join(p).exists()).collect();
    assert!(
        missing.is_empty(),
        "docs/architecture.md names files that do not exist: {missing:?}"
    );
}

#[test]
fn path_extraction() {
    let text = "`crates/a/b.rs` and `crates/x.rs::Item` in `shaders/film_NEW.wgsl`, \
                `crates/format/src/NEW_KIND.rs`, `nacre render`, `shaders/README.md`, `tests/tests/`.";
    assert_eq!(
        paths(text),
        [
            "crates/a/b.rs",
            "crates/x.rs",
            "shaders/README.md",
            "tests/tests/"
        ]
    );
}
