//! The layout "integrated" of the table kind `diffraction` (issue 7, the fast path):
//! wavelength-integrated colour tables Iₚ(u, v), p = 0 … 2N, such that
//! colour = C(ω_i, ω_r) · Σₚ wᵖ Iₚ(u, v). The derivation, the axes and the point symmetry
//! are in [`nacre_optics::diffraction::integrated`]; this module parses its recipe keys,
//! measures the table against the terms layout, refuses it past a tolerance, and writes
//! and reads its files.
//!
//! # Recipe
//!
//! ```toml
//! [diffraction]
//! layout = "integrated"
//! integrated_samples = 256       # n: texels along v over [−u_max, u_max]; u ≥ 0 gets n/2 (even, 4–4096)
//! integrated_gamma = 3.0         # warp exponent γ of both axes (1 = uniform), in [1, 8]
//! integrated_tolerance = 0.01    # refuse the table when the measured error exceeds this
//! ```
//!
//! (with the keys of the terms layout: the height field, `coherence_diameter_um`,
//! `wavelengths` (the colour grid summed into the table), `max_angle_deg` (u_max =
//! 2 sin θ_max), `taylor_tolerance` (N)). Defaults: [`DEFAULT_INTEGRATED_SAMPLES`],
//! [`DEFAULT_INTEGRATED_GAMMA`], [`DEFAULT_INTEGRATED_TOLERANCE`]. γ = 3 measured best of
//! 1–4 on the CD and sine-grating recipes (γ = 1 misses the mirror lobe entirely at
//! n ≤ 256; γ = 4 starves the first orders).
//!
//! # Error metric and tolerance
//!
//! The baker compares the colour a shader rebuilds (f32 texels, bilinear in the warped
//! coordinates, f32 Horner sum) with the exact colour of the terms layout (f64 terms,
//! ρ per wavelength weighted by the same Stam's k² (555 nm/λ)² as the table — like with
//! like —, the same [`SpectralGrid`]) over the pairs of
//! [`check_directions`] (in-plane, off-plane and around the mirror lobe; several
//! thousand), and records the largest |Δ| of any output channel in units of that
//! channel's white — the colour of a flat perfect mirror in its specular direction with
//! the same weight, Σ_λ (555 nm/λ)² u(λ), the scale every value of the table is expressed
//! in. A per-channel absolute metric is
//! used rather than ΔE because the values are unbounded HDR radiance factors (the mirror
//! lobe reaches the white, the orders a few per cent of it): a ΔE would need an exposure.
//! The default tolerance 0.01 (1 % of the specular white) passes the CD recipe of the
//! default set at n = 144 (measured 6.8 × 10⁻³, mean 9.9 × 10⁻⁵, with the k²; 6.4 × 10⁻³,
//! mean 9.2 × 10⁻⁵, without it, `nacre bake tables/recipes/cd-tracks-fast.toml`, the
//! manifest's `reconstruction_error`; the worst texels are the
//! lobe edges, where bilinear interpolation rounds the peaks) while the failures it exists
//! for are orders of magnitude above it: f32 cancellation of tall structures reaches
//! 27 × the white for a 1 µm blazed grating (max |kwh| = 16.5).
//!
//! # Files
//!
//! What every texel holds: layer p of column c, row r is I_p(u_c, v_r) in the recipe's
//! output space (linear RGB of `[colour] space`, or XYZ for `xyz`), each wavelength of its
//! sum weighted by Stam's k² as (555 nm/λ)² (the manifest's `k_squared_reference_nm`; the
//! unweighted layers at u = v = 0, for the mirror image, are its `zeroth_order_layers`;
//! a manifest without these fields is a table baked before the weight), f32, u_c =
//! u_max((2c + 1)/n)^γ (c = 0 … n/2 − 1, u ≥ 0 only), v_r = u_max sign(t)|t|^γ with
//! t = (2r + 1)/n − 1.
//!
//! * `NAME.integrated.exr`: an atlas n/2 wide and n·(2N + 1) high, layer p in rows
//!   [p·n, (p + 1)·n), R, G, B = the three channels of Iₚ, full float.
//! * `NAME.integrated.ktx2`: a 2-D array `RGBA32F` texture n/2 × n with 2N + 1 layers,
//!   layer p = (Iₚ channel 0, 1, 2, 0).
//!
//! How a shader rebuilds the colour: (u, v, w) = −ω_i − ω_r; if u < 0, (u, v, w) →
//! (−u, −v, −w); x = (sign(u)(|u|/u_max)^{1/γ} + 1)·n/2 − ½ − n/2 (column coordinate,
//! clamped to [0, n/2 − 1]), y = (sign(v)(|v|/u_max)^{1/γ} + 1)·n/2 − ½ (clamped to
//! [0, n − 1]); S = Σₚ wᵖ Iₚ(x, y) by Horner from p = 2N down, each Iₚ bilinear from four
//! integer texel loads (RGBA32F is not filterable everywhere); colour = F²(θ_h) · (1 +
//! ω_i·ω_r)² / (cos θ_i cos θ_r (cos θ_i + cos θ_r)²) · S, F² = 1 or the Fresnel reflectance
//! of one index at the half-vector angle.

