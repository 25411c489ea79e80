//! Only the `nacre` binary knows its flags: the libraries name the inputs that went wrong
//! with `nacre_format::param::Param` values, and `crates/cli/src/error.rs` spells them as
//! flags. This test fails when library code (not comments, not test modules) in
//! nacre-optics, nacre-format, nacre-bake or nacre-runtime holds a string literal that starts
//! with a flag (`"--angles"`, `"-o/--output"`).

mod source_scan;

use source_scan::{rust_files, without_test_items};
use std::path::Path;

const LIBRARIES: &[&str] = &["optics", "format", "bake", "runtime"];

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
