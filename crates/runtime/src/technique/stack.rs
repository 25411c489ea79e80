//! `film_stack`: real-time multilayer stacks at a few wavelengths chosen well
//! (`shaders/film_stack.wgsl`, [`nacre_optics::few_wavelengths`]).
//!
//! Group 1: 0 `storage, read array<StackNode>`, 1 `storage, read array<vec2<f32>>` (every
//! medium's index at every node), 2 `uniform StackParams`.

use super::{BindInputs, Slot, Technique, TechniqueEntry};
use crate::context::BufferInitExt;
use crate::error::{Error, Result};
use bytemuck::{Pod, Zeroable};
use nacre_optics::colour::Colorimeter;

/// The technique's entry.
pub const ENTRY: TechniqueEntry = TechniqueEntry {
    technique: Technique::Stack,
    name: "stack",
    module: crate::wgsl_module!("film_stack"),
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

/// What `film_stack` evaluates: a stack of 1 to 8 films whose top film takes the pixel's
/// thickness and whose other films vary as d_j + r_j s_c, s_c from their channel c of the
/// thickness map ([`nacre_optics::few_wavelengths::StackEvaluation`]).
#[derive(Clone, Debug)]
pub struct StackSetup {
    /// Ambient, films (their own thicknesses d_j⁰) and base.
    pub stack: nacre_optics::Stack,
    /// Relative thickness r_j of each film, nm (the top film's is unused).
    pub relative_nm: Vec<f64>,
    /// Each film's thickness-map channel (0 R or grey, 1 G, 2 B; the top film's is unused:
    /// it follows the material's thickness mapping of channel R); empty: every film follows
    /// channel R.
    pub channels: Vec<usize>,
    /// `None`: the rule ladder (counts from the pixel's OPD); `Some(N)`: N nodes everywhere.
    pub samples: Option<usize>,
}

impl Default for StackSetup {
    /// A two-film dielectric stack in air on glass (n 1.5): 100 nm of n 1.38 over 60 nm of
    /// n 2.3, the lower film varying by ±30 nm.
    fn default() -> Self {
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layers = vec![
            nacre_optics::Layer {
                material: constant(1.38),
                thickness_nm: 100.0,
            },
            nacre_optics::Layer {
                material: constant(2.3),
                thickness_nm: 60.0,
            },
        ];
        StackSetup {
            stack: nacre_optics::Stack::new(constant(1.0), layers, constant(1.5))
                .expect("finite thicknesses and a clear ambient"),
            relative_nm: vec![0.0, 30.0],
            channels: Vec::new(),
            samples: None,
        }
    }
}

impl StackSetup {
    /// A dielectric stack of `films` (1 to 8) films in air on glass (n 1.5), alternating
    /// n 1.38 (100 nm) and n 2.3 (60 nm), every film below the top varying by ±20 nm: the
    /// stacks `nacre bench-gpu` times.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a film count outside 1 to 8.
    pub fn alternating(films: usize) -> Result<StackSetup> {
        if !(1..=nacre_optics::few_wavelengths::MAX_STACK_FILMS).contains(&films) {
            return Err(Error::OutOfRange {
                what: "film_stack: films".into(),
                value: films as f64,
                unit: "",
                expected: format!("1 to {}", nacre_optics::few_wavelengths::MAX_STACK_FILMS),
            });
        }
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layers = (0..films)
            .map(|j| nacre_optics::Layer {
                material: constant(if j % 2 == 0 { 1.38 } else { 2.3 }),
                thickness_nm: if j % 2 == 0 { 100.0 } else { 60.0 },
            })
            .collect();
        Ok(StackSetup {
            stack: nacre_optics::Stack::new(constant(1.0), layers, constant(1.5))?,
            relative_nm: (0..films)
                .map(|j| if j == 0 { 0.0 } else { 20.0 })
                .collect(),
            channels: Vec::new(),
            samples: None,
        })
    }
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
