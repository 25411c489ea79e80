//! Host-side mirrors of the WGSL structs in `shaders/` (`#[repr(C)]`, `bytemuck`), with the
//! byte layouts the shaders document.

use bytemuck::{Pod, Zeroable};

/// Mirror of `FilmInput` (`shaders/common.wgsl`): 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FilmInput {
    /// cos θᵢ in the ambient.
    pub cos_theta_i: f32,
    /// Film thickness d, nm.
    pub thickness_nm: f32,
    /// Real film index n₂.
    pub film_ior: f32,
    /// Standard deviation of d within the pixel, nm (prefiltering; `film_fourier`).
    pub sigma_thickness_nm: f32,
    /// Ambient index n₁.
    pub ambient_ior: f32,
    /// Spatial variation s = 2g − 1 ∈ [−1, 1] of a stack's lower films from the thickness
    /// map's channel R or grey (`film_stack`: film j ≥ 2 is d_j + r_j s_c for its map
    /// channel c); the other techniques ignore it.
    pub variation: f32,
    /// The same from the map's channel G.
    pub variation_g: f32,
    /// The same from the map's channel B.
    pub variation_b: f32,
    /// Base index per output channel, real part.
    pub base_ior: [f32; 3],
    /// Padding.
    pub _pad3: f32,
    /// Base index per output channel, imaginary part κ ≥ 0.
    pub base_kappa: [f32; 3],
    /// Padding.
    pub _pad4: f32,
}

/// Mirror of `FilmOutput`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FilmOutput {
    /// Reflectance colour.
    pub reflectance: [f32; 3],
    /// Transmittance colour.
    pub transmittance: [f32; 3],
}

/// Mirror of `FilmLutParams` (`shaders/lut_mapping.wgsl`): 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FilmLutParams {
    /// Texels along x (cos θ).
    pub cos_theta_count: u32,
    /// Texels along y (Δ).
    pub opd_count: u32,
    /// Texels along z (film index).
    pub ior_count: u32,
    /// Smallest thickness, nm.
    pub thickness_min_nm: f32,
    /// Largest thickness, nm.
    pub thickness_max_nm: f32,
    /// Smallest film index.
    pub ior_min: f32,
    /// Largest film index.
    pub ior_max: f32,
    /// Ambient index n₀.
    pub ambient_index: f32,
    /// 1 when the table has a transmittance, else 0.
    pub has_transmittance: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

impl FilmLutParams {
    /// From a table's axes.
    pub fn new(axes: &nacre_format::film_lut::FilmLutAxes, has_transmittance: bool) -> Self {
        FilmLutParams {
            cos_theta_count: axes.cos_theta_count as u32,
            opd_count: axes.opd_count as u32,
            ior_count: axes.ior_count as u32,
            thickness_min_nm: axes.thickness_min_nm as f32,
            thickness_max_nm: axes.thickness_max_nm as f32,
            ior_min: axes.ior_min as f32,
            ior_max: axes.ior_max as f32,
            ambient_index: axes.ambient_index as f32,
            has_transmittance: u32::from(has_transmittance),
            _pad: [0; 3],
        }
    }
}

/// Mirror of `FourierParams` (`shaders/film_fourier.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FourierParams {
    /// D_max, nm.
    pub max_opd_nm: f32,
    /// Mip levels.
    pub level_count: u32,
    /// σ of level 1, nm.
    pub sigma1_nm: f32,
    /// Harmonics M (0: automatic).
    pub harmonics: u32,
    /// Carrier ν̄_j, 1/nm.
    pub carrier_nu_per_nm: [f32; 3],
    /// Padding.
    pub _pad0: f32,
    /// ‖s_j‖: colour of a perfect reflector.
    pub white: [f32; 3],
    /// Padding.
    pub _pad1: f32,
}

impl FourierParams {
    /// From a table's axes and the harmonics to sum (0: automatic).
    pub fn new(axes: &nacre_format::fourier::FourierAxes, harmonics: u32) -> Self {
        FourierParams {
            max_opd_nm: axes.max_opd_nm as f32,
            level_count: axes.level_samples.len() as u32,
            sigma1_nm: axes.level_sigma_nm.get(1).copied().unwrap_or(0.0) as f32,
            harmonics,
            carrier_nu_per_nm: axes.carrier_nu_per_nm.map(|v| v as f32),
            _pad0: 0.0,
            white: axes.white.map(|v| v as f32),
            _pad1: 0.0,
        }
    }
}

/// Mirror of `SpectralSample` (`shaders/film_spectral.wgsl`): 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SpectralSample {
    /// λ, nm.
    pub wavelength_nm: f32,
    /// Base index at λ, real part.
    pub base_ior: f32,
    /// Base index at λ, imaginary part.
    pub base_kappa: f32,
    /// Padding.
    pub _pad: f32,
    /// Weight per channel (Σ over samples = white); w unused.
    pub weight: [f32; 4],
}

/// Mirror of `SpectralParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SpectralParams {
    /// Samples N.
    pub count: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

impl SpectralParams {
    /// For `count` samples.
    pub fn new(count: usize) -> Self {
        SpectralParams {
            count: count as u32,
            _pad: [0; 3],
        }
    }
}

/// Mirror of `StackNode` (`shaders/film_stack.wgsl`): 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StackNode {
    /// Node wavelength λ_k, nm.
    pub wavelength_nm: f32,
    /// Padding.
    pub _pad: [f32; 3],
    /// Per-channel weight W_k (rgb), 0.
    pub weight: [f32; 4],
}

/// Mirror of `StackParams` (`shaders/film_stack.wgsl`): 288 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StackParams {
    /// Films F.
    pub films: u32,
    /// 1 when some index varies with wavelength.
    pub dispersive: u32,
    /// Rules in the ladder.
    pub rule_count: u32,
    /// 1: always rule 0 (`stack:N`).
    pub fixed: u32,
    /// N at OPD 0.
    pub base_count: f32,
    /// Samples per nm of OPD.
    pub count_per_opd_nm: f32,
    /// The stack's finesse factor h.
    pub finesse: f32,
    /// Padding.
    pub _pad0: f32,
    /// First node of rule i.
    pub rule_offset: [u32; 16],
    /// Nodes of rule i.
    pub rule_size: [u32; 16],
    /// Film j: (d_j⁰, r_j, k_j, 0).
    pub layers: [[f32; 4]; 8],
}
