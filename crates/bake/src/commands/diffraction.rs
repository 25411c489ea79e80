//! `nacre diffraction` and `nacre plot diffraction`: relative reflectance and colour of a
//! diffracting surface over view directions (Stam 1999; Dhillon et al. 2014), from a height
//! field (file or synthetic spec) or a baked `diffraction` table of either layout. The physics
//! is [`nacre_optics::diffraction`]; the height-field sources and the table kind live in
//! [`crate::kinds::diffraction`] and [`crate::kinds::diffraction_integrated`].

use crate::commands::color_request::ColourSettings;
use crate::commands::grid::parse_range;
use crate::commands::spectrum::fmt_sig;
use crate::error::{Error, Msg, Origin, Param, Result};
use crate::kinds::diffraction::HeightSource;
use crate::kinds::diffraction_integrated::DEFAULT_INTEGRATED_SAMPLES;
use nacre_format::msg;
use nacre_format::{Manifest, set};
use nacre_optics::C64;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::integrated::{IntegratedTable, WarpedAxis};
use nacre_optics::diffraction::{
    DEFAULT_COHERENCE_DIAMETER_UM, DiffractionSurface, FresnelTerm, SpectralGrid, TaylorTerms,
    in_plane_directions, max_phase, taylor_order_for,
};
use nacre_optics::elementary;
use rayon::prelude::*;
use std::io::Write;

/// Tolerance on the Taylor remainder bound for fields evaluated directly (f64 terms).
pub const TAYLOR_TOLERANCE: f64 = 1e-6;

/// The surface both `nacre diffraction` and `nacre plot diffraction` evaluate: a height
/// field (file or synthetic spec, and how to read and window it) or a baked table. Values
/// are as given on the command line.
#[derive(Clone, Debug, Default)]
pub struct SurfaceSpec {
    /// Height field: a .png/.exr/.csv file or a synthetic spec.
    pub surface: Option<String>,
    /// A baked `diffraction` table (default-set name or manifest path) instead.
    pub table: Option<String>,
    /// Layout to evaluate a height field through: `terms` or `integrated`.
    pub layout: Option<String>,
    /// Texels along v of an in-memory integrated table.
    pub integrated_samples: Option<usize>,
    /// Sample pitch of the height field, µm.
    pub pitch: Option<String>,
    /// Samples per axis of a synthetic field.
    pub samples: Option<usize>,
    /// Height of a file's full scale (PNG) or multiplier (EXR, CSV), µm.
    pub height_scale: String,
    /// Coherence diameter 4σ_s of the light, µm.
    pub coherence: Option<String>,
}

fn flag(origin: impl Into<Origin>, value: &str, message: impl Into<Msg>) -> Error {
    Error::value(origin, value, message)
}

/// Parses a finite positive number of micrometres; errors name `name`.
pub(crate) fn positive(name: Param, text: &str) -> Result<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| {
            flag(
                name,
                text,
                "expected a finite positive number of micrometres",
            )
        })
}

/// Parses a range of angles, degrees, each strictly between -90 and 90; errors name `name`.
pub fn angles(name: Param, text: &str) -> Result<Vec<f64>> {
    let v = parse_range(name, text)?;
    if let Some(a) = v.iter().find(|a| !(a.abs() < 90.0)) {
        return Err(Error::Angle {
            origin: name.into(),
            value: text.into(),
            angle: *a,
        });
    }
    Ok(v)
}

/// How the colour (and, for terms, the spectrum) is evaluated.
pub enum Evaluator {
    /// The Taylor terms, per wavelength.
    Terms(DiffractionSurface),
    /// An integrated table (colours only).
    Integrated(IntegratedTable),
}

/// Everything `nacre diffraction` and `nacre plot diffraction` share: the evaluator, its
/// colorimeter and the wavelength grid.
pub struct Loaded {
    pub evaluator: Evaluator,
    pub colorimeter: Colorimeter,
    pub wavelengths: Vec<f64>,
    pub fresnel: FresnelTerm,
    /// What the evaluator came from (the table, the integrated layout, the height field),
    /// for messages.
    pub context: Origin,
}

