//! Table kind `film-lut`: its recipe, the bake (exact spectral integration per texel) and
//! the files it writes. What every channel holds, the axis mappings and how a shader
//! rebuilds the colour: [`nacre_format::film_lut`].
//!
//! # FilmLutRecipe format (TOML)
//!
//! ```toml
//! kind = "film-lut"                 # required
//! description = "film on glass"     # optional, copied to the manifest
//!
//! [colour]                          # optional; these are the defaults
//! observer = "1931"                 # 1931 | 1964
//! illuminant = "d65"                # d65 | d50 | a | e
//! space = "srgb"                    # xyz | srgb | rec2020 | p3 | acescg (linear)
//!
//! [stack]
//! ambient = "1.0"                   # constant, non-absorbing
//! film = "thin film"                # optional label; the film index is an axis
//! base = "1.5"                      # any material spec (number, n+ki, bundled, file)
//! under = [ { material = "water", thickness_nm = 50.0 } ]   # optional fixed layers under the film
//! # a layer may be a thick incoherent slab, with coatings on both its faces:
//! # under = [ { material = "bk7", thickness_nm = 2e6, incoherent = true },
//! #           { material = "mgf2", thickness_nm = 99.0 } ]
//!
//! [axes]
//! cos_theta_count = 32              # texels along cos θ (square mapping)
//! thickness_nm = [0.0, 1200.0]      # film thickness range
//! opd_count = 384                   # texels along the optical path difference
//! film_ior = [1.0, 2.5]             # film index range (≥ ambient index)
//! film_ior_count = 32
//!
//! [output]                          # optional; these are the defaults
//! precision = "half"                # half | float (OpenEXR)
//! png = true                        # also a 16-bit PNG when every value is in [0, 1]
//! transmittance = "auto"            # auto (when the base transmits) | true | false
//! ```
//!
//! The table is named after the recipe file (`film-gold.toml` → `film-gold`). Outputs in
//! the output folder: `NAME.json` (the manifest: the only thing the runtime reads),
//! `NAME.reflectance.exr` (+ `.png`) and, when baked, `NAME.transmittance.exr` (+ `.png`),
//! and beside each EXR the same table as a KTX 2.0 texture, `NAME.QUANTITY.ktx2` (3-D
//! `RGBA16F`; a `fourier` table gives one `NAME.ktx2`, a 2-D array `RGBA32F` texture with
//! every mip level: see [`nacre_format::ktx2`]). Every file is written atomically; the manifest last.
//!
//! Each row of constant (cos θ, n) is one thickness sweep of the exact spectral rule
//! ([`Stack::colours_over_thickness`]); where the ambient and the base are non-dispersive
//! and no layers lie under the film (`film-dielectric`, `soap-film`) the same sums come from
//! the film's Airy Fourier series ([`nacre_optics::film_series`], equal to ≈ 10⁻¹¹).
//!
//! # A coated or bare slab as the base
//!
//! A layer under the film marked `incoherent = true` is a thick slab (a 2 mm lens or window
//! pane) whose back-face reflections add in intensity ([`nacre_optics::incoherent`]); the
//! layers below it coat its back face and the base is what lies behind the pane (air). The
//! table then holds the colour of the *whole pane*: its reflectance is the front coating's
//! and every back-face return summed, its transmittance what leaves through the back. Each
//! texel is one sweep of the exact intensity recurrence over the spectral rule of the
//! coherent films (the slab adds no fringes: [`Stack::max_opd_nm`]), the film's thickness
//! changed along a row ([`SpectrumSweep::set_thicknesses_nm`]). The channels, axes and the
//! shader's rebuild are a film-lut's; the manifest lists the slab in `under_incoherent`.

