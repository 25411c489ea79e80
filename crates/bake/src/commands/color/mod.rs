//! `nacre color`: the colour of a stack's reflectance or transmittance by a chosen method.
//!
//! Methods ([`Method`]):
//!
//! * `spectral` — the reference: exact spectral integration
//!   ([`nacre_optics::SpectralRule::for_stack`], which resolves the fringes at the stack's
//!   finesse: within ΔE2000 0.01 of a converged brute-force integration for films up to
//!   10 µm of index 1.0–2.5 at 0–89.9° on the bundled materials and constant indices n 1–3,
//!   κ 0–5; test `spectral_finesse` of nacre-optics);
//! * `lut:NAME|PATH` — a baked `film-lut` table, with the trilinear interpolation the GPU
//!   uses ([`nacre_format::film_lut::FilmLut::lookup`]); the table must have been baked for the
//!   same ambient, base and fixed layers, and its colour settings are used;
//! * `rgb3` — one wavelength per channel (R at 650, 510 and 475 nm, taken as linear RGB of
//!   the output space): the common real-time shortcut;
//! * `samples:N` — N wavelengths spread uniformly over 400–700 nm (inclusive), weighted by
//!   the output-space sensitivities there and normalised so that R ≡ 1 is white: the
//!   shortcut of the real-time thesis (Sussenbach 2013, §4.3);
//! * `fourier` (= `fourier:auto`, the default), `fourier:M`, `fourier:M:SIGMA_NM`,
//!   `fourier:auto:SIGMA_NM` — Belcour & Barla 2017 Eq. 10 with exact Fresnel amplitudes and
//!   phases per polarisation and the sensitivities' Fourier transforms sampled from the baked
//!   `fourier` table as a GPU would (`fourier-exact…`: evaluated exactly,
//!   [`nacre_optics::fourier`]), with M harmonics or, by default, as many as each point needs
//!   ([`Harmonics::Auto`]: the series' decay |ρ|^m times the transforms' |Ŝ(mD)| against a
//!   tolerance tuned to ΔE2000 p95 ≤ 0.1), optionally prefiltered for a Gaussian thickness
//!   distribution of standard deviation SIGMA_NM (one film on a base);
//! * `rough-lut:NAME|PATH` (with a roughness α) — the directional albedo of the rough
//!   (GGX) iridescent lobe from a baked `rough-film-lut` table, looked up as the shader does
//!   ([`nacre_format::rough_film_lut::RoughFilmLut::lookup`]); `rough-mc[:N]` — the Monte Carlo reference
//!   for the same albedo ([`nacre_optics::microfacet::directional_albedo_with`], N
//!   visible-normal samples per point, default [`ROUGH_MC_SAMPLES`], seed = the point's index);
//! * `gaussian` — the Gaussian-fit closed form with Schlick Fresnel and m ≤ 2 of glTF's
//!   `KHR_materials_iridescence` reference code, for comparison (the base enters through its
//!   normal-incidence reflectance; the fit ignores `--illuminant`).
//!
//! Output columns: `angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B` (XYZ under the illuminant
//! with a perfect reflector at Y = 1; R, G, B linear in the output space, equal to X, Y, Z
//! for `--space xyz`).

use crate::commands::spectrum::fmt_sig;
use crate::error::{Error, Origin, Param, Result};
use nacre_format::Manifest;
use nacre_format::film_lut::FilmLut;
use nacre_format::fourier::FourierTable;
use nacre_format::msg;
use nacre_format::set::resolve_table;
use nacre_format::table_io::Table3;
use nacre_optics::colour::{Colorimeter, OutputSpace, RgbSpace};
use nacre_optics::elementary;
use nacre_optics::few_wavelengths::StackEvaluation;
use nacre_optics::fourier::{FilmOnBase, Harmonics, gltf_iridescence};
use nacre_optics::spectral::sample_weights;
use nacre_optics::{C64, Layer, Material, SpectralRule, Stack, Undersampled};
use rayon::prelude::*;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod points;

pub use points::{Point, PointProblem, parse_points};

/// The CSV header line.
pub const HEADER: &str = "angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B";

/// Most points one run may evaluate.
pub const MAX_POINTS: usize = 10_000_000;

/// Default Monte Carlo samples per point of `rough-mc` (standard error ≈ 1e-5–2e-4 per
/// channel, see [`nacre_optics::microfacet`]).
pub const ROUGH_MC_SAMPLES: usize = 1 << 20;

/// The wavelengths of the `rgb3` shortcut, nm (R, G, B).
pub const RGB3_WAVELENGTHS_NM: [f64; 3] = [650.0, 510.0, 475.0];