impl Loaded {
    /// (XYZ, output-space colour) for each light/view pair.
    pub fn colours(
        &self,
        directions: &[([f64; 3], [f64; 3])],
    ) -> Result<Vec<([f64; 3], [f64; 3])>> {
        let c = &self.colorimeter;
        match &self.evaluator {
            Evaluator::Terms(surface) => {
                let grid = SpectralGrid::new(c, &self.wavelengths)
                    .map_err(|source| Error::optics_in(Param::Wavelengths, source))?;
                Ok(par_map_pairs(directions, &|wi, wr| {
                    let rho: Vec<f64> = self
                        .wavelengths
                        .iter()
                        .map(|&l| surface.relative_reflectance(wi, wr, l, self.fresnel))
                        .collect();
                    let xyz = grid.xyz(&rho);
                    (xyz, c.output_from_xyz(xyz))
                }))
            }
            Evaluator::Integrated(table) => Ok(par_map_pairs(directions, &|wi, wr| {
                let out = table.colour(wi, wr, self.fresnel);
                (c.xyz_from_output(out), out)
            })),
        }
    }
}

/// The sources and options `load` reads.
pub struct Source<'a> {
    /// The height field or table and how to read it.
    pub surface: &'a SurfaceSpec,
    /// `--wavelengths` as given.
    pub wavelengths: Option<&'a str>,
    /// The grid when `--wavelengths` is not given (terms layout).
    pub default_wavelengths: &'a str,
    pub fresnel: Option<&'a str>,
    /// `--observer`, `--illuminant`, `--space`.
    pub colour: ColourSettings<'a>,
}

fn parse_wavelengths(text: &str) -> Result<Vec<f64>> {
    let wavelengths = parse_range(Param::Wavelengths, text)?;
    if let Some(l) = wavelengths.iter().find(|l| !(**l >= 360.0 && **l <= 830.0)) {
        return Err(flag(
            Param::Wavelengths,
            text,
            format!("wavelength {l} nm is outside 360-830 nm"),
        ));
    }
    Ok(wavelengths)
}