use crate::error::{Error, Result};
use crate::kinds::{KindEntry, TableRecipe};
use crate::recipe::{
    OutputSettings, RawColour, RawOutput, RawStack, RecipeStack, line_of, parse_colour, table_name,
    toml_error,
};
use nacre_format::film_lut::{FilmLut, FilmLutAxes, validate_axes};
use nacre_format::ktx2::{Ktx2Format, film_lut_image_as};
use nacre_format::manifest::{AxisRecord, KindRecord, MAX_TEXELS, Manifest, TableKind};
use nacre_format::table_io::{Precision, Table3};
use nacre_optics::colour::Colorimeter;
use nacre_optics::elementary;
use nacre_optics::film_series::{
    RuleTransform, SingleFilm, non_dispersive_surround, series_extent,
};
use nacre_optics::{C64, FilmColours, Layer, Material, SpectralRule, SpectrumSweep, Stack};
use rayon::prelude::*;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxes {
    cos_theta_count: usize,
    thickness_nm: [f64; 2],
    opd_count: usize,
    film_ior: [f64; 2],
    film_ior_count: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRecipe {
    #[allow(dead_code)] // checked before the full parse
    kind: Spanned<String>,
    description: Option<String>,
    colour: Option<RawColour>,
    stack: RawStack,
    axes: Spanned<RawAxes>,
    output: Option<RawOutput>,
}

/// A parsed `film-lut` recipe.
pub struct FilmLutRecipe {
    /// Table name (the recipe's file stem).
    pub name: String,
    /// The recipe file.
    pub path: PathBuf,
    /// The recipe's text, recorded in the manifest.
    pub text: String,
    /// Description.
    pub description: String,
    /// Colour settings.
    pub colorimeter: Colorimeter,
    /// Material specs as written.
    pub ambient_spec: String,
    /// Film label.
    pub film_label: String,
    /// Base spec.
    pub base_spec: String,
    /// Fixed layers under the film (spec, thickness).
    pub under_specs: Vec<(String, f64)>,
    /// The job.
    pub job: FilmLutJob,
    /// Output precision.
    pub precision: Precision,
    /// Also write PNGs.
    pub png: bool,
}

impl FilmLutRecipe {
    /// Reads and validates a recipe (nothing is computed yet).
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, text)
    }

    /// Parses recipe text; `path` names it and anchors relative material paths.
    pub fn parse(path: &Path, text: String) -> Result<Self> {
        let raw: RawRecipe = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let at = |span: std::ops::Range<usize>| {
            format!("{}:{}", path.display(), line_of(&text, span.start))
        };
        let name = table_name(path)?;
        let colorimeter = parse_colour(path, &text, raw.colour)?;
        let RecipeStack {
            ambient,
            ambient_index,
            base,
            under,
            under_specs,
            under_incoherent,
        } = RecipeStack::parse(path, &text, &raw.stack, "film-lut")?;
        let ax = raw.axes.get_ref();
        let axes = FilmLutAxes {
            cos_theta_count: ax.cos_theta_count,
            opd_count: ax.opd_count,
            ior_count: ax.film_ior_count,
            thickness_min_nm: ax.thickness_nm[0],
            thickness_max_nm: ax.thickness_nm[1],
            ior_min: ax.film_ior[0],
            ior_max: ax.film_ior[1],
            ambient_index,
        };
        validate_axes(&axes, &at(raw.axes.span()), MAX_TEXELS)?;
        let output = OutputSettings::parse(path, raw.output, &under, &base, true)?;
        Ok(FilmLutRecipe {
            name,
            path: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            colorimeter: colorimeter.clone(),
            ambient_spec: raw.stack.ambient.get_ref().clone(),
            film_label: raw.stack.film.unwrap_or_else(|| "film".into()),
            base_spec: raw.stack.base.get_ref().clone(),
            under_specs,
            job: FilmLutJob {
                axes,
                ambient,
                under,
                under_incoherent,
                base,
                colorimeter,
                transmittance: output.transmittance,
            },
            precision: output.precision,
            png: output.png,
            text,
        })
    }
}

fn axis_records(a: &FilmLutAxes) -> Vec<AxisRecord> {
    vec![
        AxisRecord {
            name: "cos_theta".into(),
            unit: "1".into(),
            count: a.cos_theta_count,
            min: 0.0,
            max: 1.0,
            mapping: "square".into(),
            forward: "t = sqrt(cos_theta)".into(),
            inverse: "cos_theta = t * t".into(),
        },
        AxisRecord {
            name: "opd_nm".into(),
            unit: "nm".into(),
            count: a.opd_count,
            min: 0.0,
            max: a.opd_max_nm(),
            mapping: "linear in optical path difference".into(),
            forward: format!(
                "t = 2 * thickness_nm * sqrt(film_ior^2 - {}^2 * (1 - cos_theta^2)) / {}",
                a.ambient_index,
                a.opd_max_nm()
            ),
            inverse: format!("opd_nm = t * {}", a.opd_max_nm()),
        },
        AxisRecord {
            name: "film_ior".into(),
            unit: "1".into(),
            count: a.ior_count,
            min: a.ior_min,
            max: a.ior_max,
            mapping:
                "square root in the film's normal component q = sqrt(film_ior^2 - n0^2 sin^2 theta)"
                    .into(),
            forward: format!(
                "q(n) = sqrt(n^2 - {n0}^2 (1 - cos_theta^2)); t = sqrt((q(film_ior) - q({lo})) / (q({hi}) - q({lo})))",
                n0 = a.ambient_index,
                lo = a.ior_min,
                hi = a.ior_max
            ),
            inverse: format!(
                "q = q({lo}) + t^2 (q({hi}) - q({lo})); film_ior = sqrt(q^2 + {n0}^2 (1 - cos_theta^2))",
                n0 = a.ambient_index,
                lo = a.ior_min,
                hi = a.ior_max
            ),
        },
    ]
}

