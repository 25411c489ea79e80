//! The `diffraction` technique on the GPU: loading baked `diffraction` tables (layout
//! "terms"; either layout through [`DiffractionTables`]) through their manifests, the technique's bind group (`shaders/diffraction.wgsl`),
//! the GPU = CPU probe, and the ray-cast scenes of `nacre render --scene cd-disc |
//! snake-skin` (`shaders/diffraction_scene.wgsl`).
//!
//! # Upload
//!
//! A `diffraction` table's Taylor terms Tₙ (`nacre_bake::kinds::diffraction` says what every texel
//! holds) become one 2-D array texture, `Rgba32Float`, Mₓ × M_y texels, ⌈(N + 1)/2⌉ layers,
//! layer l = (Re T₂ₗ, Im T₂ₗ, Re T₂ₗ₊₁, Im T₂ₗ₊₁) — the layout of the table's KTX2 file. Full
//! float is not filterable everywhere, and the technique needs exact bins anyway: the shader
//! reads it with `textureLoad` only (integer texel coordinates, texel (s, t) = bin
//! (s − ⌊Mₓ/2⌋, t − ⌊M_y/2⌋)). The texels come from the EXR file, else the KTX2 file
//! ([`nacre_format::Manifest::load_diffraction`]); every file is checked against its
//! manifest's SHA-256 and the texture against the device's limits before upload.
//!
//! [`DiffractionTables::load`] dispatches on the manifest's `layout` ([`DiffractionLayout`]):
//! "terms" loads as a [`DiffractionTable`] (this module), "integrated" (the fast path, the
//! wavelength sum done at bake time) as a [`DiffractionIntegrated`]; another layout is an
//! [`Error::Manifest`] naming it. The scenes, the bench pass ([`ScenePass`]) and
//! [`render_diffraction_scene`] take either: an integrated table runs the same consumers
//! (`shaders/diffraction_scene.wgsl`) through the adapter
//! `shaders/diffraction_integrated_technique.wgsl`
//! ([`crate::diffraction_integrated::compose_scene`]) with its own bind group at group 1.
//!
//! # Spectral sum
//!
//! The terms technique sums ρ(λ) u(λ) over a regular wavelength grid uploaded with the table
//! ([`DiffractionOptions::wavelength_step_nm`]): by default the table's own grid (the one the
//! CPU evaluation uses, `nacre diffraction --color`); a coarser step trades accuracy for
//! speed (10 nm halves the cost of the 5 nm default set). Each grid gets its own CIE weights
//! ([`SpectralGrid`]: the 1 nm weights interpolated, × step, rescaled so that ρ ≡ 1 is white),
//! times the table's output matrix M: u(λ) = M · xyz_weight(λ).
//!
//! # Coherence-window neighbourhood
//!
//! The window sum runs over R bins on each side of the nearest bin, per axis, with R the
//! smallest radius whose largest dropped weight exp(−(σ_s Δκ)² (R + ½)²/2) is at most
//! [`DiffractionOptions::window_tolerance`] (10⁻³ by default; at most [`MAX_RADIUS`]). The
//! `cd-tracks` table (σ_s Δκ = π/2) gets R = 2 (5 × 5 bins), dropping weights ≤ 4.5 · 10⁻⁴;
//! a one-row (1-D) grating has R = 0 along y.

use crate::context::{BufferInitExt, GpuContext};
use crate::diffraction_integrated::{self, DiffractionIntegrated};
use crate::error::{Error, Result};
use crate::fullscreen;
use crate::readback::read_texture;
use crate::render::{Camera, EnvironmentMap, Level, Light, MAX_DIMENSION, RenderedImage};
use crate::shaders;
use crate::tables::{check_limit, verify_files};
use bytemuck::{Pod, Zeroable};
use nacre_format::Manifest;
use nacre_format::diffraction::DiffractionRecord;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::{FresnelTerm, SpectralGrid, TaylorTerms};
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// What both layouts share (`shaders/diffraction_common.wgsl`): `diffraction_finite`,
/// `diffraction_unit`, `diffraction_frame`, `diffraction_fresnel_of`,
/// `diffraction_geometry_over_w2`; no bindings. [`DIFFRACTION`] and
/// [`crate::diffraction_integrated::WGSL`] each begin with it.
pub const DIFFRACTION_COMMON: &str = include_str!("../../../shaders/diffraction_common.wgsl");
/// The technique module, layout "terms" ([`DIFFRACTION_COMMON`], then
/// `shaders/diffraction.wgsl`, which imports it; `shaders::flatten("diffraction")` plus a
/// newline): bind group 1 and the functions `diffraction_colour`,
/// `diffraction_specular_order_colour`, `diffraction_fresnel`, `diffraction_frame`.
pub const DIFFRACTION: &str = concat!(
    include_str!("../../../shaders/diffraction_common.wgsl"),
    "\n",
    include_str!("../../../shaders/diffraction.wgsl")
);
/// Its consumers (`shaders/diffraction_scene.wgsl`): the scenes, the bench pass and the probe.
pub const DIFFRACTION_SCENE: &str = include_str!("../../../shaders/diffraction_scene.wgsl");

