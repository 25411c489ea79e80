//! The `diffraction` technique for layout "integrated" (issue 7, the fast path): loading a
//! baked integrated table through its manifest, its bind group
//! (`shaders/diffraction_integrated.wgsl`), its GPU = CPU probe
//! (`shaders/diffraction_integrated_probe.wgsl`), and the adapter that lets the terms
//! technique's consumers run on it (`shaders/diffraction_integrated_technique.wgsl`).
//!
//! # What the table holds and how the shader rebuilds the colour
//!
//! Iₚ(u, v), p = 0 … 2N, wavelength-integrated colour tables in the manifest's output space
//! such that colour = F²(θ_h) · G/w² · Σₚ wᵖ Iₚ(u, v), (u, v, w) = −ω_i − ω_r
//! (Stam 1999; Dhillon et al. 2014; derivation in
//! [`nacre_optics::diffraction::integrated`], files in `nacre_bake::kinds::diffraction_integrated`).
//! The shader folds u < 0 onto u ≥ 0 ((u, v, w) → (−u, −v, −w), since
//! Iₚ(−u, −v) = (−1)ᵖ Iₚ(u, v)), maps u and v to texel coordinates on the warped axes,
//! reads every layer bilinearly from four `textureLoad`s and sums by Horner in w. It is the
//! GPU twin of [`IntegratedTable::colour`]: the same fold, forward mapping, clamping,
//! bilinear weights and f32 Horner order.
//!
//! # Upload
//!
//! One 2-D array texture, `Rgba32Float`, n/2 × n texels (u ≥ 0 columns, v rows),
//! L (2N + 1) layers, layer ℓ (2N + 1) + p = (Iₚ ch 0, ch 1, ch 2, 0) of level ℓ: level 0
//! the table as its KTX2 file holds it, levels 1 … L − 1 the table blurred in (u, v) by
//! σ_ℓ = σ₁ 2^{ℓ−1}, σ₁ = u_max/2^{L−2} ([`IntegratedLevels`], made here at load time:
//! L = [`INTEGRATED_FILTER_LEVELS`] = 10 where the device takes L (2N + 1) layers, fewer
//! otherwise). For `cd-tracks-fast` (72 × 144 texels, 23 layers) that is 230 layers,
//! 38 MB on the GPU against 3.8 MB unfiltered, and 0.45–1.5 s of load on two shared cores
//! (`crates/runtime/tests/diffraction_integrated.rs` prints it; about 1 s more for
//! `nacre render` than before, debug build). The levels serve the lookup filtered
//! over a pixel's footprint and a rough grating's facets (issue 37;
//! `diffraction_integrated_colour_filtered`, CPU twin
//! [`IntegratedLevels::colour_filtered`]). The texels come from the EXR file, else the KTX2
//! file ([`nacre_format::Manifest::load_diffraction_integrated`]); every file is checked
//! against its manifest's SHA-256 and the texture against the device's limits first.
//!
//! # Bind group (group 1 of a pipeline; fragment and compute)
//!
//! | binding | resource | WGSL |
//! |---|---|---|
//! | 0 | uniform [`DiffractionIntegratedUniform`] (48 bytes): layer size, 2N + 1, u_max, 1/γ, the host's F², levels L, σ₁², the scene's filter and σ_m² | `diffraction_integrated: DiffractionIntegratedParams` |
//! | 1 | the table, `texture_2d_array<f32>`, unfilterable (`textureLoad` only) | `diffraction_integrated_table` |
//! | 2 | read-only storage, 2N + 1 `vec4<f32>`: Jₚ, the zeroth order's layers without Stam's k² ([`IntegratedTable::specular_layers`]) | `diffraction_integrated_zeroth` |
//!
//! # Using it from a scene shader
//!
//! Compose [`WGSL`] before the consumer and bind [`DiffractionIntegrated::bind_group`] at
//! group 1 of a pipeline layout that has [`DiffractionIntegrated::bind_group_layout`] there:
//!
//! ```wgsl
//! let frame = diffraction_frame(normal, across_the_lines); // rows x, y, n
//! let c = diffraction_integrated_colour(frame * to_light, frame * to_eye,
//!                                       diffraction_integrated.fresnel_kind,
//!                                       diffraction_integrated.fresnel_ior);
//! radiance += c * light_radiance;
//! ```
//!
//! A consumer written for the terms technique (`shaders/diffraction_scene.wgsl`, which calls
//! `diffraction_colour`, `diffraction_specular_order_colour`, `diffraction_fresnel`,
//! `diffraction_frame`, `diffraction_finite3`) runs unchanged on an integrated table when
//! composed as [`compose_scene`]: [`TECHNIQUE_ADAPTER`] defines those names from this module,
//! with F² from the uniform ([`run_scene_probe`] runs that composition's probe entry point on
//! the device). Its `diffraction_specular_order_colour` is the mirror-lobe peak
//! F² Σₚ (−2 cos θ)ᵖ Jₚ, the colour of |P̃(0, 0)|², which differs from the terms
//! technique's F² |P_DC|² by the window-weighted bins next to DC (1.4 · 10⁻⁴ of the white
//! for the CD table).
//!
//! # Stam's k²
//!
//! Stam's BRDF is f = ρ (σ_s k)²/π; the scenes pass the light's gain (σ_s k_ref)²/π
//! ([`crate::diffraction::lobe_gain`]) and the colour must carry (k/k_ref)² = (λ_ref/λ)² per
//! wavelength. A table baked with it (the manifest's `k_squared_reference_nm`, 555 nm,
//! [`IntegratedTable::k_squared_reference_nm`]) holds that weight in its layers, so its
//! `diffraction_colour_footprint` needs no `reference_nm` (the adapter ignores it;
//! `lobe_gain` takes k_ref at the table's own λ_ref) — for the light, the environment's
//! samples and a rough grating's light alike, which all read the layers, and for every
//! prefiltered level (a blur is linear: the weight passes through). The mirror image reads
//! Jₚ (binding 2), which the manifest records unweighted (`zeroth_order_layers`): a zeroth
//! order's efficiency has no k². **A table without the field** (baked by a nacre before the
//! weight) loads and renders as it did: its layers are Σ_λ ρ u, tilted towards red by
//! (λ/555 nm)² against the terms technique (blue × 0.66, red × 1.37 at 450/650 nm), and its
//! Jₚ are its own layers at u = v = 0. `nacre info` shows the field (`null` for such a table).
//!
//! # Cost
//!
//! 4 (2N + 1) texel loads and 3 (2N + 1) multiply-adds per call (the CD table, N = 11: 92
//! loads; the filtered call twice that between two levels), independent of the number of
//! wavelengths; the terms technique loads
//! ⌈(N + 1)/2⌉ layers per bin for (2R + 1)² bins per wavelength (the CD table at 5 nm:
//! 6 × 25 × 81 = 12 150 loads).

