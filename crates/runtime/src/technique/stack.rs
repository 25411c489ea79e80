//! `film_stack`: real-time multilayer stacks at a few wavelengths chosen well
//! (`shaders/film_stack.wgsl`, [`nacre_optics::few_wavelengths`]).
//!
//! Group 1: 0 `storage, read array<StackNode>`, 1 `storage, read array<vec2<f32>>` (every
//! medium's index at every node), 2 `uniform StackParams`.

use super::entry::{BindInputs, Slot, TechniqueEntry};
use super::options::StackSetup;
use crate::context::BufferInitExt;
use crate::error::Result;
use bytemuck::{Pod, Zeroable};
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
/// holds the same numbers in f64 for the CPU twin).
pub fn stack_buffers(
    colorimeter: &Colorimeter,
    setup: &StackSetup,
) -> Result<(Vec<StackNode>, Vec<[f32; 2]>, StackParams)> {
    use nacre_optics::few_wavelengths::{BASE_COUNT, COUNT_PER_OPD_NM, StackEvaluation};
    let mut eval =
        StackEvaluation::new(colorimeter, &setup.stack, &setup.relative_nm, setup.samples)?;
    if !setup.channels.is_empty() {
        eval = eval.with_channels(&setup.channels)?;
    }
    let mut nodes = Vec::new();
    let mut u = StackParams {
        films: eval.thickness_nm().len() as u32,
        dispersive: u32::from(eval.dispersive()),
        rule_count: eval.rules().len() as u32,
        fixed: u32::from(eval.fixed()),
        base_count: BASE_COUNT as f32,
        count_per_opd_nm: COUNT_PER_OPD_NM as f32,
        finesse: eval.finesse() as f32,
        ..StackParams::default()
    };
    for (i, rule) in eval.rules().iter().enumerate() {
        u.rule_offset[i] = nodes.len() as u32;
        u.rule_size[i] = rule.wavelengths_nm().len() as u32;
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
    {
        u.layers[j] = [*d as f32, *r as f32, *k as f32, *c as f32];
    }
    let indices = eval
        .indices()
        .iter()
        .flatten()
        .map(|n| [n.re as f32, n.im as f32])
        .collect();
    Ok((nodes, indices, u))
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