/// Bakes one recipe into `out_dir`; returns the manifest path.
pub fn bake_recipe(
    recipe: &FilmLutRecipe,
    out_dir: &Path,
    progress: &(dyn Fn() + Sync),
) -> Result<PathBuf> {
    bake_recipe_cancellable(recipe, out_dir, progress, &AtomicBool::new(false))
}

/// [`bake_recipe`] that stops with [`Error::Cancelled`] when `cancel` is set before the
/// table is computed: rows not started yet are skipped, and nothing is written (the output
/// folder is not even created). Once the table is computed its files are written and
/// committed whatever `cancel` says, so the folder holds the whole table or none of it.
pub fn bake_recipe_cancellable(
    recipe: &FilmLutRecipe,
    out_dir: &Path,
    progress: &(dyn Fn() + Sync),
    cancel: &AtomicBool,
) -> Result<PathBuf> {
    let lut: FilmLut = recipe
        .job
        .bake_cancellable(progress, cancel, &recipe.name)?;
    if cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled {
            table: recipe.name.clone(),
        });
    }
    // Every file goes to a staging folder first; `commit` moves them in, the manifest last.
    let stage = nacre_format::stage::StagedTable::new(out_dir)?;
    let mut stale = Vec::new();
    let a = &lut.axes;
    let mut files = Vec::new();
    let channels: Vec<String> = recipe
        .colorimeter
        .space()
        .channel_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let c = &recipe.colorimeter;
    let mut manifest = Manifest {
        colour_convention: format!(
            "linear {} ({:?} channels {:?}); colour = integral of R(lambda) or T(lambda) x illuminant x CMF over 360-830 nm, normalised so that a perfect reflector has Y = 1 (RGB (1,1,1) after Bradford adaptation to the space's white); unpolarised (mean of s and p)",
            c.space(), c.space(), channels
        ),
        ambient: recipe.ambient_spec.clone(),
        film: recipe.film_label.clone(),
        under: recipe.under_specs.clone(),
        under_incoherent: recipe.job.under_incoherent.clone(),
        base: recipe.base_spec.clone(),
        axes: axis_records(a),
        texel_centres: "texel i of an axis with count n holds t = i / (n - 1); a sampler reaches t at u = (t * (n - 1) + 0.5) / n; clamp to edge".into(),
        atlas: "width = count(cos_theta); height = count(opd_nm) * count(film_ior); slice k (film_ior index) occupies rows [k * count(opd_nm), (k + 1) * count(opd_nm)), row j of the slice is opd_nm index j, top row first (EXR, PNG); the KTX2 files hold the same texels as a 3-D RGBA16F texture, width = count(cos_theta), height = count(opd_nm), depth = count(film_ior), alpha 1".into(),
        reconstruction: "cos_t = dot(N, V); opd = 2 d sqrt(n_f^2 - n0^2 (1 - cos_t^2)); q(n) = sqrt(n^2 - n0^2 (1 - cos_t^2)); t = (sqrt(cos_t), opd / opd_max, sqrt((q(n_f) - q(ior_min)) / (q(ior_max) - q(ior_min)))); colour = trilinear sample at u = (t (n - 1) + 0.5) / n per axis; specular = colour (replaces the Fresnel term)".to_string()
            + if recipe.job.under_incoherent.is_empty() {
                ""
            } else {
                "; an incoherent slab lies under the film (under_incoherent): the colour is the whole pane's, its back-face reflections included (reflectance) or what leaves through its back (transmittance), so the pane is drawn as one thin-walled surface and its back face is not added again"
            },
        files: Vec::new(),
        ..Manifest::for_recipe(
            KindRecord::FilmLut(a.clone()),
            &recipe.name,
            &recipe.description,
            &recipe.path,
            &recipe.text,
            c,
        )
    };
    let embedded = manifest.embedded_json();
    let quantities = [
        ("reflectance", Some(&lut.reflectance)),
        ("transmittance", lut.transmittance.as_ref()),
    ];
    for (quantity, table) in quantities {
        let Some(table) = table else { continue };
        let exr = format!("{}.{quantity}.exr", recipe.name);
        files.push(stage.write_exr(&exr, quantity, table, recipe.precision)?);
        if recipe.png {
            let png = format!("{}.{quantity}.png", recipe.name);
            match stage.write_png16(&png, quantity, table)? {
                Some(record) => files.push(record),
                // A stale PNG from an earlier bake would contradict the manifest.
                None => stale.push(png),
            }
        }
        let ktx2 = format!("{}.{quantity}.ktx2", recipe.name);
        let ktx2_format = match recipe.precision {
            Precision::Half => Ktx2Format::Rgba16Float,
            Precision::Float => Ktx2Format::Rgba32Float,
        };
        let image = film_lut_image_as(&stage.path().join(&ktx2), table, &embedded, ktx2_format)?;
        files.push(stage.write_ktx2(&ktx2, quantity, &image)?);
    }
    manifest.files = files;
    Ok(stage.commit_manifest(&manifest, &stale)?)
}

