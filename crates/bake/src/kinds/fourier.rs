//! Table kind `fourier`: bakes [`nacre_format::fourier`] tables — the Fourier transforms
//! Ŝ_j(μ) of the output-space sensitivities (Belcour & Barla 2017, Eq. 8–10), prefiltered
//! and mip-mapped (§5). What every texel holds and how a shader rebuilds Ŝ:
//! [`nacre_format::fourier`].

use crate::error::{Error, Result};
use crate::kinds::{KindEntry, TableRecipe};
use crate::recipe::{RawColour, line_of, parse_colour, table_name, toml_error};
use nacre_format::fourier::{FourierAxes, FourierTable};
use nacre_format::ktx2::fourier_image;
use nacre_format::manifest::{
    AxisRecord, FOURIER_KTX2_QUANTITY, KindRecord, MAX_FOURIER_SAMPLES, Manifest, TableKind,
};
use nacre_format::table_io::Precision;
use nacre_optics::C64;
use nacre_optics::colour::Colorimeter;
use nacre_optics::elementary;
use nacre_optics::fourier::SensitivitySpectrum;
use rayon::prelude::*;
use serde::Deserialize;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use toml::Spanned;
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFourier {
    samples: Spanned<usize>,
    max_opd_nm: Spanned<f64>,
    levels: Spanned<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFourierRecipe {
    #[allow(dead_code)] // checked before the full parse
    kind: Spanned<String>,
    description: Option<String>,
    colour: Option<RawColour>,
    fourier: RawFourier,
}

/// A parsed `fourier` recipe.
///
/// ```toml
/// kind = "fourier"
/// description = "..."
/// [colour]                 # as for film-lut
/// space = "srgb"
/// [fourier]
/// samples = 8192           # texels of level 0 (each level halves it)
/// max_opd_nm = 160000.0    # D_max: the μ range, nm
/// levels = 8               # mip levels (level k prefiltered with σ_k = D_max / N_k)
/// ```
pub struct FourierRecipe {
    /// Table name.
    pub name: String,
    /// Recipe file.
    pub path: PathBuf,
    /// Recipe text.
    pub text: String,
    /// Description.
    pub description: String,
    /// Colour settings.
    pub colorimeter: Colorimeter,
    /// Axes.
    pub axes: FourierAxes,
}

impl FourierRecipe {
    fn parse(path: &Path, text: String) -> Result<Self> {
        let raw: RawFourierRecipe =
            toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let colorimeter = parse_colour(path, &text, raw.colour)?;
        let f = &raw.fourier;
        let bad = |span: std::ops::Range<usize>, message: String| {
            Error::recipe(path.to_path_buf(), line_of(&text, span.start), message)
        };
        let samples = *f.samples.get_ref();
        if !(64..=MAX_FOURIER_SAMPLES).contains(&samples) {
            return Err(bad(
                f.samples.span(),
                format!("samples = {samples}: expected 64 to {MAX_FOURIER_SAMPLES}"),
            ));
        }
        let max_opd = *f.max_opd_nm.get_ref();
        if !(max_opd > 0.0 && max_opd <= 1e7) {
            return Err(bad(
                f.max_opd_nm.span(),
                format!("max_opd_nm = {max_opd}: expected a positive length up to 1e7 nm"),
            ));
        }
        let levels = *f.levels.get_ref();
        // checked_shr: `levels` of 65 or more must give this error, not a shift overflow.
        let last_level = u32::try_from(levels.wrapping_sub(1))
            .ok()
            .and_then(|shift| samples.checked_shr(shift))
            .unwrap_or(0);
        if levels == 0 || last_level < 2 {
            return Err(bad(
                f.levels.span(),
                format!(
                    "levels = {levels}: expected 1 or more, leaving at least 2 texels in the last level"
                ),
            ));
        }
        Ok(FourierRecipe {
            name: table_name(path)?,
            path: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            axes: FourierAxes::new(&colorimeter, samples, max_opd, levels),
            colorimeter,
            text,
        })
    }

    /// Bakes and writes the table; returns the manifest path.
    pub fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        let table = bake_table(&self.colorimeter, self.axes.clone());
        // Every file goes to a staging folder first; `commit` moves them in, the manifest last.
        let stage = nacre_format::stage::StagedTable::new(out_dir)?;
        let a = &self.axes;
        let c = &self.colorimeter;
        let mut manifest = Manifest {
            colour_convention: format!(
                "sensitivities s_j of linear {} (channels {:?}): perfect reflector = white {:?}; Ŝ_j(μ) = ∫ s_j(λ) exp(-2πiμ/λ) dλ / ∫ s_j dλ (forward transform in ν = 1/λ with a negative exponent; Ŝ_j(0) = 1)",
                c.space(),
                c.space().channel_names(),
                a.white
            ),
            ambient: String::new(),
            film: String::new(),
            under: Vec::new(),
            base: String::new(),
            axes: vec![AxisRecord {
                name: "opd_nm".into(),
                unit: "nm".into(),
                count: a.samples,
                min: 0.0,
                max: a.max_opd_nm,
                mapping: "linear".into(),
                forward: format!("u = opd_nm / {}", a.max_opd_nm),
                inverse: format!("opd_nm = u * {}", a.max_opd_nm),
            }],
            texel_centres: "texel i of level k (N_k = level_samples[k] texels) holds μ = (i + 0.5) D_max / N_k: the usual mip-map convention, u = μ / D_max at every level; clamp to edge".into(),
            atlas: "one OpenEXR file per mip level, width N_k, height 2: row 0 holds Re A_j, row 1 holds Im A_j for the channels R, G, B (the output space's channels in order); the KTX2 file holds every level as one 2-D array RGBA32F texture, width N, height 1, layer 0 = Re, layer 1 = Im, mip level k = level k, alpha 0".into(),
            reconstruction: "A = trilinear sample at (u = μ / D_max, lod), lod = σ_μ < σ_1 ? σ_μ / σ_1 : 1 + log2(σ_μ / σ_1); Ŝ_j(μ) = A_j exp(-2πi μ carrier_nu_per_nm[j]); colour_j = white_j [c0 + 2 Σ_m Re(c_m conj Ŝ_j(m D, m τ σ_d))] (Belcour & Barla 2017 Eq. 10; nacre_optics::fourier)".into(),
            files: Vec::new(),
            ..Manifest::for_recipe(
                KindRecord::Fourier(a.clone()),
                &self.name,
                &self.description,
                &self.path,
                &self.text,
                c,
            )
        };
        let embedded = manifest.embedded_json();
        let mut files = Vec::new();
        for k in 0..table.levels.len() {
            let file = format!("{}.level{k}.exr", self.name);
            let quantity = format!("level {k}");
            files.push(stage.write_exr(
                &file,
                &quantity,
                &table.level_image(k),
                Precision::Float,
            )?);
            progress();
        }
        let ktx2 = format!("{}.ktx2", self.name);
        let image = fourier_image(&stage.path().join(&ktx2), &table, &embedded)?;
        files.push(stage.write_ktx2(&ktx2, FOURIER_KTX2_QUANTITY, &image)?);
        manifest.files = files;
        Ok(stage.commit_manifest(&manifest, &[])?)
    }
}

