//! Source scans shared by the tests that hold library code to a rule
//! (`deterministic_math.rs`, `no_flags_in_libraries.rs`): the `.rs` files of a crate and
//! its code without `#[cfg(test)]` items.

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, recursively, in sorted order (appended to `out`).
pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

/// `text` with its `#[cfg(test)]` items blanked (the attribute up to the item's closing
/// brace, or `;` for `mod tests;`), keeping line breaks so that line numbers stay right.
pub fn without_test_items(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    let blank = |s: &str| {
        s.chars()
            .map(|c| if c == '\n' { '\n' } else { ' ' })
            .collect::<String>()
    };
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let item = &rest[at..];
        let Some(open) = item.find(['{', ';']) else {
            out.push_str(&blank(item));
            return out;
        };
        let end = if item.as_bytes()[open] == b';' {
            open + 1
        } else {
            let mut depth = 0usize;
            let mut end = item.len();
            for (i, c) in item[open..].char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            end = open + i + 1;
                            break;
                        }
                    }
                    _ => {}
                }
            }
            end
        };
        out.push_str(&blank(&item[..end]));
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}