/// Largest Taylor order N the shader evaluates (`DIFFRACTION_MAX_ORDER` in the WGSL).
pub const MAX_TAYLOR_ORDER: usize = 63;
/// Largest neighbourhood radius R, bins per side.
pub const MAX_RADIUS: i32 = 16;
/// Most environment samples of a scene (`DiffractionView.samples`).
pub const MAX_ENV_SAMPLES: usize = 8;
/// Most wavelengths of the spectral sum.
pub const MAX_WAVELENGTHS: usize = 4096;

/// The composed source of a pipeline: the technique, then the consumers
/// ([`composition`]'s source).
pub fn compose() -> String {
    composition().source
}

/// `shaders/diffraction_scene.wgsl` with its imports, `<technique>` = `diffraction`
/// (diffraction_common, diffraction, diffraction_scene), and its source map.
pub fn composition() -> shaders::Composed {
    shaders::flatten_with("diffraction_scene", "diffraction")
        .expect("the diffraction modules resolve (tested)")
}

/// How a `diffraction` table stores the surface (the manifest's `layout`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiffractionLayout {
    /// "terms": the Taylor terms T₀ … T_N, `order` = N.
    Terms {
        /// N.
        order: usize,
    },
    /// "integrated": the wavelength-integrated colour tables I₀ … I₂N, `order` = N
    /// ([`crate::diffraction_integrated`]).
    Integrated {
        /// N.
        order: usize,
    },
}

impl DiffractionLayout {
    /// The layout of `record`, read from the manifest at `manifest_path`.
    ///
    /// # Errors
    /// [`Error::Manifest`] naming a layout the runtime does not know, or an "integrated"
    /// record without its `integrated` part.
    pub fn of(record: &DiffractionRecord, manifest_path: &Path) -> Result<Self> {
        let bad = |message: String| Error::Manifest {
            path: manifest_path.to_path_buf(),
            message,
        };
        match (record.layout.as_str(), &record.integrated) {
            ("terms", _) => Ok(DiffractionLayout::Terms {
                order: record.taylor_order,
            }),
            ("integrated", Some(_)) => Ok(DiffractionLayout::Integrated {
                order: record.taylor_order,
            }),
            ("integrated", None) => Err(bad(
                "diffraction layout \"integrated\" without its `integrated` record".into(),
            )),
            (other, _) => Err(bad(format!(
                "diffraction layout `{other}` has no GPU technique (the runtime samples layouts \"terms\" and \"integrated\")"
            ))),
        }
    }

    /// The manifest's name of the layout: "terms" or "integrated".
    pub fn name(self) -> &'static str {
        match self {
            DiffractionLayout::Terms { .. } => "terms",
            DiffractionLayout::Integrated { .. } => "integrated",
        }
    }
}

/// A `diffraction` table on the GPU in either layout, as [`DiffractionTables::load`] reads it
/// from its manifest: what the scenes ([`render_diffraction_scene`]) and the bench pass
/// ([`ScenePass::bench`]) take.
pub enum DiffractionTables {
    /// Layout "terms": the Taylor terms, summed over wavelengths per pixel.
    Terms(Box<DiffractionTable>),
    /// Layout "integrated": the wavelength sum done at bake time (the fast path).
    Integrated(Box<DiffractionIntegrated>),
}

impl DiffractionTables {
    /// Reads the manifest at `manifest_path` and loads the table by its layout:
    /// [`DiffractionTable::load`] for "terms",
    /// [`DiffractionIntegrated::load`] for "integrated", whose uniform holds `fresnel` (the F²
    /// the scene consumers apply; the terms technique takes F² from
    /// [`DiffractionOptions::fresnel`] instead, and ignores this argument).
    ///
    /// # Errors
    /// As the loaders; [`Error::Manifest`] for a table of another kind or an unknown layout.
    pub fn load(
        ctx: &GpuContext,
        manifest_path: &Path,
        fresnel: FresnelTerm,
    ) -> Result<DiffractionTables> {
        let record = diffraction_record(manifest_path)?.1;
        Ok(match DiffractionLayout::of(&record, manifest_path)? {
            DiffractionLayout::Terms { .. } => {
                DiffractionTables::Terms(Box::new(DiffractionTable::load(ctx, manifest_path)?))
            }
            DiffractionLayout::Integrated { .. } => DiffractionTables::Integrated(Box::new(
                DiffractionIntegrated::load(ctx, manifest_path, fresnel)?,
            )),
        })
    }

