//! Host-side mirrors of the WGSL structs in `shaders/` (`#[repr(C)]`, `bytemuck`), with the
//! byte layouts the shaders document: the film input and output every technique shares
//! here; the uniforms that mirror a table kind's axes in `nacre_format::gpu_params` (shared
//! with engine integrations and `nacre export`); a technique's own buffers in its file of
//! [`crate::technique`].

pub use crate::technique::{SpectralParams, SpectralSample, StackNode, StackParams};
pub use nacre_format::gpu_params::{FilmLutParams, FourierParams};

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
