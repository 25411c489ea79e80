//! The uniforms that mirror a table kind's axes on the GPU, defined once for the runtime
//! (`nacre_runtime::params`), engine integrations (the Bevy plugin) and the JSON sidecars of
//! `nacre export` ([`crate::export`]).
//!
//! Each struct is `#[repr(C)]` and `bytemuck::Pod` with the byte layout of its WGSL twin
//! (`crates/runtime/tests/wgsl.rs` checks sizes and offsets against naga). One field list
//! makes both the struct (f32/u32, what the GPU reads) and `shader_params` (the same fields
//! with the manifest's own numbers, f64 and integers, without padding: what a sidecar
//! records), so the two cannot drift apart.

use crate::film_lut::FilmLutAxes;
use crate::fourier::FourierAxes;
use crate::rough_film_lut::RoughLutAxes;
use bytemuck::{Pod, Zeroable};

/// A manifest number as the GPU reads it: integers as `u32`, reals as `f32` (rounded to
/// nearest).
pub trait ToGpu {
    /// The GPU's type.
    type Gpu;
    /// The value in that type.
    fn to_gpu(self) -> Self::Gpu;
}

impl ToGpu for usize {
    type Gpu = u32;
    fn to_gpu(self) -> u32 {
        self as u32
    }
}

impl ToGpu for u32 {
    type Gpu = u32;
    fn to_gpu(self) -> u32 {
        self
    }
}

impl ToGpu for f64 {
    type Gpu = f32;
    fn to_gpu(self) -> f32 {
        self as f32
    }
}

impl ToGpu for [f64; 3] {
    type Gpu = [f32; 3];
    fn to_gpu(self) -> [f32; 3] {
        self.map(|v| v as f32)
    }
}

/// Defines a uniform from one field list: `field: type = value` (the value in the manifest's
/// own type, converted by [`ToGpu`]), then the padding fields.
macro_rules! uniform {
    (
        $(#[$meta:meta])*
        $name:ident ($($arg:ident: $arg_ty:ty),*) {
            $($(#[$fmeta:meta])* $field:ident: $ty:ty = $value:expr,)*
        }
        padding { $($pad:ident: $pad_ty:ty = $pad_value:expr,)* }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)*
            $(
                /// Padding.
                pub $pad: $pad_ty,
            )*
        }

        impl $name {
            /// The uniform of a table with these axes.
            pub fn new($($arg: $arg_ty),*) -> Self {
                $name {
                    $($field: ToGpu::to_gpu($value),)*
                    $($pad: $pad_value,)*
                }
            }

            /// The same fields as JSON, with the manifest's numbers (no padding): the
            /// `shader_params` of an exported sidecar.
            pub fn shader_params($($arg: $arg_ty),*) -> serde_json::Value {
                serde_json::json!({ $(stringify!($field): $value,)* })
            }
        }
    };
}

uniform! {
    /// Mirror of `FilmLutParams` (`shaders/lut_mapping.wgsl`): 48 bytes.
    FilmLutParams(axes: &FilmLutAxes, has_transmittance: bool) {
        /// Texels along x (cos θ).
        cos_theta_count: u32 = axes.cos_theta_count,
        /// Texels along y (Δ).
        opd_count: u32 = axes.opd_count,
        /// Texels along z (film index).
        ior_count: u32 = axes.ior_count,
        /// Smallest thickness, nm.
        thickness_min_nm: f32 = axes.thickness_min_nm,
        /// Largest thickness, nm.
        thickness_max_nm: f32 = axes.thickness_max_nm,
        /// Smallest film index.
        ior_min: f32 = axes.ior_min,
        /// Largest film index.
        ior_max: f32 = axes.ior_max,
        /// Ambient index n₀.
        ambient_index: f32 = axes.ambient_index,
        /// 1 when the table has a transmittance, else 0.
        has_transmittance: u32 = u32::from(has_transmittance),
    }
    padding { _pad: [u32; 3] = [0; 3], }
}

uniform! {
    /// Mirror of `FourierParams` (`shaders/film_fourier.wgsl`): 48 bytes. `harmonics` is the
    /// number M of harmonics to sum (0: automatic).
    FourierParams(axes: &FourierAxes, harmonics: u32) {
        /// D_max, nm.
        max_opd_nm: f32 = axes.max_opd_nm,
        /// Mip levels.
        level_count: u32 = axes.level_samples.len(),
        /// σ of level 1, nm.
        sigma1_nm: f32 = axes.level_sigma_nm.get(1).copied().unwrap_or(0.0),
        /// Harmonics M (0: automatic).
        harmonics: u32 = harmonics,
        /// Carrier ν̄_j, 1/nm.
        carrier_nu_per_nm: [f32; 3] = axes.carrier_nu_per_nm,
        /// Padding.
        _pad0: f32 = 0.0,
        /// ‖s_j‖: colour of a perfect reflector.
        white: [f32; 3] = axes.white,
    }
    padding { _pad1: f32 = 0.0, }
}

uniform! {
    /// Mirror of `RoughLutParams` (`shaders/rough_lut_mapping.wgsl`): 48 bytes.
    RoughLutParams(axes: &RoughLutAxes, has_transmittance: bool) {
        /// Texels along cos θ_o.
        cos_theta_count: u32 = axes.cos_theta_count,
        /// Texels along Δ.
        opd_count: u32 = axes.opd_count,
        /// Texels along the film index per α block.
        ior_count: u32 = axes.ior_count,
        /// α blocks.
        alpha_count: u32 = axes.alpha_count,
        /// d_max, nm.
        thickness_max_nm: f32 = axes.thickness_max_nm,
        /// Smallest film index.
        ior_min: f32 = axes.ior_min,
        /// Largest film index.
        ior_max: f32 = axes.ior_max,
        /// Smallest α.
        alpha_min: f32 = axes.alpha_min,
        /// Largest α.
        alpha_max: f32 = axes.alpha_max,
        /// Ambient index n₀.
        ambient_index: f32 = axes.ambient_index,
        /// 1 when the table has a transmittance.
        has_transmittance: u32 = u32::from(has_transmittance),
    }
    padding { _pad0: u32 = 0, }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_match_the_wgsl() {
        assert_eq!(std::mem::size_of::<FilmLutParams>(), 48);
        assert_eq!(std::mem::size_of::<FourierParams>(), 48);
        assert_eq!(std::mem::size_of::<RoughLutParams>(), 48);
        assert_eq!(std::mem::offset_of!(RoughLutParams, has_transmittance), 40);
        assert_eq!(std::mem::offset_of!(FourierParams, white), 32);
    }
}