/// How to turn a stack into colour.
#[derive(Clone, Debug, PartialEq)]
pub enum Method {
    /// Exact spectral integration (the reference).
    Spectral,
    /// A baked film LUT (manifest path).
    Lut(PathBuf),
    /// One wavelength per channel.
    Rgb3,
    /// N wavelengths over 400–700 nm.
    Samples(usize),
    /// Belcour & Barla 2017 Eq. 10 with exact Fresnel terms, prefiltered for a Gaussian
    /// thickness distribution of the given standard deviation (nm, 0 for none), with the
    /// sensitivities' transforms sampled from a baked `fourier` table as a GPU would, or
    /// computed exactly when the table is None (`fourier-exact:`).
    Fourier(Harmonics, f64, Option<Arc<FourierTable>>),
    /// The Gaussian-fit closed form of glTF's `KHR_materials_iridescence`.
    GaussianFitBelcour2017,
    /// Directional albedo of the rough iridescent GGX lobe from a baked `rough-film-lut`
    /// (manifest path) at roughness `alpha` (NaN until set with [`Method::with_roughness`]),
    /// the table loaded by the caller.
    RoughLut {
        /// Manifest path.
        path: PathBuf,
        /// GGX roughness α.
        alpha: f64,
        /// The loaded table.
        table: Option<Arc<RoughTable>>,
    },
    /// The Monte Carlo reference of the same albedo: `samples` visible-normal samples per
    /// point at roughness `alpha` (NaN until set).
    RoughMonteCarlo {
        /// GGX roughness α.
        alpha: f64,
        /// Samples per point.
        samples: usize,
    },
    /// The real-time multilayer evaluation of the GPU technique `film_stack`
    /// ([`nacre_optics::few_wavelengths::StackEvaluation`]): the few-wavelength rule ladder,
    /// its count chosen from the stack's OPD (`stack`), or a fixed rule of N nodes
    /// (`stack:N`).
    Stack(Option<usize>),
}

/// A loaded `rough-film-lut` table.
pub type RoughTable = nacre_format::load::LoadedRoughLut;

impl Method {
    /// True for the methods that need a roughness (`rough-lut:`, `rough-mc`).
    pub fn is_rough(&self) -> bool {
        matches!(
            self,
            Method::RoughLut { .. } | Method::RoughMonteCarlo { .. }
        )
    }

    /// The method with GGX roughness `alpha` (for `rough-lut:` and `rough-mc`; others are
    /// returned unchanged).
    pub fn with_roughness(self, alpha: f64) -> Self {
        match self {
            Method::RoughLut { path, table, .. } => Method::RoughLut { path, alpha, table },
            Method::RoughMonteCarlo { samples, .. } => Method::RoughMonteCarlo { alpha, samples },
            m => m,
        }
    }
}

impl Method {
    /// Parses `spectral`, `lut:NAME|PATH`, `rgb3`, `samples:N`.
    pub fn parse(text: &str) -> Result<Self> {
        let err = |message: &str| Error::value(Param::Method, text, message);
        match text.trim() {
            "spectral" => Ok(Method::Spectral),
            "rgb3" => Ok(Method::Rgb3),
            "gaussian" => Ok(Method::GaussianFitBelcour2017),
            t => {
                if let Some(name) = t.strip_prefix("rough-lut:") {
                    if name.is_empty() {
                        return Err(err(
                            "expected rough-lut:NAME or rough-lut:PATH/TO/MANIFEST.json",
                        ));
                    }
                    Ok(Method::RoughLut {
                        path: resolve_table(name),
                        alpha: f64::NAN,
                        table: None,
                    })
                } else if t == "rough-mc" || t.starts_with("rough-mc:") {
                    let samples = match t.strip_prefix("rough-mc:") {
                        None => ROUGH_MC_SAMPLES,
                        Some(n) => match n.parse::<usize>() {
                            Ok(n @ 1..=1_073_741_824) => n,
                            _ => {
                                return Err(err(
                                    "rough-mc:N needs a whole number of samples N from 1 to 2^30",
                                ));
                            }
                        },
                    };
                    Ok(Method::RoughMonteCarlo {
                        alpha: f64::NAN,
                        samples,
                    })
                } else if let Some(name) = t.strip_prefix("lut:") {
                    if name.is_empty() {
                        return Err(err("expected lut:NAME or lut:PATH/TO/MANIFEST.json"));
                    }
                    Ok(Method::Lut(resolve_table(name)))
                } else if t == "stack" {
                    Ok(Method::Stack(None))
                } else if let Some(n) = t.strip_prefix("stack:") {
                    match n.parse::<usize>() {
                        Ok(n @ 1..=256) => Ok(Method::Stack(Some(n))),
                        _ => Err(err("stack:N needs a whole number N from 1 to 256")),
                    }
                } else if let Some(n) = t.strip_prefix("samples:") {
                    match n.parse::<usize>() {
                        Ok(n @ 1..=10_000) => Ok(Method::Samples(n)),
                        _ => Err(err("samples:N needs a whole number N from 1 to 10000")),
                    }
                } else if t == "fourier" || t == "fourier-exact" {
                    // The default: as many harmonics as each point needs.
                    Ok(Method::Fourier(Harmonics::Auto, 0.0, None))
                } else if let Some(rest) = t
                    .strip_prefix("fourier:")
                    .or_else(|| t.strip_prefix("fourier-exact:"))
                {
                    let bad = || {
                        err(
                            "expected fourier, fourier:M, fourier:auto, fourier:M:SIGMA_NM or fourier:auto:SIGMA_NM (M from 1 to 512, SIGMA_NM ≥ 0), or fourier-exact with the same forms",
                        )
                    };
                    let (m, sigma) = match rest.split_once(':') {
                        Some((m, s)) => (
                            m,
                            s.parse::<f64>()
                                .ok()
                                .filter(|v| *v >= 0.0 && v.is_finite())
                                .ok_or_else(bad)?,
                        ),
                        None => (rest, 0.0),
                    };
                    let harmonics = match m {
                        "auto" => Harmonics::Auto,
                        m => match m.parse::<usize>() {
                            Ok(m @ 1..=512) => Harmonics::Fixed(m),
                            _ => return Err(bad()),
                        },
                    };
                    Ok(Method::Fourier(harmonics, sigma, None))
                } else {
                    Err(err(
                        "expected spectral, lut:NAME|PATH, rgb3, samples:N, fourier, fourier:M[:SIGMA_NM], fourier:auto[:SIGMA_NM], fourier-exact…, gaussian, rough-lut:NAME|PATH, rough-mc[:N], stack or stack:N",
                    ))
                }
            }
        }
    }
}

