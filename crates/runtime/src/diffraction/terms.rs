//! Layout "terms": a table's Taylor terms on the GPU ([`DiffractionTable`]), the technique's
//! group 1 with its wavelength grid and window ([`DiffractionBinding`],
//! `shaders/diffraction.wgsl`) and its GPU = CPU probe ([`run_probe`]). The parent module's
//! docs describe the upload, the spectral sum and the window.

use super::common::{
    DiffractionLayout, check_array_limits, diffraction_record, dispatch_probe, upload_rgba32f_array,
};
use crate::context::{BufferInitExt, GpuContext};
use crate::error::{Error, Result};
use crate::shaders;
use crate::tables::verify_files;
use bytemuck::{Pod, Zeroable};
use nacre_format::Manifest;
use nacre_format::diffraction::DiffractionRecord;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::{FresnelTerm, SpectralGrid, TaylorTerms};
use std::path::{Path, PathBuf};

/// The technique module, layout "terms" ([`DIFFRACTION_COMMON`](super::common::DIFFRACTION_COMMON), then
/// `shaders/diffraction.wgsl`, which imports it; `shaders::flatten("diffraction")` plus a
/// newline): bind group 1 and the functions `diffraction_colour`,
/// `diffraction_specular_order_colour`, `diffraction_fresnel`, `diffraction_frame`.
pub const DIFFRACTION: &str = concat!(
    include_str!("../../../../shaders/diffraction_common.wgsl"),
    "\n",
    include_str!("../../../../shaders/diffraction.wgsl")
);

/// Largest Taylor order N the shader evaluates (`DIFFRACTION_MAX_ORDER` in the WGSL).
pub const MAX_TAYLOR_ORDER: usize = 63;
/// Largest neighbourhood radius R, bins per side.
pub const MAX_RADIUS: i32 = 16;
/// Largest neighbourhood radius, bins per side, the footprint filter grows to
/// (`DIFFRACTION_MAX_FILTER_RADIUS` in the WGSL: its row buffers hold 2 · 8 + 1 bins).
pub const MAX_FILTER_RADIUS: i32 = 8;
/// Most wavelengths of the spectral sum.
pub const MAX_WAVELENGTHS: usize = 4096;

/// The composed source of a pipeline: the technique, then the consumers
/// ([`composition`]'s source).
pub fn compose() -> String {
    composition().source
}

/// `shaders/diffraction_scene.wgsl` with its imports, `<technique>` = `diffraction`
/// (diffraction_common, diffraction, output, diffraction_scene), and its source map.
pub fn composition() -> shaders::Composed {
    shaders::flatten_with("diffraction_scene", "diffraction")
        .expect("the diffraction modules resolve (tested)")
}

/// A `diffraction` table on the GPU.
pub struct DiffractionTable {
    /// Table name.
    pub name: String,
    /// The manifest it was loaded from.
    pub manifest_path: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
    /// The manifest's `diffraction` record (sizes, pitch, σ_s, wavelengths, N).
    pub record: DiffractionRecord,
    /// The layout.
    pub layout: DiffractionLayout,
    /// The terms as uploaded (f32 values, as stored), for CPU twins of the GPU results.
    pub terms: TaylorTerms,
    /// 2-D array `Rgba32Float` texture (module docs).
    pub texture: wgpu::Texture,
}

