//! Diffraction gratings: height-field sources (files and synthetic specs), the table kind
//! `diffraction` (layout "terms" here, layout "integrated" in
//! [`crate::kinds::diffraction_integrated`]); the CPU evaluation behind `nacre diffraction` is
//! [`crate::commands::diffraction`].
//! The physics is [`nacre_optics::diffraction`] (Stam 1999; Dhillon et al. 2014).
//!
//! # Height-field sources
//!
//! * Synthetic specs ([`SyntheticSpec::parse`]): `sine:PERIOD_UM:AMPLITUDE_UM`,
//!   `blazed:PERIOD_UM:HEIGHT_UM`, `cd` or `cd:SEED` (tracks 1.6 µm apart, pits 0.1 µm
//!   deep), `bumps:RADIUS_UM:HEIGHT_UM:FILL` or `bumps:RADIUS_UM:HEIGHT_UM:FILL:SEED`
//!   (Stam's random bumps). Gratings are one row (invariant along the lines) spanning
//!   whole periods over at least the coherence diameter; `cd` and `bumps` are square
//!   patches at least the coherence diameter wide.
//! * Files ([`read_height_field`]): 8- or 16-bit greyscale PNG or greyscale JPEG (value /
//!   full scale × height scale), OpenEXR (one channel `Y`, `Z`, `R` or the only channel, × height
//!   scale), or CSV (rows of comma-separated numbers, `#` comments, × height scale; row
//!   0 is y = 0). The pitch (µm per sample) and the height scale (µm) come from the
//!   recipe or the command line.
//!
//! # Table kind `diffraction`, layout "terms"
//!
//! ```toml
//! kind = "diffraction"
//! description = "CD-like tracks"
//! [colour]                        # as for film-lut; recorded for the runtime's colour sums
//! [height_field]
//! synthetic = "cd"                # or: file = "snake.png" (relative to the recipe)
//! samples = 256                   # synthetic: samples per axis (along x for gratings)
//! pitch_um = 0.125                # required with `file`; synthetic: optional
//! height_scale_um = 0.1           # `file` only: full scale of a PNG, multiplier of EXR/CSV
//! [diffraction]
//! layout = "terms"                # or "integrated" (crate::kinds::diffraction_integrated)
//! coherence_diameter_um = 65.0    # 4σ_s; default 65 (Dhillon et al. 2014)
//! wavelengths = "380:780:5"       # range (and colour step) the table serves
//! max_angle_deg = 45.0            # light and view polar angles the table serves
//! taylor_tolerance = 1e-4         # bound on the Taylor remainder |kwh|^{N+1}/(N+1)!
//! ```
//!
//! What every texel holds: layer n of the terms is Tₙ\[j\] = DFT{(i h)ⁿ}\[j\] / M (M = Mₓ·M_y
//! samples, positive exponent e^{+iκ_j·x}), computed in f64 and stored as f32, DC at
//! texel (⌊Mₓ/2⌋, ⌊M_y/2⌋); texel (s, t) is frequency κ = 2π (s − ⌊Mₓ/2⌋, t − ⌊M_y/2⌋) / L.
//! The EXR file `NAME.terms.exr` is an atlas Mₓ wide and M_y·(N+1) high (term n in rows
//! [n·M_y, (n+1)·M_y)), R = Re Tₙ, G = Im Tₙ, B = 0, full float. The KTX2 file
//! `NAME.terms.ktx2` is a 2-D array `RGBA32F` texture Mₓ × M_y with ⌈(N+1)/2⌉ layers,
//! layer l = (Re T₂ₗ, Im T₂ₗ, Re T₂ₗ₊₁, Im T₂ₗ₊₁) (zero when 2l + 1 > N).
//!
//! How a shader rebuilds the colour: for each wavelength λ of the grid, k = 2π/λ,
//! (u, v, w) = −ω_i − ω_r, P_j = Σₙ (kw)ⁿ/n! Tₙ\[j\] at the texels j near (ku, kv)·L/2π,
//! P̃ = Σ_j P_j exp(−σ_s²|(ku, kv) − κ_j|²/2), ρ = F² · G/w² · |P̃|²
//! (G/w² = (1 + ω_i·ω_r)²/(cos θ_i cos θ_r (cos θ_i + cos θ_r)²)), then
//! colour = M · Σ_λ ρ(λ) u(λ) with the CIE weights of the recorded observer and illuminant
//! ([`nacre_optics::diffraction::SpectralGrid`]). The layout "integrated" (the
//! wavelength-integrated fast path, `layout = "integrated"` with the keys
//! `integrated_samples`, `integrated_gamma`, `integrated_tolerance`) is documented in
//! [`crate::kinds::diffraction_integrated`].

