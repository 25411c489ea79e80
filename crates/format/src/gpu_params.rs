//! The uniforms that mirror a table kind's axes on the GPU, defined once for the runtime
//! (`nacre_runtime::params`), engine integrations (the Bevy plugin) and the JSON sidecars of
//! `nacre export` ([`crate::export`]).
//!
//! Each struct is `#[repr(C)]` and `bytemuck::Pod` with the byte layout of its WGSL twin
//! (`crates/runtime/tests/wgsl.rs` checks sizes and offsets against naga). One field list
//! makes both the struct (f32/u32, what the GPU reads) and `shader_params` (the same fields
//! with the manifest's own numbers, f64 and integers, without padding: what a sidecar
//! records), so the two cannot drift apart.
//!
//! `film_stack` reads no table: [`StackGpu`] holds what it reads instead (nodes, indices
//! and [`StackParams`], prepared from a [`nacre_optics::few_wavelengths::StackEvaluation`]),
//! for the runtime, the engine libraries' stack table and `nacre export`'s stack JSON.

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

            /// The uniform's bytes, as the GPU reads them.
            pub fn as_bytes(&self) -> &[u8] {
                bytemuck::bytes_of(self)
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

/// Most films of a `film_stack` stack (`STACK_MAX_FILMS` of `shaders/film_stack.wgsl`).
pub const STACK_MAX_FILMS: usize = nacre_optics::few_wavelengths::MAX_STACK_FILMS;

/// Most rules of a `film_stack` ladder (the 16 slots of `StackParams::rule_offset`).
pub const STACK_MAX_RULES: usize = 16;

/// Texels per row of the engine libraries' stack table ([`StackGpu::texels`]): the node,
/// then the (n, κ) of two media per texel for up to [`STACK_MAX_FILMS`] + 2 media.
pub const STACK_TEXTURE_WIDTH: usize = 1 + (STACK_MAX_FILMS + 2).div_ceil(2);

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
    pub fixed_rule: u32,
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
    /// Film j: (d_j⁰, r_j, k_j, c_j).
    pub layers: [[f32; 4]; 8],
}

/// Everything `film_stack` reads, in the GPU's numbers: the nodes of every rule (rules
/// concatenated), every medium's index at every node (node-major: node k, medium m at
/// `k · media + m`, medium 0 the ambient, 1 … F the films top first, F + 1 the base) and the
/// uniform. One preparation for the runtime's storage buffers, the engine libraries' stack
/// table ([`StackGpu::texels`]), the Bevy plugin and `nacre export`'s stack JSON
/// ([`crate::export::stack_json`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StackGpu {
    /// The nodes (`array<StackNode>`).
    pub nodes: Vec<StackNode>,
    /// Every medium's index (n, κ) at every node (`array<vec2<f32>>`).
    pub indices: Vec<[f32; 2]>,
    /// The uniform.
    pub params: StackParams,
}

impl StackGpu {
    /// The GPU's numbers of `eval` (f64 rounded to nearest f32).
    pub fn new(eval: &nacre_optics::few_wavelengths::StackEvaluation) -> Self {
        use nacre_optics::few_wavelengths::{BASE_COUNT, COUNT_PER_OPD_NM};
        let mut nodes = Vec::new();
        let mut params = StackParams {
            films: eval.thickness_nm().len() as u32,
            dispersive: u32::from(eval.dispersive()),
            rule_count: eval.rules().len() as u32,
            fixed_rule: u32::from(eval.fixed()),
            base_count: BASE_COUNT as f32,
            count_per_opd_nm: COUNT_PER_OPD_NM as f32,
            finesse: eval.finesse() as f32,
            ..StackParams::default()
        };
        for (i, rule) in eval.rules().iter().enumerate().take(STACK_MAX_RULES) {
            params.rule_offset[i] = nodes.len() as u32;
            params.rule_size[i] = rule.wavelengths_nm().len() as u32;
            for (&l, w) in rule.wavelengths_nm().iter().zip(rule.weights()) {
                nodes.push(StackNode {
                    wavelength_nm: l as f32,
                    _pad: [0.0; 3],
                    weight: [w[0] as f32, w[1] as f32, w[2] as f32, 0.0],
                });
            }
        }
        for (j, (((d, r), k), c)) in eval
            .thickness_nm()
            .iter()
            .zip(eval.relative_nm())
            .zip(eval.opd_factors())
            .zip(eval.channels())
            .enumerate()
            .take(STACK_MAX_FILMS)
        {
            params.layers[j] = [*d as f32, *r as f32, *k as f32, *c as f32];
        }
        let indices = eval
            .indices()
            .iter()
            .flatten()
            .map(|n| [n.re as f32, n.im as f32])
            .collect();
        StackGpu {
            nodes,
            indices,
            params,
        }
    }

    /// Media M = F + 2 (ambient, films, base).
    pub fn media(&self) -> usize {
        self.params.films as usize + 2
    }

    /// The stack table of the engine libraries (`nacre_film_stack_colour` in
    /// `shaders/glsl/nacre.glsl` and `shaders/hlsl/nacre.hlsl`): an RGBA32F 2-D texture of
    /// [`STACK_TEXTURE_WIDTH`] × (node count) texels, row-major (x fastest), row k node k:
    /// texel (0, k) = (λ_k nm, W_k,r, W_k,g, W_k,b); texel (1 + i, k) = (n, κ) of medium 2i
    /// and (n, κ) of medium 2i + 1 (zeros past the last medium).
    pub fn texels(&self) -> Vec<[f32; 4]> {
        let media = self.media();
        let mut texels = vec![[0.0f32; 4]; STACK_TEXTURE_WIDTH * self.nodes.len()];
        for (k, node) in self.nodes.iter().enumerate() {
            let row = &mut texels[k * STACK_TEXTURE_WIDTH..(k + 1) * STACK_TEXTURE_WIDTH];
            row[0] = [
                node.wavelength_nm,
                node.weight[0],
                node.weight[1],
                node.weight[2],
            ];
            for m in 0..media.min(2 * (STACK_TEXTURE_WIDTH - 1)) {
                let n = self.indices.get(k * media + m).copied().unwrap_or([0.0; 2]);
                let texel = &mut row[1 + m / 2];
                texel[2 * (m % 2)] = n[0];
                texel[2 * (m % 2) + 1] = n[1];
            }
        }
        texels
    }
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
        assert_eq!(std::mem::size_of::<StackNode>(), 32);
        assert_eq!(std::mem::size_of::<StackParams>(), 288);
        assert_eq!(std::mem::offset_of!(StackParams, layers), 160);
        assert_eq!(STACK_TEXTURE_WIDTH, 6);
    }
}