impl DiffractionTable {
    /// Reads the manifest at `manifest_path`, checks its files' SHA-256 and the device's
    /// limits, reads the terms and uploads them.
    ///
    /// # Errors
    /// [`Error::Table`] for unreadable or malformed files; [`Error::Manifest`] for a table
    /// of another kind or layout (an "integrated" table loads with
    /// [`DiffractionTables::load`](super::tables::DiffractionTables::load)), a file that does not match its manifest, or an order
    /// above [`MAX_TAYLOR_ORDER`]; [`Error::Limit`] when the texture exceeds the device.
    pub fn load(ctx: &GpuContext, manifest_path: &Path) -> Result<DiffractionTable> {
        let (manifest, record) = diffraction_record(manifest_path)?;
        let layout = DiffractionLayout::of(&record, manifest_path)?;
        let DiffractionLayout::Terms { order } = layout else {
            return Err(Error::Manifest {
                path: manifest_path.to_path_buf(),
                message: format!(
                    "diffraction table `{}` has the layout \"{}\", not \"terms\" (DiffractionTables::load loads either layout)",
                    manifest.name,
                    layout.name()
                ),
            });
        };
        verify_files(&manifest, manifest_path)?;
        if order > MAX_TAYLOR_ORDER {
            return Err(Error::Manifest {
                path: manifest_path.to_path_buf(),
                message: format!(
                    "Taylor order {order}: the GPU technique evaluates at most {MAX_TAYLOR_ORDER}"
                ),
            });
        }
        let layers = (order + 1).div_ceil(2);
        check_array_limits(
            ctx,
            &format!("diffraction `{}`", manifest.name),
            [record.nx, record.ny, layers],
        )?;
        let (loaded, terms) = manifest.load_diffraction(manifest_path)?;
        if (loaded.nx, loaded.ny) != terms.size() || terms.order() != order {
            return Err(Error::Manifest {
                path: manifest_path.to_path_buf(),
                message: "the terms file disagrees with the manifest's sizes".into(),
            });
        }
        let (nx, ny) = (record.nx, record.ny);
        let texels: Vec<f32> = {
            let layer_data: Vec<Vec<nacre_optics::C64>> =
                (0..=order).map(|n| terms.layer(n)).collect();
            let mut v = Vec::with_capacity(layers * nx * ny * 4);
            for l in 0..layers {
                for i in 0..nx * ny {
                    let a = layer_data[2 * l][i];
                    let b = layer_data
                        .get(2 * l + 1)
                        .map_or(nacre_optics::C64::new(0.0, 0.0), |t| t[i]);
                    v.extend([a.re, a.im, b.re, b.im].map(|x| x as f32));
                }
            }
            v
        };
        let texture = upload_rgba32f_array(ctx, &manifest.name, [nx, ny, layers], &texels)?;
        Ok(DiffractionTable {
            name: manifest.name.clone(),
            manifest_path: manifest_path.to_path_buf(),
            manifest,
            record,
            layout,
            terms,
            texture,
        })
    }

    /// The colorimeter recorded in the manifest (observer, illuminant, output space).
    pub fn colorimeter(&self) -> Result<Colorimeter> {
        Ok(self.manifest.colorimeter(&self.manifest_path)?)
    }

    /// The neighbourhood radius R per axis for a dropped-weight `tolerance` (module docs).
    ///
    /// # Errors
    /// [`Error::Invalid`] for a tolerance outside (0, 1) or a window needing more than
    /// [`MAX_RADIUS`] bins.
    pub fn radius(&self, tolerance: f64) -> Result<[i32; 2]> {
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(Error::OutOfRange {
                what: "diffraction window tolerance".into(),
                value: tolerance,
                unit: "",
                expected: "between 0 and 1".into(),
            });
        }
        let r = &self.record;
        let axis = |n: usize, l_um: f64| -> Result<i32> {
            if n <= 1 {
                return Ok(0);
            }
            let s = r.sigma_s_um * 2.0 * std::f64::consts::PI / l_um;
            // exp(−s² (R + ½)²/2) ≤ tolerance ⇔ R ≥ √(2 ln(1/tol))/s − ½.
            let need = ((2.0 * (1.0 / tolerance).ln()).sqrt() / s - 0.5)
                .ceil()
                .max(1.0);
            if need.is_nan() || need > f64::from(MAX_RADIUS) {
                return Err(Error::CoherenceWindow {
                    table: self.name.clone(),
                    bins: need,
                    max: MAX_RADIUS,
                });
            }
            Ok((need as i32).min((n / 2) as i32))
        };
        Ok([axis(r.nx, r.patch_um[0])?, axis(r.ny, r.patch_um[1])?])
    }

    /// The largest window weight the shader drops at `radius` (per axis, the weight of the
    /// nearest bin left out: exp(−(σ_s Δκ)² (R + ½)²/2); 0 where every bin is summed).
    pub fn dropped_weight(&self, radius: [i32; 2]) -> f64 {
        let r = &self.record;
        let axis = |n: usize, l_um: f64, rad: i32| {
            if n <= 1 || 2 * rad as usize + 1 >= n {
                return 0.0;
            }
            let s = r.sigma_s_um * 2.0 * std::f64::consts::PI / l_um;
            (-0.5 * s * s * (f64::from(rad) + 0.5).powi(2)).exp()
        };
        axis(r.nx, r.patch_um[0], radius[0]).max(axis(r.ny, r.patch_um[1], radius[1]))
    }
}