/// Reflectance or transmittance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Unpolarised reflectance.
    Reflectance,
    /// Unpolarised transmittance into the base.
    Transmittance,
}

/// The stack with the first film's thickness and index overridden by `point`.
fn stack_at(stack: &Stack, point: &Point) -> Result<Stack> {
    let mut layers = stack.layers().to_vec();
    if let Some(first) = layers.first_mut() {
        if let Some(d) = point.thickness_nm {
            first.thickness_nm = d;
        }
        if let Some(n) = point.film_ior {
            first.material = Material::constant(format!("{n}"), C64::new(n, 0.0))?;
        }
    } else if point.thickness_nm.is_some() || point.film_ior.is_some() {
        return Err(Error::invalid(
            Param::Points,
            msg![
                "the stack has no film to override: give at least one ",
                Param::Layer
            ],
        ));
    }
    Ok(
        Stack::new(stack.ambient().clone(), layers, stack.substrate().clone())?
            .with_incoherent(stack.incoherent_flags())?,
    )
}

/// The (thickness, real index) a point has for the first film, for the output columns.
pub fn film_columns(stack: &Stack, point: &Point) -> (f64, f64) {
    match stack.layers().first() {
        Some(l) => (
            point.thickness_nm.unwrap_or(l.thickness_nm),
            point
                .film_ior
                .unwrap_or_else(|| l.material.index_at(550.0).map_or(f64::NAN, |n| n.re)),
        ),
        None => (
            0.0,
            stack.ambient().index_at(550.0).map_or(f64::NAN, |n| n.re),
        ),
    }
}

fn value(p: &nacre_optics::Power, quantity: Quantity) -> f64 {
    match quantity {
        Quantity::Reflectance => p.R(),
        Quantity::Transmittance => p.T(),
    }
}

/// A loaded LUT with what is needed to check and use it.
pub struct LoadedLut {
    /// The manifest.
    pub manifest: Manifest,
    /// Reflectance table.
    pub reflectance: Table3,
    /// Transmittance table, if baked.
    pub transmittance: Option<Table3>,
    /// The table's colorimeter.
    pub colorimeter: Colorimeter,
}

impl LoadedLut {
    /// Loads a table through its manifest.
    pub fn load(path: &Path) -> Result<Self> {
        let manifest = Manifest::read(path)?;
        if manifest.film_lut().is_none() {
            return Err(Error::invalid(
                path.display().to_string(),
                format!(
                    "table `{}` is a `{}` table, not a film-lut",
                    manifest.name, manifest.kind
                ),
            ));
        }
        let reflectance = manifest.load_table(path, "reflectance")?.ok_or_else(|| {
            Error::invalid(
                path.display().to_string(),
                "the manifest lists no reflectance EXR or KTX2 file",
            )
        })?;
        let transmittance = manifest.load_table(path, "transmittance")?;
        let colorimeter = manifest.colorimeter(path)?;
        Ok(LoadedLut {
            manifest,
            reflectance,
            transmittance,
            colorimeter,
        })
    }