/// Loads the surface or table of `src` for the light/view pairs `directions`, checking
/// the sampling and the table's range.
pub fn load(src: &Source, directions: &[([f64; 3], [f64; 3])]) -> Result<Loaded> {
    let a = src.surface;
    let (surface, table, layout) = (
        a.surface.as_deref(),
        a.table.as_deref(),
        a.layout.as_deref(),
    );
    let (pitch, coherence) = (a.pitch.as_deref(), a.coherence.as_deref());
    let (samples, integrated_samples, height_scale) =
        (a.samples, a.integrated_samples, a.height_scale.as_str());
    let integrated_wanted = match layout.map(str::trim) {
        None | Some("terms") => false,
        Some("integrated") => true,
        Some(other) => {
            return Err(flag(
                Param::Layout,
                other,
                "expected `terms` or `integrated`",
            ));
        }
    };
    if integrated_samples.is_some() && !integrated_wanted {
        return Err(flag(
            Param::IntegratedSamples,
            &integrated_samples.unwrap_or(0).to_string(),
            msg!["applies to ", Param::Layout.given("integrated"), " only"],
        ));
    }
    let fresnel = match src.fresnel {
        None => FresnelTerm::Unity,
        Some(text) => {
            let m = nacre_optics::Material::parse_index(text)
                .map_err(|e| flag(Param::Fresnel, text, e.to_string()))?;
            let n: C64 = m
                .index_at(550.0)
                .map_err(|e| flag(Param::Fresnel, text, e.to_string()))?;
            FresnelTerm::Index(n)
        }
    };
    // |u|, |v| and |w| reached by the directions asked for.
    let max_uv = directions
        .iter()
        .map(|(i, r)| (i[0] + r[0]).abs().max((i[1] + r[1]).abs()))
        .fold(0.0, f64::max);
    let w_max = directions
        .iter()
        .map(|(i, r)| i[2] + r[2])
        .fold(0.0, f64::max);
    let pick = |given: Option<&str>, table: &Option<String>, default: &str| {
        given
            .map(str::to_string)
            .or_else(|| table.clone())
            .unwrap_or_else(|| default.to_string())
    };
    let colorimeter_of = |table_colour: [Option<String>; 3]| -> Result<Colorimeter> {
        let o = pick(src.colour.observer, &table_colour[0], "1931");
        let i = pick(src.colour.illuminant, &table_colour[1], "d65");
        let s = pick(src.colour.space, &table_colour[2], "srgb");
        Ok(Colorimeter::new(
            o.parse()
                .map_err(|e: nacre_optics::Error| flag(Param::Observer, &o, e.to_string()))?,
            i.parse()
                .map_err(|e: nacre_optics::Error| flag(Param::Illuminant, &i, e.to_string()))?,
            s.parse()
                .map_err(|e: nacre_optics::Error| flag(Param::Space, &s, e.to_string()))?,
        ))
    };
    let (terms, sigma_s, table_colour, context, wavelengths) = match (surface, table) {
        (_, Some(name)) => {
            let path = set::resolve_table(name);
            let manifest = Manifest::read(&path)?;
            let record = manifest.diffraction().cloned().ok_or_else(|| {
                Error::invalid(
                    path.display().to_string(),
                    format!(
                        "table `{}` is a `{}` table, not a diffraction table",
                        manifest.name, manifest.kind
                    ),
                )
            })?;
            if let Some(l) = layout {
                return Err(flag(
                    Param::Layout,
                    l,
                    format!(
                        "applies to height fields; table `{name}` has the layout \"{}\"",
                        record.layout
                    ),
                ));
            }
            let integrated = record.layout == "integrated";
            let table_grid = format!(
                "{}:{}:{}",
                record.wavelength_min_nm, record.wavelength_max_nm, record.wavelength_step_nm
            );
            let wavelengths = match (src.wavelengths, integrated) {
                (Some(text), true) => {
                    let w = parse_wavelengths(text)?;
                    if w != parse_range(Param::Wavelengths, &table_grid)? {
                        return Err(flag(
                            Param::Wavelengths,
                            text,
                            msg![
                                format!(
                                    "table `{name}` has the integrated layout: its colours are summed over {table_grid} nm (leave "
                                ),
                                Param::Wavelengths,
                                " out)"
                            ],
                        ));
                    }
                    w
                }
                (None, true) => parse_range(Param::Wavelengths, &table_grid)?,
                (text, false) => parse_wavelengths(text.unwrap_or(src.default_wavelengths))?,
            };
            let wl_min = wavelengths.iter().copied().fold(f64::INFINITY, f64::min);
            let wl_max = wavelengths.iter().copied().fold(0.0, f64::max);
            if wl_min < record.wavelength_min_nm - 1e-9 || wl_max > record.wavelength_max_nm + 1e-9
            {
                return Err(flag(
                    Param::Wavelengths,
                    src.wavelengths.unwrap_or(src.default_wavelengths),
                    format!(
                        "table `{name}` serves {}-{} nm",
                        record.wavelength_min_nm, record.wavelength_max_nm
                    ),
                ));
            }
            let max_polar_deg = directions
                .iter()
                .map(|(i, r)| elementary::acos(i[2].min(r[2]).clamp(-1.0, 1.0)).to_degrees())
                .fold(0.0, f64::max);
            if max_polar_deg > record.max_angle_deg + 1e-9 || max_uv > record.max_uv * (1.0 + 1e-9)
            {
                return Err(Error::invalid(
                    msg![Param::Incidence, "/", Param::Views],
                    format!(
                        "light or view reaches {max_polar_deg:.2}° from the normal; table `{name}` serves light and view within {}° (|u|, |v| ≤ {:.4})",
                        record.max_angle_deg, record.max_uv
                    ),
                ));
            }
            if coherence.is_some() || pitch.is_some() || samples.is_some() {
                return Err(flag(
                    Param::Table,
                    name,
                    msg![
                        Param::Coherence,
                        ", ",
                        Param::Pitch,
                        " and ",
                        Param::Samples,
                        " come from the table"
                    ],
                ));
            }
            let c = [
                Some(manifest.observer.clone()),
                Some(manifest.illuminant.clone()),
                Some(manifest.space.clone()),
            ];
            if integrated {
                let colorimeter = colorimeter_of(c.clone())?;
                let baked = manifest.colorimeter(&path)?;
                for (given, flag_name, same) in [
                    (
                        src.colour.observer,
                        Param::Observer,
                        colorimeter.observer() == baked.observer(),
                    ),
                    (
                        src.colour.illuminant,
                        Param::Illuminant,
                        colorimeter.illuminant() == baked.illuminant(),
                    ),
                    (
                        src.colour.space,
                        Param::Space,
                        colorimeter.space() == baked.space(),
                    ),
                ] {
                    if let (Some(v), false) = (given, same) {
                        return Err(flag(
                            flag_name,
                            v,
                            format!(
                                "table `{name}` has the integrated layout, baked for observer {}, illuminant {} and space {}",
                                baked.observer(),
                                baked.illuminant(),
                                baked.space()
                            ),
                        ));
                    }
                }
                let (_, table) = manifest.load_diffraction_integrated(&path)?;
                // What the colours are: with Stam's k² (issue 37) the table's sum, not ρ's.
                match table.k_squared_reference_nm() {
                    Some(r) => eprintln!(
                        "nacre: table `{name}` is summed with Stam's k^2 as ({r} nm / lambda)^2 per wavelength (k_squared_reference_nm): its colours are those of sum_lambda ({r}/lambda)^2 rho u, what a renderer lights at the gain (sigma_s k_ref)^2/pi, not the relative reflectance's sum_lambda rho u"
                    ),
                    None => eprintln!(
                        "nacre: table `{name}` was baked without Stam's k^2 (no k_squared_reference_nm: an older nacre): its colours are those of sum_lambda rho u"
                    ),
                }
                return Ok(Loaded {
                    evaluator: Evaluator::Integrated(table),
                    colorimeter,
                    wavelengths,
                    fresnel,
                    context: Param::Table.given(name),
                });
            }
            let (record, terms) = manifest.load_diffraction(&path)?;
            (
                terms,
                record.sigma_s_um,
                c,
                Param::Table.given(name),
                wavelengths,
            )
        }
        (Some(text), None) => {
            let wavelengths =
                parse_wavelengths(src.wavelengths.unwrap_or(src.default_wavelengths))?;
            let wl_min = wavelengths.iter().copied().fold(f64::INFINITY, f64::min);
            let coherence_um = match coherence {
                Some(t) => positive(Param::Coherence, t)?,
                None => DEFAULT_COHERENCE_DIAMETER_UM,
            };
            let pitch_um = pitch.map(|t| positive(Param::Pitch, t)).transpose()?;
            let scale = height_scale
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    flag(
                        Param::HeightScale,
                        height_scale,
                        "expected a finite non-negative number of micrometres",
                    )
                })?;
            if samples == Some(0) {
                return Err(flag(Param::Samples, "0", "expected at least 1"));
            }
            let source = HeightSource::parse(Param::Surface, text)?;
            let field = source.load(
                &text.into(),
                &Param::Pitch.into(),
                coherence_um,
                pitch_um,
                samples,
                scale,
            )?;
            let x = max_phase(&field, wl_min, w_max);
            let (order, bound) = taylor_order_for(x, TAYLOR_TOLERANCE)
                .map_err(|source| Error::optics_in(text.to_string(), source))?;
            eprintln!(
                "nacre: {}x{} samples at {} µm, Taylor order N = {order} (remainder bound {bound:.1e} at max |k w h| = {x:.3}), 4σ_s = {coherence_um} µm",
                field.nx(),
                field.ny(),
                field.pitch_um()
            );
            (
                TaylorTerms::compute(&field, order),
                coherence_um / 4.0,
                [None, None, None],
                Origin::from(text),
                wavelengths,
            )
        }
        (None, None) => {
            return Err(Error::invalid(
                msg![Param::Surface, ", ", Param::Table],
                "give a height field or a table",
            ));
        }
    };
    let wl_min = wavelengths.iter().copied().fold(f64::INFINITY, f64::min);
    let surface = DiffractionSurface::new(terms, sigma_s)
        .map_err(|source| Error::optics_in(context.clone(), source))?;
    surface.check_sampling(wl_min, max_uv).map_err(|source| {
        Error::optics_in(
            msg![
                context.clone(),
                " with ",
                Param::Views,
                "/",
                Param::Incidence,
                " and ",
                Param::Wavelengths
            ],
            source,
        )
    })?;
    let colorimeter = colorimeter_of(table_colour)?;
    let evaluator = if integrated_wanted {
        let n = integrated_samples.unwrap_or(DEFAULT_INTEGRATED_SAMPLES);
        let axis = WarpedAxis::new(max_uv.clamp(1e-3, 2.0), 3.0, n)
            .map_err(|source| Error::optics_in(Param::IntegratedSamples, source))?;
        let grid = SpectralGrid::new(&colorimeter, &wavelengths)
            .map_err(|source| Error::optics_in(Param::Wavelengths, source))?;
        eprintln!(
            "nacre: integrated table of {} x {n} texels x {} layers over |u|, |v| <= {:.4}",
            n / 2,
            2 * surface.terms().order() + 1,
            axis.max_uv
        );
        // Without Stam's k²: the colour of Σ_λ ρ u, as the terms evaluator gives it.
        Evaluator::Integrated(IntegratedTable::compute(
            &surface,
            &grid,
            &colorimeter,
            axis,
            None,
        ))
    } else {
        Evaluator::Terms(surface)
    };
    Ok(Loaded {
        evaluator,
        colorimeter,
        wavelengths,
        fresnel,
        context: if integrated_wanted {
            Param::Layout.given("integrated")
        } else {
            context
        },
    })
}

