//! `film_stack`: real-time multilayer stacks at a few wavelengths chosen well
//! (`shaders/film_stack.wgsl`, [`nacre_optics::few_wavelengths`]).
//!
//! Group 1: 0 `storage, read array<StackNode>`, 1 `storage, read array<vec2<f32>>` (every
//! medium's index at every node), 2 `uniform StackParams`.

use super::entry::{BindInputs, Slot, TechniqueEntry};
use super::options::StackSetup;
use crate::context::BufferInitExt;
use crate::error::{Error, Result};
pub use nacre_format::gpu_params::{StackGpu, StackNode, StackParams};
use nacre_optics::colour::Colorimeter;

/// The technique's entry.
pub const ENTRY: TechniqueEntry = TechniqueEntry {
    name: "stack",
    module: "film_stack",
    source: include_str!("../../../../shaders/film_stack.wgsl"),
    bench_label: "film_stack",
    cpu_twin: "stack",
    layout: &[Slot::Storage, Slot::Storage, Slot::Uniform],
    bind,
};

fn bind(inputs: &BindInputs<'_>) -> Result<wgpu::BindGroup> {
    let device = inputs.device;
    let (nodes, indices, uniform) = stack_buffers(inputs.colorimeter, &inputs.options.stack)?;
    let nodes = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("StackNode[]"),
        contents: bytemuck::cast_slice(&nodes),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("stack indices"),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("StackParams"),
        contents: bytemuck::bytes_of(&uniform),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    Ok(inputs.bind_group(
        "stack tables",
        &[
            nodes.as_entire_binding(),
            indices.as_entire_binding(),
            uniform.as_entire_binding(),
        ],
    ))
}

/// Group 1 of `film_stack` for `setup`: the nodes of every rule, every medium's index at
/// every node and the uniform ([`StackEvaluation`](nacre_optics::few_wavelengths::StackEvaluation)
/// holds the same numbers in f64 for the CPU twin; [`StackGpu`] lays them out, as it does
/// for the engine libraries and `nacre export`).
pub fn stack_buffers(
    colorimeter: &Colorimeter,
    setup: &StackSetup,
) -> Result<(Vec<StackNode>, Vec<[f32; 2]>, StackParams)> {
    let gpu = stack_gpu(colorimeter, setup)?;
    Ok((gpu.nodes, gpu.indices, gpu.params))
}

/// What `film_stack` reads for `setup`, as [`StackGpu`].
///
/// # Errors
/// [`Error::IncoherentStack`] for a stack with an incoherent slab (`film_stack` sums
/// amplitudes only; `film_glass` draws it); the evaluation's errors.
pub fn stack_gpu(colorimeter: &Colorimeter, setup: &StackSetup) -> Result<StackGpu> {
    let eval = evaluation(colorimeter, setup)?;
    if let Some(layer) = eval.slab() {
        return Err(Error::IncoherentStack {
            technique: ENTRY.name,
            layer,
        });
    }
    Ok(StackGpu::new(&eval))
}

/// The evaluation of `setup` (its stack, relative thicknesses, map channels and rule), which
/// `film_stack` and `film_glass` upload and the CPU twin evaluates.
pub(super) fn evaluation(
    colorimeter: &Colorimeter,
    setup: &StackSetup,
) -> Result<nacre_optics::few_wavelengths::StackEvaluation> {
    use nacre_optics::few_wavelengths::StackEvaluation;
    let mut eval =
        StackEvaluation::new(colorimeter, &setup.stack, &setup.relative_nm, setup.samples)?;
    if !setup.channels.is_empty() {
        eval = eval.with_channels(&setup.channels)?;
    }
    Ok(eval)
}
