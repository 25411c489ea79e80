//! No two source files of a crate import each other in a circle (`docs/architecture.md`).
//!
//! The test reads every crate of the workspace (and `integrations/bevy`) as text: the module
//! tree from the `mod` declarations of non-test code, from `lib.rs` / `main.rs` down; in each
//! file the paths it takes names through (`use` declarations, and `crate::…`, `super::…`,
//! `self::…` or child-module paths in code), each resolved to the file that defines the name
//! (following `pub use` re-exports). A file declaring a child module is not an import, nor
//! is a module taking a name from one of its ancestors (`super::Type` in a folder's file:
//! the folder's own structure); a file taking a name from any other file is. Every strongly
//! connected set of two or more files is a circle; the failure lists each with the names
//! that tie it, file by file.

mod source_scan;

use source_scan::without_test_items;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One module that lives in a file of its own.
struct Module {
    /// Path segments from the crate root (`["gltf_scene", "materials"]`).
    path: Vec<String>,
    /// The file, relative to the crate's folder, and its code without comments, string
    /// contents and `#[cfg(test)]` items.
    file: PathBuf,
    code: String,
}

/// A crate read as text: its file modules, keyed by their path.
struct Crate {
    modules: BTreeMap<Vec<String>, Module>,
}

/// `text` with comments removed and string/char literal contents blanked (line breaks kept).
fn code_only(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if b[i] == '\n' {
                        out.push('\n');
                    }
                    i += 1;
                }
            }
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !ident_char_before(&b, i)
        {
            // Raw string r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == '#' {
                hashes += 1;
                j += 1;
            }
            if j < b.len() && b[j] == '"' {
                out.push_str("\"\"");
                j += 1;
                loop {
                    if j >= b.len() {
                        break;
                    }
                    if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                        j += 1 + hashes;
                        break;
                    }
                    if b[j] == '\n' {
                        out.push('\n');
                    }
                    j += 1;
                }
                i = j;
            } else {
                out.push(c);
                i += 1;
            }
        } else if c == '"' {
            out.push_str("\"\"");
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                if i < b.len() && b[i] == '\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
        } else if c == '\'' {
            // A char literal ('x', '\n', '\u{1F}') or a lifetime ('a).
            let close = if next == Some('\\') {
                (i + 2..b.len().min(i + 12)).find(|&j| b[j] == '\'')
            } else if b.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(j) => {
                    out.push_str("' '");
                    i = j + 1;
                }
                None => {
                    out.push(c);
                    i += 1;
                }
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn ident_char_before(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The `mod NAME;` declarations of `code` (file modules, not inline ones).
fn declared_modules(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for stmt in code.split(';') {
        let words: Vec<&str> = stmt.split_whitespace().collect();
        if let Some(k) = words.iter().rposition(|w| *w == "mod")
            && k + 2 == words.len()
            && words[k + 1].chars().all(is_ident)
            && words[..k].iter().all(|w| {
                w.starts_with("pub") || w.starts_with("#[") || w.ends_with(']') || w.ends_with(')')
            })
        {
            out.push(words[k + 1].to_string());
        }
    }
    out
}

impl Crate {
    /// Reads the crate whose sources are under `src` (roots `lib.rs` and `main.rs`).
    fn read(src: &Path) -> Crate {
        let mut files = BTreeMap::new();
        let mut all = Vec::new();
        source_scan::rust_files(src, &mut all);
        for file in all {
            let text = std::fs::read_to_string(&file).unwrap();
            let rel = file.strip_prefix(src).unwrap().to_path_buf();
            files.insert(rel, text);
        }
        Crate::from_files(&files)
    }

    /// The crate made of `files` (path under `src/` → text).
    fn from_files(files: &BTreeMap<PathBuf, String>) -> Crate {
        let mut modules = BTreeMap::new();
        for root in ["lib.rs", "main.rs"] {
            if files.contains_key(Path::new(root)) {
                let prefix = if root == "main.rs" && files.contains_key(Path::new("lib.rs")) {
                    vec!["<bin>".to_string()]
                } else {
                    Vec::new()
                };
                Self::walk(files, Path::new(root), prefix, &mut modules);
            }
        }
        Crate { modules }
    }

    fn walk(
        files: &BTreeMap<PathBuf, String>,
        file: &Path,
        path: Vec<String>,
        modules: &mut BTreeMap<Vec<String>, Module>,
    ) {
        let code = code_only(&without_test_items(&files[file]));
        let name = file.file_name().unwrap().to_str().unwrap();
        let dir = file.parent().unwrap_or(Path::new(""));
        let child_dir = if matches!(name, "lib.rs" | "main.rs" | "mod.rs") {
            dir.to_path_buf()
        } else {
            dir.join(file.file_stem().unwrap())
        };
        for child in declared_modules(&code) {
            let flat = child_dir.join(format!("{child}.rs"));
            let nested = child_dir.join(&child).join("mod.rs");
            let found = [flat, nested].into_iter().find(|f| files.contains_key(f));
            if let Some(f) = found {
                let mut p = path.clone();
                p.push(child);
                Self::walk(files, &f, p, modules);
            }
        }
        modules.insert(
            path.clone(),
            Module {
                path,
                file: file.to_path_buf(),
                code,
            },
        );
    }

    /// The file module a path of segments (from the root) lands in, and the segments left.
    fn deepest<'a>(&self, segments: &'a [String]) -> (&Module, &'a [String]) {
        let mut k = segments.len();
        loop {
            if let Some(m) = self.modules.get(&segments[..k]) {
                return (m, &segments[k..]);
            }
            k -= 1;
        }
    }

    /// The file that defines what `segments` (an absolute path) names, following `pub use`
    /// re-exports; `depth` bounds the search.
    fn defining_file(&self, segments: &[String], depth: usize) -> PathBuf {
        let (module, rest) = self.deepest(segments);
        let Some(name) = rest.first() else {
            return module.file.clone();
        };
        if depth == 0 || defines(&module.code, name) {
            return module.file.clone();
        }
        for import in uses(&module.code) {
            if !import.public {
                continue;
            }
            let Some(abs) = self.absolute(&module.path, &import.path) else {
                continue;
            };
            if import.local == *name || (import.local == "*" && self.glob_has(&abs, name)) {
                let mut target = abs;
                if import.local == "*" {
                    target.push(name.clone());
                }
                target.extend(rest[1..].iter().cloned());
                return self.defining_file(&target, depth - 1);
            }
        }
        module.file.clone()
    }

    /// Whether the glob import of module `abs` can supply `name`.
    fn glob_has(&self, abs: &[String], name: &str) -> bool {
        let mut p = abs.to_vec();
        p.push(name.to_string());
        self.modules.contains_key(&p)
            || self.modules.get(abs).is_some_and(|m| {
                defines(&m.code, name) || uses(&m.code).iter().any(|u| u.public && u.local == name)
            })
    }

    /// `path` (as written in module `from`) as a path from the crate root; `None` for a
    /// path into another crate.
    fn absolute(&self, from: &[String], path: &[String]) -> Option<Vec<String>> {
        let (first, rest) = path.split_first()?;
        let mut base: Vec<String> = match first.as_str() {
            "crate" => self.root_of(from),
            "self" => from.to_vec(),
            "super" => from[..from.len().checked_sub(1)?].to_vec(),
            _ => {
                let mut child = from.to_vec();
                child.push(first.clone());
                if self.modules.contains_key(&child) {
                    child
                } else {
                    // A name a `use` of this file brought in as a module.
                    let module = self.modules.get(from)?;
                    let alias = uses(&module.code)
                        .into_iter()
                        .find(|u| u.local == *first && u.path.len() > 1)?;
                    let abs = self.absolute(from, &alias.path)?;
                    if !self.modules.contains_key(&abs) {
                        return None;
                    }
                    abs
                }
            }
        };
        let mut rest = rest;
        while let Some((s, r)) = rest.split_first() {
            if s == "super" {
                base.pop()?;
                rest = r;
            } else if s == "self" {
                rest = r;
            } else {
                break;
            }
        }
        base.extend(rest.iter().cloned());
        Some(base)
    }

    fn root_of(&self, from: &[String]) -> Vec<String> {
        if from.first().is_some_and(|s| s == "<bin>") {
            vec!["<bin>".to_string()]
        } else {
            Vec::new()
        }
    }

    /// Every import between files: (from, to) → the names taken.
    fn edges(&self) -> BTreeMap<(PathBuf, PathBuf), BTreeSet<String>> {
        let mut edges: BTreeMap<(PathBuf, PathBuf), BTreeSet<String>> = BTreeMap::new();
        for module in self.modules.values() {
            let mut paths: Vec<Vec<String>> =
                uses(&module.code).into_iter().map(|u| u.path).collect();
            paths.extend(code_paths(&module.code));
            for path in paths {
                let Some(abs) = self.absolute(&module.path, &path) else {
                    continue;
                };
                let to = self.defining_file(&abs, 8);
                // A module taking a name from one of its ancestors (`super::Type` in a
                // folder's file) is the folder's own structure, not an import between
                // concepts.
                let ancestor = self
                    .modules
                    .values()
                    .any(|m| m.file == to && module.path.starts_with(&m.path));
                if to != module.file && !ancestor {
                    let name = path.last().cloned().unwrap_or_default();
                    edges
                        .entry((module.file.clone(), to))
                        .or_default()
                        .insert(name);
                }
            }
        }
        edges
    }
}

/// One name a `use` declaration brings in: the full path and the local name (`*` for a glob).
struct Use {
    path: Vec<String>,
    local: String,
    public: bool,
}

/// The `use` declarations of `code`, expanded (`use a::{b, c::d as e, f::*}`).
fn uses(code: &str) -> Vec<Use> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    let mut at = 0;
    while let Some(k) = code[at..].find("use ") {
        let start = at + k;
        at = start + 4;
        if start > 0 && is_ident(bytes[start - 1] as char) {
            continue;
        }
        // Only at the start of a statement: after `;`, `{`, `}`, `]` or `pub…`.
        let before = code[..start].trim_end();
        let public = before.ends_with("pub") || before.ends_with(')') && before.contains("pub(");
        let head = before
            .trim_end_matches(|c: char| c != ';' && c != '{' && c != '}' && c != ']')
            .len();
        let between = code[head..start].trim();
        if !(between.is_empty() || between.starts_with("pub")) {
            continue;
        }
        let Some(end) = code[start..].find(';') else {
            break;
        };
        let tree = compact(&code[start + 4..start + end]);
        expand(&tree, &mut Vec::new(), public, &mut out);
        at = start + end;
    }
    out
}

