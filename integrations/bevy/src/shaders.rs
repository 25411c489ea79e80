//! nacre's WGSL modules in Bevy's shader system.
//!
//! The repository's `shaders/*.wgsl` files are the single source: this module embeds them
//! (`include_str!`) and turns each into a naga_oil module that Bevy's composer imports:
//!
//! * `#define_import_path nacre::<module>` is prepended (`nacre::common`,
//!   `nacre::lut_mapping`, `nacre::film_lut`, `nacre::film_fourier`, `nacre::film_stack`);
//! * the module's `// import: a, b` header line (shaders/README.md, read by
//!   `nacre_format::wgsl_header`, as the runtime reads it) becomes one
//!   `#import nacre::a::{…}` line per name, listing every top-level `fn`, `struct` and
//!   `const` of module `a` (naga_oil imports items, not whole namespaces);
//! * a technique's bind group 1 (`@group(1) @binding(k)`) moves into Bevy's material bind
//!   group at `@group(#{MATERIAL_BIND_GROUP}) @binding(base + k)` ([`FILM_LUT_BINDING`],
//!   [`FILM_FOURIER_BINDING`], [`FILM_STACK_BINDING`]), where [`crate::NacreFilm`]'s
//!   `AsBindGroup` puts the tables and the stack's buffers.
//!
//! * struct members whose names naga's WGSL writer would change (a name ending in a digit or
//!   `_`, or holding `__`: `_pad3`, `c0`, …), which naga_oil refuses in a composable module,
//!   get the suffix `_x` wherever the identifier appears in code ([`renamed_members`]).
//!
//! Nothing else of the source changes, so the functions Bevy runs are the ones the runtime's
//! tests prove against the CPU.

use bevy::asset::{Assets, Handle, uuid_handle};
use bevy::shader::Shader;
use nacre_format::wgsl_header::{BadImport, Import, parse_imports};
use std::fmt::Write as _;

/// First binding of `film_lut.wgsl`'s group 1 in the material bind group (bindings 100–103:
/// reflectance, transmittance, sampler, `FilmLutParams`).
pub const FILM_LUT_BINDING: u32 = 100;
/// First binding of `film_fourier.wgsl`'s group 1 in the material bind group (bindings
/// 104–105: the coefficient texture, `FourierParams`).
pub const FILM_FOURIER_BINDING: u32 = 104;
/// First binding of `film_stack.wgsl`'s group 1 in the material bind group (bindings
/// 111–113: the nodes, the indices, `StackParams`).
pub const FILM_STACK_BINDING: u32 = 111;

/// nacre's modules registered with Bevy, in dependency order: (name, source, first binding
/// of its group 1).
pub const MODULES: [(&str, &str, Option<u32>); 5] = [
    ("common", include_str!("../../../shaders/common.wgsl"), None),
    (
        "lut_mapping",
        include_str!("../../../shaders/lut_mapping.wgsl"),
        None,
    ),
    (
        "film_lut",
        include_str!("../../../shaders/film_lut.wgsl"),
        Some(FILM_LUT_BINDING),
    ),
    (
        "film_fourier",
        include_str!("../../../shaders/film_fourier.wgsl"),
        Some(FILM_FOURIER_BINDING),
    ),
    (
        "film_stack",
        include_str!("../../../shaders/film_stack.wgsl"),
        Some(FILM_STACK_BINDING),
    ),
];

/// Handles under which [`crate::NacrePlugin`] registers the modules (same order as
/// [`MODULES`]).
pub const MODULE_HANDLES: [Handle<Shader>; 5] = [
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a01"),
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a02"),
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a03"),
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a04"),
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a05"),
];

/// The material's fragment shader (`src/film_material.wgsl`).
pub const FILM_MATERIAL_HANDLE: Handle<Shader> =
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a10");

