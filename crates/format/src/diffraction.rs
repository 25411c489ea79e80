//! Table kind `diffraction`: what its manifest records (both layouts) and the readers of
//! its files. How the tables are baked is `nacre_bake::kinds::diffraction`.

use crate::error::{Error, Result};
use crate::ktx2::{self, Ktx2Format};
use crate::manifest::{FileFormat, Manifest};
use crate::table_io;
use nacre_optics::C64;
use nacre_optics::diffraction::TaylorTerms;
use nacre_optics::diffraction::integrated::{IntegratedTable, MAX_INTEGRATED_SAMPLES, WarpedAxis};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The sign convention recorded in manifests and printed by the CLI.
pub const SIGN_CONVENTION: &str = "P(ku, kv) = ∬ exp(+i k (u x + v y + w h(x, y))) dx dy with (u, v, w) = −ω_i − ω_r (ω_i towards the light, ω_r towards the viewer; time dependence exp(−iωt)); T_n[j] = (1/M) Σ_m (i h_m)^n exp(+i κ_j·x_m), κ_j = 2π j / L; P_j = Σ_n (k w)^n / n! T_n[j]; x runs across the grating lines";

/// Everything a `diffraction` manifest records about the table (beside the common fields).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiffractionRecord {
    /// `terms` or `integrated`.
    pub layout: String,
    /// The height field: a synthetic spec or the file name as written in the recipe.
    pub source: String,
    /// Samples (bins) along x.
    pub nx: usize,
    /// Samples (bins) along y.
    pub ny: usize,
    /// Sample spacing Δ, µm.
    pub pitch_um: f64,
    /// Patch size (Lₓ, L_y), µm.
    pub patch_um: [f64; 2],
    /// The mean height removed (a global phase), µm.
    pub mean_removed_um: f64,
    /// Largest |h| after removing the mean, µm.
    pub max_abs_height_um: f64,
    /// Coherence diameter 4σ_s, µm.
    pub coherence_diameter_um: f64,
    /// σ_s, µm.
    pub sigma_s_um: f64,
    /// Shortest wavelength served, nm.
    pub wavelength_min_nm: f64,
    /// Longest wavelength served, nm.
    pub wavelength_max_nm: f64,
    /// Wavelength step of the colour sums, nm.
    pub wavelength_step_nm: f64,
    /// Largest polar angle of light and view served, degrees.
    pub max_angle_deg: f64,
    /// 2 sin(max_angle): the largest |u|, |v|.
    pub max_uv: f64,
    /// Taylor order N (terms T₀ … T_N).
    pub taylor_order: usize,
    /// Tolerance asked for on the remainder bound.
    pub taylor_tolerance: f64,
    /// max |k w h| at the shortest wavelength with |w| ≤ 2.
    pub max_phase: f64,
    /// The remainder bound |kwh|^{N+1}/(N+1)! at max_phase.
    pub taylor_bound: f64,
    /// Bound on the error of the Taylor sum from storing Tₙ as f32: 2⁻²⁴ e^{max_phase}.
    pub f32_rounding_bound: f64,
    /// Texel of the DC bin, (⌊Mₓ/2⌋, ⌊M_y/2⌋).
    pub dc_texel: [usize; 2],
    /// [`SIGN_CONVENTION`].
    pub sign_convention: String,
    /// Layout "integrated" only: its axes, settings and measured reconstruction error
    /// (`nacre_bake::kinds::diffraction_integrated`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrated: Option<IntegratedRecord>,
}