use crate::error::{Error, Origin, Result};
pub use crate::kinds::diffraction_recipe::DiffractionRecipe;
pub use crate::kinds::height_field::{MAX_AXIS, read_height_field};
use crate::kinds::{KindEntry, TableRecipe};
use crate::recipe::{RawColour, line_of, parse_colour, table_name, toml_error};
use nacre_format::diffraction::{DiffractionRecord, SIGN_CONVENTION};
use nacre_format::manifest::{AxisRecord, KindRecord, Manifest, TableKind};
use nacre_format::msg;
use nacre_format::table_io::{Precision, Table3};
use nacre_optics::C64;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::{
    CD_PIT_DEPTH_UM, CD_TRACK_PITCH_UM, DEFAULT_COHERENCE_DIAMETER_UM, DiffractionSurface,
    HeightField, SpectralGrid, TaylorTerms, taylor_order_for,
};
use nacre_optics::elementary;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Largest pitch the automatic sampling of synthetic specs uses, µm: the Nyquist limit of
/// 380 nm light at |u| = 2 is 0.095 µm.
pub const AUTO_PITCH_UM: f64 = 0.09;

/// A synthetic height field.
#[derive(Clone, Debug, PartialEq)]
pub enum SyntheticSpec {
    /// h = a sin(2πx/d).
    Sine {
        /// Period d, µm.
        period_um: f64,
        /// Amplitude a, µm.
        amplitude_um: f64,
    },
    /// A sawtooth rising by `height_um` over each period.
    Blazed {
        /// Period d, µm.
        period_um: f64,
        /// Height, µm.
        height_um: f64,
    },
    /// CD-like tracks of pits.
    Cd {
        /// Random seed of the pit sequence.
        seed: u64,
    },
    /// Stam's random bumps.
    Bumps {
        /// Bump radius, µm.
        radius_um: f64,
        /// Bump height, µm.
        height_um: f64,
        /// Covered area fraction (bumps × πr² / patch area).
        fill: f64,
        /// Random seed.
        seed: u64,
    },
}

