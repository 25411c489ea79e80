//! Every relative link of the project's Markdown resolves: `README.md`, `BENCHMARKS.md`, the
//! user guide (`docs/guide/src/`) and everything else under `docs/`, plus the READMEs and
//! guides beside the code (`python/`, `integrations/`, `shaders/`, `fuzz/`, `tables/`,
//! `scripts/`). A link `PATH` must name an existing file or folder (relative to the file
//! that holds it); `PATH#ANCHOR` and `#ANCHOR` into a Markdown file must name one of its
//! headings, by the anchor GitHub and mdBook both derive from the heading's text
//! (lower-cased; letters, digits, `-` and `_` kept, each space a `-`, other characters
//! dropped; a repeated heading gets `-1`, `-2`, …) or an explicit `<a id="…">`.
//! Links with a scheme (`https:`, `mailto:`) are not followed.
//!
//! The scanner knows the Markdown these files use: inline links and images
//! `[text](dest "title")`, reference definitions `[label]: dest`, fenced code blocks and
//! inline code spans (whose contents are not links).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Folders whose Markdown is not ours to check: build outputs, dependencies, generated books.
const SKIPPED_DIRS: [&str; 6] = ["target", ".git", "node_modules", "book", ".venv", "corpus"];

fn markdown_files(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md"), root.join("BENCHMARKS.md")];
    for dir in [
        "docs",
        "python",
        "integrations",
        "shaders",
        "fuzz",
        "tables",
        "scripts",
    ] {
        walk(&root.join(dir), &mut files);
    }
    files.retain(|f| f.is_file());
    files.sort();
    files.dedup();
    files
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).collect();
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if path.is_dir() {
            if !SKIPPED_DIRS.contains(&name.as_ref()) {
                walk(&path, out);
            }
        } else if name.ends_with(".md") {
            out.push(path);
        }
    }
}

/// One link found in a file: its line (1-based) and destination.
struct Link {
    line: usize,
    dest: String,
}

/// The text of each line with code removed: fenced blocks become empty lines, inline code
/// spans are blanked. Returns (line number, text) pairs.
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fence: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        if let Some(marker) = &fence {
            if trimmed.starts_with(marker.as_str()) {
                fence = None;
            }
            continue;
        }
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            let ch = trimmed.chars().next().unwrap_or('`');
            let len = trimmed.chars().take_while(|&c| c == ch).count();
            fence = Some(std::iter::repeat_n(ch, len).collect());
            continue;
        }
        out.push((i + 1, blank_code_spans(line)));
    }
    out
}

/// Replaces the contents of inline code spans (`` `…` ``, ``` ``…`` ```) with spaces.
fn blank_code_spans(line: &str) -> String {
    let chars: Vec<char> = line.chars().collect();
    let mut out = String::with_capacity(line.len());
    let mut i = 0;
    while i < chars.len() {
        if chars[i] == '`' {
            let run = chars[i..].iter().take_while(|&&c| c == '`').count();
            // Find the closing run of the same length.
            let mut j = i + run;
            let mut close = None;
            while j < chars.len() {
                if chars[j] == '`' {
                    let r = chars[j..].iter().take_while(|&&c| c == '`').count();
                    if r == run {
                        close = Some(j);
                        break;
                    }
                    j += r;
                } else {
                    j += 1;
                }
            }
            match close {
                Some(j) => {
                    out.extend(std::iter::repeat_n(' ', j + run - i));
                    i = j + run;
                }
                None => {
                    out.extend(&chars[i..i + run]);
                    i += run;
                }
            }
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

fn links(text: &str) -> Vec<Link> {
    let mut found = Vec::new();
    for (line, prose) in prose_lines(text) {
        // Reference definitions: `[label]: dest`.
        let trimmed = prose.trim_start();
        if trimmed.starts_with('[')
            && let Some(end) = trimmed.find("]:")
        {
            let dest = trimmed[end + 2..].split_whitespace().next().unwrap_or("");
            if !dest.is_empty() {
                found.push(Link {
                    line,
                    dest: dest.trim_matches(['<', '>']).to_string(),
                });
            }
        }
        // Inline links and images: `](dest)` or `](dest "title")`.
        let mut rest = prose.as_str();
        while let Some(start) = rest.find("](") {
            let after = &rest[start + 2..];
            let Some(close) = after.find(')') else {
                break;
            };
            let inside = after[..close].trim();
            let dest = inside.split_whitespace().next().unwrap_or("");
            if !dest.is_empty() {
                found.push(Link {
                    line,
                    dest: dest.trim_matches(['<', '>']).to_string(),
                });
            }
            rest = &after[close..];
        }
    }
    found
}

/// The anchor GitHub and mdBook derive from a heading's text.
fn slug(heading: &str) -> String {
    heading
        .chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                Some(c.to_lowercase().next().unwrap_or(c))
            } else if c == ' ' {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// A heading's text as rendered: code spans keep their text, links keep their label,
/// emphasis markers go.
fn heading_text(raw: &str) -> String {
    let mut text = String::new();
    let mut chars = raw.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '`' | '*' => {}
            '[' => {}
            ']' => {
                // Drop a following `(dest)`.
                if chars.peek() == Some(&'(') {
                    for d in chars.by_ref() {
                        if d == ')' {
                            break;
                        }
                    }
                }
            }
            _ => text.push(c),
        }
    }
    text.trim().to_string()
}

/// Every anchor a Markdown file defines.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = BTreeSet::new();
    let mut fence = false;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fence = !fence;
            continue;
        }
        if fence {
            continue;
        }
        for marker in ["<a id=\"", "<a name=\""] {
            let mut rest = line;
            while let Some(start) = rest.find(marker) {
                let after = &rest[start + marker.len()..];
                if let Some(end) = after.find('"') {
                    out.insert(after[..end].to_string());
                }
                rest = after;
            }
        }
        let hashes = trimmed.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && trimmed[hashes..].starts_with(' ') {
            let base = slug(&heading_text(&trimmed[hashes..]));
            let n = seen.entry(base.clone()).or_insert(0);
            let anchor = if *n == 0 {
                base.clone()
            } else {
                format!("{base}-{n}")
            };
            *n += 1;
            out.insert(anchor);
        }
    }
    out
}