/// Parses an incidence angle θ_i, degrees, strictly between -90 and 90; errors name `name`.
pub fn incidence(name: Param, text: &str) -> Result<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|a| a.abs() < 90.0)
        .ok_or_else(|| {
            flag(
                name,
                text,
                "expected an angle in degrees strictly between -90 and 90",
            )
        })
}

/// A `nacre diffraction` request: the surface, one incidence and in-plane view angles, as
/// given on the command line.
pub struct ViewsRequest<'a> {
    /// The surface and its colour and wavelength options.
    pub source: Source<'a>,
    /// `--incidence`, degrees.
    pub incidence: &'a str,
    /// `--views`, degrees (a range).
    pub views: &'a str,
    /// Colours (`--color`) instead of spectra.
    pub color: bool,
}

/// What [`evaluate_views`] computed.
pub enum ViewsOutput {
    /// (XYZ, output-space colour) per view.
    Colours {
        /// View angles, degrees.
        views: Vec<f64>,
        /// One colour per view.
        colours: Vec<([f64; 3], [f64; 3])>,
    },
    /// ρ per (view, wavelength), view-major.
    Reflectance {
        /// The surface evaluated.
        loaded: Box<Loaded>,
        /// Incidence angle, degrees.
        incidence_deg: f64,
        /// View angles, degrees.
        views: Vec<f64>,
        /// ρ, view-major.
        rho: Vec<f64>,
    },
}