/// Everything needed to bake one film LUT.
pub struct FilmLutJob {
    /// Axes.
    pub axes: FilmLutAxes,
    /// Ambient medium (constant real index).
    pub ambient: Material,
    /// Fixed layers under the film, top first.
    pub under: Vec<Layer>,
    /// Per fixed layer: incoherent (a thick slab); empty when every layer is coherent.
    pub under_incoherent: Vec<bool>,
    /// Base (substrate).
    pub base: Material,
    /// Colour conversion.
    pub colorimeter: Colorimeter,
    /// Whether to bake transmittance.
    pub transmittance: bool,
}

impl FilmLutJob {
    /// Bakes the table: rows of constant (cos θ, n) in parallel, each a thickness sweep
    /// integrated spectrally; `progress` is called once per finished row.
    pub fn bake(&self, progress: &(dyn Fn() + Sync)) -> Result<FilmLut> {
        self.bake_cancellable(progress, &AtomicBool::new(false), "film-lut")
    }

    /// [`FilmLutJob::bake`] that stops with [`Error::Cancelled`] (naming `table`) when
    /// `cancel` is set: every row checks it before it starts. The rows' values do not
    /// depend on it, so a bake that is not cancelled gives the same bytes.
    pub fn bake_cancellable(
        &self,
        progress: &(dyn Fn() + Sync),
        cancel: &AtomicBool,
        table: &str,
    ) -> Result<FilmLut> {
        let check = || {
            if cancel.load(Ordering::Relaxed) {
                Err(Error::Cancelled {
                    table: table.to_string(),
                })
            } else {
                Ok(())
            }
        };
        let a = &self.axes;
        let under_opd: f64 = {
            let probe = Stack::new(self.ambient.clone(), self.under.clone(), self.base.clone())?;
            let probe = if self.under_incoherent.is_empty() {
                probe
            } else {
                probe.with_incoherent(self.under_incoherent.clone())?
            };
            probe.max_opd_nm(None)
        };
        let rule = SpectralRule::new(&self.colorimeter, a.opd_max_nm() + under_opd);
        let rows: Vec<(usize, usize)> = (0..a.ior_count)
            .flat_map(|z| (0..a.cos_theta_count).map(move |x| (x, z)))
            .collect();
        let thicknesses = |x: usize, z: usize| -> Vec<f64> {
            (0..a.opd_count)
                .map(|y| a.texel_parameters(x, y, z).1)
                .collect()
        };
        if !self.under_incoherent.is_empty() {
            let results = rows
                .par_iter()
                .map(|&(x, z)| {
                    check()?;
                    let (cos_theta, _, n) = a.texel_parameters(x, 0, z);
                    let colours = self.slab_row(cos_theta, n, &rule, &thicknesses(x, z))?;
                    progress();
                    Ok(colours)
                })
                .collect::<Result<Vec<_>>>()?;
            return Ok(self.assemble(&rows, &results));
        }
        // A non-dispersive film between non-dispersive media: the same wavelength sums from
        // the film's Airy Fourier series (nacre_optics::film_series; rough_film_lut's
        // module docs, step 2).
        let plans: Option<Vec<Option<(SingleFilm, usize, f64)>>> =
            non_dispersive_surround(&self.ambient, &self.under, &self.base).map(
                |(n_ambient, base)| {
                    rows.iter()
                        .map(|&(x, z)| {
                            let (cos_theta, _, n) = a.texel_parameters(x, 0, z);
                            let film =
                                SingleFilm::new(n_ambient, n, base, cos_theta, self.transmittance)?;
                            let d = thicknesses(x, z).into_iter().fold(0.0, f64::max);
                            let (m, mu) = film.plan(d)?;
                            Some((film, m, mu))
                        })
                        .collect()
                },
            );
        let extent = plans.as_ref().map(|plans| {
            let needs: Vec<(f64, usize)> = plans
                .iter()
                .flatten()
                .map(|&(_, _, mu)| (mu, a.opd_count))
                .collect();
            series_extent(&needs)
        });
        let films: Option<Vec<Option<(SingleFilm, usize)>>> = plans.map(|plans| {
            plans
                .into_iter()
                .map(|p| {
                    p.filter(|&(_, _, mu)| Some(mu) <= extent)
                        .map(|(f, m, _)| (f, m))
                })
                .collect()
        });
        let transform = extent
            .map(|extent| RuleTransform::new(&rule, extent))
            .transpose()?;
        let results: Vec<nacre_optics::FilmColours> = rows
            .par_iter()
            .enumerate()
            .map(|(i, &(x, z))| {
                check()?;
                let (cos_theta, _, n) = a.texel_parameters(x, 0, z);
                let thicknesses = thicknesses(x, z);
                if let (Some(films), Some(transform)) = (&films, &transform)
                    && let Some((film, m)) = &films[i]
                {
                    progress();
                    return Ok(film.colours_over_thickness(transform, *m, &thicknesses));
                }
                let film = Material::constant(format!("{n}"), C64::new(n, 0.0))?;
                let mut layers = vec![Layer {
                    material: film,
                    thickness_nm: 0.0,
                }];
                layers.extend(self.under.iter().cloned());
                let stack = Stack::new(self.ambient.clone(), layers, self.base.clone())?;
                let angle_deg = elementary::acos(cos_theta).to_degrees();
                let colours = stack.colours_over_thickness(1, angle_deg, &rule, &thicknesses)?;
                progress();
                Ok(colours)
            })
            .collect::<Result<_>>()?;
        Ok(self.assemble(&rows, &results))
    }

