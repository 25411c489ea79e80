//! The bundled material library and the resolution of material specifications.
//!
//! A material specification `M` (a `--ambient`/`--layer`/`--substrate` value or a recipe's
//! `material` string) is, in this order:
//!
//! 1. a real index (`1.33`) or a complex index `n+κi` (`0.27+2.9i`);
//! 2. a bundled material name, case-insensitive (see [`BUNDLED`]; a few common aliases
//!    such as `gold` or `sio2` are accepted);
//! 3. a path to a refractiveindex.info `.yml`/`.yaml` file or a `wavelength_nm,n,k` `.csv`
//!    file (relative paths in a recipe are taken relative to the recipe's folder).
//!
//! The bundled data files live in `tables/materials/` with their sources and licences;
//! they are embedded into the binary at build time so that `nacre` works from any folder.

use crate::error::{Error, Result};
use nacre_optics::Material;
use std::path::Path;

/// A bundled material: its name, what it is, and its data file's text.
pub struct Bundled {
    /// Name used on the command line and in recipes.
    pub name: &'static str,
    /// One-line description with the data source.
    pub description: &'static str,
    /// File name under `tables/materials/`.
    pub file: &'static str,
    /// The file's contents.
    pub text: &'static str,
}

macro_rules! bundled {
    ($( $name:literal, $file:literal, $desc:literal; )*) => {
        /// Every bundled material.
        pub const BUNDLED: &[Bundled] = &[
            $( Bundled {
                name: $name,
                description: $desc,
                file: $file,
                text: include_str!(concat!("../../../tables/materials/", $file)),
            }, )*
        ];
    };
}

bundled! {
    "air", "air.yml", "dry air, 15 °C, 450 ppm CO2 (Ciddor 1996)";
    "water", "water.yml", "liquid water, 20 °C (Daimon & Masumura 2007)";
    "fused-silica", "fused-silica.yml", "fused silica SiO2 (Malitson 1965)";
    "bk7", "bk7.yml", "SCHOTT N-BK7 optical glass";
    "mgf2", "mgf2.yml", "magnesium fluoride, ordinary ray (Dodge 1984)";
    "tio2", "tio2.yml", "titanium dioxide ALD thin film (Siefke et al. 2016)";
    "si", "si.yml", "crystalline silicon, 300 K (Green 2008)";
    "au", "au.yml", "gold (Johnson & Christy 1972)";
    "ag", "ag.yml", "silver (Johnson & Christy 1972)";
    "cu", "cu.yml", "copper (Johnson & Christy 1972)";
    "al", "al.yml", "aluminium (Rakić 1995)";
    "cr", "cr.yml", "chromium (Johnson & Christy 1974)";
    "oil", "oil.yml", "biodiesel fuel oil, 20 °C, a gasoline/oil-like dispersive dielectric (Wang et al. 2015)";
}

const ALIASES: &[(&str, &str)] = &[
    ("sio2", "fused-silica"),
    ("silica", "fused-silica"),
    ("n-bk7", "bk7"),
    ("gold", "au"),
    ("silver", "ag"),
    ("copper", "cu"),
    ("aluminium", "al"),
    ("aluminum", "al"),
    ("chromium", "cr"),
    ("silicon", "si"),
    ("titania", "tio2"),
    ("h2o", "water"),
];

/// Comma-separated bundled names, for messages.
pub fn bundled_names() -> String {
    BUNDLED
        .iter()
        .map(|b| b.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Looks up a bundled material by name or alias (case-insensitive).
pub fn bundled(name: &str) -> Option<&'static Bundled> {
    let lower = name.trim().to_ascii_lowercase();
    let canonical = ALIASES
        .iter()
        .find(|(alias, _)| *alias == lower)
        .map_or(lower.as_str(), |(_, target)| target);
    BUNDLED.iter().find(|b| b.name == canonical)
}

/// Parses a bundled material.
pub fn load_bundled(b: &Bundled) -> Result<Material> {
    let source = format!("tables/materials/{}", b.file);
    Ok(parse_material_text(b.name, &source, b.text)?)
}

fn parse_material_text(name: &str, source: &str, text: &str) -> nacre_optics::Result<Material> {
    if source.to_ascii_lowercase().ends_with(".csv") {
        Material::from_nk_csv(name, source, text)
    } else {
        Material::from_refractiveindex_yaml(name, source, text)
    }
}

/// Resolves a material specification (see module docs). `context` names where it came
/// from (a flag or `recipe.toml:12`) for messages; `base_dir` anchors relative paths.
pub fn resolve(spec: &str, context: &str, base_dir: Option<&Path>) -> Result<Material> {
    let spec = spec.trim();
    let looks_numeric = spec
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+'));
    if looks_numeric {
        return Material::parse_index(spec).map_err(|source| Error::OpticsIn {
            context: context.to_string(),
            source,
        });
    }
    if let Some(b) = bundled(spec) {
        return load_bundled(b);
    }
    let lower = spec.to_ascii_lowercase();
    if [".yml", ".yaml", ".csv"]
        .iter()
        .any(|ext| lower.ends_with(ext))
    {
        let path = match base_dir {
            Some(dir) if Path::new(spec).is_relative() => dir.join(spec),
            _ => Path::new(spec).to_path_buf(),
        };
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Io {
            path: path.clone(),
            source,
        })?;
        let shown = path.display().to_string();
        return Ok(parse_material_text(spec, &shown, &text)?);
    }
    Err(Error::UnknownMaterial {
        context: context.to_string(),
        name: spec.to_string(),
        bundled: bundled_names(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bundled_material_parses_and_covers_the_visible() {
        for b in BUNDLED {
            let m = load_bundled(b).unwrap_or_else(|e| panic!("{}: {e}", b.name));
            let (lo, hi) = m.range_nm();
            assert!(lo <= 300.0 && hi >= 1000.0, "{}: {lo}–{hi} nm", b.name);
            for wl in [300.0, 380.0, 555.5, 780.0, 1000.0] {
                m.index_at(wl).unwrap();
            }
        }
    }

    #[test]
    fn resolution_order_and_messages() {
        assert_eq!(resolve("1.5", "--substrate", None).unwrap().name(), "1.5");
        assert_eq!(resolve("Gold", "--substrate", None).unwrap().name(), "au");
        let e = resolve("unobtainium", "--layer", None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--layer: unknown material `unobtainium`"),
            "{e}"
        );
        let e = resolve("1.5-0.2i", "--layer", None)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--layer: invalid refractive index"), "{e}");
        let e = resolve("missing.yml", "--layer", None)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("missing.yml: "), "{e}");
    }
}