use super::common::{allocated_layers, check_array_limits, dispatch_probe, upload_rgba32f_array};
use crate::context::{BufferInitExt, GpuContext};
use crate::error::{Error, Result};
use crate::shaders;
use crate::tables::verify_files;
use bytemuck::{Pod, Zeroable};
use nacre_format::Manifest;
use nacre_format::diffraction::DiffractionRecord;
use nacre_format::diffraction::IntegratedRecord;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::FresnelTerm;
use nacre_optics::diffraction::integrated::{
    INTEGRATED_FILTER_LEVELS, IntegratedLevels, IntegratedTable,
};
use std::path::{Path, PathBuf};

/// The technique module, layout "integrated" ([`crate::diffraction::DIFFRACTION_COMMON`],
/// then `shaders/diffraction_integrated.wgsl`, which imports it;
/// `shaders::flatten("diffraction_integrated")` plus a newline): bind group 1 and the functions
/// `diffraction_integrated_colour`, `diffraction_integrated_specular_colour`, with
/// `diffraction_frame` and `diffraction_fresnel_of` from the common module.
pub const WGSL: &str = concat!(
    include_str!("../../../../shaders/diffraction_common.wgsl"),
    "\n",
    include_str!("../../../../shaders/diffraction_integrated.wgsl")
);
/// `shaders/diffraction_integrated_technique.wgsl`: the names a terms-technique consumer
/// calls (`diffraction_colour`, …), defined from [`WGSL`] with F² from the uniform.
pub const TECHNIQUE_ADAPTER: &str =
    include_str!("../../../../shaders/diffraction_integrated_technique.wgsl");