use crate::error::{Error, Result};
use crate::kinds::diffraction_recipe::DiffractionRecipe;
use nacre_format::diffraction::{
    DiffractionRecord, ERROR_METRIC, IntegratedRecord, MAX_INTEGRATED_BYTES,
};
use nacre_format::manifest::{AxisRecord, KindRecord, Manifest};
use nacre_format::table_io::{Precision, Table3};
use nacre_optics::diffraction::integrated::{
    IntegratedTable, K_SQUARED_REFERENCE_NM, MAX_INTEGRATED_SAMPLES, WarpedAxis, check_directions,
};
use nacre_optics::diffraction::{DiffractionSurface, SpectralGrid, TaylorTerms};
use nacre_optics::elementary;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Default texels n along v (u ≥ 0 gets n/2).
pub const DEFAULT_INTEGRATED_SAMPLES: usize = 256;
/// Default warp exponent γ.
pub const DEFAULT_INTEGRATED_GAMMA: f64 = 3.0;
/// Default tolerance on the measured reconstruction error, in units of the specular white.
pub const DEFAULT_INTEGRATED_TOLERANCE: f64 = 1e-2;

/// The layout "integrated" settings of a recipe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratedSettings {
    /// Texels n along v.
    pub samples: usize,
    /// Warp exponent γ.
    pub gamma: f64,
    /// Tolerance on the measured error.
    pub tolerance: f64,
}