    /// Errors unless `stack` (film first) matches the table's ambient, fixed layers and base.
    pub fn check_stack(&self, path: &Path, stack: &Stack) -> Result<()> {
        check_stack_matches(&self.manifest, path, stack, "lut")
    }

    /// Colour at a point (output space of the table).
    pub fn colour(&self, stack: &Stack, point: &Point, quantity: Quantity) -> Result<[f64; 3]> {
        let film = stack.layers().first().ok_or_else(|| {
            Error::invalid(
                Param::Method.given("lut"),
                msg!["a film-lut needs a film: give ", Param::Layer],
            )
        })?;
        let n = match point.film_ior {
            Some(n) => n,
            None => {
                let n = film.material.index_at(550.0)?;
                if !film.material.is_constant() || n.im != 0.0 {
                    return Err(Error::invalid(
                        Param::Method.given("lut"),
                        msg![
                            format!(
                                "a film-lut takes a constant real film index; `{}` is dispersive or absorbing (give ",
                                film.material.name()
                            ),
                            Param::Points,
                            " with film_ior)"
                        ],
                    ));
                }
                n.re
            }
        };
        let d = point.thickness_nm.unwrap_or(film.thickness_nm);
        let table = match quantity {
            Quantity::Reflectance => &self.reflectance,
            Quantity::Transmittance => self.transmittance.as_ref().ok_or_else(|| {
                Error::invalid(
                    Param::Quantity.given("t"),
                    format!("table `{}` has no transmittance", self.manifest.name),
                )
            })?,
        };
        let cos_theta = elementary::cos(point.angle_deg.to_radians());
        Ok(FilmLut::lookup(
            self.manifest.film_lut().expect("checked at load"),
            table,
            cos_theta,
            d,
            n,
        ))
    }
}

/// Errors unless `stack` (film first) matches the ambient, fixed layers and base of the
/// table `m` at `path`; `method` (`lut`, `rough-lut`) names the flag in messages.
pub fn check_stack_matches(m: &Manifest, path: &Path, stack: &Stack, method: &str) -> Result<()> {
    let context = Param::Method.given(format!("{method}:{}", path.display()));

    let mismatch = |what: &str, ours: String, theirs: &str| {
        Error::invalid(
            context.clone(),
            format!("the table was baked for {what} `{theirs}`, this stack has `{ours}`"),
        )
    };
    let base_dir = path.parent();
    let same = |a: &Material, spec: &str| -> Result<bool> {
        let b = nacre_format::materials::resolve(spec, context.clone(), base_dir)?;
        Ok((0..=20).all(|i| {
            let wl = 380.0 + 20.0 * f64::from(i);
            match (a.index_at(wl), b.index_at(wl)) {
                (Ok(x), Ok(y)) => elementary::norm(x - y) <= 1e-12,
                _ => false,
            }
        }))
    };
    if !same(stack.ambient(), &m.ambient)? {
        return Err(mismatch(
            "ambient",
            stack.ambient().name().into(),
            &m.ambient,
        ));
    }
    if !same(stack.substrate(), &m.base)? {
        return Err(mismatch("base", stack.substrate().name().into(), &m.base));
    }
    let layers = stack.layers();
    if layers.len() != 1 + m.under.len() {
        return Err(Error::invalid(
            context,
            format!(
                "the table has one film over {} fixed layer(s); this stack has {} layer(s)",
                m.under.len(),
                layers.len()
            ),
        ));
    }
    let slab = |incoherent: bool| if incoherent { ":incoherent" } else { "" };
    for (j, (l, (spec, d))) in layers[1..].iter().zip(&m.under).enumerate() {
        let theirs = m.under_incoherent.get(j) == Some(&true);
        let ours = stack.is_incoherent(j + 2);
        if !same(&l.material, spec)? || (l.thickness_nm - d).abs() > 1e-9 || ours != theirs {
            return Err(mismatch(
                "fixed layer",
                format!("{}@{}{}", l.material.name(), l.thickness_nm, slab(ours)),
                &format!("{spec}@{d}{}", slab(theirs)),
            ));
        }
    }
    if stack.is_incoherent(1) {
        return Err(Error::invalid(
            context,
            "the table's film (layer 1) is coherent; this stack has it incoherent",
        ));
    }
    Ok(())
}

/// The first film's thickness (nm) and constant real index at `point` (the point's own
/// values, else the film's); `context` names the method in errors.
pub fn film_parameters(stack: &Stack, point: &Point, context: &Origin) -> Result<(f64, f64)> {
    let film = stack.layers().first().ok_or_else(|| {
        Error::invalid(
            context.clone(),
            msg!["the method needs a film: give ", Param::Layer],
        )
    })?;
    let n = match point.film_ior {
        Some(n) => n,
        None => {
            let n = film.material.index_at(550.0)?;
            if !film.material.is_constant() || n.im != 0.0 {
                return Err(Error::invalid(
                    context.clone(),
                    msg![
                        format!(
                            "the table takes a constant real film index; `{}` is dispersive or absorbing (give ",
                            film.material.name()
                        ),
                        Param::Points,
                        " with film_ior)"
                    ],
                ));
            }
            n.re
        }
    };
    Ok((point.thickness_nm.unwrap_or(film.thickness_nm), n))
}