/// `shaders/diffraction_integrated_probe.wgsl`: the compute probe (entry point
/// `diffraction_integrated_probe`; group 2 its buffers).
pub const PROBE: &str = include_str!("../../../../shaders/diffraction_integrated_probe.wgsl");

/// The probe pipeline's source: [`WGSL`] then [`PROBE`] ([`probe_composition`]'s source).
pub fn compose_probe() -> String {
    probe_composition().source
}

/// `shaders/diffraction_integrated_probe.wgsl` with its imports (diffraction_common,
/// diffraction_integrated, diffraction_integrated_probe) and its source map.
pub fn probe_composition() -> shaders::Composed {
    shaders::flatten("diffraction_integrated_probe")
        .expect("the diffraction modules resolve (tested)")
}

/// The scene pipeline's source: [`WGSL`], [`TECHNIQUE_ADAPTER`], then the terms technique's
/// consumers ([`crate::diffraction::DIFFRACTION_SCENE`]: scenes, bench pass, probe)
/// ([`scene_composition`]'s source).
pub fn compose_scene() -> String {
    scene_composition().source
}

/// `shaders/diffraction_scene.wgsl` with its imports, `<technique>` =
/// `diffraction_integrated_technique` (diffraction_common, diffraction_integrated, the
/// adapter, output, diffraction_scene), and its source map.
pub fn scene_composition() -> shaders::Composed {
    shaders::flatten_with("diffraction_scene", "diffraction_integrated_technique")
        .expect("the diffraction modules resolve (tested)")
}

/// Mirror of `DiffractionIntegratedParams` (shaders/diffraction_integrated.wgsl, 48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct DiffractionIntegratedUniform {
    /// (columns n/2, rows n) of a layer.
    pub size: [u32; 2],
    /// Layers 2N + 1.
    pub layers: u32,
    /// The host's F² (used by [`TECHNIQUE_ADAPTER`]): 0 = 1; 1 = Fresnel of `fresnel_ior`.
    pub fresnel_kind: u32,
    /// u_max = 2 sin θ_max.
    pub max_uv: f32,
    /// 1/γ, the inverse warp exponent.
    pub inv_gamma: f32,
    /// (n, κ) of the bulk material (`fresnel_kind` 1).
    pub fresnel_ior: [f32; 2],
    /// L, the prefiltered levels in the texture (1: the table only).
    pub levels: u32,
    /// The footprint filter of [`TECHNIQUE_ADAPTER`]'s `diffraction_colour_footprint`: 0
    /// point-samples, 1 filters (a scene pass sets it; the table's own uniform has 1).
    pub footprint_filter: u32,
    /// σ₁² of level 1 ([`IntegratedLevels::sigma_base_sq_f32`]).
    pub sigma_base_sq: f32,
    /// σ_m² = α²/2, the slope variance of a rough grating's facets per axis, for
    /// [`TECHNIQUE_ADAPTER`] (a scene pass sets it; 0 in the table's own uniform).
    pub slope_variance: f32,
}

/// (kind, (n, κ)) of `fresnel` as the shader takes it.
///
/// # Errors
/// [`Error::Invalid`] for an index that is not finite with n > 0, κ ≥ 0.
pub fn fresnel_parameters(fresnel: FresnelTerm) -> Result<(u32, [f32; 2])> {
    match fresnel {
        FresnelTerm::Unity => Ok((0, [1.0, 0.0])),
        FresnelTerm::Index(n) => {
            if !(n.re.is_finite() && n.im.is_finite() && n.re > 0.0 && n.im >= 0.0) {
                return Err(Error::FresnelIndex {
                    index: n.to_string(),
                });
            }
            Ok((1, [n.re as f32, n.im as f32]))
        }
    }
}

/// An integrated `diffraction` table on the GPU with its bind group (module docs).
pub struct DiffractionIntegrated {
    /// Table name.
    pub name: String,
    /// The manifest it was loaded from.
    pub manifest_path: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
    /// The manifest's `diffraction` record (N, u_max, wavelengths, …).
    pub record: DiffractionRecord,
    /// Its `integrated` part (axes, measured reconstruction error).
    pub integrated: IntegratedRecord,
    /// The table as uploaded (f32 values), for CPU twins ([`IntegratedTable::colour`]).
    pub table: IntegratedTable,
    /// The table and its prefiltered levels as uploaded, for the filtered CPU twin
    /// ([`IntegratedLevels::colour_filtered`]).
    pub levels: IntegratedLevels,
    /// The 2-D array `Rgba32Float` texture (module docs).
    pub texture: wgpu::Texture,
    /// Jₚ, the zeroth order's layers (binding 2; module docs).
    pub zeroth_order: wgpu::Buffer,
    /// The uniform as uploaded.
    pub uniform: DiffractionIntegratedUniform,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
}