/// Settings of the technique. The wavelength step and the window tolerance shape the terms
/// technique's sums; an "integrated" table's sum was done at bake time (on its manifest's
/// wavelength grid, with the whole window), so it leaves them unused (`nacre render` and
/// `nacre bench-gpu` refuse the flags that set them for one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffractionOptions {
    /// Step of the wavelength grid of the colour sum, nm (the table's range); `None` = the
    /// table's own step (the CPU's grid). Layout "terms" only.
    pub wavelength_step_nm: Option<f64>,
    /// The Fresnel factor F² (default: 1, a perfect reflector). An integrated table holds
    /// its F² in its uniform ([`DiffractionTables::load`](super::tables::DiffractionTables::load)); a scene or bench pass refuses
    /// one loaded with another F².
    pub fresnel: FresnelTerm,
    /// Largest window weight the neighbourhood may drop (default 10⁻³; module docs). Layout
    /// "terms" only.
    pub window_tolerance: f64,
    /// The footprint filter of the scenes (`diffraction_colour_footprint`,
    /// `shaders/diffraction.wgsl`): the largest neighbourhood radius per axis, bins, it may
    /// grow to as a pixel's footprint widens (default [`MAX_FILTER_RADIUS`]; at least the
    /// table's own radius R, at most [`MAX_FILTER_RADIUS`] and the table's half-size; 0 keeps
    /// R: the filter's weights without the wider neighbourhood). `None`: no filter, one point
    /// sample of the BRDF per pixel (what the scenes drew before issue 37). An "integrated"
    /// table filters through its prefiltered levels instead (`Some` of any radius; `None`
    /// point-samples a smooth grating: `shaders/diffraction_integrated_technique.wgsl`).
    pub filter_radius: Option<i32>,
}

impl Default for DiffractionOptions {
    fn default() -> Self {
        DiffractionOptions {
            wavelength_step_nm: None,
            fresnel: FresnelTerm::Unity,
            window_tolerance: 1e-3,
            filter_radius: Some(MAX_FILTER_RADIUS),
        }
    }
}

/// The wavelength grid of `table` at `step_nm` (its own step when `None`): from the table's
/// shortest wavelength up to its longest, nm.
///
/// # Errors
/// [`Error::Invalid`] for a step that is not finite and positive or gives fewer than two or
/// more than [`MAX_WAVELENGTHS`] wavelengths.
pub fn wavelength_grid(record: &DiffractionRecord, step_nm: Option<f64>) -> Result<Vec<f64>> {
    let step = step_nm.unwrap_or(record.wavelength_step_nm);
    let span = record.wavelength_max_nm - record.wavelength_min_nm;
    let count = (span / step + 1e-9).floor() + 1.0;
    if !(step > 0.0 && step.is_finite() && (2.0..=MAX_WAVELENGTHS as f64).contains(&count)) {
        return Err(Error::WavelengthStep {
            step_nm: step,
            range_nm: [record.wavelength_min_nm, record.wavelength_max_nm],
            max_count: MAX_WAVELENGTHS,
        });
    }
    Ok((0..count as usize)
        .map(|i| record.wavelength_min_nm + i as f64 * step)
        .collect())
}

/// (λ nm, u_R, u_G, u_B) per wavelength: the output-space CIE weights of `grid`.
pub fn spectrum_weights(grid: &SpectralGrid, colorimeter: &Colorimeter) -> Vec<[f32; 4]> {
    let n = grid.wavelengths_nm().len();
    let mut unit = vec![0.0; n];
    (0..n)
        .map(|i| {
            unit[i] = 1.0;
            let xyz = grid.xyz(&unit);
            unit[i] = 0.0;
            let rgb = colorimeter.output_from_xyz(xyz);
            [
                grid.wavelengths_nm()[i] as f32,
                rgb[0] as f32,
                rgb[1] as f32,
                rgb[2] as f32,
            ]
        })
        .collect()
}