impl Manifest {
    /// Loads the Taylor terms of a `diffraction` table (from its EXR file, else its KTX2
    /// file) as stored (f32 values).
    pub fn load_diffraction(
        &self,
        manifest_path: &Path,
    ) -> Result<(DiffractionRecord, TaylorTerms)> {
        let r = self
            .diffraction()
            .cloned()
            .ok_or_else(|| self.wrong_kind(manifest_path, "a diffraction table"))?;
        if r.layout != "terms" {
            return Err(Error::Invalid {
                context: manifest_path.display().to_string(),
                message: format!(
                    "diffraction table `{}` has the layout \"{}\", which stores colours summed over wavelengths, not the Taylor terms",
                    self.name, r.layout
                ),
            });
        }
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        let layers = r.taylor_order + 1;
        let find = |format| self.file("terms", format);
        let mut terms = vec![vec![C64::new(0.0, 0.0); r.nx * r.ny]; layers];
        if let Some(f) = find(FileFormat::Exr) {
            let (t, _) = table_io::read_exr_table(&dir.join(&f.path), r.nx, r.ny, layers)?;
            for (n, layer) in terms.iter_mut().enumerate() {
                for (i, v) in layer.iter_mut().enumerate() {
                    let [re, im, _] = t.texel(i % r.nx, i / r.nx, n);
                    *v = C64::new(f64::from(re), f64::from(im));
                }
            }
        } else if let Some(f) = find(FileFormat::Ktx2) {
            let path = dir.join(&f.path);
            let image = ktx2::read_ktx2(&path)?;
            if image.format != Ktx2Format::Rgba32Float
                || (
                    image.width as usize,
                    image.height as usize,
                    image.layers as usize,
                ) != (r.nx, r.ny, layers.div_ceil(2))
                || image.levels.len() != 1
            {
                return Err(Error::Table {
                    path,
                    message: format!(
                        "texture is {:?} {}x{} with {} layers; expected Rgba32Float {}x{} with {} layers",
                        image.format,
                        image.width,
                        image.height,
                        image.layers,
                        r.nx,
                        r.ny,
                        layers.div_ceil(2)
                    ),
                });
            }
            let data = image.level_f32(0);
            for (n, layer) in terms.iter_mut().enumerate() {
                for (i, v) in layer.iter_mut().enumerate() {
                    let at = ((n / 2) * r.nx * r.ny + i) * 4 + 2 * (n % 2);
                    *v = C64::new(f64::from(data[at]), f64::from(data[at + 1]));
                }
            }
        } else {
            return Err(Error::Invalid {
                context: manifest_path.display().to_string(),
                message: "the manifest lists no terms file".into(),
            });
        }
        let t = TaylorTerms::from_terms(r.nx, r.ny, r.pitch_um, &terms).map_err(|source| {
            Error::OpticsIn {
                context: manifest_path.display().to_string(),
                source,
            }
        })?;
        Ok((r, t))
    }
}

/// The error metric recorded in manifests.
pub const ERROR_METRIC: &str = "max over light/view pairs and output channels c of |colour_integrated,c - colour_terms,c| / white_c, white = the colour of rho = 1 (a flat perfect mirror in its specular direction); colour_integrated as a shader rebuilds it (f32 texels, bilinear in the warped coordinates, f32 Horner sum), colour_terms from the f64 Taylor terms at the same N and wavelength grid, F = 1";

/// Largest integrated table accepted: (2N + 1)·n·n/2 RGBA32F texels, 1 GiB (the KTX2
/// file; the EXR file is ¾ of it).
pub const MAX_INTEGRATED_BYTES: u64 = 1 << 30;

/// What a manifest records about an integrated table (inside [`DiffractionRecord`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IntegratedRecord {
    /// Columns n/2 (u ≥ 0).
    pub samples_u: usize,
    /// Rows n (v over [−u_max, u_max]).
    pub samples_v: usize,
    /// Warp exponent γ.
    pub gamma: f64,
    /// u_max = 2 sin θ_max.
    pub max_uv: f64,
    /// Layers 2N + 1 (p = 0 … 2N).
    pub layers: usize,
    /// What the three channels hold.
    pub channels: String,
    /// Column coordinate of u ≥ 0.
    pub u_forward: String,
    /// u at the centre of column c.
    pub u_inverse: String,
    /// Row coordinate of v.
    pub v_forward: String,
    /// v at the centre of row r.
    pub v_inverse: String,
    /// How u < 0 is read.
    pub fold: String,
    /// [`ERROR_METRIC`].
    pub error_metric: String,
    /// The tolerance the bake was held to.
    pub tolerance: f64,
    /// The measured error ([`ERROR_METRIC`]).
    pub reconstruction_error: f64,
    /// Its mean over the pairs.
    pub mean_error: f64,
    /// Light direction of the largest error: (θ, φ), degrees (φ from +x towards +y).
    pub worst_light_deg: [f64; 2],
    /// View direction of the largest error: (θ, φ), degrees.
    pub worst_view_deg: [f64; 2],
    /// Output channel of the largest error.
    pub worst_channel: String,
    /// Light/view pairs measured.
    pub pairs: usize,
    /// Error of f32 storage and the f32 sum alone, at texel centres (no interpolation),
    /// same units: the catastrophic cancellation of tall structures.
    pub storage_error: f64,
}

