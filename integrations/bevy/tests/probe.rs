//! GPU = CPU inside Bevy: a compute pass through the plugin's shader modules (nacre's
//! `film_lut` and `film_fourier`, composed by Bevy's naga_oil shader system from the
//! repository's WGSL), on the tables as the plugin loads them (the built-in default set),
//! against the CPU references of `nacre color --method lut:film-dielectric` (the trilinear
//! lookup `nacre_format::film_lut::FilmLut::lookup` on the same KTX2 texels) and
//! `--method fourier:auto` (`nacre_optics::fourier::FilmOnBase::fourier_colour_with` on
//! the same table), over a grid of (cos θ, thickness, film index, base): within 2×10⁻³ per
//! channel; and `film_stack` (the stack's buffers as [`NacreFilm::set_stack`] uploads them)
//! against its CPU twin `StackEvaluation::colour` (`nacre color --method stack`) for a
//! dispersive, absorbing four-film stack on silicon with one map channel per film, over the
//! same points with random variations: within 10⁻⁴ per channel. A missing adapter fails the
//! test.

use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::binding_types::{
    sampler, storage_buffer_read_only_sized, storage_buffer_sized, texture_2d_array, texture_3d,
    uniform_buffer_sized,
};
use bevy::render::render_resource::encase::UniformBuffer;
use bevy::render::render_resource::{
    BindGroupEntries, BindGroupLayoutDescriptor, BindGroupLayoutEntries, BufferDescriptor,
    BufferInitDescriptor, BufferUsages, CachedComputePipelineId, CachedPipelineState,
    CommandEncoderDescriptor, ComputePassDescriptor, ComputePipelineDescriptor, MapMode,
    PipelineCache, PollType, SamplerBindingType, ShaderStages, ShaderType, TextureSampleType,
};
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::texture::GpuImage;
use bevy::render::{Render, RenderApp, RenderSystems};
use bevy::shader::{Shader, ShaderDefVal};
use bevy_nacre::tables::{FilmLutUniform, FourierUniform, NacreTableAxes};
use bevy_nacre::{DEFAULT_FILM_LUT, DEFAULT_FOURIER, NacreTable, StackUniform};
use nacre_format::Manifest;
use nacre_format::film_lut::FilmLut;
use nacre_format::gpu_params::StackGpu;
use nacre_optics::C64;
use nacre_optics::few_wavelengths::StackEvaluation;
use nacre_optics::fourier::{FilmOnBase, Harmonics};
use std::sync::{Arc, Mutex};

mod support;
use support::{headless_app, repo_root};

/// Floats per `FilmInput` (64 bytes).
const STRIDE: usize = 16;
/// Floats per `ProbeOutput` (96 bytes).
const OUT_STRIDE: usize = 24;

type Slot = Arc<Mutex<Option<Result<Vec<f32>, String>>>>;

#[derive(Resource)]
struct Probe {
    inputs: Vec<f32>,
    layout: BindGroupLayoutDescriptor,
    pipeline: CachedComputePipelineId,
    images: [Handle<Image>; 3],
    lut_axes: FilmLutUniform,
    fourier_axes: FourierUniform,
    stack: StackGpu,
    result: Slot,
    done: bool,
}

fn uniform_bytes<T: ShaderType + bevy::render::render_resource::encase::internal::WriteInto>(
    value: &T,
) -> Vec<u8> {
    let mut buffer = UniformBuffer::new(Vec::new());
    buffer.write(value).unwrap();
    buffer.into_inner()
}