impl DiffractionIntegrated {
    /// The technique's WGSL ([`WGSL`]).
    pub const WGSL: &'static str = WGSL;

    /// Reads the manifest at `manifest_path`, checks its files' SHA-256 and the device's
    /// limits, reads the table and uploads it with a uniform whose F² is `fresnel` (what
    /// [`TECHNIQUE_ADAPTER`] applies; `diffraction_integrated_colour` takes F² as arguments).
    ///
    /// # Errors
    /// [`Error::Table`] for unreadable or malformed files; [`Error::Manifest`] for a table of
    /// another kind or layout, or a file that does not match its manifest; [`Error::Limit`]
    /// when the texture exceeds the device; [`Error::Invalid`] for a bad Fresnel index.
    pub fn load(
        ctx: &GpuContext,
        manifest_path: &Path,
        fresnel: FresnelTerm,
    ) -> Result<DiffractionIntegrated> {
        let (fresnel_kind, fresnel_ior) = fresnel_parameters(fresnel)?;
        let bad = |message: String| Error::Manifest {
            path: manifest_path.to_path_buf(),
            message,
        };
        let manifest = Manifest::read(manifest_path)?;
        if manifest.kind != nacre_format::TableKind::DIFFRACTION {
            return Err(bad(format!(
                "table `{}` is a `{}` table, not a `diffraction` table",
                manifest.name, manifest.kind
            )));
        }
        verify_files(&manifest, manifest_path)?;
        let record = manifest
            .diffraction()
            .cloned()
            .ok_or_else(|| bad("a diffraction manifest without its `diffraction` record".into()))?;
        let integrated = match (&record.integrated, record.layout.as_str()) {
            (Some(s), "integrated") => s.clone(),
            (_, layout) => {
                return Err(bad(format!(
                    "diffraction table `{}` has the layout \"{layout}\", not \"integrated\" (nacre_runtime::diffraction::DiffractionTables::load loads either layout)",
                    manifest.name
                )));
            }
        };
        check_array_limits(
            ctx,
            &format!("integrated diffraction `{}`", manifest.name),
            [
                integrated.samples_u,
                integrated.samples_v,
                integrated.layers,
            ],
        )?;
        let (_, table) = manifest.load_diffraction_integrated(manifest_path)?;
        let (cols, rows) = table.size();
        let layers = table.layers();
        if (cols, rows, layers)
            != (
                integrated.samples_u,
                integrated.samples_v,
                integrated.layers,
            )
        {
            return Err(bad(format!(
                "the integrated file holds {cols} × {rows} × {layers} texels; the manifest says {} × {} × {}",
                integrated.samples_u, integrated.samples_v, integrated.layers
            )));
        }
        let axis = table.axis();
        // As many prefiltered levels (up to INTEGRATED_FILTER_LEVELS) as the device's array
        // layers take.
        let max_layers = ctx.device.limits().max_texture_array_layers as usize;
        let count = (1..=INTEGRATED_FILTER_LEVELS)
            .rev()
            .find(|l| allocated_layers([cols, rows, l * layers]) <= max_layers)
            .unwrap_or(1);
        let levels = IntegratedLevels::new(&table, count).map_err(|e| bad(e.to_string()))?;
        let uniform = DiffractionIntegratedUniform {
            size: [cols as u32, rows as u32],
            layers: layers as u32,
            fresnel_kind,
            max_uv: axis.max_uv as f32,
            inv_gamma: (1.0 / axis.gamma) as f32,
            fresnel_ior,
            levels: count as u32,
            footprint_filter: 1,
            sigma_base_sq: levels.sigma_base_sq_f32(),
            slope_variance: 0.0,
        };
        let texels: Vec<f32> = levels
            .levels()
            .iter()
            .flat_map(|level| level.values())
            .flat_map(|v| [v[0], v[1], v[2], 0.0])
            .collect();
        let name = manifest.name.clone();
        let device = &ctx.device;
        let texture = upload_rgba32f_array(ctx, &name, [cols, rows, count * layers], &texels)?;
        // 2: the zeroth order's layers Jₚ (unweighted; the table's own peak for a table
        // without Stam's k²), one vec4 each.
        let zeroth: Vec<[f32; 4]> = table
            .specular_layers()
            .iter()
            .map(|j| [j[0], j[1], j[2], 0.0])
            .collect();
        let zeroth_order = ctx.checked("uploading an integrated table's zeroth order", || {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("diffraction_integrated_zeroth"),
                contents: bytemuck::cast_slice(&zeroth),
                usage: wgpu::BufferUsages::STORAGE,
            })
        })?;
        let (layout, bind_group) =
            ctx.checked("binding an integrated diffraction table", || {
                let visibility = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("diffraction integrated technique"),
                    entries: &[
                        // 0: DiffractionIntegratedParams.
                        wgpu::BindGroupLayoutEntry {
                            binding: 0,
                            visibility,
                            ty: wgpu::BindingType::Buffer {
                                ty: wgpu::BufferBindingType::Uniform,
                                has_dynamic_offset: false,
                                min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<
                                    DiffractionIntegratedUniform,
                                >(
                                )
                                    as u64),
                            },
                            count: None,
                        },
                        // 1: the Iₚ layers, Rgba32Float, read with textureLoad.
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
                        // 2: Jₚ, the zeroth order's layers, read-only storage.
                        wgpu::BindGroupLayoutEntry {
                            binding: 2,
                            visibility,
                            ty: wgpu::BindingType::Buffer {
                                ty: wgpu::BufferBindingType::Storage { read_only: true },
                                has_dynamic_offset: false,
                                min_binding_size: wgpu::BufferSize::new(16),
                            },
                            count: None,
                        },
                    ],
                });
                let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("DiffractionIntegratedParams"),
                    contents: bytemuck::bytes_of(&uniform),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let view = texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    ..Default::default()
                });
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("diffraction integrated technique"),
                    layout: &layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: buffer.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: zeroth_order.as_entire_binding(),
                        },
                    ],
                });
                (layout, bind_group)
            })?;
        Ok(DiffractionIntegrated {
            name: manifest.name.clone(),
            manifest_path: manifest_path.to_path_buf(),
            manifest,
            record,
            integrated,
            table,
            levels,
            texture,
            zeroth_order,
            uniform,
            layout,
            bind_group,
        })
    }

    /// A bind group of group 1 ([`Self::bind_group_layout`]) with this table's texture and
    /// `uniform` in place of its own (a scene pass's footprint filter and slope variance).
    ///
    /// # Errors
    /// [`Error::Gpu`] or [`Error::DeviceLost`] from the device.
    pub fn bind_group_with(
        &self,
        ctx: &GpuContext,
        uniform: &DiffractionIntegratedUniform,
    ) -> Result<wgpu::BindGroup> {
        let device = &ctx.device;
        ctx.checked("binding an integrated diffraction table", || {
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("DiffractionIntegratedParams"),
                contents: bytemuck::bytes_of(uniform),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let view = self.texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("diffraction integrated technique"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: self.zeroth_order.as_entire_binding(),
                    },
                ],
            })
        })
    }

    /// The layout of group 1 (module docs: binding 0 the uniform, 1 the table, 2 the zeroth
    /// order's layers; fragment and compute stages).
    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The bind group of group 1.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// The colorimeter recorded in the manifest (observer, illuminant, output space).
    pub fn colorimeter(&self) -> Result<Colorimeter> {
        Ok(self.manifest.colorimeter(&self.manifest_path)?)
    }

    /// Texel loads per `diffraction_integrated_colour` call: 4 (2N + 1).
    pub fn texel_loads_per_call(&self) -> usize {
        4 * self.table.layers()
    }

    /// Bytes of the texture on the GPU (`Rgba32Float`, every level and any extra layer).
    pub fn texture_bytes(&self) -> u64 {
        let s = self.texture.size();
        u64::from(s.width) * u64::from(s.height) * u64::from(s.depth_or_array_layers) * 16
    }
}