/// `rough-mc` at every point: the Monte Carlo directional albedo (reflected or
/// transmitted, per `quantity`) of the GGX lobe with the exact film term of the point's
/// stack, `samples` samples, seed = the point's index. Returns each point's estimate.
pub fn rough_monte_carlo(
    stack: &Stack,
    points: &[Point],
    alpha: f64,
    samples: usize,
    colorimeter: &Colorimeter,
    quantity: Quantity,
) -> Result<Vec<nacre_optics::microfacet::Estimate>> {
    check_roughness(alpha)?;
    points
        .par_iter()
        .enumerate()
        .map(|(i, point)| {
            let s = stack_at(stack, point)?;
            if quantity == Quantity::Transmittance
                && s.substrate()
                    .index_at(nacre_optics::microfacet::REFRACTION_WAVELENGTH_NM)?
                    .im
                    != 0.0
            {
                return Err(Error::invalid(
                    msg![
                        Param::Method.given("rough-mc"),
                        " ",
                        Param::Quantity.given("t")
                    ],
                    "transmittance through a rough interface needs a non-absorbing base",
                ));
            }
            let film = nacre_optics::microfacet::FilmTerm::from_stack(&s, colorimeter)?;
            let cos_theta_o = elementary::cos(point.angle_deg.to_radians());
            let e = nacre_optics::microfacet::directional_albedo_with(
                &film,
                alpha,
                cos_theta_o,
                samples,
                i as u64,
            )?;
            Ok(match quantity {
                Quantity::Reflectance => e.reflection,
                Quantity::Transmittance => e.transmission,
            })
        })
        .collect()
}

fn check_roughness(alpha: f64) -> Result<()> {
    if alpha.is_nan() {
        return Err(Error::invalid(
            Param::Method.given("rough-lut/rough-mc"),
            msg!["needs a roughness: give ", Param::Roughness.arg()],
        ));
    }
    if !(alpha > 0.0 && alpha <= 1.0) {
        return Err(Error::value(
            Param::Roughness,
            alpha.to_string(),
            "GGX roughness α must lie in (0, 1]",
        ));
    }
    Ok(())
}

