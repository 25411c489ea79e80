//! `film_glass`: thin-walled coated glass, a `film_stack` stack that may hold one incoherent
//! slab (`shaders/film_glass.wgsl`, [`nacre_optics::few_wavelengths::StackEvaluation`] with
//! its slab): films on the front face, a pane millimetres thick, films on the back face, in
//! reflection and transmission. Its CPU twin is `nacre color --method stack`.
//!
//! Group 1: 0 `storage, read array<StackNode>`, 1 `storage, read array<vec2<f32>>`,
//! 2 `uniform StackParams` (as `film_stack`), 3 `uniform GlassParams`.

use super::entry::{BindInputs, Slot, TechniqueEntry};
use super::options::StackSetup;
use crate::context::BufferInitExt;
use crate::error::Result;
use bytemuck::{Pod, Zeroable};
use nacre_format::gpu_params::StackGpu;
use nacre_optics::colour::Colorimeter;

/// The technique's entry.
pub const ENTRY: TechniqueEntry = TechniqueEntry {
    name: "glass",
    module: "film_glass",
    source: include_str!("../../../../shaders/film_glass.wgsl"),
    bench_label: "film_glass",
    cpu_twin: "stack",
    layout: &[Slot::Storage, Slot::Storage, Slot::Uniform, Slot::Uniform],
    bind,
};

/// Mirror of `GlassParams` (`shaders/film_glass.wgsl`): 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GlassParams {
    /// The slab's medium index s (film s, 1-based), 0: no slab.
    pub slab: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

fn bind(inputs: &BindInputs<'_>) -> Result<wgpu::BindGroup> {
    let device = inputs.device;
    let (gpu, glass) = glass_gpu(inputs.colorimeter, &inputs.options.stack)?;
    let buffer = |label: &str, contents: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    };
    let storage = wgpu::BufferUsages::STORAGE;
    let uniform = wgpu::BufferUsages::UNIFORM;
    let nodes = buffer("StackNode[]", bytemuck::cast_slice(&gpu.nodes), storage);
    let indices = buffer("stack indices", bytemuck::cast_slice(&gpu.indices), storage);
    let params = buffer("StackParams", bytemuck::bytes_of(&gpu.params), uniform);
    let glass = buffer("GlassParams", bytemuck::bytes_of(&glass), uniform);
    Ok(inputs.bind_group(
        "glass tables",
        &[
            nodes.as_entire_binding(),
            indices.as_entire_binding(),
            params.as_entire_binding(),
            glass.as_entire_binding(),
        ],
    ))
}

/// What `film_glass` reads for `setup`: `film_stack`'s nodes, indices and uniform
/// ([`StackGpu`]) and the slab's place.
pub fn glass_gpu(colorimeter: &Colorimeter, setup: &StackSetup) -> Result<(StackGpu, GlassParams)> {
    let eval = super::stack::evaluation(colorimeter, setup)?;
    let glass = GlassParams {
        slab: eval.slab().map_or(0, |s| s as u32),
        _pad: [0; 3],
    };
    Ok((StackGpu::new(&eval), glass))
}
