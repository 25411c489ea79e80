//! Only the `nacre` binary knows its flags: the libraries name the inputs that went wrong
//! with `nacre_format::param::Param` values, and `crates/cli/src/error.rs` spells them as
//! flags. This test fails when library code (not comments, not test modules) in
//! nacre-optics, nacre-format, nacre-bake or nacre-runtime holds a string literal that starts
//! with a flag (`"--angles"`, `"-o/--output"`).

use std::path::{Path, PathBuf};

const LIBRARIES: &[&str] = &["optics", "format", "bake", "runtime"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
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

/// `text` without its `#[cfg(test)]` items (the attribute up to the item's closing brace).
fn without_test_items(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let item = &rest[at..];
        let Some(open) = item.find(['{', ';']) else {
            return out;
        };
        if item.as_bytes()[open] == b';' {
            rest = &item[open + 1..];
            continue;
        }
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
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// True when `line` holds a string literal that starts with a flag: `"--x` or `"-x/--y`.
fn names_a_flag(line: &str) -> bool {
    let b = line.as_bytes();
    (0..b.len()).any(|i| {
        if b[i] != b'"' {
            return false;
        }
        let s = &b[i + 1..];
        let long = |s: &[u8]| s.len() > 2 && s.starts_with(b"--") && s[2].is_ascii_lowercase();
        long(s)
            || (s.len() > 3
                && s[0] == b'-'
                && s[1].is_ascii_lowercase()
                && s[2] == b'/'
                && long(&s[3..]))
    })
}

#[test]
fn library_code_names_no_command_line_flag() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    for lib in LIBRARIES {
        let mut files = Vec::new();
        rust_files(&crates.join(lib).join("src"), &mut files);
        assert!(!files.is_empty(), "no sources under crates/{lib}/src");
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            for line in without_test_items(&text).lines() {
                let code = line.trim_start();
                if code.starts_with("//") {
                    continue;
                }
                if names_a_flag(code) {
                    found.push(format!("{}: {}", file.display(), code.trim()));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "library code names command-line flags (use nacre_format::param::Param and let the CLI spell it):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_sees_flags_and_skips_tests_and_comments() {
    assert!(names_a_flag(r#"Error::value("--angles", text, m)"#));
    assert!(names_a_flag(r#"flag: "-o/--output".into(),"#));
    assert!(!names_a_flag(r#"format!("{} --quick", x)"#));
    assert!(!names_a_flag(r#"let s = "a--b";"#));
    let text = "fn a() { f(\"x\") }\n#[cfg(test)]\nmod tests {\n    fn b() { g(\"--angles\") }\n}\nfn c() {}\n";
    let kept = without_test_items(text);
    assert!(kept.contains("fn a()") && kept.contains("fn c()"), "{kept}");
    assert!(!kept.contains("--angles"), "{kept}");
}