impl ViewsOutput {
    /// Writes `view_deg,X,Y,Z,R,G,B` or `view_deg,wavelength_nm,reflectance`.
    pub fn write_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        match self {
            ViewsOutput::Colours { views, colours } => write_colour_csv(w, views, colours),
            ViewsOutput::Reflectance {
                loaded,
                incidence_deg,
                views,
                rho,
            } => {
                let Evaluator::Terms(surface) = &loaded.evaluator else {
                    unreachable!("reflectance comes from the terms layout")
                };
                ViewSweep {
                    surface,
                    incidence_deg: *incidence_deg,
                    views_deg: views,
                    wavelengths_nm: &loaded.wavelengths,
                    fresnel: loaded.fresnel,
                }
                .write_reflectance_csv(w, rho)
            }
        }
    }
}

/// Evaluates a `nacre diffraction` request: checks the angles, loads the surface and
/// computes colours or spectra.
pub fn evaluate_views(req: &ViewsRequest) -> Result<ViewsOutput> {
    let incidence = incidence(Param::Incidence, req.incidence)?;
    let views = angles(Param::Views, req.views)?;
    let directions: Vec<_> = views
        .iter()
        .map(|&v| nacre_optics::diffraction::in_plane_directions(incidence, v))
        .collect();
    if req.source.surface.layout.as_deref().map(str::trim) == Some("integrated") && !req.color {
        return Err(flag(
            Param::Layout,
            "integrated",
            msg![
                "the integrated layout holds colours summed over wavelengths: add ",
                Param::Color,
                ", or use the terms layout for per-wavelength reflectance"
            ],
        ));
    }
    let loaded = load(&req.source, &directions)?;
    if req.color {
        let colours = loaded.colours(&directions)?;
        return Ok(ViewsOutput::Colours { views, colours });
    }
    let Evaluator::Terms(surface) = &loaded.evaluator else {
        return Err(Error::invalid(
            loaded.context.clone(),
            msg![
                "the integrated layout holds colours summed over wavelengths, not spectra: add ",
                Param::Color,
                ", or use a terms table for per-wavelength reflectance"
            ],
        ));
    };
    let sweep = ViewSweep {
        surface,
        incidence_deg: incidence,
        views_deg: &views,
        wavelengths_nm: &loaded.wavelengths,
        fresnel: loaded.fresnel,
    };
    let rho = sweep.reflectance();
    Ok(ViewsOutput::Reflectance {
        loaded: Box::new(loaded),
        incidence_deg: incidence,
        views,
        rho,
    })
}