impl IntegratedSettings {
    /// Parses the `integrated_*` keys; `bad` makes a recipe error at a span. Refuses up
    /// front a table beyond [`MAX_INTEGRATED_BYTES`] for Taylor order `order`.
    pub(crate) fn parse(
        bad: &dyn Fn(std::ops::Range<usize>, String) -> Error,
        samples: Option<&Spanned<i64>>,
        gamma: Option<&Spanned<f64>>,
        tolerance: Option<&Spanned<f64>>,
        order: usize,
    ) -> Result<Self> {
        let samples_v = match samples {
            None => DEFAULT_INTEGRATED_SAMPLES,
            Some(s)
                if (4..=MAX_INTEGRATED_SAMPLES as i64).contains(s.get_ref())
                    && s.get_ref() % 2 == 0 =>
            {
                *s.get_ref() as usize
            }
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!(
                        "integrated_samples = {}: expected an even number from 4 to {MAX_INTEGRATED_SAMPLES}",
                        s.get_ref()
                    ),
                ));
            }
        };
        let gamma_value = match gamma {
            None => DEFAULT_INTEGRATED_GAMMA,
            Some(s) if (1.0..=8.0).contains(s.get_ref()) => *s.get_ref(),
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!("integrated_gamma = {}: expected [1, 8]", s.get_ref()),
                ));
            }
        };
        let tolerance_value = match tolerance {
            None => DEFAULT_INTEGRATED_TOLERANCE,
            Some(s) if *s.get_ref() > 0.0 && s.get_ref().is_finite() => *s.get_ref(),
            Some(s) => {
                return Err(bad(
                    s.span(),
                    format!(
                        "integrated_tolerance = {}: must be finite and positive (an error in units of the specular white, e.g. 0.01)",
                        s.get_ref()
                    ),
                ));
            }
        };
        let layers = 2 * order as u64 + 1;
        let bytes = layers * samples_v as u64 * (samples_v as u64 / 2) * 16;
        if bytes > MAX_INTEGRATED_BYTES {
            let span = samples.map(Spanned::span).unwrap_or(0..0);
            return Err(bad(
                span,
                format!(
                    "an integrated table of {} × {samples_v} texels × {layers} layers (2N + 1, N = {order}) needs {bytes} bytes, above the limit of {MAX_INTEGRATED_BYTES}: lower integrated_samples or raise taylor_tolerance",
                    samples_v / 2
                ),
            ));
        }
        Ok(IntegratedSettings {
            samples: samples_v,
            gamma: gamma_value,
            tolerance: tolerance_value,
        })
    }

    /// The record of these settings for the table of `r` (measured fields zero until the
    /// bake fills them).
    pub(crate) fn record(&self, r: &DiffractionRecord) -> IntegratedRecord {
        let n = self.samples;
        let (g, m) = (self.gamma, r.max_uv);
        IntegratedRecord {
            samples_u: n / 2,
            samples_v: n,
            gamma: g,
            max_uv: m,
            layers: 2 * r.taylor_order + 1,
            channels: String::new(),
            u_forward: format!(
                "x = clamp(((u / {m}) ^ (1 / {g}) + 1) * {n} / 2 - 0.5 - {h}, 0, {hm}) for u >= 0 (texel coordinate: column c's centre at x = c)",
                h = n / 2,
                hm = n / 2 - 1
            ),
            u_inverse: format!("u = {m} * ((2 c + 1) / {n}) ^ {g}"),
            v_forward: format!(
                "y = clamp((sign(v) (|v| / {m}) ^ (1 / {g}) + 1) * {n} / 2 - 0.5, 0, {}) (row r's centre at y = r)",
                n - 1
            ),
            v_inverse: format!("v = {m} * sign(t) |t| ^ {g}, t = (2 r + 1) / {n} - 1"),
            fold: "u < 0: sum_p w^p I_p(u, v) = sum_p (-w)^p I_p(-u, -v) (I_p(-u, -v) = (-1)^p I_p(u, v) for a real height field): evaluate at (-u, -v) with w -> -w".into(),
            error_metric: ERROR_METRIC.into(),
            tolerance: self.tolerance,
            reconstruction_error: 0.0,
            mean_error: 0.0,
            worst_light_deg: [0.0; 2],
            worst_view_deg: [0.0; 2],
            worst_channel: String::new(),
            pairs: 0,
            storage_error: 0.0,
            k_squared_reference_nm: Some(K_SQUARED_REFERENCE_NM),
            zeroth_order_layers: Vec::new(),
        }
    }
}

/// (θ, φ) of a unit vector, degrees.
fn polar_deg(d: [f64; 3]) -> [f64; 2] {
    let theta = elementary::acos(d[2].clamp(-1.0, 1.0)).to_degrees();
    // + 0.0 turns −0 into +0, so that φ of a light on the −x axis reads 180°, not −180°.
    let phi = if d[0] == 0.0 && d[1] == 0.0 {
        0.0
    } else {
        elementary::atan2(d[1] + 0.0, d[0] + 0.0).to_degrees()
    };
    [theta, phi]
}

/// Round to 4 significant digits for messages and manifests (stable text).
fn sig4(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = elementary::powi(10.0, 3 - elementary::log10(v.abs()).floor() as i32);
    (v * scale).round() / scale
}