/// One probe evaluation: a light/view pair in the grating frame (any values, unit or not,
/// finite or not), F², and the cos θ of a `diffraction_integrated_specular_colour` call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeCase {
    /// ω_i, towards the light.
    pub omega_i: [f32; 3],
    /// ω_r, towards the viewer.
    pub omega_r: [f32; 3],
    /// F²; an index is passed to the shader as given (f32), unchecked.
    pub fresnel: FresnelTerm,
    /// cos θ of the specular-colour call.
    pub cos_theta: f32,
    /// σ_uv of the filtered call (`diffraction_integrated_colour_filtered`).
    pub sigma_uv: f32,
    /// σ_m² of the filtered call.
    pub slope_variance: f32,
}

/// One probe result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeOutput {
    /// `diffraction_integrated_colour(ω_i, ω_r, F²)`, output space.
    pub colour: [f32; 3],
    /// `diffraction_integrated_specular_colour(cos θ, F²)`.
    pub specular: [f32; 3],
    /// `diffraction_integrated_colour_filtered(ω_i, ω_r, σ_uv, σ_m², F²)` ([`run_probe`]
    /// only; 0 from [`run_scene_probe`]).
    pub filtered: [f32; 3],
}

/// Evaluates the technique for every case in a compute pass
/// (`shaders/diffraction_integrated_probe.wgsl`) and reads the colours back.
///
/// # Errors
/// [`Error::Invalid`] for more cases than one dispatch takes; [`Error::Gpu`] or
/// [`Error::DeviceLost`] from the device.
pub fn run_probe(
    ctx: &GpuContext,
    technique: &DiffractionIntegrated,
    cases: &[ProbeCase],
) -> Result<Vec<ProbeOutput>> {
    let input: Vec<[f32; 4]> = cases
        .iter()
        .flat_map(|c| {
            let (kind, ior) = match c.fresnel {
                FresnelTerm::Unity => (0.0, [1.0, 0.0]),
                FresnelTerm::Index(n) => (1.0, [n.re as f32, n.im as f32]),
            };
            let (i, r) = (c.omega_i, c.omega_r);
            [
                [i[0], i[1], i[2], kind],
                [r[0], r[1], r[2], c.sigma_uv],
                [ior[0], ior[1], c.cos_theta, c.slope_variance],
            ]
        })
        .collect();
    // Four vec4 per case: twice the dispatcher's two (the probe shader's header).
    let values = dispatch_probe(
        ctx,
        &probe_composition(),
        "diffraction_integrated_probe",
        (technique.bind_group_layout(), technique.bind_group()),
        &input,
        2 * cases.len(),
    )?;
    Ok(values
        .chunks_exact(4)
        .take(cases.len())
        .map(|c| ProbeOutput {
            colour: [c[0][0], c[0][1], c[0][2]],
            specular: [c[1][0], c[1][1], c[1][2]],
            filtered: [c[2][0], c[2][1], c[2][2]],
        })
        .collect())
}