/// `path` with `.` and `..` resolved lexically (the files need not exist).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16)
        {
            out.push(v);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn has_scheme(dest: &str) -> bool {
    let Some(colon) = dest.find(':') else {
        return false;
    };
    let scheme = &dest[..colon];
    !scheme.is_empty()
        && scheme
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '+' || c == '-' || c == '.')
        && !scheme.contains('/')
}

/// The broken links of one file, as messages naming the file, line and destination.
fn broken_links(
    root: &Path,
    file: &Path,
    cache: &mut BTreeMap<PathBuf, BTreeSet<String>>,
) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap();
    let rel = file
        .strip_prefix(root)
        .unwrap_or(file)
        .display()
        .to_string();
    let mut broken = Vec::new();
    for link in links(&text) {
        if has_scheme(&link.dest) {
            continue;
        }
        let (path, anchor) = match link.dest.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (link.dest.as_str(), None),
        };
        let target = if path.is_empty() {
            file.to_path_buf()
        } else if path.starts_with('/') {
            broken.push(format!(
                "{rel}:{}: `{}` is absolute; links must be relative to the file",
                link.line, link.dest
            ));
            continue;
        } else {
            normalise(&file.parent().unwrap().join(percent_decode(path)))
        };
        if !target.exists() {
            broken.push(format!(
                "{rel}:{}: `{}`: no such file or folder ({})",
                link.line,
                link.dest,
                target.strip_prefix(root).unwrap_or(&target).display()
            ));
            continue;
        }
        let Some(anchor) = anchor else { continue };
        if target.extension().is_none_or(|e| e != "md") || anchor.is_empty() {
            continue;
        }
        let defined = cache
            .entry(target.clone())
            .or_insert_with(|| anchors(&std::fs::read_to_string(&target).unwrap()));
        if !defined.contains(&percent_decode(anchor)) {
            broken.push(format!(
                "{rel}:{}: `{}`: {} has no heading with the anchor `#{anchor}`",
                link.line,
                link.dest,
                target.strip_prefix(root).unwrap_or(&target).display()
            ));
        }
    }
    broken
}

#[test]
fn every_relative_link_and_anchor_resolves() {
    let root = normalise(&repo_root().canonicalize().unwrap());
    let files = markdown_files(&root);
    assert!(
        files
            .iter()
            .any(|f| f.ends_with("docs/guide/src/SUMMARY.md")),
        "the user guide (docs/guide/src/SUMMARY.md) is missing"
    );
    let mut cache = BTreeMap::new();
    let mut broken = Vec::new();
    let mut count = 0;
    for file in &files {
        count += links(&std::fs::read_to_string(file).unwrap()).len();
        broken.extend(broken_links(&root, file, &mut cache));
    }
    assert!(
        broken.is_empty(),
        "{} broken links in {} Markdown files:\n{}",
        broken.len(),
        files.len(),
        broken.join("\n")
    );
    println!("{count} links in {} Markdown files resolve", files.len());
}

#[test]
fn the_checker_finds_what_it_should() {
    // Headings: code spans, links and punctuation as GitHub and mdBook render them.
    let text = "# The GPU runtime: `nacre-runtime`, `shaders/`, `nacre render`\n\
                ## Errors\n## Errors\n### [Bevy](x.md) plugin\n\
                ```sh\n# not a heading\n```\n<a id=\"custom\"></a>\n";
    let a = anchors(text);
    for expected in [
        "the-gpu-runtime-nacre-runtime-shaders-nacre-render",
        "errors",
        "errors-1",
        "bevy-plugin",
        "custom",
    ] {
        assert!(a.contains(expected), "missing anchor {expected}: {a:?}");
    }
    assert!(!a.contains("not-a-heading"));
    // Links: inline, images with titles, references; none inside code.
    let text = "See [a](a.md#x) and ![p](img/p.png \"title\") and `[no](code.md)`.\n\
                ```\n[no](fence.md)\n```\n[ref]: ../b.md\n";
    let found: Vec<String> = links(text).into_iter().map(|l| l.dest).collect();
    assert!(found.contains(&"a.md#x".to_string()));
    assert!(found.contains(&"img/p.png".to_string()));
    assert!(found.contains(&"../b.md".to_string()));
    assert_eq!(found.len(), 3);
    // Schemes are not followed; relative paths are.
    assert!(has_scheme("https://example.com"));
    assert!(has_scheme("mailto:x@y"));
    assert!(!has_scheme("docs/a.md"));
    assert!(!has_scheme("#anchor"));
    // A broken link and a broken anchor are reported with file and line.
    let dir = std::env::temp_dir().join(format!("nacre-doc-links-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("b.md"), "# Only heading\n").unwrap();
    std::fs::write(
        dir.join("a.md"),
        "[ok](b.md#only-heading)\n[gone](missing.md)\n[bad anchor](b.md#nope)\n[self](#top)\n# Top\n",
    )
    .unwrap();
    let broken = broken_links(&dir, &dir.join("a.md"), &mut BTreeMap::new());
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(broken[0].starts_with("a.md:2: `missing.md`"), "{broken:?}");
    assert!(broken[1].starts_with("a.md:3: `b.md#nope`"), "{broken:?}");
}
