//! The import header of the WGSL modules under `shaders/` (`shaders/README.md`), read in
//! one place for every host that composes them: the runtime's composer
//! (`nacre_runtime::shaders`) and the Bevy plugin's naga_oil modules.
//!
//! WGSL has no `import`: each module names what it needs in its leading comment block,
//!
//! ```text
//! // import: common, <technique>, rough_lut_mapping
//! // import: (none)
//! ```
//!
//! where a name is another module's file name without `.wgsl` and [`TECHNIQUE_SLOT`] stands
//! for the technique module the host composes the consumer with.

use std::fmt;

/// The placeholder of an import header for the technique module chosen by the host.
pub const TECHNIQUE_SLOT: &str = "<technique>";

/// One entry of an import header.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Import<'a> {
    /// A module, by name.
    Module(&'a str),
    /// [`TECHNIQUE_SLOT`]: the technique module the host composes with.
    Technique,
}

impl fmt::Display for Import<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Import::Module(name) => f.write_str(name),
            Import::Technique => f.write_str(TECHNIQUE_SLOT),
        }
    }
}

/// An import line that is not `// import: name, name, …` (names of letters, digits and `_`,
/// or [`TECHNIQUE_SLOT`]) or `// import: (none)`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{module} line {line}: bad import header `{text}`")]
pub struct BadImport {
    /// The module.
    pub module: String,
    /// 1-based line in the module.
    pub line: usize,
    /// The line.
    pub text: String,
}

/// The imports declared in the leading comment block of `source` (the lines that begin with
/// `//`, up to the first that does not): every line `// import: a, b, <technique>`, in order;
/// `// import: (none)` declares none. `module` names the source in errors.
///
/// # Errors
/// [`BadImport`] for a malformed import line.
pub fn parse_imports<'a>(module: &str, source: &'a str) -> Result<Vec<Import<'a>>, BadImport> {
    let mut imports = Vec::new();
    for (i, line) in source.lines().enumerate() {
        let Some(comment) = line.strip_prefix("//") else {
            break;
        };
        let Some(list) = comment.trim_start().strip_prefix("import:") else {
            continue;
        };
        let list = list.trim();
        if list == "(none)" {
            continue;
        }
        for name in list.split(',').map(str::trim) {
            if name == TECHNIQUE_SLOT {
                imports.push(Import::Technique);
            } else if !name.is_empty()
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                imports.push(Import::Module(name));
            } else {
                return Err(BadImport {
                    module: module.to_string(),
                    line: i + 1,
                    text: line.to_string(),
                });
            }
        }
    }
    Ok(imports)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_syntax() {
        let src =
            "// title\n// import: a, <technique>\n//\n// import: b_2\nfn f() {}\n// import: c\n";
        assert_eq!(
            parse_imports("x", src).unwrap(),
            [
                Import::Module("a"),
                Import::Technique,
                Import::Module("b_2")
            ]
        );
        assert_eq!(parse_imports("x", "// import: (none)\n").unwrap(), []);
        assert_eq!(parse_imports("x", "fn f() {}\n").unwrap(), []);
        let err = parse_imports("x", "// t\n// import: a b\n").unwrap_err();
        assert_eq!(
            err,
            BadImport {
                module: "x".into(),
                line: 2,
                text: "// import: a b".into()
            }
        );
        assert_eq!(
            err.to_string(),
            "x line 2: bad import header `// import: a b`"
        );
        assert!(parse_imports("x", "// import: a,\n").is_err());
        assert_eq!(Import::Technique.to_string(), "<technique>");
    }
}