    /// The table from the colours of each row `rows[i]` = (x, z) over its thicknesses.
    fn assemble(&self, rows: &[(usize, usize)], results: &[FilmColours]) -> FilmLut {
        let a = &self.axes;
        let mut reflectance = Table3::new(a.cos_theta_count, a.opd_count, a.ior_count);
        let mut transmittance = self
            .transmittance
            .then(|| Table3::new(a.cos_theta_count, a.opd_count, a.ior_count));
        for (&(x, z), colours) in rows.iter().zip(results) {
            for y in 0..a.opd_count {
                reflectance.set(x, y, z, colours.reflectance[y].map(|v| v as f32));
                if let Some(t) = transmittance.as_mut() {
                    t.set(x, y, z, colours.transmittance[y].map(|v| v as f32));
                }
            }
        }
        FilmLut {
            axes: a.clone(),
            reflectance,
            transmittance,
        }
    }

    /// One row of a table whose fixed layers hold an incoherent slab: the whole pane's
    /// reflectance and transmittance colours at incidence cos θ = `cos_theta`, film index
    /// `n`, for each film thickness of `thicknesses_nm`, by the intensity recurrence
    /// ([`nacre_optics::incoherent`]) at the nodes of `rule` (unpolarised, R = (R_s + R_p)/2).
    fn slab_row(
        &self,
        cos_theta: f64,
        n: f64,
        rule: &SpectralRule,
        thicknesses_nm: &[f64],
    ) -> Result<FilmColours> {
        let film = Material::constant(format!("{n}"), C64::new(n, 0.0))?;
        let mut layers = vec![Layer {
            material: film,
            thickness_nm: 0.0,
        }];
        layers.extend(self.under.iter().cloned());
        let mut incoherent = vec![false];
        incoherent.extend(&self.under_incoherent);
        let stack = Stack::new(self.ambient.clone(), layers, self.base.clone())?
            .with_incoherent(incoherent)?;
        let angle_deg = elementary::acos(cos_theta).to_degrees();
        let mut sweep = SpectrumSweep::new(&stack, &[angle_deg], rule.wavelengths_nm())?;
        let mut d = stack.thicknesses_nm();
        let mut out = FilmColours {
            reflectance: Vec::with_capacity(thicknesses_nm.len()),
            transmittance: Vec::with_capacity(thicknesses_nm.len()),
        };
        for &film_nm in thicknesses_nm {
            d[0] = film_nm;
            sweep.set_thicknesses_nm(&d)?;
            let p = sweep.powers()?;
            out.reflectance.push(rule.colour(p.iter().map(|p| p.R())));
            out.transmittance.push(rule.colour(p.iter().map(|p| p.T())));
        }
        Ok(out)
    }
}