impl SyntheticSpec {
    /// Parses `sine:PERIOD_UM:AMPLITUDE_UM`, `blazed:PERIOD_UM:HEIGHT_UM`, `cd[:SEED]` or
    /// `bumps:RADIUS_UM:HEIGHT_UM:FILL[:SEED]`; `None` when `text` names none of these
    /// kinds (it may be a file). Errors name `context` (a parameter or `file:line`).
    pub fn parse(context: impl Into<Origin>, text: &str) -> Result<Option<Self>> {
        let context = context.into();
        let parts: Vec<&str> = text.trim().split(':').map(str::trim).collect();
        let err = |message: String| Error::value(context.clone(), text, message);
        let num = |s: &str, what: &str, positive: bool| -> Result<f64> {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && if positive { *v > 0.0 } else { *v >= 0.0 })
                .ok_or_else(|| {
                    err(format!(
                        "{what} `{s}` must be a finite {} number",
                        if positive { "positive" } else { "non-negative" }
                    ))
                })
        };
        let seed = |s: &str| -> Result<u64> {
            s.parse::<u64>()
                .map_err(|_| err(format!("SEED `{s}` must be a non-negative integer")))
        };
        let spec = match parts.as_slice() {
            ["sine", d, a] => SyntheticSpec::Sine {
                period_um: num(d, "PERIOD_UM", true)?,
                amplitude_um: num(a, "AMPLITUDE_UM", false)?,
            },
            ["blazed", d, h] => SyntheticSpec::Blazed {
                period_um: num(d, "PERIOD_UM", true)?,
                height_um: num(h, "HEIGHT_UM", false)?,
            },
            ["cd"] => SyntheticSpec::Cd { seed: 1 },
            ["cd", s] => SyntheticSpec::Cd { seed: seed(s)? },
            ["bumps", r, h, f] | ["bumps", r, h, f, _] => SyntheticSpec::Bumps {
                radius_um: num(r, "RADIUS_UM", true)?,
                height_um: num(h, "HEIGHT_UM", false)?,
                fill: num(f, "FILL", true)?,
                seed: parts.get(4).map_or(Ok(1), |s| seed(s))?,
            },
            [kind, ..] if ["sine", "blazed", "cd", "bumps"].contains(kind) => {
                return Err(err(
                    "expected sine:PERIOD_UM:AMPLITUDE_UM, blazed:PERIOD_UM:HEIGHT_UM, cd[:SEED] or bumps:RADIUS_UM:HEIGHT_UM:FILL[:SEED]".into(),
                ));
            }
            _ => return Ok(None),
        };
        Ok(Some(spec))
    }

    /// Generates the field. The patch spans at least `coherence_diameter_um` (gratings:
    /// whole periods; `cd`: whole 1.6 µm tracks). `pitch_um` defaults to d/⌈d/0.04⌉ (at
    /// least 16 samples per period) for gratings and at most [`AUTO_PITCH_UM`] otherwise;
    /// `samples` (per axis; along x for gratings) overrides the patch size.
    ///
    /// # Errors
    /// [`nacre_format::Error::OpticsIn`] naming `context` for out-of-range parameters;
    /// [`nacre_format::Error::TooLarge`] beyond [`MAX_AXIS`] samples per axis.
    pub fn generate(
        &self,
        context: &Origin,
        coherence_diameter_um: f64,
        pitch_um: Option<f64>,
        samples: Option<usize>,
    ) -> Result<HeightField> {
        let core = |source| Error::optics_in(context.clone(), source);
        let too_large = |n: usize| nacre_format::Error::TooLarge {
            what: format!("{context}: samples per axis").into(),
            count: n as u64,
            limit: MAX_AXIS as u64,
        };
        let square = |n: usize| {
            if n > MAX_AXIS {
                Err(too_large(n))
            } else {
                Ok(n)
            }
        };
        match *self {
            SyntheticSpec::Sine { period_um, .. } | SyntheticSpec::Blazed { period_um, .. } => {
                let pitch =
                    pitch_um.unwrap_or_else(|| period_um / ((period_um / 0.04).ceil().max(16.0)));
                let periods = (coherence_diameter_um / period_um).ceil().max(1.0);
                let nx = samples
                    .unwrap_or_else(|| (periods * period_um / pitch).round().max(1.0) as usize);
                if nx > MAX_AXIS * MAX_AXIS {
                    return Err(too_large(nx).into());
                }
                match *self {
                    SyntheticSpec::Sine {
                        period_um,
                        amplitude_um,
                    } => HeightField::sine_grating(period_um, amplitude_um, pitch, nx),
                    SyntheticSpec::Blazed {
                        period_um,
                        height_um,
                    } => HeightField::blazed_grating(period_um, height_um, pitch, nx),
                    _ => unreachable!(),
                }
                .map_err(core)
            }
            SyntheticSpec::Cd { seed } => {
                let tracks = (coherence_diameter_um / CD_TRACK_PITCH_UM).ceil().max(1.0);
                let l = tracks * CD_TRACK_PITCH_UM;
                let n = square(auto_samples(l, pitch_um, samples))?;
                let pitch = pitch_um.unwrap_or(l / n as f64);
                HeightField::cd_tracks(n, n, pitch, CD_PIT_DEPTH_UM, seed).map_err(core)
            }
            SyntheticSpec::Bumps {
                radius_um,
                height_um,
                fill,
                seed,
            } => {
                let l = coherence_diameter_um;
                let n = square(auto_samples(l, pitch_um, samples))?;
                let pitch = pitch_um.unwrap_or(l / n as f64);
                HeightField::random_bumps(n, n, pitch, radius_um, height_um, fill, seed)
                    .map_err(core)
            }
        }
    }
}

/// Samples per axis covering `l` µm: given, or `l / pitch`, or `l / 0.09` rounded up to a
/// multiple of 8.
fn auto_samples(l: f64, pitch_um: Option<f64>, samples: Option<usize>) -> usize {
    samples.unwrap_or_else(|| match pitch_um {
        Some(p) => (l / p).ceil().max(1.0) as usize,
        None => ((l / AUTO_PITCH_UM / 8.0).ceil() as usize).max(1) * 8,
    })
}

/// Where a height field comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum HeightSource {
    /// A synthetic spec.
    Synthetic(SyntheticSpec),
    /// A file.
    File(PathBuf),
}

impl HeightSource {
    /// A synthetic spec when `text` parses as one, else a file path.
    pub fn parse(context: impl Into<Origin>, text: &str) -> Result<Self> {
        Ok(match SyntheticSpec::parse(context, text)? {
            Some(s) => HeightSource::Synthetic(s),
            None => HeightSource::File(PathBuf::from(text)),
        })
    }

