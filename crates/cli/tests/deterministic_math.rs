//! Baked tables are the same bytes for the same recipe on every machine (docs/hardening.md,
//! "Determinism"). The platform C library's transcendental functions are not correctly
//! rounded and differ between glibc, macOS, musl and Windows, so library code computes them
//! with `nacre_optics::elementary` (pure Rust, the same bits everywhere) instead. This test
//! fails when library code (not comments, not `#[cfg(test)]` items) in nacre-optics,
//! nacre-format or nacre-bake calls one of `f64`'s transcendental methods (`.sin(`,
//! `.exp(`, `.powi(`, …, also named as `f64::cos`) or num-complex's `from_polar`, `to_polar`
//! or `norm()` (which call the platform's sin, cos, atan2 and hypot).
//!
//! A justified use (a value that never reaches a table or an exact output, e.g. a plot's
//! tick spacing) carries the marker `det-allow:` and its reason in a comment on the same
//! line or the line above. Not caught by a text scan: num-complex's `Complex::sqrt` (libm
//! `atan2`/`hypot`/`sin`/`cos` off the axes); complex square roots go through
//! `nacre_optics::elementary::csqrt`.

mod source_scan;

use source_scan::{rust_files, without_test_items};
use std::path::Path;

/// The crates whose library code produces table bytes (and `nacre color` / `nacre spectrum`
/// outputs): every `.rs` file under their `src/`.
const LIBRARIES: &[&str] = &["optics", "format", "bake"];

/// The one module allowed to call the underlying functions (it wraps the `libm` crate, not
/// the platform's, and tests it against the platform's).
const WRAPPER: &str = "crates/optics/src/elementary.rs";

/// `f64` methods whose results the platform libm computes (powi: the standard leaves its
/// result to the implementation).
const FORBIDDEN_METHODS: &[&str] = &[
    "sin", "cos", "tan", "sin_cos", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
    "asinh", "acosh", "atanh", "exp", "exp2", "exp_m1", "ln", "ln_1p", "log", "log2", "log10",
    "powf", "powi", "cbrt", "hypot",
];

/// The forbidden calls in `code` (one line, comments removed): `.name(` for a method of
/// [`FORBIDDEN_METHODS`], `f64::name` as a path, and num-complex's libm-backed methods.
fn forbidden_calls(code: &str) -> Vec<String> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut found = Vec::new();
    for name in FORBIDDEN_METHODS {
        if code.contains(&format!(".{name}(")) {
            found.push(format!(".{name}("));
        }
        let path = format!("f64::{name}");
        let mut from = 0;
        while let Some(at) = code[from..].find(&path) {
            let end = from + at + path.len();
            if !code[end..].starts_with(ident) {
                found.push(path.clone());
            }
            from = end;
        }
    }
    for call in ["from_polar(", ".to_polar(", ".norm()"] {
        if code.contains(call) && !code.contains(&format!("elementary::{call}")) {
            found.push(call.to_string());
        }
    }
    found
}

/// Offending (file:line, call, source) of every crate's library code.
fn offending_lines(root: &Path) -> Vec<String> {
    let mut files = Vec::new();
    for lib in LIBRARIES {
        rust_files(&root.join("crates").join(lib).join("src"), &mut files);
    }
    assert!(files.len() > 40, "found only {} source files", files.len());
    let mut bad = Vec::new();
    for path in files {
        let relative = path
            .strip_prefix(root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        // `#[cfg(test)] mod tests;` modules live in their own `tests.rs`.
        if relative == WRAPPER || path.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        bad.extend(offending_in(&relative, &text));
    }
    bad
}

/// Offending lines of one file's `text` (`relative` names it in the messages).
fn offending_in(relative: &str, text: &str) -> Vec<String> {
    let mut bad = Vec::new();
    let code = without_test_items(text);
    let mut previous = "";
    for (i, line) in code.lines().enumerate() {
        let (code_part, comment) = match line.find("//") {
            Some(at) => (&line[..at], &line[at..]),
            None => (line, ""),
        };
        let allowed = comment.contains("det-allow:") || previous.contains("det-allow:");
        previous = line;
        if allowed {
            continue;
        }
        for call in forbidden_calls(code_part) {
            bad.push(format!("{relative}:{}: {call} in `{}`", i + 1, line.trim()));
        }
    }
    bad
}

#[test]
fn table_code_calls_no_platform_transcendental() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let bad = offending_lines(&root);
    assert!(
        bad.is_empty(),
        "platform libm calls in library code (use nacre_optics::elementary, or mark a value \
         that never reaches a table or an exact output with `// det-allow: reason`):\n{}",
        bad.join("\n")
    );
}

/// The scan catches each form it promises to, and not the deterministic spellings.
#[test]
fn the_scan_finds_what_it_forbids() {
    for line in [
        "let s = x.sin();",
        "let (s, c) = (2.0 * PI * u).sin_cos();",
        "let e = (-a).exp();",
        "let p = h.powi(n as i32);",
        "let f = [f64::cos, f64::sin];",
        "let r = z.norm();",
        "let e = C64::from_polar(1.0, phi);",
        "let t = y.atan2(x);",
    ] {
        assert!(!forbidden_calls(line).is_empty(), "{line}");
    }
    for line in [
        "let s = elementary::sin(x);",
        "let (s, c) = elementary::sin_cos(2.0 * PI * u);",
        "let r = elementary::norm(z);",
        "let e = elementary::from_polar(1.0, phi);",
        "let q = x.sqrt();",
        "let n = z.norm_sqr();",
        "let d = angle.to_radians();",
        "let s = f64::sinusoid;",
    ] {
        assert_eq!(forbidden_calls(line), Vec::<String>::new(), "{line}");
    }
    let text = "fn f() {}\n#[cfg(test)]\nmod tests {\n    fn g() { 1f64.sin(); }\n}\nfn h(x: f64) -> f64 { x.exp() }\n";
    let code = without_test_items(text);
    assert_eq!(code.lines().count(), text.lines().count());
    assert!(!code.contains(".sin("));
    assert!(code.contains("x.exp()"));
    assert_eq!(
        offending_in("f.rs", text),
        ["f.rs:6: .exp( in `fn h(x: f64) -> f64 { x.exp() }`"]
    );
    let allowed = "// det-allow: a plot's tick spacing, never in a table\nlet e = 10f64.powf(k);\nlet t = v.ln(); // det-allow: log axis of a picture\n// the real thing: x.sin() in a comment\n";
    assert_eq!(offending_in("g.rs", allowed), Vec::<String>::new());
    assert_eq!(offending_in("g.rs", "let e = 10f64.powf(k);\n").len(), 1);
}