/// A `nacre plot diffraction` request, as given on the command line.
pub struct MapRequest<'a> {
    /// The surface.
    pub surface: &'a SurfaceSpec,
    /// `--incidence`, degrees.
    pub incidence: &'a str,
    /// `--max-view`, degrees.
    pub max_view: &'a str,
    /// `--cells`.
    pub cells: usize,
    /// `--wavelengths`.
    pub wavelengths: Option<&'a str>,
    /// `--exposure`: a positive factor or `auto`.
    pub exposure: &'a str,
}

/// Computes the diffraction map of a `nacre plot diffraction` request, titled.
pub fn map(req: &MapRequest) -> Result<DiffractionMap> {
    let incidence = incidence(Param::Incidence, req.incidence)?;
    let max_view = req
        .max_view
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|a| *a > 0.0 && *a < 90.0)
        .ok_or_else(|| {
            flag(
                Param::MaxView,
                req.max_view,
                "expected an angle in degrees strictly between 0 and 90",
            )
        })?;
    if !(16..=1024).contains(&req.cells) {
        return Err(Error::OutOfRange {
            param: Param::Cells,
            value: req.cells as f64,
            low: 16.0,
            high: 1024.0,
        });
    }
    let exposure = match req.exposure.trim() {
        "auto" => None,
        t => Some(
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| flag(Param::Exposure, t, "expected a positive number or `auto`"))?,
        ),
    };
    // The extreme view directions: the rim of the disc.
    let (wi, _) = nacre_optics::diffraction::in_plane_directions(incidence, 0.0);
    let s = elementary::sin(max_view.to_radians());
    let c = elementary::cos(max_view.to_radians());
    let directions: Vec<_> = [[s, 0.0, c], [-s, 0.0, c], [0.0, s, c], [0.0, -s, c]]
        .into_iter()
        .map(|r| (wi, r))
        .collect();
    let loaded = load(
        &Source {
            surface: req.surface,
            wavelengths: req.wavelengths,
            default_wavelengths: "380:780:10",
            fresnel: None,
            colour: ColourSettings::default(),
        },
        &directions,
    )?;
    let name = req
        .surface
        .surface
        .clone()
        .or_else(|| req.surface.table.clone())
        .unwrap_or_default();
    let map = match &loaded.evaluator {
        Evaluator::Terms(surface) => {
            let grid = SpectralGrid::new(&loaded.colorimeter, &loaded.wavelengths)
                .map_err(|source| Error::optics_in(Param::Wavelengths, source))?;
            DiffractionMap::compute(
                String::new(),
                surface,
                incidence,
                max_view,
                req.cells,
                &grid,
                &loaded.colorimeter,
                loaded.fresnel,
                exposure,
            )
        }
        Evaluator::Integrated(table) => DiffractionMap::compute_with(
            String::new(),
            &|wi, wr| table.colour(wi, wr, loaded.fresnel),
            incidence,
            max_view,
            req.cells,
            &loaded.colorimeter,
            exposure,
        ),
    };
    let title = format!(
        "diffraction map of {name}: light at {incidence}°, views to {max_view}°, exposure {:.3}",
        map.exposure
    );
    Ok(DiffractionMap { title, ..map })
}

/// A `nacre diffraction` evaluation: one incidence, a list of in-plane view angles.
pub struct ViewSweep<'a> {
    /// The surface.
    pub surface: &'a DiffractionSurface,
    /// Incidence angle θ_i, degrees (light on the −x side when positive).
    pub incidence_deg: f64,
    /// View angles θ_r, degrees (viewer on the +x side when positive).
    pub views_deg: &'a [f64],
    /// Wavelengths, nm.
    pub wavelengths_nm: &'a [f64],
    /// Fresnel factor.
    pub fresnel: FresnelTerm,
}