    /// Builds the field (see [`SyntheticSpec::generate`], [`read_height_field`]); a file
    /// needs `pitch_um` (named by `pitch_context` in the error).
    #[allow(clippy::too_many_arguments)]
    pub fn load(
        &self,
        context: &Origin,
        pitch_context: &Origin,
        coherence_diameter_um: f64,
        pitch_um: Option<f64>,
        samples: Option<usize>,
        height_scale_um: f64,
    ) -> Result<HeightField> {
        match self {
            HeightSource::Synthetic(s) => {
                s.generate(context, coherence_diameter_um, pitch_um, samples)
            }
            HeightSource::File(path) => {
                let pitch = pitch_um.ok_or_else(|| {
                    Error::invalid(
                        path.display().to_string(),
                        msg![
                            "a height-field file needs its sample pitch in µm (",
                            pitch_context.clone(),
                            ")"
                        ],
                    )
                })?;
                read_height_field(path, pitch, height_scale_um)
            }
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeightField {
    synthetic: Option<Spanned<String>>,
    file: Option<Spanned<String>>,
    samples: Option<Spanned<usize>>,
    pitch_um: Option<Spanned<f64>>,
    height_scale_um: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDiffraction {
    layout: Option<Spanned<String>>,
    coherence_diameter_um: Option<Spanned<f64>>,
    wavelengths: Option<Spanned<String>>,
    max_angle_deg: Option<Spanned<f64>>,
    taylor_tolerance: Option<Spanned<f64>>,
    integrated_samples: Option<Spanned<i64>>,
    integrated_gamma: Option<Spanned<f64>>,
    integrated_tolerance: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDiffractionRecipe {
    #[allow(dead_code)] // checked before the full parse
    kind: Spanned<String>,
    description: Option<String>,
    colour: Option<toml::Value>,
    height_field: Spanned<RawHeightField>,
    diffraction: Option<RawDiffraction>,
}

impl DiffractionRecipe {
    /// Parses and validates a recipe: reads or generates the height field, chooses N and
    /// checks the sampling (nothing is transformed yet). `colorimeter` and `name` come from
    /// the shared `[colour]` parsing of [`crate::recipe`].
    pub fn parse(
        path: &Path,
        text: String,
        name: String,
        colorimeter: Colorimeter,
    ) -> Result<Self> {
        let raw: RawDiffractionRecipe =
            toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let _ = &raw.colour;
        let at = |span: std::ops::Range<usize>| {
            format!("{}:{}", path.display(), line_of(&text, span.start))
        };
        let bad = |span: std::ops::Range<usize>, message: String| {
            Error::recipe(path.to_path_buf(), line_of(&text, span.start), message)
        };
        let d = raw.diffraction.unwrap_or(RawDiffraction {
            layout: None,
            coherence_diameter_um: None,
            wavelengths: None,
            max_angle_deg: None,
            taylor_tolerance: None,
            integrated_samples: None,
            integrated_gamma: None,
            integrated_tolerance: None,
        });
        let integrated_layout = match d.layout.as_ref().map(|l| (l, l.get_ref().as_str())) {
            None | Some((_, "terms")) => false,
            Some((_, "integrated")) => true,
            Some((l, other)) => {
                return Err(bad(
                    l.span(),
                    format!("layout = \"{other}\": expected \"terms\" or \"integrated\""),
                ));
            }
        };
        if !integrated_layout {
            for (key, span) in [
                (
                    "integrated_samples",
                    d.integrated_samples.as_ref().map(Spanned::span),
                ),
                (
                    "integrated_gamma",
                    d.integrated_gamma.as_ref().map(Spanned::span),
                ),
                (
                    "integrated_tolerance",
                    d.integrated_tolerance.as_ref().map(Spanned::span),
                ),
            ] {
                if let Some(span) = span {
                    return Err(bad(
                        span,
                        format!("{key} applies to layout = \"integrated\" only"),
                    ));
                }
            }
        }
        let positive = |v: &Option<Spanned<f64>>, default: f64, what: &str| -> Result<f64> {
            match v {
                None => Ok(default),
                Some(s) if *s.get_ref() > 0.0 && s.get_ref().is_finite() => Ok(*s.get_ref()),
                Some(s) => Err(bad(
                    s.span(),
                    format!("{what} = {}: must be finite and positive", s.get_ref()),
                )),
            }
        };
        let coherence = positive(
            &d.coherence_diameter_um,
            DEFAULT_COHERENCE_DIAMETER_UM,
            "coherence_diameter_um",
        )?;
        let (wl_context, wl_text) = match &d.wavelengths {
            Some(s) => (format!("{} wavelengths", at(s.span())), s.get_ref().clone()),
            None => ("wavelengths".into(), "380:780:5".into()),
        };
        let wavelengths = crate::commands::grid::parse_range(wl_context.clone(), &wl_text)?;
        SpectralGrid::new(&colorimeter, &wavelengths)
            .map_err(|source| Error::optics_in(wl_context.clone(), source))?;
        let max_angle = match &d.max_angle_deg {
            None => 45.0,
            Some(s) if *s.get_ref() > 0.0 && *s.get_ref() < 90.0 => *s.get_ref(),
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!("max_angle_deg = {}: expected (0, 90)", s.get_ref()),
                ));
            }
        };
        let tolerance = match &d.taylor_tolerance {
            None => 1e-4,
            Some(s) if *s.get_ref() > 0.0 && *s.get_ref() < 1.0 => *s.get_ref(),
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!("taylor_tolerance = {}: expected (0, 1)", s.get_ref()),
                ));
            }
        };
        let hf = raw.height_field.get_ref();
        let (source_span, source_text, source) = match (&hf.synthetic, &hf.file) {
            (Some(s), None) => {
                let spec = SyntheticSpec::parse(format!("{} synthetic", at(s.span())), s.get_ref())?
                    .ok_or_else(|| bad(s.span(), format!("synthetic = \"{}\": expected sine:PERIOD_UM:AMPLITUDE_UM, blazed:PERIOD_UM:HEIGHT_UM, cd[:SEED] or bumps:RADIUS_UM:HEIGHT_UM:FILL[:SEED]", s.get_ref())))?;
                (s.span(), s.get_ref().clone(), HeightSource::Synthetic(spec))
            }
            (None, Some(f)) => {
                let p = Path::new(f.get_ref());
                let full = match path.parent() {
                    Some(dir) if p.is_relative() => dir.join(p),
                    _ => p.to_path_buf(),
                };
                (f.span(), f.get_ref().clone(), HeightSource::File(full))
            }
            _ => {
                return Err(bad(
                    raw.height_field.span(),
                    "[height_field] needs exactly one of `synthetic` and `file`".into(),
                ));
            }
        };
        let pitch = match &hf.pitch_um {
            None => None,
            Some(s) if *s.get_ref() > 0.0 && s.get_ref().is_finite() => Some(*s.get_ref()),
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!("pitch_um = {}: must be finite and positive", s.get_ref()),
                ));
            }
        };
        let samples = match &hf.samples {
            None => None,
            Some(s) if (1..=MAX_AXIS).contains(s.get_ref()) => Some(*s.get_ref()),
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!("samples = {}: expected 1 to {MAX_AXIS}", s.get_ref()),
                ));
            }
        };
        let scale = positive(&hf.height_scale_um, 1.0, "height_scale_um")?;
        if matches!(source, HeightSource::Synthetic(_)) && hf.height_scale_um.is_some() {
            return Err(bad(
                raw.height_field.span(),
                "height_scale_um applies to `file` only".into(),
            ));
        }
        let field = source.load(
            &at(source_span.clone()).into(),
            &format!("{} pitch_um", at(raw.height_field.span())).into(),
            coherence,
            pitch,
            samples,
            scale,
        )?;
        let mut record = plan(
            &field,
            &source_text,
            coherence,
            &wavelengths,
            max_angle,
            tolerance,
        )
        .map_err(|source| Error::optics_in(at(source_span), source))?;
        if integrated_layout {
            let settings = crate::kinds::diffraction_integrated::IntegratedSettings::parse(
                &bad,
                d.integrated_samples.as_ref(),
                d.integrated_gamma.as_ref(),
                d.integrated_tolerance.as_ref(),
                record.taylor_order,
            )?;
            record.layout = "integrated".into();
            record.integrated = Some(settings.record(&record));
        } else if record.f32_rounding_bound > tolerance {
            return Err(Error::invalid(
                path.display().to_string(),
                format!(
                    "max |k w h| = {:.3}: the Taylor sum of f32 terms could err by {:.2e} (2^-24 e^{{|kwh|}}), above taylor_tolerance {tolerance:e}; the structure is too tall for a terms table at {} nm",
                    record.max_phase, record.f32_rounding_bound, record.wavelength_min_nm
                ),
            ));
        }
        Ok(DiffractionRecipe {
            name,
            path: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            colorimeter,
            source_text,
            field,
            record,
            wavelengths_nm: wavelengths,
            text,
        })
    }

    /// Computes the terms and writes `NAME.terms.exr`, `NAME.terms.ktx2` and `NAME.json`
    /// (layout "integrated": [`crate::kinds::diffraction_integrated::bake`]); returns the
    /// manifest path.
    pub fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        if self.record.integrated.is_some() {
            return crate::kinds::diffraction_integrated::bake(self, out_dir, progress);
        }
        let terms = TaylorTerms::compute(&self.field, self.record.taylor_order);
        progress();
        // Every file goes to a staging folder first; `commit` moves them into `out_dir`,
        // the manifest last (nacre_format::stage::StagedTable).
        let stage = nacre_format::stage::StagedTable::new(out_dir)?;
        let r = &self.record;
        let c = &self.colorimeter;
        let layers = r.taylor_order + 1;
        let mut manifest = Manifest {
            colour_convention: format!(
                "relative reflectance rho = F^2 G/w^2 |P~|^2 (1 for a flat perfect mirror in its specular direction); colour = M * sum over the wavelength grid {}:{}:{} nm of rho(lambda) u(lambda), u the CIE XYZ weights of observer {} under illuminant {} rescaled so that rho = 1 gives the illuminant white, M the matrix to linear {} (Bradford adapted; rho = 1 is (1, 1, 1))",
                r.wavelength_min_nm, r.wavelength_max_nm, r.wavelength_step_nm, c.observer(), c.illuminant(), c.space()
            ),
            axes: vec![
                AxisRecord {
                    name: "kappa_x".into(),
                    unit: "rad/um".into(),
                    count: r.nx,
                    min: -2.0 * std::f64::consts::PI * (r.nx / 2) as f64 / r.patch_um[0],
                    max: 2.0 * std::f64::consts::PI * (r.nx as f64 - 1.0 - (r.nx / 2) as f64) / r.patch_um[0],
                    mapping: "DFT bins, DC centred".into(),
                    forward: format!("s = round(kappa_x * {} / (2 pi)) + {}", r.patch_um[0], r.nx / 2),
                    inverse: format!("kappa_x = 2 pi (s - {}) / {}", r.nx / 2, r.patch_um[0]),
                },
                AxisRecord {
                    name: "kappa_y".into(),
                    unit: "rad/um".into(),
                    count: r.ny,
                    min: -2.0 * std::f64::consts::PI * (r.ny / 2) as f64 / r.patch_um[1],
                    max: 2.0 * std::f64::consts::PI * (r.ny as f64 - 1.0 - (r.ny / 2) as f64) / r.patch_um[1],
                    mapping: "DFT bins, DC centred".into(),
                    forward: format!("t = round(kappa_y * {} / (2 pi)) + {}", r.patch_um[1], r.ny / 2),
                    inverse: format!("kappa_y = 2 pi (t - {}) / {}", r.ny / 2, r.patch_um[1]),
                },
                AxisRecord {
                    name: "taylor_term".into(),
                    unit: "1".into(),
                    count: layers,
                    min: 0.0,
                    max: r.taylor_order as f64,
                    mapping: "term index n".into(),
                    forward: "n".into(),
                    inverse: "n".into(),
                },
            ],
            texel_centres: "texel (s, t) holds the DFT bin of frequency kappa = 2 pi (s - floor(nx/2), t - floor(ny/2)) / L exactly (integer texel loads; no filtering)".into(),
            atlas: format!(
                "EXR: width nx = {}, height ny * (N + 1) = {} * {}; term n occupies rows [n ny, (n + 1) ny), R = Re T_n, G = Im T_n, B = 0, full float. KTX2: 2-D array RGBA32F texture nx x ny with ceil((N + 1) / 2) = {} layers, layer l = (Re T_2l, Im T_2l, Re T_2l+1, Im T_2l+1), zero beyond T_N",
                r.nx, r.ny, layers, layers.div_ceil(2)
            ),
            reconstruction: format!(
                "k = 2 pi / lambda; (u, v, w) = -omega_i - omega_r; P_j = sum_n (k w)^n / n! T_n[j]; P~ = sum over bins j near (k u, k v) L / (2 pi) of P_j exp(-sigma_s^2 |(k u, k v) - kappa_j|^2 / 2), sigma_s = {} um; rho = F^2 (1 + omega_i.omega_r)^2 / (cos_i cos_r (cos_i + cos_r)^2) |P~|^2 (Stam 1999; Dhillon et al. 2014); colour as colour_convention",
                r.sigma_s_um
            ),
            files: Vec::new(),
            ..Manifest::for_recipe(
                KindRecord::Diffraction(Box::new(r.clone())),
                &self.name,
                &self.description,
                &self.path,
                &self.text,
                c,
            )
        };
        let embedded = manifest.embedded_json();
        let mut table = Table3::new(r.nx, r.ny, layers);
        let layer_data: Vec<Vec<C64>> = (0..layers).map(|n| terms.layer(n)).collect();
        for (n, layer) in layer_data.iter().enumerate() {
            for (i, v) in layer.iter().enumerate() {
                table.set(i % r.nx, i / r.nx, n, [v.re as f32, v.im as f32, 0.0]);
            }
        }
        let exr = format!("{}.terms.exr", self.name);
        let ktx2 = format!("{}.terms.ktx2", self.name);
        let files = vec![
            stage.write_exr(&exr, "terms", &table, Precision::Float)?,
            stage.write_ktx2(
                &ktx2,
                "terms",
                &terms_image(&layer_data, r.nx, r.ny, &embedded),
            )?,
        ];
        manifest.files = files;
        Ok(stage.commit_manifest(&manifest, &[])?)
    }
}