/// Builds the integrated table of `recipe`, measures it against the terms layout, and
/// writes `NAME.integrated.exr`, `NAME.integrated.ktx2` and `NAME.json` (module docs);
/// returns the manifest path.
///
/// # Errors
/// [`nacre_format::Error::Invalid`] naming the recipe when the measured error exceeds the tolerance
/// (nothing written) or the recipe is not of the layout "integrated"; write errors.
pub fn bake(
    recipe: &DiffractionRecipe,
    out_dir: &Path,
    progress: &(dyn Fn() + Sync),
) -> Result<PathBuf> {
    let mut r = recipe.record.clone();
    let context = recipe.path.display().to_string();
    let Some(mut s) = r.integrated.clone() else {
        return Err(Error::invalid(
            context,
            format!(
                "layout \"{}\": expected a recipe with layout = \"integrated\"",
                r.layout
            ),
        ));
    };
    let c = &recipe.colorimeter;
    let optics = |source| Error::optics_in(context.clone(), source);
    let terms = TaylorTerms::compute(&recipe.field, r.taylor_order);
    let surface = DiffractionSurface::new(terms, r.sigma_s_um).map_err(optics)?;
    let grid = SpectralGrid::new(c, &recipe.wavelengths_nm).map_err(optics)?;
    let axis = WarpedAxis::new(r.max_uv, s.gamma, s.samples_v).map_err(optics)?;
    let table = IntegratedTable::compute(&surface, &grid, c, axis, s.k_squared_reference_nm);
    let pairs = check_directions(r.max_angle_deg);
    let e = table.reconstruction_error(&surface, &grid, c, &pairs);
    let w_min = -2.0 * elementary::cos(r.max_angle_deg.to_radians());
    let storage = table.storage_error(&surface, &grid, c, (s.samples_v / 64).max(1), w_min);
    progress();
    let channel_names = c.space().channel_names();
    s.channels = format!(
        "I_p in linear {} ({}, {}, {}), each wavelength weighted by Stam's k^2 as (k/k_ref)^2 = ({} nm/lambda)^2 (k_squared_reference_nm; the light's gain (sigma_s k_ref)^2/pi carries the rest of f = rho (sigma_s k)^2/pi): colour = C * sum_p w^p I_p is the table's output colour of sum_lambda (k/k_ref)^2 rho u directly; zeroth_order_layers are the layers at u = v = 0 without the weight (the mirror image's efficiency)",
        c.space(),
        channel_names[0],
        channel_names[1],
        channel_names[2],
        K_SQUARED_REFERENCE_NM
    );
    s.zeroth_order_layers = table
        .specular_layers()
        .iter()
        .map(|j| j.map(f64::from))
        .collect();
    s.reconstruction_error = e.max_error;
    s.mean_error = e.mean_error;
    s.worst_light_deg = polar_deg(e.omega_i).map(sig4);
    s.worst_view_deg = polar_deg(e.omega_r).map(sig4);
    s.worst_channel = channel_names[e.channel].to_string();
    s.pairs = e.pairs;
    s.storage_error = storage;
    if !(e.max_error <= s.tolerance) {
        let [ti, pi] = polar_deg(e.omega_i).map(sig4);
        let [tr, pr] = polar_deg(e.omega_r).map(sig4);
        let cause = if !(storage <= 0.5 * s.tolerance) {
            format!(
                "f32 storage alone errs by {storage:.3e}: the sum Σ w^p I_p cancels catastrophically for this structure (max |k w h| = {:.3} at {} nm), so no resolution can fix it — use layout = \"terms\"",
                r.max_phase, r.wavelength_min_nm
            )
        } else {
            format!(
                "f32 storage alone errs by {storage:.3e}, so the error is interpolation: raise integrated_samples ({}) or integrated_tolerance, or use layout = \"terms\"",
                s.samples_v
            )
        };
        return Err(Error::invalid(
            context,
            format!(
                "the integrated layout's reconstruction error {:.3e} (in units of the specular white, channel {}: terms layout {:.4e}, integrated {:.4e}) at light θ = {ti}°, φ = {pi}° and view θ = {tr}°, φ = {pr}° exceeds integrated_tolerance {}; {cause}",
                e.max_error,
                channel_names[e.channel],
                e.exact[e.channel],
                e.integrated[e.channel],
                s.tolerance
            ),
        ));
    }
    r.integrated = Some(s.clone());
    write_files(recipe, &r, &s, &table, out_dir)
}