/// The registry entry of `film-lut` ([`crate::kinds::REGISTRY`]).
pub const ENTRY: KindEntry = KindEntry {
    kind: TableKind::FILM_LUT,
    parse: |path, text| Ok(Box::new(FilmLutRecipe::parse(path, text)?)),
    start_rank: 3,
};

impl TableRecipe for FilmLutRecipe {
    fn kind(&self) -> TableKind {
        TableKind::FILM_LUT
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn work(&self) -> u64 {
        (self.job.axes.cos_theta_count * self.job.axes.ior_count) as u64
    }

    fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        bake_recipe(self, out_dir, progress)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes() -> FilmLutAxes {
        FilmLutAxes {
            cos_theta_count: 17,
            opd_count: 33,
            ior_count: 9,
            thickness_min_nm: 0.0,
            thickness_max_nm: 1200.0,
            ior_min: 1.0,
            ior_max: 2.5,
            ambient_index: 1.0,
        }
    }

    #[test]
    fn forward_and_inverse_round_trip() {
        let a = axes();
        for &(c, d, n) in &[
            (1.0, 0.0, 1.0),
            (0.5, 300.0, 1.7),
            (0.01, 1200.0, 2.5),
            (0.9, 17.0, 1.2),
        ] {
            let t = a.forward(c, d, n);
            let (c2, opd, n2) = a.inverse(t);
            assert!((c2 - c).abs() < 1e-12 && (n2 - n).abs() < 1e-12);
            assert!((opd - a.opd_nm(c, d, n)).abs() < 1e-9);
        }
        // Texel centres: t_i = i/(n−1) is sampled at u = (i + 0.5)/n.
        for i in 0..17 {
            let t = FilmLutAxes::texel_t(i, 17);
            assert!(
                (FilmLutAxes::texture_coordinate(t, 17) - (i as f64 + 0.5) / 17.0).abs() < 1e-15
            );
        }
        // Texel parameters map back to their own t.
        for (x, y, z) in [(0, 0, 0), (16, 32, 8), (3, 7, 5)] {
            let (c, d, n) = a.texel_parameters(x, y, z);
            let t = a.forward(c, d, n);
            let want = [
                FilmLutAxes::texel_t(x, 17),
                FilmLutAxes::texel_t(y, 33),
                FilmLutAxes::texel_t(z, 9),
            ];
            for k in 0..3 {
                // x = 0 is evaluated at cos θ = 1e-6 (t = 1e-3).
                assert!(
                    (t[k] - want[k]).abs() < 2e-3,
                    "{x},{y},{z}: {t:?} vs {want:?}"
                );
                if x > 0 {
                    assert!(
                        (t[k] - want[k]).abs() < 1e-12,
                        "{x},{y},{z}: {t:?} vs {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn lookup_is_exact_at_texels_and_linear_between() {
        let a = axes();
        let mut table = Table3::new(17, 33, 9);
        for z in 0..9 {
            for y in 0..33 {
                for x in 0..17 {
                    let v = (x + 100 * y + 10_000 * z) as f32;
                    table.set(x, y, z, [v, 2.0 * v, -v]);
                }
            }
        }
        let (c, d, n) = a.inverse([0.5, 0.25, 0.5]);
        let d = d / (2.0 * (n * n - (1.0 - c * c)).sqrt());
        let v = FilmLut::lookup(&a, &table, c, d, n);
        assert!((v[0] - (8.0 + 800.0 + 40_000.0)).abs() < 1e-6, "{v:?}");
        // Half-way between texels x = 8 and 9 (t = 8.5/16) in the t domain.
        let tx: f64 = 8.5 / 16.0;
        let (c, _, n) = a.inverse([tx, 0.25, 0.5]);
        let d = 0.25 * a.opd_max_nm() / a.opd_nm(c, 1.0, n);
        let v = FilmLut::lookup(&a, &table, c, d, n);
        assert!((v[0] - (8.5 + 800.0 + 40_000.0)).abs() < 1e-6, "{v:?}");
    }
}