/// A use tree with no whitespace but the one space around `as`.
fn compact(tree: &str) -> String {
    let words: Vec<&str> = tree.split_whitespace().collect();
    let mut out = String::new();
    for (k, w) in words.iter().enumerate() {
        if k > 0 && (*w == "as" || words[k - 1] == "as") {
            out.push(' ');
        }
        out.push_str(w);
    }
    out
}

/// Expands one use tree (see [`compact`]) under `prefix`.
fn expand(tree: &str, prefix: &mut Vec<String>, public: bool, out: &mut Vec<Use>) {
    let tree = tree.trim_start_matches("::");
    if let Some(open) = tree.find('{')
        && tree.ends_with('}')
        && !tree[..open].contains(',')
    {
        let head: Vec<String> = tree[..open]
            .split("::")
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let n = head.len();
        prefix.extend(head);
        for part in split_top(&tree[open + 1..tree.len() - 1]) {
            expand(part, prefix, public, out);
        }
        prefix.truncate(prefix.len() - n);
        return;
    }
    if tree.is_empty() {
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p, Some(a)),
        None => (tree, None),
    };
    let mut full = prefix.clone();
    full.extend(path.split("::").filter(|s| !s.is_empty()).map(String::from));
    if full.last().is_some_and(|s| s == "self") {
        full.pop();
    }
    let local = match alias {
        Some(a) => a.to_string(),
        None => full.last().cloned().unwrap_or_default(),
    };
    out.push(Use {
        path: full,
        local,
        public,
    });
}