fn run_probe(
    mut probe: ResMut<Probe>,
    cache: Res<PipelineCache>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    images: Res<RenderAssets<GpuImage>>,
) {
    if probe.done {
        return;
    }
    let Some(pipeline) = cache.get_compute_pipeline(probe.pipeline) else {
        if let CachedPipelineState::Err(e) = cache.get_compute_pipeline_state(probe.pipeline) {
            *probe.result.lock().unwrap() = Some(Err(format!("probe pipeline: {e}")));
            probe.done = true;
        }
        return;
    };
    let [Some(lut_r), Some(lut_t), Some(fourier)] = probe.images.clone().map(|h| images.get(&h))
    else {
        return;
    };
    let floats_to_bytes = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let count = probe.inputs.len() / STRIDE;
    let size = (count * OUT_STRIDE * 4) as u64;
    let input = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("nacre probe inputs"),
        contents: &floats_to_bytes(&probe.inputs),
        usage: BufferUsages::STORAGE,
    });
    let output = device.create_buffer(&BufferDescriptor {
        label: Some("nacre probe outputs"),
        size,
        usage: BufferUsages::STORAGE | BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&BufferDescriptor {
        label: Some("nacre probe readback"),
        size,
        usage: BufferUsages::MAP_READ | BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let lut_params = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("FilmLutParams"),
        contents: &uniform_bytes(&probe.lut_axes),
        usage: BufferUsages::UNIFORM,
    });
    let fourier_params = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("FourierParams"),
        contents: &uniform_bytes(&probe.fourier_axes),
        usage: BufferUsages::UNIFORM,
    });
    let stack_nodes = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("StackNode[]"),
        contents: bytemuck::cast_slice(&probe.stack.nodes),
        usage: BufferUsages::STORAGE,
    });
    let stack_indices = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("stack indices"),
        contents: bytemuck::cast_slice(&probe.stack.indices),
        usage: BufferUsages::STORAGE,
    });
    let stack_params = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("StackParams"),
        contents: &uniform_bytes(&StackUniform::from(&probe.stack.params)),
        usage: BufferUsages::UNIFORM,
    });
    let layout = cache.get_bind_group_layout(&probe.layout);
    let bind_group = device.create_bind_group(
        "nacre probe",
        &layout,
        &BindGroupEntries::with_indices((
            (0, input.as_entire_binding()),
            (1, output.as_entire_binding()),
            (100, &lut_r.texture_view),
            (101, &lut_t.texture_view),
            (102, &lut_r.sampler),
            (103, lut_params.as_entire_binding()),
            (104, &fourier.texture_view),
            (105, fourier_params.as_entire_binding()),
            (111, stack_nodes.as_entire_binding()),
            (112, stack_indices.as_entire_binding()),
            (113, stack_params.as_entire_binding()),
        )),
    );
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_compute_pass(&ComputePassDescriptor::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(count.div_ceil(64) as u32, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    queue.submit([encoder.finish()]);
    let slice = readback.slice(..);
    slice.map_async(MapMode::Read, |r| {
        r.expect("mapping the probe's readback buffer")
    });
    device
        .poll(PollType::Wait {
            submission_index: None,
            timeout: None,
        })
        .expect("waiting for the probe");
    let floats: Vec<f32> = slice
        .get_mapped_range()
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    *probe.result.lock().unwrap() = Some(Ok(floats));
    probe.done = true;
}

/// Runs the probe on `inputs` (STRIDE floats each, `FilmInput`'s layout) with `stack`; per
/// input (lut R, lut T, fourier R, fourier T, stack R, stack T).
fn gpu_probe(inputs: Vec<f32>, stack: StackGpu) -> Vec<[[f32; 3]; 6]> {
    let mut app = headless_app(&repo_root());
    let (lut, fourier) = {
        let tables = app.world().resource::<Assets<NacreTable>>();
        let lut = tables.get(&DEFAULT_FILM_LUT).unwrap().clone();
        let fourier = tables.get(&DEFAULT_FOURIER).unwrap().clone();
        (lut, fourier)
    };
    let (NacreTableAxes::FilmLut(lut_axes), NacreTableAxes::Fourier(fourier_axes)) =
        (lut.axes.clone(), fourier.axes.clone())
    else {
        panic!("the default set is a film-lut and a fourier table");
    };
    let shader = app
        .world_mut()
        .resource_mut::<Assets<Shader>>()
        .add(Shader::from_wgsl(
            include_str!("probe.wgsl"),
            "bevy_nacre/tests/probe.wgsl",
        ));
    let result: Slot = Arc::default();
    let layout = BindGroupLayoutDescriptor::new(
        "nacre probe",
        &BindGroupLayoutEntries::with_indices(
            ShaderStages::COMPUTE,
            (
                (0, storage_buffer_read_only_sized(false, None)),
                (1, storage_buffer_sized(false, None)),
                (
                    100,
                    texture_3d(TextureSampleType::Float { filterable: true }),
                ),
                (
                    101,
                    texture_3d(TextureSampleType::Float { filterable: true }),
                ),
                (102, sampler(SamplerBindingType::Filtering)),
                (103, uniform_buffer_sized(false, None)),
                (
                    104,
                    texture_2d_array(TextureSampleType::Float { filterable: false }),
                ),
                (105, uniform_buffer_sized(false, None)),
                (111, storage_buffer_read_only_sized(false, None)),
                (112, storage_buffer_read_only_sized(false, None)),
                (113, uniform_buffer_sized(false, None)),
            ),
        ),
    );
    let render_app = app.sub_app_mut(RenderApp);
    let pipeline = render_app
        .world()
        .resource::<PipelineCache>()
        .queue_compute_pipeline(ComputePipelineDescriptor {
            label: Some("nacre probe".into()),
            layout: vec![layout.clone()],
            immediate_size: 0,
            shader,
            shader_defs: vec![ShaderDefVal::UInt("MATERIAL_BIND_GROUP".into(), 0)],
            entry_point: Some("probe".into()),
            zero_initialize_workgroup_memory: true,
        });
    render_app.insert_resource(Probe {
        inputs,
        layout,
        pipeline,
        images: [
            lut.texture.clone(),
            lut.transmittance
                .clone()
                .expect("film-dielectric has a transmittance"),
            fourier.texture.clone(),
        ],
        lut_axes,
        fourier_axes,
        stack,
        result: result.clone(),
        done: false,
    });
    render_app.add_systems(Render, run_probe.in_set(RenderSystems::Cleanup));
    for _ in 0..200 {
        app.update();
        if let Some(r) = result.lock().unwrap().take() {
            let floats = r.unwrap_or_else(|e| panic!("{e}"));
            return floats
                .chunks_exact(OUT_STRIDE)
                .map(|o| std::array::from_fn(|k| [o[4 * k], o[4 * k + 1], o[4 * k + 2]]))
                .collect();
        }
    }
    panic!("the probe never ran");
}

/// Deterministic uniform numbers in [0, 1) (the runtime's probe tests' generator).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Point {
    cos_theta: f64,
    thickness_nm: f64,
    film_ior: f64,
    base: C64,
    variation: [f64; 3],
}