impl Manifest {
    /// Loads an integrated `diffraction` table (from its EXR file, else its KTX2 file) as
    /// stored (f32 values).
    ///
    /// # Errors
    /// [`Error::Invalid`] for another kind or layout, or sizes a bake could not have
    /// written; file errors.
    pub fn load_diffraction_integrated(
        &self,
        manifest_path: &Path,
    ) -> Result<(DiffractionRecord, IntegratedTable)> {
        let invalid = |message: String| Error::Invalid {
            context: manifest_path.display().to_string(),
            message,
        };
        let r = self
            .diffraction()
            .cloned()
            .ok_or_else(|| self.wrong_kind(manifest_path, "a diffraction table"))?;
        let s = match (&r.integrated, r.layout.as_str()) {
            (Some(s), "integrated") => s.clone(),
            _ => {
                return Err(invalid(format!(
                    "diffraction table `{}` has the layout \"{}\", not \"integrated\"",
                    self.name, r.layout
                )));
            }
        };
        let n = s.samples_v;
        let bytes = (s.layers as u64)
            .saturating_mul(n as u64)
            .saturating_mul(s.samples_u as u64)
            .saturating_mul(16);
        if !(4..=MAX_INTEGRATED_SAMPLES).contains(&n)
            || n % 2 == 1
            || s.samples_u != n / 2
            || s.layers != 2 * r.taylor_order + 1
            || bytes > MAX_INTEGRATED_BYTES
        {
            return Err(invalid(format!(
                "integrated table of {} × {n} texels and {} layers for N = {}: expected n even from 4 to {MAX_INTEGRATED_SAMPLES}, n/2 columns, 2N + 1 layers, at most {MAX_INTEGRATED_BYTES} bytes",
                s.samples_u, s.layers, r.taylor_order
            )));
        }
        let axis = WarpedAxis::new(s.max_uv, s.gamma, n).map_err(|source| Error::OpticsIn {
            context: manifest_path.display().to_string(),
            source,
        })?;
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        let find = |format| self.file("integrated", format);
        let (cols, layers) = (s.samples_u, s.layers);
        let mut values = vec![[0.0f32; 3]; layers * n * cols];
        if let Some(f) = find(FileFormat::Exr) {
            let (t, _) = table_io::read_exr_table(&dir.join(&f.path), cols, n, layers)?;
            for p in 0..layers {
                for iv in 0..n {
                    for c in 0..cols {
                        values[(p * n + iv) * cols + c] = t.texel(c, iv, p);
                    }
                }
            }
        } else if let Some(f) = find(FileFormat::Ktx2) {
            let path = dir.join(&f.path);
            let image = ktx2::read_ktx2(&path)?;
            if image.format != Ktx2Format::Rgba32Float
                || (
                    image.width as usize,
                    image.height as usize,
                    image.layers as usize,
                ) != (cols, n, layers)
                || image.levels.len() != 1
            {
                return Err(Error::Table {
                    path,
                    message: format!(
                        "texture is {:?} {}x{} with {} layers; expected Rgba32Float {cols}x{n} with {layers} layers",
                        image.format, image.width, image.height, image.layers
                    ),
                });
            }
            let data = image.level_f32(0);
            for (i, v) in values.iter_mut().enumerate() {
                *v = [data[4 * i], data[4 * i + 1], data[4 * i + 2]];
            }
        } else {
            return Err(invalid("the manifest lists no integrated file".into()));
        }
        let table =
            IntegratedTable::from_values(axis, r.taylor_order, values).map_err(|source| {
                Error::OpticsIn {
                    context: manifest_path.display().to_string(),
                    source,
                }
            })?;
        Ok((r, table))
    }
}