impl ViewSweep<'_> {
    /// ρ for every (view, wavelength), view-major; views in parallel (each value
    /// independent: the same result whatever the thread count).
    pub fn reflectance(&self) -> Vec<f64> {
        self.views_deg
            .par_iter()
            .flat_map_iter(|&view| {
                let (wi, wr) = in_plane_directions(self.incidence_deg, view);
                self.wavelengths_nm
                    .iter()
                    .map(move |&wl| self.surface.relative_reflectance(wi, wr, wl, self.fresnel))
            })
            .collect()
    }

    /// Writes `view_deg,wavelength_nm,reflectance`.
    pub fn write_reflectance_csv(&self, w: &mut dyn Write, rho: &[f64]) -> std::io::Result<()> {
        let mut csv = crate::csv_text::writer(w);
        csv.write_record(["view_deg", "wavelength_nm", "reflectance"])?;
        let mut cells = rho.iter();
        for &v in self.views_deg {
            for &wl in self.wavelengths_nm {
                let value = *cells.next().expect("one value per cell");
                csv.write_record([v.to_string(), wl.to_string(), fmt_sig(value)])?;
            }
        }
        csv.flush()
    }

    /// Colours (XYZ, output space) per view from ρ on the wavelength grid.
    pub fn colours(
        &self,
        rho: &[f64],
        grid: &SpectralGrid,
        colorimeter: &Colorimeter,
    ) -> Vec<([f64; 3], [f64; 3])> {
        rho.chunks(self.wavelengths_nm.len())
            .map(|values| {
                let xyz = grid.xyz(values);
                (xyz, colorimeter.output_from_xyz(xyz))
            })
            .collect()
    }

    /// Writes `view_deg,X,Y,Z,R,G,B`.
    pub fn write_colour_csv(
        &self,
        w: &mut dyn Write,
        colours: &[([f64; 3], [f64; 3])],
    ) -> std::io::Result<()> {
        write_colour_csv(w, self.views_deg, colours)
    }
}

/// `f` of every light/view pair, in parallel (each value independent, the order kept: the
/// same result whatever the thread count).
pub fn par_map_pairs<T: Send>(
    pairs: &[([f64; 3], [f64; 3])],
    f: &(dyn Fn([f64; 3], [f64; 3]) -> T + Sync),
) -> Vec<T> {
    pairs.par_iter().map(|&(wi, wr)| f(wi, wr)).collect()
}

/// Writes `view_deg,X,Y,Z,R,G,B`, one row per view angle (degrees) with its (XYZ,
/// output-space) colour.
pub fn write_colour_csv(
    w: &mut dyn Write,
    views_deg: &[f64],
    colours: &[([f64; 3], [f64; 3])],
) -> std::io::Result<()> {
    let mut csv = crate::csv_text::writer(w);
    csv.write_record(["view_deg", "X", "Y", "Z", "R", "G", "B"])?;
    for (&v, (xyz, rgb)) in views_deg.iter().zip(colours) {
        let mut row = vec![v.to_string()];
        row.extend(xyz.iter().chain(rgb).map(|&c| fmt_sig(c)));
        csv.write_record(&row)?;
    }
    csv.flush()
}

/// A diffraction map (`nacre plot diffraction`): the colour of ρ over view directions for
/// a fixed light, on the projected hemisphere (x = sin θ_r cos φ_r across the grating
/// lines, y = sin θ_r sin φ_r along them; the light at θ_i in the x–z plane on the −x
/// side), as sRGB: linear sRGB × exposure, clipped per channel (the `nacre plot`
/// conventions).
#[derive(Clone, Debug)]
pub struct DiffractionMap {
    /// Title.
    pub title: String,
    /// Cells per side.
    pub cells: usize,
    /// sin of the largest view angle drawn: the disc's radius.
    pub radius: f64,
    /// Linear sRGB per cell (row-major from y = −radius), `None` outside the disc.
    pub colours: Vec<Option<[f64; 3]>>,
    /// Factor applied before clipping.
    pub exposure: f64,
    /// (x, y) of the specular direction.
    pub specular: [f64; 2],
}

/// The view direction of map cell (ix, iy), or `None` outside the disc.
fn map_direction(ix: usize, iy: usize, cells: usize, radius: f64) -> Option<[f64; 3]> {
    let at = |i: usize| radius * (2.0 * (i as f64 + 0.5) / cells as f64 - 1.0);
    let (x, y) = (at(ix), at(iy));
    let r2 = x * x + y * y;
    (r2 <= radius * radius).then(|| [x, y, (1.0 - r2).sqrt()])
}