/// Evaluates `points` of `stack` by `method`; returns output-space colours of `colorimeter`
/// (for `lut:`, of the table's colorimeter).
pub fn evaluate(
    stack: &Stack,
    points: &[Point],
    method: &Method,
    colorimeter: &Colorimeter,
    quantity: Quantity,
    lut: Option<&LoadedLut>,
) -> Result<Vec<[f64; 3]>> {
    if points.len() > MAX_POINTS {
        return Err(nacre_format::Error::TooLarge {
            what: "points".into(),
            count: points.len() as u64,
            limit: MAX_POINTS as u64,
        }
        .into());
    }
    refuse_incoherent(stack, method)?;
    // The stack technique's rules and indices, prepared once for the stack's own films (a
    // point that overrides the top film's index prepares its own).
    let stack_eval = match method {
        Method::Stack(n) => {
            let relative = vec![0.0; stack.layers().len()];
            Some(
                StackEvaluation::new(colorimeter, stack, &relative, *n)
                    .map_err(|e| Error::optics_in(Param::Method.given("stack"), e))?,
            )
        }
        _ => None,
    };
    points
        .par_iter()
        .map(|point| -> Result<[f64; 3]> {
            match method {
                Method::Stack(n) => {
                    let own = stack_eval.as_ref().expect("prepared above");
                    let fresh;
                    let eval = if point.film_ior.is_some() {
                        let s = stack_at(stack, point)?;
                        let relative = vec![0.0; s.layers().len()];
                        fresh = StackEvaluation::new(colorimeter, &s, &relative, *n)
                            .map_err(|e| Error::optics_in(Param::Method.given("stack"), e))?;
                        &fresh
                    } else {
                        own
                    };
                    let angle = point.angle_deg;
                    if !(angle.abs() < 90.0) {
                        return Err(nacre_optics::Error::InvalidAngle { angle_deg: angle }.into());
                    }
                    let top = point.thickness_nm.unwrap_or(stack.layers()[0].thickness_nm);
                    let (r, t) = eval.colour(elementary::cos(angle.to_radians()), top, [0.0; 3]);
                    Ok(match quantity {
                        Quantity::Reflectance => r,
                        Quantity::Transmittance => t,
                    })
                }
                Method::Lut(_) => {
                    let lut = lut.expect("lut loaded by the caller");
                    lut.colour(stack, point, quantity)
                }
                Method::RoughLut { path, alpha, table } => {
                    check_roughness(*alpha)?;
                    let t = match table {
                        Some(t) => t.clone(),
                        None => Arc::new(RoughTable::load(path)?),
                    };
                    let (d, n) = film_parameters(stack, point, &Param::Method.given("rough-lut"))?;
                    let table = match quantity {
                        Quantity::Reflectance => &t.lut.reflectance,
                        Quantity::Transmittance => {
                            t.lut.transmittance.as_ref().ok_or_else(|| {
                                Error::invalid(
                                    Param::Quantity.given("t"),
                                    format!("table `{}` has no transmittance", t.manifest.name),
                                )
                            })?
                        }
                    };
                    Ok(nacre_format::rough_film_lut::RoughFilmLut::lookup(
                        &t.lut.axes,
                        table,
                        elementary::cos(point.angle_deg.to_radians()),
                        *alpha,
                        d,
                        n,
                    ))
                }
                Method::RoughMonteCarlo { alpha, samples } => rough_monte_carlo(
                    stack,
                    std::slice::from_ref(point),
                    *alpha,
                    *samples,
                    colorimeter,
                    quantity,
                )
                .map(|e| e[0].colour),
                Method::Spectral => {
                    let s = stack_at(stack, point)?;
                    if !s.is_coherent() {
                        // Incoherent slabs: the rule resolves the coherent groups' fringes;
                        // the slabs add in intensity ([`nacre_optics::incoherent`]).
                        let rule = SpectralRule::for_stack(
                            colorimeter,
                            &s,
                            &[point.angle_deg],
                            s.max_opd_nm(None),
                        )?;
                        let p = s.sweep(&[point.angle_deg], rule.wavelengths_nm())?;
                        return Ok(rule.colour(p.iter().map(|p| value(p, quantity))));
                    }
                    if s.layers().is_empty() {
                        let rule = SpectralRule::new(colorimeter, 0.0);
                        let p = s.sweep(&[point.angle_deg], rule.wavelengths_nm())?;
                        return Ok(rule.colour(p.iter().map(|p| value(p, quantity))));
                    }
                    let rule = SpectralRule::for_stack(
                        colorimeter,
                        &s,
                        &[point.angle_deg],
                        s.max_opd_nm(None),
                    )?;
                    let d = s.layers()[0].thickness_nm;
                    let c = s.colours_over_thickness(1, point.angle_deg, &rule, &[d])?;
                    Ok(match quantity {
                        Quantity::Reflectance => c.reflectance[0],
                        Quantity::Transmittance => c.transmittance[0],
                    })
                }
                Method::Rgb3 => {
                    let s = stack_at(stack, point)?;
                    let p = s.sweep(&[point.angle_deg], &RGB3_WAVELENGTHS_NM)?;
                    Ok([0, 1, 2].map(|c| value(&p[c], quantity)))
                }
                Method::Fourier(harmonics, sigma_d_nm, table) => {
                    let (film, cos_theta, d) = film_on_base(stack, point, colorimeter)?;
                    let transmittance = quantity == Quantity::Transmittance;
                    if transmittance && film.base.iter().any(|b| b.im != 0.0) {
                        return Err(Error::invalid(
                            msg![
                                Param::Method.given("fourier"),
                                " ",
                                Param::Quantity.given("t")
                            ],
                            "transmittance needs a non-absorbing (dielectric) base",
                        ));
                    }
                    let result = match table {
                        Some(t) => film.fourier_colour_with(
                            colorimeter,
                            cos_theta,
                            d,
                            *harmonics,
                            *sigma_d_nm,
                            transmittance,
                            |mu, s| t.sample(mu, s),
                        ),
                        None => film.fourier_colour(
                            colorimeter,
                            cos_theta,
                            d,
                            *harmonics,
                            *sigma_d_nm,
                            transmittance,
                        ),
                    };
                    match result {
                        Some(c) => Ok(c.colour),
                        // An evanescent film has no Fourier series in 1/λ: exact reference.
                        None => evaluate(
                            stack,
                            std::slice::from_ref(point),
                            &Method::Spectral,
                            colorimeter,
                            quantity,
                            None,
                        )
                        .map(|v| v[0]),
                    }
                }
                Method::GaussianFitBelcour2017 => {
                    if quantity == Quantity::Transmittance {
                        return Err(Error::invalid(
                            Param::Method.given("gaussian"),
                            msg![
                                "the Gaussian fit evaluates reflectance only (use ",
                                Param::Quantity.given("r"),
                                ")"
                            ],
                        ));
                    }
                    let (film, cos_theta, d) = film_on_base(stack, point, colorimeter)?;
                    // The base enters only through its normal-incidence reflectance F0 (RGB),
                    // as in glTF.
                    let bare =
                        Stack::new(stack.ambient().clone(), vec![], stack.substrate().clone())?;
                    let rule = SpectralRule::new(colorimeter, 0.0);
                    let p = bare.sweep(&[0.0], rule.wavelengths_nm())?;
                    let f0 = rule.colour(p.iter().map(|p| p.R()));
                    let f0 = match colorimeter.space() {
                        OutputSpace::Rgb(RgbSpace::Srgb) => f0,
                        _ => mat3(
                            RgbSpace::Srgb.xyz_to_rgb_matrix(),
                            colorimeter.xyz_from_output(f0),
                        ),
                    };
                    let rec709 = gltf_iridescence(film.n_ambient, film.n_film, cos_theta, d, f0);
                    Ok(match colorimeter.space() {
                        OutputSpace::Rgb(RgbSpace::Srgb) => rec709,
                        _ => colorimeter
                            .output_from_xyz(mat3(RgbSpace::Srgb.rgb_to_xyz_matrix(), rec709)),
                    })
                }
                Method::Samples(n) => {
                    let s = stack_at(stack, point)?;
                    let (wl, w) = sample_weights(colorimeter, *n);
                    let p = s.sweep(&[point.angle_deg], &wl)?;
                    let mut c = [0.0; 3];
                    for (p, w) in p.iter().zip(&w) {
                        for k in 0..3 {
                            c[k] += value(p, quantity) * w[k];
                        }
                    }
                    Ok(c)
                }
            }
        })
        .collect()
}

