//! What both `diffraction` layouts share: the WGSL both technique modules begin with
//! ([`DIFFRACTION_COMMON`]), the manifest's layout ([`DiffractionLayout`]) and `diffraction`
//! record, the upload of a table's `Rgba32Float` array texture and the compute dispatch of
//! the GPU = CPU probes.

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu::{self, check_limit};
use crate::shaders;
use nacre_format::Manifest;
use nacre_format::diffraction::DiffractionRecord;
use std::path::Path;

/// What both layouts share (`shaders/diffraction_common.wgsl`): `diffraction_finite`,
/// `diffraction_unit`, `diffraction_frame`, `diffraction_fresnel_of`,
/// `diffraction_geometry_over_w2`; no bindings. [`DIFFRACTION`](super::terms::DIFFRACTION) and
/// [`super::integrated::WGSL`] each begin with it.
pub const DIFFRACTION_COMMON: &str = include_str!("../../../../shaders/diffraction_common.wgsl");

/// How a `diffraction` table stores the surface (the manifest's `layout`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiffractionLayout {
    /// "terms": the Taylor terms T₀ … T_N, `order` = N.
    Terms {
        /// N.
        order: usize,
    },
    /// "integrated": the wavelength-integrated colour tables I₀ … I₂N, `order` = N
    /// ([`super::integrated`]).
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

/// The manifest at `manifest_path` and its `diffraction` record.
///
/// # Errors
/// [`Error::Manifest`] for a table of another kind or a manifest without the record.
pub(super) fn diffraction_record(manifest_path: &Path) -> Result<(Manifest, DiffractionRecord)> {
    let manifest = Manifest::read(manifest_path)?;
    if manifest.kind != nacre_format::TableKind::DIFFRACTION {
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

/// Refuses a 2-D array texture of `[width, height, layers]` beyond the device's limits
/// (before anything is uploaded), naming `what`.
pub(super) fn check_array_limits(ctx: &GpuContext, what: &str, size: [usize; 3]) -> Result<()> {
    let limits = ctx.device.limits();
    for (axis, n, limit) in [
        ("width", size[0], limits.max_texture_dimension_2d),
        ("height", size[1], limits.max_texture_dimension_2d),
        (
            "layers",
            allocated_layers(size),
            limits.max_texture_array_layers,
        ),
    ] {
        check_limit(ctx, &format!("{what} {axis}"), n as u64, limit)?;
    }
    Ok(())
}

/// The layers allocated for a 2-D array texture of `[width, height, layers]`: `layers`, or
/// one more (left zero, never read) where wgpu's GL backend would not make the texture a
/// 2-D array. wgpu-hal's GLES backend fixes a texture's GL target when it creates it, from
/// its size alone (`gles::Texture::get_info_from_desc`): one layer gives `GL_TEXTURE_2D`,
/// and a square one whose layer count is a multiple of 6 gives `GL_TEXTURE_CUBE_MAP(_ARRAY)`
/// ("cube compatible"). A `D2Array` view of either reads nothing in a `sampler2DArray`
/// (texelFetch returns 0): the 256 × 256 × 6 layers of `cd-tracks` made its every colour 0
/// on GL. The extra layer keeps the target `GL_TEXTURE_2D_ARRAY` on every backend; the
/// shaders read only the layers their uniform names.
pub(super) fn allocated_layers([width, height, layers]: [usize; 3]) -> usize {
    let cube_compatible = width == height && layers % 6 == 0;
    if layers == 1 || cube_compatible {
        layers + 1
    } else {
        layers
    }
}

/// Uploads `texels` (RGBA, layer-major, rows of `width`) into a new `Rgba32Float` 2-D array
/// texture of `[width, height, layers]` named `name`: the storage of both diffraction
/// layouts, unfilterable and read with `textureLoad`. The texture has
/// [`allocated_layers`] layers, the last one zero where that is one more.
pub(super) fn upload_rgba32f_array(
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
        let allocated = wgpu::Extent3d {
            depth_or_array_layers: allocated_layers([width, height, layers]) as u32,
            ..size
        };
        let texture = gpu::sampled_texture(
            &ctx.device,
            name,
            allocated,
            wgpu::TextureDimension::D2,
            wgpu::TextureFormat::Rgba32Float,
            1,
        );
        gpu::write_region(
            &ctx.queue,
            &texture,
            0,
            0,
            size,
            16,
            bytemuck::cast_slice(texels),
        );
        texture
    })
}

/// One compute dispatch of `entry` in `source` (64 invocations per workgroup, one per
/// case) for the probes of both layouts, through [`crate::probe::dispatch_compute`]: group 0
/// empty, group 1 the technique's (`technique`: layout and bind group), group 2 empty (the
/// scenes' lights), group 3 binding 0 the `input` (read-only storage), binding 1 two
/// vec4<f32> outputs per case; returns the outputs.
///
/// # Errors
/// [`Error::Limit`] for more cases than one dispatch takes; [`Error::Gpu`] or
/// [`Error::DeviceLost`] from the device.
pub(super) fn dispatch_probe(
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
    let module = shaders::create_module(ctx, entry, source)?;
    crate::probe::dispatch_compute(
        ctx,
        &crate::probe::ComputeProbe {
            label: &format!("diffraction probe `{entry}`"),
            module: &module,
            entry_point: entry,
            tables: technique,
            io_group: 3,
            inputs: bytemuck::cast_slice(input),
            uniform: None,
            cases,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::allocated_layers;

    #[test]
    fn arrays_gl_would_take_for_a_2d_texture_or_a_cube_get_one_more_layer() {
        // cd-tracks: 256 × 256, order 11 → 6 layers (a cube map to wgpu's GL backend).
        assert_eq!(allocated_layers([256, 256, 6]), 7);
        assert_eq!(allocated_layers([64, 64, 12]), 13);
        // One layer (a GL_TEXTURE_2D) of any shape.
        assert_eq!(allocated_layers([800, 1, 1]), 2);
        assert_eq!(allocated_layers([16, 16, 1]), 2);
        // Already 2-D arrays: unchanged.
        assert_eq!(allocated_layers([800, 1, 6]), 6);
        assert_eq!(allocated_layers([256, 256, 5]), 5);
        assert_eq!(allocated_layers([256, 128, 6]), 6);
    }
}