/// Runs the terms technique's own probe entry point (`diffraction_probe` of
/// `shaders/diffraction_scene.wgsl`) on this table through [`TECHNIQUE_ADAPTER`]
/// ([`compose_scene`]): for each (ω_i, ω_r) in the grating frame, `diffraction_colour(ω_i,
/// ω_r)` and `diffraction_specular_order_colour(ω_r.z)` with the uniform's F². This is the
/// scene pipeline's source, run on the device: what the renderer gets when it binds this
/// table at group 1 instead of a terms table.
///
/// # Errors
/// As [`run_probe`].
pub fn run_scene_probe(
    ctx: &GpuContext,
    technique: &DiffractionIntegrated,
    pairs: &[([f32; 3], [f32; 3])],
) -> Result<Vec<ProbeOutput>> {
    let input: Vec<[f32; 4]> = pairs
        .iter()
        .flat_map(|(i, r)| [[i[0], i[1], i[2], 0.0], [r[0], r[1], r[2], 0.0]])
        .collect();
    let values = dispatch_probe(
        ctx,
        &scene_composition(),
        "diffraction_probe",
        (technique.bind_group_layout(), technique.bind_group()),
        &input,
        pairs.len(),
    )?;
    Ok(values
        .chunks_exact(2)
        .map(|c| ProbeOutput {
            colour: [c[0][0], c[0][1], c[0][2]],
            specular: [c[1][0], c[1][1], c[1][2]],
            filtered: [0.0; 3],
        })
        .collect())
}