/// `a, b::{c, d}, e` split at the commas outside braces.
fn split_top(s: &str) -> Vec<&str> {
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&s[start..]);
    parts
}

/// Paths written in code outside `use` declarations: `a::b::c` with two or more segments
/// (the first may be `crate`, `super`, `self` or a module name).
fn code_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let without_uses = blank_uses(code);
    let chars: Vec<char> = without_uses.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if is_ident(chars[i]) && !ident_char_before(&chars, i) && !(i > 0 && chars[i - 1] == ':') {
            let mut segments = Vec::new();
            let mut j = i;
            loop {
                let s = j;
                while j < chars.len() && is_ident(chars[j]) {
                    j += 1;
                }
                segments.push(chars[s..j].iter().collect::<String>());
                if j + 2 < chars.len()
                    && chars[j] == ':'
                    && chars[j + 1] == ':'
                    && is_ident(chars[j + 2])
                {
                    j += 2;
                } else {
                    break;
                }
            }
            if segments.len() > 1 && !segments[0].chars().next().unwrap().is_ascii_digit() {
                out.push(segments);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// `code` with its `use` declarations blanked.
fn blank_uses(code: &str) -> String {
    let mut out = String::with_capacity(code.len());
    for stmt in code.split_inclusive(';') {
        let trimmed = stmt.trim_start();
        let body = trimmed
            .strip_prefix("pub(crate) ")
            .or_else(|| trimmed.strip_prefix("pub(super) "))
            .or_else(|| trimmed.strip_prefix("pub "))
            .unwrap_or(trimmed);
        if body.starts_with("use ") {
            out.extend(stmt.chars().map(|c| if c == '\n' { '\n' } else { ' ' }));
        } else {
            out.push_str(stmt);
        }
    }
    out
}

/// Whether `code` defines an item called `name` (fn, type, constant, macro, module).
fn defines(code: &str, name: &str) -> bool {
    const KEYWORDS: &[&str] = &[
        "fn",
        "struct",
        "enum",
        "union",
        "trait",
        "type",
        "const",
        "static",
        "mod",
        "macro_rules!",
    ];
    let words: Vec<&str> = code
        .split(|c: char| !(is_ident(c) || c == '!'))
        .filter(|w| !w.is_empty())
        .collect();
    words
        .windows(2)
        .any(|w| w[1] == name && KEYWORDS.contains(&w[0]))
        || code.contains(&format!("macro_rules! {name}"))
}

/// The strongly connected sets of two or more files (Tarjan), each sorted.
fn circles(edges: &BTreeMap<(PathBuf, PathBuf), BTreeSet<String>>) -> Vec<Vec<PathBuf>> {
    let mut next: BTreeMap<&PathBuf, Vec<&PathBuf>> = BTreeMap::new();
    for (from, to) in edges.keys() {
        next.entry(from).or_default().push(to);
        next.entry(to).or_default();
    }
    let nodes: Vec<&PathBuf> = next.keys().copied().collect();
    let index_of: BTreeMap<&PathBuf, usize> =
        nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let n = nodes.len();
    let (mut index, mut low, mut on) = (vec![usize::MAX; n], vec![0; n], vec![false; n]);
    let (mut stack, mut counter, mut out) = (Vec::new(), 0, Vec::new());
    fn strong(
        v: usize,
        g: &[Vec<usize>],
        st: &mut (Vec<usize>, Vec<usize>, Vec<bool>, Vec<usize>, usize),
        out: &mut Vec<Vec<usize>>,
    ) {
        st.0[v] = st.4;
        st.1[v] = st.4;
        st.4 += 1;
        st.3.push(v);
        st.2[v] = true;
        for &w in &g[v] {
            if st.0[w] == usize::MAX {
                strong(w, g, st, out);
                st.1[v] = st.1[v].min(st.1[w]);
            } else if st.2[w] {
                st.1[v] = st.1[v].min(st.0[w]);
            }
        }
        if st.1[v] == st.0[v] {
            let mut set = Vec::new();
            loop {
                let w = st.3.pop().unwrap();
                st.2[w] = false;
                set.push(w);
                if w == v {
                    break;
                }
            }
            if set.len() > 1 {
                set.sort();
                out.push(set);
            }
        }
    }
    let g: Vec<Vec<usize>> = nodes
        .iter()
        .map(|v| next[v].iter().map(|w| index_of[w]).collect())
        .collect();
    let mut st = (
        std::mem::take(&mut index),
        std::mem::take(&mut low),
        std::mem::take(&mut on),
        std::mem::take(&mut stack),
        std::mem::take(&mut counter),
    );
    let mut sets = Vec::new();
    for v in 0..n {
        if st.0[v] == usize::MAX {
            strong(v, &g, &mut st, &mut sets);
        }
    }
    for set in sets {
        out.push(set.into_iter().map(|i| nodes[i].clone()).collect());
    }
    out.sort();
    out
}

/// A readable account of each circle: its files and the names each takes from another.
fn describe(
    dir: &Path,
    edges: &BTreeMap<(PathBuf, PathBuf), BTreeSet<String>>,
    circles: &[Vec<PathBuf>],
) -> String {
    let mut text = String::new();
    for files in circles {
        let names: Vec<String> = files
            .iter()
            .map(|f| dir.join(f).display().to_string())
            .collect();
        text.push_str(&format!(
            "circle of {} files: {}\n",
            files.len(),
            names.join(", ")
        ));
        for ((from, to), items) in edges {
            if files.contains(from) && files.contains(to) {
                let items: Vec<&str> = items.iter().map(String::as_str).collect();
                text.push_str(&format!(
                    "  {} -> {}: {}\n",
                    dir.join(from).display(),
                    dir.join(to).display(),
                    items.join(", ")
                ));
            }
        }
    }
    text
}

/// The source folders checked: every crate of the workspace and the Bevy integration.
fn source_dirs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .unwrap()
        .map(|e| e.unwrap().path().join("src"))
        .filter(|p| p.is_dir())
        .collect();
    dirs.push(root.join("integrations/bevy/src"));
    dirs.sort();
    dirs
}

#[test]
fn no_two_source_files_import_each_other_in_a_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut report = String::new();
    let mut files = 0;
    for dir in source_dirs() {
        let krate = Crate::read(&dir);
        assert!(
            !krate.modules.is_empty(),
            "no lib.rs or main.rs under {}",
            dir.display()
        );
        files += krate.modules.len();
        let edges = krate.edges();
        let rel = dir.strip_prefix(&root).unwrap_or(&dir).to_path_buf();
        report.push_str(&describe(&rel, &edges, &circles(&edges)));
    }
    assert!(files > 100, "only {files} source files found");
    assert!(
        report.is_empty(),
        "source files import each other in a circle (move what they share into a module \
         both import, see docs/architecture.md):\n{report}"
    );
}