impl DiffractionMap {
    /// Evaluates ρ over `grid`'s wavelengths at every cell (rows in parallel, each cell
    /// independent) and converts to linear sRGB. With `exposure` `None` the exposure puts
    /// the 98th percentile of the cells' largest channel at 1 (the specular highlight
    /// saturates; the orders show).
    #[allow(clippy::too_many_arguments)]
    pub fn compute(
        title: String,
        surface: &DiffractionSurface,
        incidence_deg: f64,
        max_view_deg: f64,
        cells: usize,
        grid: &SpectralGrid,
        colorimeter: &Colorimeter,
        fresnel: FresnelTerm,
        exposure: Option<f64>,
    ) -> Self {
        let colour = |omega_i: [f64; 3], omega_r: [f64; 3]| {
            let rho: Vec<f64> = grid
                .wavelengths_nm()
                .iter()
                .map(|&wl| surface.relative_reflectance(omega_i, omega_r, wl, fresnel))
                .collect();
            colorimeter.output_from_xyz(grid.xyz(&rho))
        };
        Self::compute_with(
            title,
            &colour,
            incidence_deg,
            max_view_deg,
            cells,
            colorimeter,
            exposure,
        )
    }

    /// As [`DiffractionMap::compute`] for any evaluation `colour(ω_i, ω_r)` giving the
    /// colour in `colorimeter`'s output space (e.g. an integrated table's,
    /// [`nacre_optics::diffraction::integrated::IntegratedTable::colour`]).
    pub fn compute_with(
        title: String,
        colour: &(dyn Fn([f64; 3], [f64; 3]) -> [f64; 3] + Sync),
        incidence_deg: f64,
        max_view_deg: f64,
        cells: usize,
        colorimeter: &Colorimeter,
        exposure: Option<f64>,
    ) -> Self {
        let radius = elementary::sin(max_view_deg.to_radians());
        let (omega_i, _) = in_plane_directions(incidence_deg, 0.0);
        let display = crate::commands::plot::DisplayConverter::new(colorimeter);
        let colours: Vec<Option<[f64; 3]>> = (0..cells)
            .into_par_iter()
            .flat_map_iter(|iy| {
                let display = &display;
                (0..cells).map(move |ix| {
                    let omega_r = map_direction(ix, iy, cells, radius)?;
                    Some(display.linear_srgb(colour(omega_i, omega_r)))
                })
            })
            .collect();
        let exposure = exposure.unwrap_or_else(|| {
            let mut peaks: Vec<f64> = colours
                .iter()
                .flatten()
                .map(|c| c.iter().fold(0.0f64, |m, v| m.max(*v)))
                .collect();
            peaks.sort_by(f64::total_cmp);
            let p = peaks.get(peaks.len() * 98 / 100).copied().unwrap_or(0.0);
            if p > 0.0 { 1.0 / p } else { 1.0 }
        });
        DiffractionMap {
            title,
            cells,
            radius,
            colours,
            exposure,
            specular: [elementary::sin(incidence_deg.to_radians()), 0.0],
        }
    }
}

impl crate::commands::plot::Figure for DiffractionMap {
    fn size(&self) -> (u32, u32) {
        (760, 800)
    }

    fn draw<DB: plotters::prelude::DrawingBackend>(
        &self,
        root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
        format: crate::commands::plot::ImageFormat,
    ) -> crate::commands::plot::DrawResult<DB> {
        use plotters::prelude::*;
        let area = root.titled(&self.title, ("sans-serif", 17))?;
        let r = self.radius;
        let mut chart = ChartBuilder::on(&area)
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(60)
            .build_cartesian_2d(-r..r, -r..r)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("sin θ_r cos φ_r (across the grating lines)")
            .y_desc("sin θ_r sin φ_r (along the lines)")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()?;
        chart.draw_series(std::iter::once(Rectangle::new(
            [(-r, -r), (r, r)],
            BLACK.filled(),
        )))?;
        // SVG: coarser cells (every other one) to keep files small.
        let stride = if format == crate::commands::plot::ImageFormat::Png {
            1
        } else {
            2
        };
        let step = 2.0 * r / self.cells as f64;
        let mut rects = Vec::new();
        for iy in (0..self.cells).step_by(stride) {
            for ix in (0..self.cells).step_by(stride) {
                if let Some(c) = self.colours[iy * self.cells + ix] {
                    let (x0, y0) = (-r + ix as f64 * step, -r + iy as f64 * step);
                    let span = step * stride as f64;
                    rects.push(Rectangle::new(
                        [(x0, y0), (x0 + span, y0 + span)],
                        crate::commands::plot::srgb8(c.map(|v| v * self.exposure)).filled(),
                    ));
                }
            }
        }
        chart.draw_series(rects)?;
        chart.draw_series(std::iter::once(Cross::new(
            (self.specular[0], self.specular[1]),
            6,
            WHITE.stroke_width(1),
        )))?;
        Ok(())
    }
}