/// The coherent films of `stack` (with the top film as `points` override it) whose
/// interference fringes `method`'s wavelength sampling cannot follow
/// ([`Stack::undersampled_films`]): at most one per film, for a warning. Only `samples:N`
/// samples a spectrum on a fixed grid (N wavelengths over 400–700 nm, step 300/(N − 1) nm);
/// `spectral` steps its rule by the fringes' phase ([`SpectralRule::for_stack`], so it
/// never undersamples: a film too thick for it is refused instead), `rgb3` takes one
/// wavelength per channel by design and integrates nothing, and the table and closed-form
/// methods integrate exactly when baked or model one film. For the top film the point
/// with the finest fringes is checked: the largest optical thickness Re(ñ)·d (the fringe
/// period λ²/(2 Re ñ d) is the smallest there on any grid), the first such point on ties.
pub fn undersampled(
    stack: &Stack,
    points: &[Point],
    method: &Method,
    colorimeter: &Colorimeter,
) -> Vec<Undersampled> {
    let Method::Samples(n) = method else {
        return Vec::new();
    };
    let (wavelengths_nm, _) = sample_weights(colorimeter, *n);
    let own_index = stack.layers().first().map_or(0.0, |l| {
        l.material.index_at(550.0).map_or(0.0, |n| n.re.abs())
    });
    let optical = |p: &Point| -> f64 {
        let d = p
            .thickness_nm
            .or(stack.layers().first().map(|l| l.thickness_nm))
            .unwrap_or(0.0);
        p.film_ior.map_or(own_index, f64::abs) * d
    };
    let finest = points.iter().filter(|p| optical(p).is_finite()).fold(
        None::<&Point>,
        |best, p| match best {
            Some(b) if optical(b) >= optical(p) => Some(b),
            _ => Some(p),
        },
    );
    // A point the stack refuses is reported by the evaluation itself.
    match finest {
        Some(p) => stack_at(stack, p)
            .map_or_else(|_| Vec::new(), |s| s.undersampled_films(&wavelengths_nm)),
        None => stack.undersampled_films(&wavelengths_nm),
    }
}

/// `Ok` when `stack` is coherent or `method` takes a stack with incoherent layers
/// (`spectral`, `rgb3`, `samples:N`: each integrates the stack's reflectance or
/// transmittance spectrum, which [`Stack::sweep`] gives with the slabs added in intensity;
/// `lut:` with a film-lut baked over the same slab, checked by [`LoadedLut::check_stack`];
/// `stack`, the real-time technique's twin, with one slab: [`StackEvaluation`] refuses more);
/// otherwise an error that names the method and the slab and says why the method's
/// physics does not apply.
pub(crate) fn refuse_incoherent(stack: &Stack, method: &Method) -> Result<()> {
    if stack.is_coherent() {
        return Ok(());
    }
    let (name, why) = match method {
        Method::Spectral | Method::Rgb3 | Method::Samples(_) | Method::Stack(_) => return Ok(()),
        // A film-lut baked with the same slab under its film (checked by `check_stack`).
        Method::Lut(_) => return Ok(()),
        Method::Fourier(..) => (
            "fourier",
            "the Fourier series in 1/λ describes one coherent film on a base; an incoherent slab below it has no such series",
        ),
        Method::GaussianFitBelcour2017 => (
            "gaussian",
            "the Gaussian fit describes one coherent film on a base given by its Fresnel reflectance",
        ),
        Method::RoughLut { .. } => (
            "rough-lut",
            "a rough-film-lut holds one film over fixed coherent layers, baked without incoherent slabs",
        ),
        Method::RoughMonteCarlo { .. } => (
            "rough-mc",
            "the microfacet model reflects from one rough interface; light returning through an incoherent slab behind it leaves at other points and angles",
        ),
    };
    let layer = (1..=stack.layers().len())
        .find(|&j| stack.is_incoherent(j))
        .unwrap_or(0);
    Err(Error::invalid(
        Param::Method.given(name),
        format!(
            "layer {layer} is incoherent and {why}: use `spectral` (exact), `rgb3`, `samples:N` or `lut:` with a film-lut baked over the same slab"
        ),
    ))
}