fn crate_of(files: &[(&str, &str)]) -> Crate {
    let map = files
        .iter()
        .map(|(p, t)| (PathBuf::from(p), t.to_string()))
        .collect();
    Crate::from_files(&map)
}

#[test]
fn the_check_finds_a_circle_through_uses_code_paths_and_re_exports() {
    let krate = crate_of(&[
        ("lib.rs", "mod a;\nmod b;\nmod c;\npub use c::Shared;\n"),
        (
            "a.rs",
            "use crate::b::{self, Other};\npub fn f() -> Other { b::make() }\n",
        ),
        (
            "b.rs",
            "pub struct Other;\npub fn make() -> Other { let _ = crate::a::f; Other }\n",
        ),
        (
            "c.rs",
            "pub struct Shared;\n// use crate::a::f;\nconst S: &str = \"crate::a::f\";\n",
        ),
    ]);
    let edges = krate.edges();
    let found = circles(&edges);
    assert_eq!(
        found,
        vec![vec![PathBuf::from("a.rs"), PathBuf::from("b.rs")]]
    );
    let text = describe(Path::new("src"), &edges, &found);
    assert!(
        text.contains("src/a.rs -> src/b.rs: Other, b, make"),
        "{text}"
    );
    assert!(text.contains("src/b.rs -> src/a.rs: f"), "{text}");

    // A name taken through the root's re-export counts against the defining file.
    let krate = crate_of(&[
        ("lib.rs", "mod a;\nmod c;\npub use c::Shared;\n"),
        ("a.rs", "use crate::Shared;\npub fn f() {}\n"),
        ("c.rs", "use super::a::f;\npub struct Shared;\n"),
    ]);
    let edges = krate.edges();
    let found = circles(&edges);
    assert_eq!(
        found,
        vec![vec![PathBuf::from("a.rs"), PathBuf::from("c.rs")]]
    );

    // A parent declaring a child, and a child using its parent's items, is no circle (nor
    // a parent calling into a child that uses the parent's types); test modules do not
    // count.
    let krate = crate_of(&[
        ("lib.rs", "mod m;\n"),
        (
            "m/mod.rs",
            "mod k;\npub struct T;\npub fn g() {}\n#[cfg(test)]\nmod tests { use super::k::h; }\n",
        ),
        ("m/k.rs", "use super::{T, g};\npub fn h() -> T { g(); T }\n"),
    ]);
    assert!(circles(&krate.edges()).is_empty());
    let krate = crate_of(&[
        ("lib.rs", "mod m;\n"),
        (
            "m/mod.rs",
            "mod k;\npub struct T;\npub fn g() { k::h(); }\n",
        ),
        ("m/k.rs", "use super::T;\npub fn h() -> T { T }\n"),
    ]);
    assert!(circles(&krate.edges()).is_empty());
    // Siblings inside a folder make one, and so do a folder's file and a module outside it.
    let krate = crate_of(&[
        ("lib.rs", "mod m;\nmod x;\n"),
        (
            "m/mod.rs",
            "mod k;\nmod j;\npub const LIMIT: u32 = 1;\npub fn g() { crate::x::y(); }\n",
        ),
        ("m/k.rs", "use super::j::J;\npub struct K;\n"),
        ("m/j.rs", "pub struct J(super::k::K);\n"),
        (
            "x.rs",
            "use crate::m::LIMIT;\npub fn y() -> u32 { LIMIT }\n",
        ),
    ]);
    let edges = krate.edges();
    assert_eq!(
        circles(&edges),
        vec![
            vec![PathBuf::from("m/j.rs"), PathBuf::from("m/k.rs")],
            vec![PathBuf::from("m/mod.rs"), PathBuf::from("x.rs")],
        ],
        "{}",
        describe(Path::new("src"), &edges, &circles(&edges))
    );
}