/// The KTX2 image of the terms (module docs).
fn terms_image(
    layers: &[Vec<C64>],
    nx: usize,
    ny: usize,
    manifest_json: &str,
) -> nacre_format::ktx2::Ktx2Image {
    let pairs = layers.len().div_ceil(2);
    let mut level = Vec::with_capacity(pairs * nx * ny * 16);
    for l in 0..pairs {
        for i in 0..nx * ny {
            let a = layers[2 * l][i];
            let b = layers.get(2 * l + 1).map_or(C64::new(0.0, 0.0), |t| t[i]);
            for v in [a.re, a.im, b.re, b.im] {
                level.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
    }
    let nul = |s: &str| {
        let mut v = s.as_bytes().to_vec();
        v.push(0);
        v
    };
    nacre_format::ktx2::Ktx2Image {
        format: nacre_format::ktx2::Ktx2Format::Rgba32Float,
        width: nx as u32,
        height: ny as u32,
        depth: 0,
        layers: pairs as u32,
        levels: vec![level],
        key_values: vec![
            (
                nacre_format::ktx2::WRITER_KEY.into(),
                nul(&format!("nacre {}", env!("CARGO_PKG_VERSION"))),
            ),
            (nacre_format::ktx2::MANIFEST_KEY.into(), nul(manifest_json)),
        ],
    }
}

/// Chooses N and checks the sampling for a field; the record of a terms table.
///
/// # Errors
/// The core's [`nacre_optics::Error::TaylorOrder`], `PatchTooSmall` or `NyquistExceeded`.
pub fn plan(
    field: &HeightField,
    source: &str,
    coherence_diameter_um: f64,
    wavelengths_nm: &[f64],
    max_angle_deg: f64,
    tolerance: f64,
) -> nacre_optics::Result<DiffractionRecord> {
    let wl_min = wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min);
    let wl_max = wavelengths_nm
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let max_phase = nacre_optics::diffraction::max_phase(field, wl_min, 2.0);
    let (order, bound) = taylor_order_for(max_phase, tolerance)?;
    let sigma_s_um = coherence_diameter_um / 4.0;
    let max_uv = 2.0 * elementary::sin(max_angle_deg.to_radians());
    // The checks need only the geometry: a one-term surface suffices.
    let probe = DiffractionSurface::new(
        TaylorTerms::from_terms(
            field.nx(),
            field.ny(),
            field.pitch_um(),
            &[vec![C64::new(0.0, 0.0); field.nx() * field.ny()]],
        )?,
        sigma_s_um,
    )?;
    probe.check_sampling(wl_min, max_uv)?;
    let (lx, ly) = field.patch_um();
    Ok(DiffractionRecord {
        layout: "terms".into(),
        source: source.to_string(),
        nx: field.nx(),
        ny: field.ny(),
        pitch_um: field.pitch_um(),
        patch_um: [lx, ly],
        mean_removed_um: field.mean_removed_um(),
        max_abs_height_um: field.max_abs_height_um(),
        coherence_diameter_um,
        sigma_s_um,
        wavelength_min_nm: wl_min,
        wavelength_max_nm: wl_max,
        wavelength_step_nm: if wavelengths_nm.len() > 1 {
            wavelengths_nm[1] - wavelengths_nm[0]
        } else {
            0.0
        },
        max_angle_deg,
        max_uv,
        taylor_order: order,
        taylor_tolerance: tolerance,
        max_phase,
        taylor_bound: bound,
        f32_rounding_bound: f64::from(f32::EPSILON) * 0.5 * elementary::exp(max_phase),
        dc_texel: [field.nx() / 2, field.ny() / 2],
        sign_convention: SIGN_CONVENTION.into(),
        integrated: None,
    })
}

/// The registry entry of `diffraction` ([`crate::kinds::REGISTRY`]).
pub const ENTRY: KindEntry = KindEntry {
    kind: TableKind::DIFFRACTION,
    parse: |path, text| {
        #[derive(Deserialize)]
        struct ColourOnly {
            colour: Option<RawColour>,
        }
        let c: ColourOnly = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let colorimeter = parse_colour(path, &text, c.colour)?;
        let name = table_name(path)?;
        Ok(Box::new(DiffractionRecipe::parse(
            path,
            text,
            name,
            colorimeter,
        )?))
    },
    start_rank: 1,
};

impl TableRecipe for DiffractionRecipe {
    fn kind(&self) -> TableKind {
        TableKind::DIFFRACTION
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn work(&self) -> u64 {
        1
    }

    fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        DiffractionRecipe::bake(self, out_dir, progress)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Param;

    #[test]
    fn specs_parse_and_name_the_flag() {
        assert_eq!(
            SyntheticSpec::parse(Param::Surface, "sine:1.6:0.05").unwrap(),
            Some(SyntheticSpec::Sine {
                period_um: 1.6,
                amplitude_um: 0.05
            })
        );
        assert_eq!(
            SyntheticSpec::parse(Param::Surface, "cd").unwrap(),
            Some(SyntheticSpec::Cd { seed: 1 })
        );
        assert_eq!(
            SyntheticSpec::parse(Param::Surface, "bumps:0.5:0.1:0.3:9").unwrap(),
            Some(SyntheticSpec::Bumps {
                radius_um: 0.5,
                height_um: 0.1,
                fill: 0.3,
                seed: 9
            })
        );
        assert_eq!(
            SyntheticSpec::parse(Param::Surface, "snake.png").unwrap(),
            None
        );
        for bad in [
            "sine:0:0.1",
            "sine:1.6",
            "blazed:a:1",
            "cd:-1",
            "bumps:1:1",
            "sine:1:-0.1",
        ] {
            let e = SyntheticSpec::parse(Param::Surface, bad)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("surface `"), "{bad}: {e}");
        }
    }

    fn recipe(dir: &Path, name: &str, text: &str) -> Result<Box<dyn crate::kinds::TableRecipe>> {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        crate::kinds::read_recipe(&path)
    }

    #[test]
    fn recipes_bake_terms_and_refuse_bad_sampling() {
        let dir = tempfile::tempdir().unwrap();
        let good = "kind = \"diffraction\"\n[height_field]\nsynthetic = \"sine:1.6:0.05\"\n[diffraction]\ncoherence_diameter_um = 16.0\nmax_angle_deg = 60.0\n";
        let r = recipe(dir.path(), "sine.toml", good).unwrap();
        let out = dir.path().join("out");
        let manifest_path = r.bake(&out, &|| {}).unwrap();
        let m = Manifest::read(&manifest_path).unwrap();
        assert_eq!(m.kind, TableKind::DIFFRACTION);
        let (record, terms) = m.load_diffraction(&manifest_path).unwrap();
        assert_eq!((record.nx, record.ny), (terms.size().0, 1));
        assert!(record.taylor_bound <= 1e-4);
        assert_eq!(record.patch_um[0], 16.0);
        // The stored terms are the f64 terms rounded to f32.
        let field = HeightField::sine_grating(1.6, 0.05, 0.04, 400).unwrap();
        let exact = TaylorTerms::compute(&field, record.taylor_order);
        for n in 0..=record.taylor_order {
            for (a, b) in terms.layer(n).iter().zip(exact.layer(n)) {
                assert_eq!((a.re as f32, a.im as f32), (b.re as f32, b.im as f32));
            }
        }
        assert_eq!(terms.bin(0, 0, 0), Some(C64::new(1.0, 0.0)));
        // Bad sampling: clear errors naming the recipe.
        let e = recipe(
            dir.path(),
            "coarse.toml",
            &good.replace("[diffraction]", "pitch_um = 0.2\n[diffraction]"),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("coarse.toml:3") && e.contains("Nyquist"), "{e}");
        let e = recipe(
            dir.path(),
            "small.toml",
            "kind = \"diffraction\"\n[height_field]\nsynthetic = \"cd\"\nsamples = 64\npitch_um = 0.1\n",
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("small.toml:3") && e.contains("coherence diameter"),
            "{e}"
        );
        let e = recipe(
            dir.path(),
            "layout.toml",
            &good.replace("[diffraction]", "[diffraction]\nlayout = \"spectral\""),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("layout.toml:5") && e.contains("\"integrated\""),
            "{e}"
        );
        let e = recipe(
            dir.path(),
            "keys.toml",
            &good.replace("[diffraction]", "[diffraction]\nintegrated_samples = 64"),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("keys.toml:5") && e.contains("integrated_samples"),
            "{e}"
        );
        assert!(
            m.load_diffraction_integrated(&manifest_path)
                .unwrap_err()
                .to_string()
                .contains("\"terms\"")
        );
        let e = recipe(
            dir.path(),
            "file.toml",
            "kind = \"diffraction\"\n[height_field]\nfile = \"h.csv\"\n",
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("pitch_um"), "{e}");
    }
}