fn mat3(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// The single film on a base that the Fourier methods need, with the point's angle and
/// thickness. The base's index is taken per channel at the channel's centroid wavelength
/// ∫ λ |s_j| dλ / ∫ |s_j| dλ (exact for non-dispersive bases).
fn film_on_base(
    stack: &Stack,
    point: &Point,
    colorimeter: &Colorimeter,
) -> Result<(FilmOnBase, f64, f64)> {
    let context = || Param::Method.given("fourier/gaussian");
    if stack.layers().len() != 1 {
        return Err(Error::invalid(
            context(),
            format!(
                "needs exactly one film on a base; the stack has {} layers",
                stack.layers().len()
            ),
        ));
    }
    let film = &stack.layers()[0];
    let n_film = match point.film_ior {
        Some(n) => n,
        None => {
            let n = film.material.index_at(550.0)?;
            if !film.material.is_constant() || n.im != 0.0 {
                return Err(Error::invalid(
                    context(),
                    format!(
                        "needs a constant real film index; `{}` is dispersive or absorbing",
                        film.material.name()
                    ),
                ));
            }
            n.re
        }
    };
    let ambient = stack.ambient().index_at(550.0)?;
    if !stack.ambient().is_constant() {
        return Err(Error::invalid(
            context(),
            format!(
                "needs a constant ambient index; `{}` is dispersive",
                stack.ambient().name()
            ),
        ));
    }
    let weights = colorimeter.weights_1nm();
    let centroid_nm: [f64; 3] = std::array::from_fn(|j| {
        let (num, den) = weights
            .iter()
            .enumerate()
            .fold((0.0, 0.0), |(a, b), (i, w)| {
                let wl = nacre_optics::colour::spectral_wavelength_nm(i);
                (a + wl * w[j].abs(), b + w[j].abs())
            });
        num / den
    });
    let mut base = [C64::new(0.0, 0.0); 3];
    for (b, wl) in base.iter_mut().zip(centroid_nm) {
        *b = stack.substrate().index_at(wl)?;
    }
    Ok((
        FilmOnBase {
            n_ambient: ambient.re,
            n_film,
            base,
        },
        elementary::cos(point.angle_deg.to_radians()),
        point.thickness_nm.unwrap_or(film.thickness_nm),
    ))
}

/// The XYZ (the CSV's X, Y, Z columns) of a colour `c` in `colorimeter`'s output space.
pub fn output_to_xyz(colorimeter: &Colorimeter, c: [f64; 3]) -> [f64; 3] {
    match colorimeter.space() {
        OutputSpace::Xyz => c,
        OutputSpace::Rgb(_) => colorimeter.xyz_from_output(c),
    }
}

/// Writes the CSV.
pub fn write_csv(
    w: &mut dyn Write,
    stack: &Stack,
    points: &[Point],
    colours: &[[f64; 3]],
    colorimeter: &Colorimeter,
) -> std::io::Result<()> {
    let mut csv = crate::csv_text::writer(w);
    csv.write_record(HEADER.split(','))?;
    for (p, c) in points.iter().zip(colours) {
        let xyz = output_to_xyz(colorimeter, *c);
        let (d, n) = film_columns(stack, p);
        csv.write_record([
            p.angle_deg.to_string(),
            d.to_string(),
            n.to_string(),
            fmt_sig(xyz[0]),
            fmt_sig(xyz[1]),
            fmt_sig(xyz[2]),
            fmt_sig(c[0]),
            fmt_sig(c[1]),
            fmt_sig(c[2]),
        ])?;
    }
    csv.flush()
}

/// Builds the stack of a film over fixed layers (used by tests and tools).
pub fn film_stack(
    ambient: Material,
    film: Material,
    thickness_nm: f64,
    under: Vec<Layer>,
    base: Material,
) -> Result<Stack> {
    let mut layers = vec![Layer {
        material: film,
        thickness_nm,
    }];
    layers.extend(under);
    Ok(Stack::new(ambient, layers, base)?)
}