/// Why a nacre module could not be turned into a naga_oil module.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ShaderError {
    /// The `// import:` header names a module this plugin does not register.
    #[error("shaders/{module}.wgsl imports `{import}`, which bevy_nacre does not register")]
    UnknownImport {
        /// The importing module.
        module: String,
        /// The unknown name.
        import: String,
    },
    /// A malformed `// import:` line.
    #[error("shaders/{0}")]
    BadImport(#[from] BadImport),
    /// A binding outside group 1, or a group-1 binding in a module without a binding base.
    #[error(
        "shaders/{module}.wgsl line {line}: binding `{text}` has no place in the material bind group"
    )]
    UnexpectedBinding {
        /// The module.
        module: String,
        /// 1-based line.
        line: usize,
        /// The line's text.
        text: String,
    },
}

/// The module's top-level `fn`, `struct` and `const` names, in source order.
pub fn top_level_items(source: &str) -> Vec<String> {
    source
        .lines()
        .filter_map(|l| {
            ["fn ", "struct ", "const "]
                .iter()
                .find_map(|k| l.strip_prefix(k))
        })
        .filter_map(|rest| {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            (!name.is_empty()).then_some(name)
        })
        .collect()
}

/// Whether naga's namer would rename `name` when writing WGSL back (naga_oil requires a
/// composable module's struct members to survive that unchanged).
fn naga_renames(name: &str) -> bool {
    name.ends_with(|c: char| c.is_ascii_digit()) || name.ends_with('_') || name.contains("__")
}

/// The struct members of every module in [`MODULES`] that naga would rename, sorted.
pub fn renamed_members() -> Vec<String> {
    let mut names: Vec<String> = MODULES
        .iter()
        .flat_map(|(_, source, _)| {
            let mut in_struct = false;
            let mut members = Vec::new();
            for line in source.lines() {
                let code = line.split("//").next().unwrap_or("").trim();
                if code.starts_with("struct ") {
                    in_struct = true;
                } else if in_struct && code.starts_with('}') {
                    in_struct = false;
                } else if in_struct && let Some((member, _)) = code.split_once(':') {
                    let member = member.trim();
                    if naga_renames(member) {
                        members.push(member.to_owned());
                    }
                }
            }
            members
        })
        .collect();
    names.sort();
    names.dedup();
    names
}