/// Mirror of `DiffractionParams` (shaders/diffraction.wgsl, 64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DiffractionUniform {
    /// Bins (nx, ny).
    pub size: [u32; 2],
    /// Texel of the DC bin.
    pub dc: [i32; 2],
    /// Δκ = 2π/L per axis, rad/µm.
    pub dk_per_um: [f32; 2],
    /// Neighbourhood radius per axis, bins.
    pub radius: [i32; 2],
    /// Taylor order N.
    pub order: u32,
    /// σ_s, µm.
    pub sigma_s_um: f32,
    /// Wavelengths of the spectral sum.
    pub wavelength_count: u32,
    /// 0: F² = 1; 1: the Fresnel reflectance of `fresnel_ior`.
    pub fresnel_kind: u32,
    /// (n, κ) of the bulk material.
    pub fresnel_ior: [f32; 2],
    /// Largest radius per axis the footprint filter grows the neighbourhood to, bins
    /// ([`DiffractionOptions::filter_radius`] within its bounds); (−1, −1): no filter.
    pub filter_radius: [i32; 2],
}

/// Group 1 of the technique: the table, its uniform and the spectral weights.
pub struct DiffractionBinding {
    /// The layout (binding 0 uniform, 1 the terms, 2 the spectrum; fragment and compute).
    pub layout: wgpu::BindGroupLayout,
    /// The bind group.
    pub bind_group: wgpu::BindGroup,
    /// The uniform as uploaded.
    pub uniform: DiffractionUniform,
    /// The wavelength grid with its weights, as uploaded.
    pub spectrum: Vec<[f32; 4]>,
    /// The CPU twin of the grid (the same wavelengths and weights, f64).
    pub grid: SpectralGrid,
}

/// Mesa's llvmpipe (the rasteriser behind lavapipe) ends every shader invocation after
/// 65,535 loop iterations in all — gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`, "shared between
/// every loop in a shader", an infinite-loop guard — and carries on with the loops cut
/// short, so a longer sum silently draws a wrong picture. Hardware drivers have no such cap.
pub const LLVMPIPE_LOOP_LIMIT: u64 = 65_535;

impl DiffractionBinding {
    /// An upper bound on the loop iterations of one `diffraction_colour` call
    /// (`shaders/diffraction.wgsl`): per wavelength, one of the colour loop, N + 1 Taylor
    /// coefficients, and 2R_y + 1 rows of 2R_x + 1 bins of ⌈(N + 1)/2⌉ layer loads each.
    pub fn loop_iterations_per_colour(&self) -> u64 {
        let u = &self.uniform;
        let order = u64::from(u.order);
        let layers = (order + 2) / 2;
        let rows = 2 * u64::from(u.radius[1].unsigned_abs()) + 1;
        let bins = 2 * u64::from(u.radius[0].unsigned_abs()) + 1;
        u64::from(u.wavelength_count) * (1 + (order + 1) + rows * (1 + bins * (1 + layers)))
    }

    /// An upper bound on the loop iterations of one `diffraction_colour_footprint` call:
    /// per wavelength, one of the colour loop, N + 1 Taylor coefficients, two axes of
    /// 2R_f + 1 weights, and 2R_f,y + 1 rows of 2R_f,x + 1 bins of ⌈(N + 1)/2⌉ layer loads
    /// each, R_f the uniform's `filter_radius`.
    /// Without a filter (`filter_radius` −1), [`Self::loop_iterations_per_colour`].
    pub fn loop_iterations_per_filtered_colour(&self) -> u64 {
        let u = &self.uniform;
        if u.filter_radius[0] < 0 {
            return self.loop_iterations_per_colour();
        }
        filtered_iterations(u.order, u.wavelength_count, u.filter_radius)
    }