    /// Table name.
    pub fn name(&self) -> &str {
        match self {
            DiffractionTables::Terms(t) => &t.name,
            DiffractionTables::Integrated(t) => &t.name,
        }
    }

    /// The manifest's `diffraction` record.
    pub fn record(&self) -> &DiffractionRecord {
        match self {
            DiffractionTables::Terms(t) => &t.record,
            DiffractionTables::Integrated(t) => &t.record,
        }
    }

    /// The layout.
    pub fn layout(&self) -> DiffractionLayout {
        match self {
            DiffractionTables::Terms(t) => t.layout,
            DiffractionTables::Integrated(t) => DiffractionLayout::Integrated {
                order: t.record.taylor_order,
            },
        }
    }
}

impl From<DiffractionTable> for DiffractionTables {
    fn from(table: DiffractionTable) -> Self {
        DiffractionTables::Terms(Box::new(table))
    }
}

impl From<DiffractionIntegrated> for DiffractionTables {
    fn from(table: DiffractionIntegrated) -> Self {
        DiffractionTables::Integrated(Box::new(table))
    }
}

/// The manifest at `manifest_path` and its `diffraction` record.
///
/// # Errors
/// [`Error::Manifest`] for a table of another kind or a manifest without the record.
fn diffraction_record(manifest_path: &Path) -> Result<(Manifest, DiffractionRecord)> {
    let manifest = Manifest::read(manifest_path)?;
    if manifest.kind != nacre_format::TableKind::Diffraction {
        return Err(Error::Manifest {
            path: manifest_path.to_path_buf(),
            message: format!(
                "table `{}` is a `{}` table, not a `diffraction` table",
                manifest.name, manifest.kind
            ),
        });
    }
    let record = manifest
        .diffraction()
        .cloned()
        .ok_or_else(|| Error::Manifest {
            path: manifest_path.to_path_buf(),
            message: "a diffraction manifest without its `diffraction` record".into(),
        })?;
    Ok((manifest, record))
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
    /// [`DiffractionTables::load`]), a file that does not match its manifest, or an order
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
            return Err(Error::Invalid {
                context: "diffraction window tolerance".into(),
                message: format!("{tolerance} (expected between 0 and 1)"),
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
                return Err(Error::Invalid {
                    context: format!("diffraction `{}`", self.name),
                    message: format!(
                        "the coherence window spans {need} bins on each side (at most {MAX_RADIUS}): the patch is too large for σ_s"
                    ),
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
    /// its F² in its uniform ([`DiffractionTables::load`]); a scene or bench pass refuses
    /// one loaded with another F².
    pub fresnel: FresnelTerm,
    /// Largest window weight the neighbourhood may drop (default 10⁻³; module docs). Layout
    /// "terms" only.
    pub window_tolerance: f64,
}

impl Default for DiffractionOptions {
    fn default() -> Self {
        DiffractionOptions {
            wavelength_step_nm: None,
            fresnel: FresnelTerm::Unity,
            window_tolerance: 1e-3,
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
        return Err(Error::Invalid {
            context: "diffraction wavelength step".into(),
            message: format!(
                "{step} nm over {}–{} nm (expected 2 to {MAX_WAVELENGTHS} wavelengths)",
                record.wavelength_min_nm, record.wavelength_max_nm
            ),
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
    /// Padding.
    pub pad: [f32; 2],
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

/// Refuses a 2-D array texture of `[width, height, layers]` beyond the device's limits
/// (before anything is uploaded), naming `what`.
pub(crate) fn check_array_limits(ctx: &GpuContext, what: &str, size: [usize; 3]) -> Result<()> {
    let limits = ctx.device.limits();
    for (axis, n, limit) in [
        ("width", size[0], limits.max_texture_dimension_2d),
        ("height", size[1], limits.max_texture_dimension_2d),
        ("layers", size[2], limits.max_texture_array_layers),
    ] {
        check_limit(ctx, &format!("{what} {axis}"), n as u64, limit)?;
    }
    Ok(())
}

/// Uploads `texels` (RGBA, layer-major, rows of `width`) into a new `Rgba32Float` 2-D array
/// texture of `[width, height, layers]` named `name`: the storage of both diffraction
/// layouts, unfilterable and read with `textureLoad`.
pub(crate) fn upload_rgba32f_array(
    ctx: &GpuContext,
    name: &str,
    [width, height, layers]: [usize; 3],
    texels: &[f32],
) -> Result<wgpu::Texture> {
    ctx.checked(&format!("uploading the diffraction table `{name}`"), || {
        let size = wgpu::Extent3d {
            width: width as u32,
            height: height as u32,
            depth_or_array_layers: layers as u32,
        };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(name),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width as u32 * 16),
                rows_per_image: Some(height as u32),
            },
            size,
        );
        texture
    })
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
        let grid = SpectralGrid::new(&colorimeter, &wavelengths).map_err(|e| Error::Invalid {
            context: "diffraction wavelength grid".into(),
            message: e.to_string(),
        })?;
        let spectrum = spectrum_weights(&grid, &colorimeter);
        let (fresnel_kind, fresnel_ior) = match options.fresnel {
            FresnelTerm::Unity => (0, [1.0, 0.0]),
            FresnelTerm::Index(n) => {
                if !(n.re.is_finite() && n.im.is_finite() && n.re > 0.0 && n.im >= 0.0) {
                    return Err(Error::Invalid {
                        context: "diffraction Fresnel index".into(),
                        message: format!("{n} (expected n > 0, κ ≥ 0, finite)"),
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
            pad: [0.0; 2],
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

/// One compute dispatch of `entry` in `source` (64 invocations per workgroup, one per
/// case) for the probes of both layouts: group 0 empty, group 1 the technique's
/// (`technique`: layout and bind group), group 2 binding 0 the `input` (read-only storage),
/// binding 1 two vec4<f32> outputs per case; returns the outputs.
///
/// # Errors
/// [`Error::Invalid`] for more cases than one dispatch takes; [`Error::Gpu`] or
/// [`Error::DeviceLost`] from the device.
pub(crate) fn dispatch_probe(
    ctx: &GpuContext,
    source: &shaders::Composed,
    entry: &str,
    technique: (&wgpu::BindGroupLayout, &wgpu::BindGroup),
    input: &[[f32; 4]],
    cases: usize,
) -> Result<Vec<[f32; 4]>> {
    if cases == 0 {
        return Ok(Vec::new());
    }
    let groups = u32::try_from(cases.div_ceil(64))
        .ok()
        .filter(|g| *g <= ctx.device.limits().max_compute_workgroups_per_dimension)
        .ok_or_else(|| Error::Invalid {
            context: format!("diffraction probe `{entry}`"),
            message: format!("{cases} cases are too many for one dispatch"),
        })?;
    let out_bytes = (cases * 2 * 16) as u64;
    let device = &ctx.device;
    let module = shaders::create_module(ctx, entry, source)?;
    let readback = ctx.checked(&format!("running the diffraction probe `{entry}`"), || {
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let io_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("diffraction probe io"),
            entries: &[storage(0, true), storage(1, false)],
        });
        let empty = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("diffraction probe (no view)"),
            entries: &[],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("diffraction probe"),
            bind_group_layouts: &[Some(&empty), Some(technique.0), Some(&io_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        let inputs = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("diffraction probe inputs"),
            contents: bytemuck::cast_slice(input),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let outputs = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("diffraction probe outputs"),
            size: out_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("diffraction probe readback"),
            size: out_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("diffraction probe (no view)"),
            layout: &empty,
            entries: &[],
        });
        let io = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("diffraction probe io"),
            layout: &io_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: inputs.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: outputs.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &empty_group, &[]);
            pass.set_bind_group(1, technique.1, &[]);
            pass.set_bind_group(2, &io, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&outputs, 0, &readback, 0, out_bytes);
        ctx.queue.submit([encoder.finish()]);
        readback
    })?;
    let bytes = crate::readback::read_buffer(ctx, &readback, "reading the diffraction probe back")?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}

// ─── Scenes ────────────────────────────────────────────────────────────────────────────────

/// The diffraction scenes of `nacre render` (`shaders/diffraction_scene.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DiffractionScene {
    /// A CD-like disc (an annulus in y = 0, radius 1) with circular tracks, seen at an angle.
    CdDisc,
    /// A patch of a cylinder (a snake's body) tiled with domed scales whose ridges run along
    /// the body, rotated and fanned per scale.
    SnakeSkin,
}

impl DiffractionScene {
    /// Every scene.
    pub const ALL: [DiffractionScene; 2] = [DiffractionScene::CdDisc, DiffractionScene::SnakeSkin];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            DiffractionScene::CdDisc => "cd-disc",
            DiffractionScene::SnakeSkin => "snake-skin",
        }
    }

    /// The default-set table the scene uses.
    pub fn default_table(self) -> &'static str {
        match self {
            DiffractionScene::CdDisc => "cd-tracks",
            DiffractionScene::SnakeSkin => "snake-ridges",
        }
    }

    fn id(self) -> u32 {
        match self {
            DiffractionScene::CdDisc => 0,
            DiffractionScene::SnakeSkin => 1,
        }
    }

    /// The scene's camera.
    pub fn camera(self) -> Camera {
        match self {
            DiffractionScene::CdDisc => Camera {
                eye: [0.0, 1.9, 2.2],
                target: [0.0, -0.12, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 40.0,
            },
            DiffractionScene::SnakeSkin => Camera {
                eye: [0.35, 2.6, 2.3],
                target: [0.0, 0.55, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 42.0,
            },
        }
    }

    /// The scene's Fresnel factor: 1 for the disc (an aluminium-coated CD reflects ~90 %),
    /// the Fresnel reflectance of keratin (n = 1.56, about 5 % at normal incidence) for the
    /// snake's scales.
    pub fn fresnel(self) -> FresnelTerm {
        match self {
            DiffractionScene::CdDisc => FresnelTerm::Unity,
            DiffractionScene::SnakeSkin => FresnelTerm::Index(nacre_optics::C64::new(1.56, 0.0)),
        }
    }

    /// The scene's light: a white directional light (the sun) from behind and to the left
    /// of the camera for the disc, from above and behind for the snake.
    pub fn light(self) -> Light {
        match self {
            DiffractionScene::CdDisc => Light {
                direction: [-0.35, 0.8, -0.5],
                colour: [1.0, 0.97, 0.92],
                intensity: 3.0,
            },
            DiffractionScene::SnakeSkin => Light {
                direction: [0.3, 0.85, -0.45],
                colour: [1.0, 0.97, 0.92],
                intensity: 3.0,
            },
        }
    }
}

impl FromStr for DiffractionScene {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        DiffractionScene::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::Invalid {
                context: format!("diffraction scene `{s}`"),
                message: "expected cd-disc or snake-skin".into(),
            })
    }
}

/// Settings of a diffraction scene.
#[derive(Clone, Debug)]
pub struct DiffractionSceneOptions {
    /// The scene.
    pub scene: DiffractionScene,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The camera.
    pub camera: Camera,
    /// Equirectangular environment (OpenEXR); `None`: the default studio without its sun
    /// (the directional light is the sun) — [`crate::render::procedural_environment_with`].
    pub environment: Option<PathBuf>,
    /// Environment multiplier (default 0.5: a dim room, so that the rainbows stand out).
    pub env_intensity: f32,
    /// Environment samples diffracted like the light (0 to [`MAX_ENV_SAMPLES`]).
    pub env_samples: usize,
    /// The directional light; `intensity` is its irradiance E₀ at normal incidence (the
    /// grating sees the radiance E₀ (σ_s k₀)²/π of its mirror image, [`lobe_gain`]).
    pub light: Light,
    /// Exposure, EV stops.
    pub exposure_ev: f32,
    /// The technique's settings (default here: a 10 nm wavelength step, which an
    /// integrated table leaves unused: [`DiffractionOptions`]).
    pub technique: DiffractionOptions,
}

impl DiffractionSceneOptions {
    /// The defaults of `scene`: 800 × 600, 4 environment samples, 10 nm wavelength step,
    /// the scene's [`DiffractionScene::fresnel`].
    pub fn new(scene: DiffractionScene) -> DiffractionSceneOptions {
        DiffractionSceneOptions {
            scene,
            width: 800,
            height: 600,
            camera: scene.camera(),
            environment: None,
            env_intensity: 0.5,
            env_samples: 4,
            light: scene.light(),
            exposure_ev: 0.0,
            technique: DiffractionOptions {
                wavelength_step_nm: Some(10.0),
                fresnel: scene.fresnel(),
                ..DiffractionOptions::default()
            },
        }
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the setting.
    pub fn validate(&self) -> Result<()> {
        let bad = |context: &str, message: String| {
            Err(Error::Invalid {
                context: context.into(),
                message,
            })
        };
        for (what, n) in [("width", self.width), ("height", self.height)] {
            if n == 0 || n > MAX_DIMENSION {
                return bad(what, format!("{n} (expected 1 to {MAX_DIMENSION} pixels)"));
            }
        }
        if !self.exposure_ev.is_finite() || self.exposure_ev.abs() > 64.0 {
            return bad(
                "exposure",
                format!("{} (expected −64 to 64 EV)", self.exposure_ev),
            );
        }
        if !(self.env_intensity.is_finite() && self.env_intensity >= 0.0) {
            return bad(
                "environment intensity",
                format!("{} (expected ≥ 0)", self.env_intensity),
            );
        }
        if self.env_samples > MAX_ENV_SAMPLES {
            return bad(
                "environment samples",
                format!("{} (expected 0 to {MAX_ENV_SAMPLES})", self.env_samples),
            );
        }
        let l = &self.light;
        if !(l.direction.iter().chain(&l.colour).all(|x| x.is_finite())
            && l.intensity.is_finite()
            && l.intensity >= 0.0
            && l.direction.iter().any(|x| *x != 0.0))
        {
            return bad("light", format!("{l:?} (finite, non-zero direction)"));
        }
        self.camera
            .inverse_view_projection(f64::from(self.width) / f64::from(self.height))?;
        Ok(())
    }
}

/// Mirror of `DiffractionView` (shaders/diffraction_scene.wgsl, 400 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DiffractionViewUniform {
    /// Clip → world.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Camera position.
    pub eye: [f32; 3],
    /// 2^EV.
    pub exposure: f32,
    /// Towards the light, unit.
    pub light_direction: [f32; 3],
    /// Light intensity.
    pub light_intensity: f32,
    /// Light colour.
    pub light_colour: [f32; 3],
    /// Environment multiplier.
    pub env_intensity: f32,
    /// Target size, pixels.
    pub resolution: [f32; 2],
    /// 0 cd-disc, 1 snake-skin, 2 bench.
    pub scene: u32,
    /// Environment samples used.
    pub sample_count: u32,
    /// Sample directions (xyz unit, w 0).
    pub samples: [[f32; 4]; MAX_ENV_SAMPLES],
    /// Sample radiance I_k (rgb, × env_intensity; w 0).
    pub sample_radiance: [[f32; 4]; MAX_ENV_SAMPLES],
    /// E₀, the light's irradiance at normal incidence.
    pub light_irradiance: f32,
    /// Padding.
    pub pad: [f32; 3],
}

/// The `count` brightest texels (by luminance 0.2126 R + 0.7152 G + 0.0722 B) of the 32 × 16
/// (or the first narrower) level of `env`'s mip chain, above the horizon (y > 0.05) and at
/// least 25° apart, as (unit direction, irradiance L·Ω at normal incidence, Ω the texel's
/// solid angle (2π/w)(π/h) sin θ); brightest first, ties by texel index.
pub fn environment_samples(env: &EnvironmentMap, count: usize) -> Vec<([f32; 3], [f32; 3])> {
    let levels = env.mip_chain();
    let (w, h, texels): &Level<4> = levels
        .iter()
        .find(|(w, _, _)| *w <= 32)
        .unwrap_or_else(|| levels.last().expect("a mip chain has a level"));
    let mut order: Vec<(f32, usize)> = texels
        .iter()
        .enumerate()
        .map(|(i, t)| (0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2], i))
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let min_cos = 25f64.to_radians().cos();
    let mut chosen: Vec<([f32; 3], [f32; 3])> = Vec::new();
    for (lum, i) in order {
        if chosen.len() == count || lum.is_nan() || lum <= 0.0 {
            break;
        }
        let (u, v) = (
            ((i % w) as f64 + 0.5) / *w as f64,
            ((i / w) as f64 + 0.5) / *h as f64,
        );
        let d = crate::ibl::env_uv_to_direction(u, v);
        if d[1] <= 0.05 {
            continue;
        }
        let far = chosen.iter().all(|(c, _)| {
            f64::from(c[0]) * d[0] + f64::from(c[1]) * d[1] + f64::from(c[2]) * d[2] < min_cos
        });
        if far {
            let t = texels[i];
            let theta = std::f64::consts::PI * v;
            let omega = (std::f64::consts::TAU / *w as f64)
                * (std::f64::consts::PI / *h as f64)
                * theta.sin();
            chosen.push((
                d.map(|x| x as f32),
                [t[0], t[1], t[2]].map(|x| (f64::from(x) * omega) as f32),
            ));
        }
    }
    chosen
}

/// Group 0 of the scene and bench passes: the view uniform, the environment and its sampler.
struct ViewGroup {
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
}

fn view_group(
    ctx: &GpuContext,
    uniform: &DiffractionViewUniform,
    env: &EnvironmentMap,
) -> Result<ViewGroup> {
    let texture = crate::render::upload_mips(
        ctx,
        "diffraction environment",
        wgpu::TextureFormat::Rgba16Float,
        &env.mip_chain(),
    )?;
    let device = &ctx.device;
    ctx.checked("binding the diffraction view", || {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("diffraction view"),
            entries: &[
                crate::render::uniform_entry(0),
                crate::render::texture_entry(1),
                crate::render::sampler_entry(2),
            ],
        });
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("DiffractionView"),
            contents: bytemuck::bytes_of(uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = texture.create_view(&Default::default());
        let sampler = crate::render::linear_sampler(device, "diffraction environment", false);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("diffraction view"),
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
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        ViewGroup { layout, group }
    })
}

/// Group 1 of a scene pass: the technique of the table's layout.
enum SceneTechnique {
    /// Layout "terms": the table, its uniform and the spectral weights.
    Terms(DiffractionBinding),
    /// Layout "integrated": the table's own bind group
    /// ([`DiffractionIntegrated::bind_group`]).
    Integrated {
        layout: wgpu::BindGroupLayout,
        bind_group: wgpu::BindGroup,
    },
}

/// The scene (or bench) pipeline with its groups 0 and 1, ready to draw.
pub struct ScenePass {
    pipeline: wgpu::RenderPipeline,
    view: ViewGroup,
    technique: SceneTechnique,
}

impl ScenePass {
    /// Group 1 and the source for `table`: the terms technique ([`compose`]) with a
    /// [`DiffractionBinding`], or the integrated module with the adapter
    /// ([`diffraction_integrated::compose_scene`]) and the table's own bind group.
    fn new(
        ctx: &GpuContext,
        table: &DiffractionTables,
        technique: &DiffractionOptions,
        uniform: &DiffractionViewUniform,
        env: &EnvironmentMap,
    ) -> Result<ScenePass> {
        let (technique, source) = match table {
            DiffractionTables::Terms(t) => (
                SceneTechnique::Terms(DiffractionBinding::new(ctx, t, technique)?),
                composition(),
            ),
            DiffractionTables::Integrated(t) => {
                let wanted = diffraction_integrated::fresnel_parameters(technique.fresnel)?;
                if wanted != (t.uniform.fresnel_kind, t.uniform.fresnel_ior) {
                    return Err(Error::Invalid {
                        context: format!("integrated diffraction `{}`", t.name),
                        message: format!(
                            "the table was loaded with another Fresnel factor than the pass's {:?} (load it with that one)",
                            technique.fresnel
                        ),
                    });
                }
                (
                    SceneTechnique::Integrated {
                        layout: t.bind_group_layout().clone(),
                        bind_group: t.bind_group().clone(),
                    },
                    diffraction_integrated::scene_composition(),
                )
            }
        };
        let technique_layout = match &technique {
            SceneTechnique::Terms(b) => &b.layout,
            SceneTechnique::Integrated { layout, .. } => layout,
        };
        let view = view_group(ctx, uniform, env)?;
        let device = &ctx.device;
        let module = shaders::create_module(ctx, "diffraction scene", &source)?;
        let pipeline = ctx.checked("building the diffraction pipeline", || {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("diffraction scene"),
                bind_group_layouts: &[Some(&view.layout), Some(technique_layout)],
                immediate_size: 0,
            });
            fullscreen::pipeline(
                device,
                "diffraction scene",
                &module,
                &layout,
                ("diffraction_vs", "diffraction_scene_fs"),
                &[crate::render::TARGET_FORMAT],
            )
        })?;
        Ok(ScenePass {
            pipeline,
            view,
            technique,
        })
    }

    /// The bench pass of `nacre bench-gpu`: every pixel of a `width × height` target shaded
    /// with the technique of `table`'s layout (scene 2 of `shaders/diffraction_scene.wgsl`),
    /// lit by `light`.
    pub fn bench(
        ctx: &GpuContext,
        table: &DiffractionTables,
        technique: &DiffractionOptions,
        width: u32,
        height: u32,
        light: &Light,
    ) -> Result<ScenePass> {
        let mut uniform = DiffractionViewUniform::zeroed();
        uniform.exposure = 1.0;
        uniform.light_direction = unit(light.direction);
        uniform.light_colour = light.colour;
        uniform.light_intensity = light.intensity * lobe_gain(table.record());
        uniform.light_irradiance = light.intensity;
        uniform.resolution = [width as f32, height as f32];
        uniform.scene = 2;
        let env = EnvironmentMap {
            width: 1,
            height: 1,
            rgb: vec![[0.0; 3]],
        };
        let pass = ScenePass::new(ctx, table, technique, &uniform, &env)?;
        pass.check_loop_cap(ctx, 1, "bench")?;
        Ok(pass)
    }

    /// On llvmpipe, refuses a terms-layout pass whose per-pixel loops — `diffracted` calls of
    /// `diffraction_colour` plus the specular order — could run past
    /// [`LLVMPIPE_LOOP_LIMIT`], which would silently cut them short. The estimate counts
    /// the sums' own loops; llvmpipe's count runs ~20 % higher (cd-disc went wrong from 56
    /// wavelengths on, an estimate of 54,824), so the pass is refused above three quarters of
    /// the cap. Other adapters and integrated tables (a few dozen iterations) always pass.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the way out (a coarser step, fewer samples, the fast layout).
    pub fn check_loop_cap(&self, ctx: &GpuContext, diffracted: u64, what: &str) -> Result<()> {
        let Some(binding) = self.technique() else {
            return Ok(());
        };
        let u = &binding.uniform;
        let specular = u64::from(u.wavelength_count) * (u64::from(u.order) + 3);
        let needed = diffracted * binding.loop_iterations_per_colour() + specular;
        if ctx.info.name.contains("llvmpipe") && needed > LLVMPIPE_LOOP_LIMIT * 3 / 4 {
            return Err(Error::Invalid {
                context: format!("the diffraction {what} pass on {}", ctx.info.name),
                message: format!(
                    "needs about {needed} shader loop iterations per pixel ({diffracted} diffracted lights × {} wavelengths), more than llvmpipe allows with margin (it stops every shader invocation after {LLVMPIPE_LOOP_LIMIT} and would draw a wrong picture): use a coarser --wavelength-step (--diffraction-step in bench-gpu), fewer --env-samples, or a table in the layout \"integrated\" (e.g. --tables cd-tracks-fast)",
                    u.wavelength_count
                ),
            });
        }
        Ok(())
    }

    /// Records the draw into `pass` (a render pass on a [`crate::render::TARGET_FORMAT`] target).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.view.group, &[]);
        let technique = match &self.technique {
            SceneTechnique::Terms(b) => &b.bind_group,
            SceneTechnique::Integrated { bind_group, .. } => bind_group,
        };
        pass.set_bind_group(1, technique, &[]);
        pass.draw(0..3, 0..1);
    }

    /// The terms technique's bind group (uniform, spectrum) as built; `None` for an
    /// integrated table (its group 1 is the table's own).
    pub fn technique(&self) -> Option<&DiffractionBinding> {
        match &self.technique {
            SceneTechnique::Terms(b) => Some(b),
            SceneTechnique::Integrated { .. } => None,
        }
    }
}