/// `code` with every identifier in `names` suffixed `_x` (identifiers are maximal runs of
/// ASCII letters, digits and `_`).
fn rename_identifiers(code: &str, names: &[String]) -> String {
    let mut out = String::with_capacity(code.len() + 16);
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        out.push_str(word);
        if names.iter().any(|n| n == word) {
            out.push_str("_x");
        }
        word.clear();
    };
    for c in code.chars() {
        if c.is_ascii_alphanumeric() || c == '_' {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// The naga_oil form of module `name` (one of [`MODULES`]): import path, `#import` lines from
/// its header, group-1 bindings moved into the material bind group.
pub fn naga_oil_source(name: &str) -> Result<String, ShaderError> {
    let (_, source, binding_base) = MODULES
        .iter()
        .find(|(n, _, _)| *n == name)
        .copied()
        .ok_or_else(|| ShaderError::UnknownImport {
            module: name.to_owned(),
            import: name.to_owned(),
        })?;
    let mut out = format!("#define_import_path nacre::{name}\n");
    for import in parse_imports(name, source)? {
        let imported = match import {
            Import::Module(import) => MODULES.iter().find(|(n, _, _)| *n == import),
            // The plugin composes no consumer that imports a technique.
            Import::Technique => None,
        };
        let (_, imported, _) = imported.ok_or_else(|| ShaderError::UnknownImport {
            module: name.to_owned(),
            import: import.to_string(),
        })?;
        let items = top_level_items(imported).join(", ");
        let _ = writeln!(out, "#import nacre::{import}::{{{items}}}");
    }
    let renamed = renamed_members();
    for (i, line) in source.lines().enumerate() {
        let line = &match line.split_once("//") {
            Some((code, comment)) => format!("{}//{comment}", rename_identifiers(code, &renamed)),
            None => rename_identifiers(line, &renamed),
        };
        if let Some(rest) = line.trim_start().strip_prefix("@group(") {
            let unexpected = || ShaderError::UnexpectedBinding {
                module: name.to_owned(),
                line: i + 1,
                text: line.to_owned(),
            };
            let base = binding_base.ok_or_else(unexpected)?;
            let rest = rest.strip_prefix("1) @binding(").ok_or_else(unexpected)?;
            let (k, rest) = rest.split_once(')').ok_or_else(unexpected)?;
            let k: u32 = k.parse().map_err(|_| unexpected())?;
            let _ = writeln!(
                out,
                "@group(#{{MATERIAL_BIND_GROUP}}) @binding({}){rest}",
                base + k
            );
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(out)
}

/// Registers nacre's modules and the material's fragment shader under their fixed handles.
///
/// # Panics
///
/// Never for the sources this crate embeds: [`naga_oil_source`] succeeds on each of them
/// (the unit tests check it), so its error can only come from a repository whose
/// `shaders/` was changed without this integration.
pub(crate) fn register(shaders: &mut Assets<Shader>) {
    for ((name, _, _), handle) in MODULES.iter().zip(MODULE_HANDLES) {
        let source = naga_oil_source(name)
            .unwrap_or_else(|e| panic!("bevy_nacre: nacre's WGSL changed shape: {e}"));
        let _ = shaders.insert(
            handle.id(),
            Shader::from_wgsl(source, format!("nacre/{name}.wgsl")),
        );
    }
    let _ = shaders.insert(
        FILM_MATERIAL_HANDLE.id(),
        Shader::from_wgsl(
            include_str!("film_material.wgsl"),
            "bevy_nacre/film_material.wgsl",
        ),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_module_converts() {
        for (name, _, _) in MODULES {
            let s = naga_oil_source(name).unwrap();
            assert!(s.starts_with(&format!("#define_import_path nacre::{name}\n")));
            assert!(!s.contains("@group(1)"), "{name} keeps a group-1 binding");
        }
    }

    #[test]
    fn header_imports_become_item_imports() {
        let s = naga_oil_source("film_lut").unwrap();
        assert!(s.contains("#import nacre::common::{"));
        assert!(s.contains("#import nacre::lut_mapping::{FilmLutParams, lut_counts"));
        assert!(s.contains("sanitize_input"));
        assert!(!naga_oil_source("common").unwrap().contains("#import"));
    }

    #[test]
    fn bindings_move_into_the_material_group() {
        let lut = naga_oil_source("film_lut").unwrap();
        for k in 100..=103 {
            assert!(
                lut.contains(&format!(
                    "@group(#{{MATERIAL_BIND_GROUP}}) @binding({k}) var"
                )),
                "binding {k}"
            );
        }
        let fourier = naga_oil_source("film_fourier").unwrap();
        assert!(fourier.contains("@binding(104) var fourier_table"));
        assert!(fourier.contains("@binding(105) var<uniform> fourier_params"));
        let stack = naga_oil_source("film_stack").unwrap();
        assert!(stack.contains("@binding(111) var<storage, read> stack_nodes"));
        assert!(stack.contains("@binding(112) var<storage, read> stack_indices"));
        assert!(stack.contains("@binding(113) var<uniform> stack_params"));
    }

    #[test]
    fn members_naga_would_rename_get_a_suffix_in_code_only() {
        assert_eq!(
            renamed_members(),
            ["_pad0", "_pad1", "_pad2", "_pad3", "_pad4", "c0"]
        );
        let common = naga_oil_source("common").unwrap();
        assert!(common.contains("    _pad3_x: f32,"));
        assert!(common.contains("o._pad3_x = 0.0;"));
        assert!(!common.contains("_pad3 "));
        let fourier = naga_oil_source("film_fourier").unwrap();
        assert!(fourier.contains("0.5 * (rs.c0_x + rp.c0_x)"));
        assert!(fourier.contains("c0_r[j]"), "other identifiers are kept");
        assert!(fourier.contains("AirySeries.c0, .k"), "comments are kept");
    }

    #[test]
    fn top_level_item_parsing() {
        assert_eq!(
            top_level_items("fn a_b(x: f32) {}\nstruct S {}\n  fn inner() {}\nconst K: f32 = 1.0;"),
            ["a_b", "S", "K"]
        );
    }
}