    /// Builds the technique's group 1 for `table`.
    ///
    /// # Errors
    /// [`Error::Invalid`] for bad options; [`Error::Table`] for a manifest whose colour
    /// settings do not parse.
    pub fn new(
        ctx: &GpuContext,
        table: &DiffractionTable,
        options: &DiffractionOptions,
    ) -> Result<DiffractionBinding> {
        let r = &table.record;
        let radius = table.radius(options.window_tolerance)?;
        let colorimeter = table.colorimeter()?;
        let wavelengths = wavelength_grid(r, options.wavelength_step_nm)?;
        let grid = SpectralGrid::new(&colorimeter, &wavelengths)?;
        let spectrum = spectrum_weights(&grid, &colorimeter);
        let (fresnel_kind, fresnel_ior) = match options.fresnel {
            FresnelTerm::Unity => (0, [1.0, 0.0]),
            FresnelTerm::Index(n) => {
                if !(n.re.is_finite() && n.im.is_finite() && n.re > 0.0 && n.im >= 0.0) {
                    return Err(Error::FresnelIndex {
                        index: n.to_string(),
                    });
                }
                (1, [n.re as f32, n.im as f32])
            }
        };
        let uniform = DiffractionUniform {
            size: [r.nx as u32, r.ny as u32],
            dc: [(r.nx / 2) as i32, (r.ny / 2) as i32],
            dk_per_um: [
                (2.0 * std::f64::consts::PI / r.patch_um[0]) as f32,
                (2.0 * std::f64::consts::PI / r.patch_um[1]) as f32,
            ],
            radius,
            order: table.terms.order() as u32,
            sigma_s_um: r.sigma_s_um as f32,
            wavelength_count: spectrum.len() as u32,
            fresnel_kind,
            fresnel_ior,
            filter_radius: match options.filter_radius {
                Some(cap) => filter_radius(radius, [r.nx, r.ny], cap),
                None => [-1, -1],
            },
        };
        let device = &ctx.device;
        let (layout, bind_group) = ctx.checked("binding a diffraction table", || {
            let visibility = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("diffraction technique"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Storage { read_only: true },
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                ],
            });
            let ubuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("DiffractionParams"),
                contents: bytemuck::bytes_of(&uniform),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let sbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("diffraction spectrum"),
                contents: bytemuck::cast_slice(&spectrum),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let view = table.texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            });
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("diffraction technique"),
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: ubuf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: sbuf.as_entire_binding(),
                    },
                ],
            });
            (layout, bind_group)
        })?;
        Ok(DiffractionBinding {
            layout,
            bind_group,
            uniform,
            spectrum,
            grid,
        })
    }
}

/// The footprint filter's radius cap per axis: `wanted` (≥ 0) within the table's own
/// `radius` and the smaller of [`MAX_FILTER_RADIUS`] and (n − 1)/2 (a wider window than the
/// table only adds empty bins).
pub fn filter_radius(radius: [i32; 2], size: [usize; 2], wanted: i32) -> [i32; 2] {
    [0, 1].map(|a| {
        let half = i32::try_from((size[a].max(1) - 1) / 2).unwrap_or(i32::MAX);
        wanted.clamp(0, MAX_FILTER_RADIUS).min(half).max(radius[a])
    })
}

/// [`DiffractionBinding::loop_iterations_per_filtered_colour`] for Taylor order `order`,
/// `wavelengths` wavelengths and the cap `filter_radius`.
pub fn filtered_iterations(order: u32, wavelengths: u32, filter_radius: [i32; 2]) -> u64 {
    let order = u64::from(order);
    let layers = (order + 2) / 2;
    let rows = 2 * u64::from(filter_radius[1].unsigned_abs()) + 1;
    let bins = 2 * u64::from(filter_radius[0].unsigned_abs()) + 1;
    u64::from(wavelengths) * (1 + (order + 1) + rows + bins + rows * (1 + bins * (1 + layers)))
}

/// One probe result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeOutput {
    /// `diffraction_colour(ω_i, ω_r)`: Σ_λ ρ u(λ), output space.
    pub colour: [f32; 3],
    /// `diffraction_specular_order_colour(ω_r.z)`: Σ_λ F² |P_DC|² u(λ).
    pub specular_order: [f32; 3],
}

/// Evaluates the technique for (ω_i, ω_r) pairs in the grating frame (any values, unit or
/// not, finite or not) in a compute pass and reads the colours back.
pub fn run_probe(
    ctx: &GpuContext,
    binding: &DiffractionBinding,
    pairs: &[([f32; 3], [f32; 3])],
) -> Result<Vec<ProbeOutput>> {
    let input: Vec<[f32; 4]> = pairs
        .iter()
        .flat_map(|(i, r)| [[i[0], i[1], i[2], 0.0], [r[0], r[1], r[2], 0.0]])
        .collect();
    let values = dispatch_probe(
        ctx,
        &composition(),
        "diffraction_probe",
        (&binding.layout, &binding.bind_group),
        &input,
        pairs.len(),
    )?;
    Ok(values
        .chunks_exact(2)
        .map(|c| ProbeOutput {
            colour: [c[0][0], c[0][1], c[0][2]],
            specular_order: [c[1][0], c[1][1], c[1][2]],
        })
        .collect())
}