/// Computes every level (texels in parallel; each texel independent, so the result
/// does not depend on the thread count).
pub fn bake_table(colorimeter: &Colorimeter, axes: FourierAxes) -> FourierTable {
    let spectrum = SensitivitySpectrum::new(colorimeter);
    let levels = axes
        .level_samples
        .iter()
        .zip(&axes.level_sigma_nm)
        .map(|(&n, &sigma)| {
            let damped = spectrum.damped(sigma);
            (0..n)
                .into_par_iter()
                .map(|i| {
                    let mu = (i as f64 + 0.5) * axes.max_opd_nm / n as f64;
                    let s = spectrum.transform_damped(mu, &damped);
                    std::array::from_fn(|j| {
                        let a = s[j]
                            * elementary::from_polar(
                                1.0,
                                2.0 * PI * mu * axes.carrier_nu_per_nm[j],
                            );
                        // Stored as f32: round here so that CPU lookups see the file's values.
                        C64::new(f64::from(a.re as f32), f64::from(a.im as f32))
                    })
                })
                .collect()
        })
        .collect();
    FourierTable { axes, levels }
}

/// The registry entry of `fourier` ([`crate::kinds::REGISTRY`]).
pub const ENTRY: KindEntry = KindEntry {
    kind: TableKind::FOURIER,
    parse: |path, text| Ok(Box::new(FourierRecipe::parse(path, text)?)),
    start_rank: 2,
};

impl TableRecipe for FourierRecipe {
    fn kind(&self) -> TableKind {
        TableKind::FOURIER
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn work(&self) -> u64 {
        self.axes.level_samples.len() as u64
    }

    fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        FourierRecipe::bake(self, out_dir, progress)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nacre_optics::colour::{Illuminant, Observer, OutputSpace, RgbSpace};

    #[test]
    fn sampled_transform_matches_the_exact_one() {
        let c = Colorimeter::new(
            Observer::Cie1931_2Deg,
            Illuminant::D65,
            OutputSpace::Rgb(RgbSpace::Srgb),
        );
        let table = bake_table(&c, FourierAxes::new(&c, 8192, 160_000.0, 8));
        let spectrum = SensitivitySpectrum::new(&c);
        let mut worst: f64 = 0.0;
        for k in 0..400 {
            let mu = 37.3 + 123.7 * k as f64;
            let (a, b) = (table.sample(mu, 0.0), spectrum.transform(mu, 0.0));
            for j in 0..3 {
                worst = worst.max((a[j] - b[j]).norm());
            }
        }
        assert!(worst < 2e-4, "{worst:e}");
        // At a level's own σ the level is exact up to interpolation.
        let sigma = table.axes.level_sigma_nm[3];
        let (a, b) = (
            table.sample(5000.0, sigma),
            spectrum.transform(5000.0, sigma),
        );
        for j in 0..3 {
            assert!((a[j] - b[j]).norm() < 2e-4, "{a:?} {b:?}");
        }
    }
}