/// Reference wavelength of [`lobe_gain`], nm.
pub const LOBE_REFERENCE_NM: f64 = 555.0;

/// (σ_s k₀)²/π at k₀ = 2π/[`LOBE_REFERENCE_NM`]: the radiance, per unit irradiance at normal
/// incidence, of a light's mirror image spread over the coherence lobe. A flat mirror's
/// |P̃|² = exp(−σ_s² k² |Δ(u, v)|²) integrates to π/(σ_s k)² over (u, v), so a source of
/// irradiance E seen in a surface of relative reflectance ρ has radiance
/// ρ · E · (σ_s k)²/π (the k² of Stam's BRDF); the scenes take k at 555 nm for every
/// wavelength (the lobe's wavelength dependence, a factor (555/λ)², is left out).
pub fn lobe_gain(record: &DiffractionRecord) -> f32 {
    let k0 = std::f64::consts::TAU / (LOBE_REFERENCE_NM * 1e-3);
    ((record.sigma_s_um * k0).powi(2) / std::f64::consts::PI) as f32
}

fn unit(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        v.map(|x| x / l)
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// Renders a diffraction scene with `table` (either layout) and reads it back as
/// sRGB-encoded RGBA8.
///
/// # Errors
/// [`Error::Invalid`] for bad options (and an integrated table loaded with another F² than
/// `options.technique.fresnel`); environment and GPU errors as [`crate::render`].
pub fn render_diffraction_scene(
    ctx: &GpuContext,
    table: &DiffractionTables,
    options: &DiffractionSceneOptions,
) -> Result<RenderedImage> {
    options.validate()?;
    let env = match &options.environment {
        Some(path) => EnvironmentMap::load(path)?,
        None => {
            let (w, h) = crate::render::DEFAULT_ENVIRONMENT_SIZE;
            crate::render::procedural_environment_with(w, h, false)
        }
    };
    let (width, height) = (options.width, options.height);
    let mut uniform = DiffractionViewUniform::zeroed();
    uniform.inv_view_proj = options
        .camera
        .inverse_view_projection(f64::from(width) / f64::from(height))?;
    uniform.eye = options.camera.eye;
    uniform.exposure = 2f32.powf(options.exposure_ev);
    let gain = lobe_gain(table.record());
    uniform.light_direction = unit(options.light.direction);
    uniform.light_colour = options.light.colour;
    uniform.light_intensity = options.light.intensity * gain;
    uniform.light_irradiance = options.light.intensity;
    uniform.env_intensity = options.env_intensity;
    uniform.resolution = [width as f32, height as f32];
    uniform.scene = options.scene.id();
    let samples = environment_samples(&env, options.env_samples);
    uniform.sample_count = samples.len() as u32;
    for (k, (d, l)) in samples.iter().enumerate() {
        uniform.samples[k] = [d[0], d[1], d[2], 0.0];
        uniform.sample_radiance[k] =
            [l[0], l[1], l[2], 0.0].map(|x| x * options.env_intensity * gain);
    }
    let pass = ScenePass::new(ctx, table, &options.technique, &uniform, &env)?;
    // The light and every environment sample are diffracted.
    pass.check_loop_cap(ctx, 1 + samples.len() as u64, options.scene.name())?;
    let device = &ctx.device;
    let target = ctx.checked("creating the diffraction target", || {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("diffraction scene"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: crate::render::TARGET_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    })?;
    let target_view = target.create_view(&Default::default());
    let start = std::time::Instant::now();
    ctx.checked("drawing the diffraction scene", || {
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("diffraction scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.draw(&mut rp);
        }
        ctx.queue.submit([encoder.finish()]);
    })?;
    ctx.wait("rendering the diffraction scene")?;
    let gpu_seconds = start.elapsed().as_secs_f64();
    let pixels = read_texture(ctx, &target, 4)?;
    Ok(RenderedImage {
        width,
        height,
        pixels,
        gpu_seconds,
    })
}