fn write_files(
    recipe: &DiffractionRecipe,
    r: &DiffractionRecord,
    s: &IntegratedRecord,
    table: &IntegratedTable,
    out_dir: &Path,
) -> Result<PathBuf> {
    let stage = nacre_format::stage::StagedTable::new(out_dir)?;
    let c = &recipe.colorimeter;
    let (cols, rows, layers) = (s.samples_u, s.samples_v, s.layers);
    let axis = table.axis();
    let mut manifest = Manifest {
        colour_convention: format!(
            "colour (linear {}) = F^2 G/w^2 sum_p w^p I_p(u, v) = M * sum over the wavelength grid {}:{}:{} nm of rho(lambda) u(lambda), rho = F^2 G/w^2 |P~|^2 the relative reflectance (1 for a flat perfect mirror in its specular direction), u the CIE XYZ weights of observer {} under illuminant {} rescaled so that rho = 1 gives the illuminant white, M the matrix to linear {} (Bradford adapted; rho = 1 is (1, 1, 1)); F^2 must not depend on the wavelength",
            c.space(),
            r.wavelength_min_nm,
            r.wavelength_max_nm,
            r.wavelength_step_nm,
            c.observer(),
            c.illuminant(),
            c.space()
        ),
        axes: vec![
            AxisRecord {
                name: "u".into(),
                unit: "1".into(),
                count: cols,
                min: axis.texel_centre(cols),
                max: axis.texel_centre(2 * cols - 1),
                mapping: format!("warped, gamma = {}, u >= 0 (u < 0 by the fold)", s.gamma),
                forward: s.u_forward.clone(),
                inverse: s.u_inverse.clone(),
            },
            AxisRecord {
                name: "v".into(),
                unit: "1".into(),
                count: rows,
                min: axis.texel_centre(0),
                max: axis.texel_centre(rows - 1),
                mapping: format!("warped, gamma = {}", s.gamma),
                forward: s.v_forward.clone(),
                inverse: s.v_inverse.clone(),
            },
            AxisRecord {
                name: "power_of_w".into(),
                unit: "1".into(),
                count: layers,
                min: 0.0,
                max: (layers - 1) as f64,
                mapping: "power p of w".into(),
                forward: "p".into(),
                inverse: "p".into(),
            },
        ],
        texel_centres: format!(
            "column c holds u = {m} ((2 c + 1) / {n})^{g}, row r holds v = {m} sign(t) |t|^{g} with t = (2 r + 1) / {n} - 1 (centres of a {n}-texel warped axis over [-{m}, {m}], of which the columns are the half u >= 0); bilinear interpolation in these texel coordinates by four integer loads",
            m = s.max_uv,
            n = rows,
            g = s.gamma
        ),
        atlas: format!(
            "EXR: width n/2 = {cols}, height n * (2N + 1) = {rows} * {layers}; layer p occupies rows [p n, (p + 1) n), R, G, B = the three output channels of I_p, full float. KTX2: 2-D array RGBA32F texture {cols} x {rows} with 2N + 1 = {layers} layers, layer p = (I_p channel 0, 1, 2, 0)"
        ),
        reconstruction: format!(
            "(u, v, w) = -omega_i - omega_r; if u < 0 then (u, v, w) = (-u, -v, -w); x, y from u_forward and v_forward; S = sum_(p=0)^(2N) w^p I_p(x, y) (Horner from p = 2N, each I_p bilinear); colour = F^2 (1 + omega_i.omega_r)^2 / (cos_i cos_r (cos_i + cos_r)^2) S (Stam 1999; Dhillon et al. 2014); measured error {:.3e} of the specular white (tolerance {}), f32 storage alone {:.3e}",
            s.reconstruction_error, s.tolerance, s.storage_error
        ),
        files: Vec::new(),
        ..Manifest::for_recipe(
            KindRecord::Diffraction(Box::new(r.clone())),
            &recipe.name,
            &recipe.description,
            &recipe.path,
            &recipe.text,
            c,
        )
    };
    let embedded = manifest.embedded_json();
    let mut atlas = Table3::new(cols, rows, layers);
    for p in 0..layers {
        for iv in 0..rows {
            for col in 0..cols {
                atlas.set(col, iv, p, table.texel(p, col, iv));
            }
        }
    }
    let exr = format!("{}.integrated.exr", recipe.name);
    let mut files = vec![stage.write_exr(&exr, "integrated", &atlas, Precision::Float)?];
    let ktx2 = format!("{}.integrated.ktx2", recipe.name);
    let mut level = Vec::with_capacity(table.values().len() * 16);
    for v in table.values() {
        for x in [v[0], v[1], v[2], 0.0] {
            level.extend_from_slice(&x.to_le_bytes());
        }
    }
    let nul = |s: &str| {
        let mut v = s.as_bytes().to_vec();
        v.push(0);
        v
    };
    let image = nacre_format::ktx2::Ktx2Image {
        format: nacre_format::ktx2::Ktx2Format::Rgba32Float,
        width: cols as u32,
        height: rows as u32,
        depth: 0,
        layers: layers as u32,
        levels: vec![level],
        key_values: vec![
            (
                nacre_format::ktx2::WRITER_KEY.into(),
                nul(&format!("nacre {}", env!("CARGO_PKG_VERSION"))),
            ),
            (nacre_format::ktx2::MANIFEST_KEY.into(), nul(&embedded)),
        ],
    };
    files.push(stage.write_ktx2(&ktx2, "integrated", &image)?);
    manifest.files = files;
    Ok(stage.commit_manifest(&manifest, &[])?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nacre_optics::diffraction::HeightField;

    fn recipe(dir: &Path, name: &str, text: &str) -> Result<Box<dyn crate::kinds::TableRecipe>> {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        crate::kinds::read_recipe(&path)
    }

    const SINE: &str = "kind = \"diffraction\"
[height_field]
synthetic = \"sine:1.6:0.05\"
[diffraction]
layout = \"integrated\"
coherence_diameter_um = 16.0
wavelengths = \"380:780:10\"
max_angle_deg = 30.0
integrated_samples = 256
";

    #[test]
    fn a_sine_grating_bakes_within_tolerance_and_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let r = recipe(dir.path(), "sine.toml", SINE).unwrap();
        let out = dir.path().join("out");
        let manifest_path = r.bake(&out, &|| {}).unwrap();
        let m = Manifest::read(&manifest_path).unwrap();
        let (record, table) = m.load_diffraction_integrated(&manifest_path).unwrap();
        assert_eq!(record.layout, "integrated");
        let s = record.integrated.clone().unwrap();
        assert_eq!(
            (s.samples_u, s.samples_v, s.gamma),
            (128, 256, DEFAULT_INTEGRATED_GAMMA)
        );
        assert_eq!(s.layers, 2 * record.taylor_order + 1);
        assert_eq!(s.tolerance, DEFAULT_INTEGRATED_TOLERANCE);
        assert!(s.reconstruction_error <= s.tolerance && s.reconstruction_error > 0.0);
        assert!(s.storage_error < 1e-5 && s.pairs > 1000, "{s:?}");
        eprintln!(
            "sine recipe: error {:.2e}, mean {:.2e}, f32 storage {:.2e}",
            s.reconstruction_error, s.mean_error, s.storage_error
        );
        // The files hold what the core computes, rounded to f32 (EXR and KTX2 alike).
        let d = r.downcast_ref::<DiffractionRecipe>().unwrap();
        let field = HeightField::sine_grating(1.6, 0.05, 0.04, 400).unwrap();
        assert_eq!(field, d.field);
        let surface =
            DiffractionSurface::new(TaylorTerms::compute(&field, record.taylor_order), 4.0)
                .unwrap();
        let grid = SpectralGrid::new(&d.colorimeter, &d.wavelengths_nm).unwrap();
        let exact = IntegratedTable::compute(
            &surface,
            &grid,
            &d.colorimeter,
            table.axis(),
            Some(K_SQUARED_REFERENCE_NM),
        );
        assert_eq!(table, exact);
        assert_eq!(s.k_squared_reference_nm, Some(K_SQUARED_REFERENCE_NM));
        assert!(s.channels.contains("k^2") && s.zeroth_order_layers.len() == s.layers);
        let mut ktx_only = m.clone();
        ktx_only
            .files
            .retain(|f| f.format == nacre_format::FileFormat::Ktx2);
        let copy = out.join("ktx-only.json");
        std::fs::write(&copy, serde_json::to_string(&ktx_only).unwrap()).unwrap();
        let (_, from_ktx2) = Manifest::read(&copy)
            .unwrap()
            .load_diffraction_integrated(&copy)
            .unwrap();
        assert_eq!(from_ktx2, table);
        // The terms loader refuses the layout by name.
        let e = m.load_diffraction(&manifest_path).unwrap_err().to_string();
        assert!(e.contains("\"integrated\""), "{e}");
        assert!(m.atlas.contains("128 x 256") && m.texel_centres.contains("u >= 0"));
        // A manifest without the k² fields (baked before issue 37's k²) still loads: the
        // same texels, marked as summed without the weight, its own peak as the zeroth order.
        let mut json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&manifest_path).unwrap()).unwrap();
        let fields = json["diffraction"]["integrated"].as_object_mut().unwrap();
        assert!(fields.remove("k_squared_reference_nm").is_some());
        assert!(fields.remove("zeroth_order_layers").is_some());
        let old_path = out.join("old.json");
        std::fs::write(&old_path, serde_json::to_string(&json).unwrap()).unwrap();
        let (old_record, old) = Manifest::read(&old_path)
            .unwrap()
            .load_diffraction_integrated(&old_path)
            .unwrap();
        let old_s = old_record.integrated.unwrap();
        assert_eq!(old_s.k_squared_reference_nm, None);
        assert!(old_s.zeroth_order_layers.is_empty());
        assert_eq!(
            (old.k_squared_reference_nm(), old.values()),
            (None, table.values())
        );
        assert_eq!(old.specular_sum(-2.0), old.sum_at(0.0, 0.0, -2.0));
        assert_ne!(old.specular_sum(-2.0), table.specular_sum(-2.0));
    }

    #[test]
    fn a_tall_blazed_grating_is_refused_with_the_measured_error() {
        let dir = tempfile::tempdir().unwrap();
        let text = SINE
            .replace("sine:1.6:0.05", "blazed:2.5:1.0")
            .replace("integrated_samples = 256", "integrated_samples = 32");
        let r = recipe(dir.path(), "tall.toml", &text).unwrap();
        let out = dir.path().join("out");
        let e = r.bake(&out, &|| {}).unwrap_err().to_string();
        eprintln!("{e}");
        for needle in [
            "tall.toml",
            "reconstruction error",
            "exceeds integrated_tolerance 0.01",
            "light θ =",
            "view θ =",
            "cancels catastrophically",
            "layout = \"terms\"",
        ] {
            assert!(e.contains(needle), "{needle}: {e}");
        }
        assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    }

    #[test]
    fn bad_integrated_keys_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        for (from, to, needle) in [
            (
                "integrated_samples = 256",
                "integrated_samples = 161",
                "even",
            ),
            (
                "integrated_samples = 256",
                "integrated_samples = 100000",
                "4096",
            ),
            (
                "integrated_samples = 256",
                "integrated_samples = -4",
                "even",
            ),
            (
                "integrated_samples = 256",
                "integrated_samples = 4096\ntaylor_tolerance = 1e-12",
                "bytes",
            ),
            (
                "integrated_samples = 256",
                "integrated_gamma = 0.5",
                "[1, 8]",
            ),
            (
                "integrated_samples = 256",
                "integrated_tolerance = 0.0",
                "positive",
            ),
            (
                "integrated_samples = 256",
                "integrated_tolerance = nan",
                "positive",
            ),
        ] {
            let e = recipe(dir.path(), "bad.toml", &SINE.replace(from, to))
                .err()
                .unwrap()
                .to_string();
            assert!(e.contains("bad.toml:9") && e.contains(needle), "{to}: {e}");
        }
    }
}