fn film_input(p: &Point) -> [f32; STRIDE] {
    let mut v = [0.0f32; STRIDE];
    v[0] = p.cos_theta as f32;
    v[1] = p.thickness_nm as f32;
    v[2] = p.film_ior as f32;
    v[4] = 1.0; // ambient
    for c in 0..3 {
        v[5 + c] = p.variation[c] as f32;
    }
    v[8..11].fill(p.base.re as f32);
    v[12..15].fill(p.base.im as f32);
    v
}

fn max_diff(cpu: &[[f64; 3]], gpu: &[[f32; 3]]) -> (f64, usize) {
    let mut worst = (0.0f64, 0usize);
    for (i, (x, y)) in cpu.iter().zip(gpu).enumerate() {
        for c in 0..3 {
            let d = (x[c] - f64::from(y[c])).abs();
            if d.is_nan() || d > worst.0 {
                worst = (d, i);
            }
        }
    }
    worst
}

#[test]
fn the_plugins_shader_functions_match_nacre_color() {
    let baked = repo_root().join("tables/baked");
    let lut_path = baked.join("film-dielectric.json");
    let lut_manifest = Manifest::read(&lut_path).unwrap();
    let axes = lut_manifest.film_lut().cloned().unwrap();
    let refl = lut_manifest
        .load_table(&lut_path, "reflectance")
        .unwrap()
        .unwrap();
    let trans = lut_manifest
        .load_table(&lut_path, "transmittance")
        .unwrap()
        .unwrap();
    let fourier_path = baked.join("fourier-srgb.json");
    let fourier_manifest = Manifest::read(&fourier_path).unwrap();
    let fourier = fourier_manifest.load_fourier(&fourier_path).unwrap();
    let colorimeter = fourier_manifest.colorimeter(&fourier_path).unwrap();

    // A grid over cos θ × thickness × film index for the film-lut (on its baked base 1.5),
    // and random points on four bases (dielectric, high-index, two metals) for fourier.
    let mut lut_points = Vec::new();
    for i in 0..=8 {
        for j in 0..=24 {
            for k in 0..=6 {
                lut_points.push(Point {
                    cos_theta: f64::from(i) / 8.0,
                    thickness_nm: axes.thickness_max_nm * f64::from(j) / 24.0,
                    film_ior: axes.ior_min + (axes.ior_max - axes.ior_min) * f64::from(k) / 6.0,
                    base: C64::new(1.5, 0.0),
                    variation: [f64::from(i) / 4.0 - 1.0, f64::from(k) / 3.0 - 1.0, 0.5],
                });
            }
        }
    }
    let mut rng = Lcg(19);
    let mut fourier_points = Vec::new();
    for base in [
        C64::new(1.5, 0.0),
        C64::new(2.2, 0.0),
        C64::new(0.27, 2.9),
        C64::new(1.2, 1.5),
    ] {
        for _ in 0..300 {
            fourier_points.push(Point {
                cos_theta: (rng.next() * 85.0).to_radians().cos(),
                thickness_nm: rng.next() * 2000.0,
                film_ior: 1.2 + rng.next() * 1.2,
                base,
                variation: [(); 3].map(|_| 2.0 * rng.next() - 1.0),
            });
        }
    }
    let inputs: Vec<f32> = lut_points
        .iter()
        .chain(&fourier_points)
        .flat_map(film_input)
        .collect();
    // A dispersive, absorbing stack: MgF₂, TiO₂, 8 nm of chromium and water on silicon, one
    // map channel per film.
    let bundled = |name: &str| nacre_format::materials::resolve(name, "test", None).unwrap();
    let layer = |name: &str, thickness_nm: f64| nacre_optics::Layer {
        material: bundled(name),
        thickness_nm,
    };
    let stack = nacre_optics::Stack::new(
        bundled("air"),
        vec![
            layer("mgf2", 90.0),
            layer("tio2", 50.0),
            layer("cr", 8.0),
            layer("water", 200.0),
        ],
        bundled("si"),
    )
    .unwrap();
    let eval = StackEvaluation::new(&colorimeter, &stack, &[0.0, 15.0, 3.0, 60.0], None)
        .unwrap()
        .with_channels(&[0, 1, 2, 0])
        .unwrap();
    let gpu = gpu_probe(inputs.clone(), StackGpu::new(&eval));
    assert_eq!(gpu.len(), lut_points.len() + fourier_points.len());
    let (gpu_lut, gpu_fourier) = gpu.split_at(lut_points.len());

    for (k, table, name) in [(0, &refl, "reflectance"), (1, &trans, "transmittance")] {
        let cpu: Vec<[f64; 3]> = lut_points
            .iter()
            .map(|p| FilmLut::lookup(&axes, table, p.cos_theta, p.thickness_nm, p.film_ior))
            .collect();
        let g: Vec<[f32; 3]> = gpu_lut.iter().map(|o| o[k]).collect();
        let (worst, at) = max_diff(&cpu, &g);
        eprintln!(
            "film_lut {name}: {} points, max |GPU − CPU| = {worst:.2e}",
            lut_points.len()
        );
        assert!(
            worst <= 2e-3,
            "film_lut {name}: {worst:e} at cos θ {} d {} n {}",
            lut_points[at].cos_theta,
            lut_points[at].thickness_nm,
            lut_points[at].film_ior
        );
    }
    for (k, transmittance, name) in [(2, false, "reflectance"), (3, true, "transmittance")] {
        let mut cpu = Vec::new();
        let mut g = Vec::new();
        for (p, o) in fourier_points.iter().zip(gpu_fourier) {
            if transmittance && p.base.im != 0.0 {
                continue;
            }
            let film = FilmOnBase {
                n_ambient: 1.0,
                n_film: p.film_ior,
                base: [p.base; 3],
            };
            let c = film
                .fourier_colour_with(
                    &colorimeter,
                    p.cos_theta,
                    p.thickness_nm,
                    Harmonics::Auto,
                    0.0,
                    transmittance,
                    |mu, s| fourier.sample(mu, s),
                )
                .expect("no evanescent film among the points (n ≥ 1.2 > ambient)");
            cpu.push(c.colour);
            g.push(o[k]);
        }
        let (worst, _) = max_diff(&cpu, &g);
        eprintln!(
            "film_fourier {name}: {} points, max |GPU − CPU| = {worst:.2e}",
            cpu.len()
        );
        assert!(worst <= 2e-3, "film_fourier {name}: {worst:e}");
    }
    // The stack's CPU twin at the f32 inputs the GPU saw.
    let cpu: Vec<([f64; 3], [f64; 3])> = inputs
        .chunks_exact(STRIDE)
        .map(|v| {
            eval.colour(
                f64::from(v[0]),
                f64::from(v[1]),
                [v[5], v[6], v[7]].map(f64::from),
            )
        })
        .collect();
    for (k, name) in [(4, "reflectance"), (5, "transmittance")] {
        let c: Vec<[f64; 3]> = cpu.iter().map(|x| if k == 4 { x.0 } else { x.1 }).collect();
        let g: Vec<[f32; 3]> = gpu.iter().map(|o| o[k]).collect();
        let (worst, at) = max_diff(&c, &g);
        eprintln!(
            "film_stack {name}: {} points, max |GPU − CPU| = {worst:.2e}",
            c.len()
        );
        assert!(
            worst <= 1e-4,
            "film_stack {name}: {worst:e} at input {:?}",
            &inputs[at * STRIDE..at * STRIDE + 8]
        );
    }
}
