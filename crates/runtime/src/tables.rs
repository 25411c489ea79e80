//! Loading baked tables through their manifests and uploading them as textures.
//!
//! * `film-lut` → two 3-D `Rgba16Float` textures (reflectance, transmittance; a 1×1×1 zero
//!   texture when the base is opaque), x = cos θ, y = Δ, z = film index. The files hold half
//!   floats (or 16-bit PNG), so the upload is exact, and a linear, clamp-to-edge sampler at
//!   the texture coordinates of `lut_mapping.wgsl` reproduces the CPU `lut:` method.
//! * `rough-film-lut` → two 3-D `Rgba16Float` textures (reflectance, transmittance; a 1×1×1
//!   zero texture when the base is opaque) in the layout of `nacre_bake::kinds::rough_film_lut`: x =
//!   cos θ_o, y = Δ, z = i_α · count(n_f) + i_n (α-major blocks); `rough_lut_mapping.wgsl`
//!   samples it (two trilinear fetches, mixed in α).
//! * `fourier` → one 2-D array texture, `Rgba32Float`, two layers (0: Re A_j, 1: Im A_j),
//!   width N, height 1, mip level k = the table's level k (N / 2^k texels). Full float
//!   is not filterable everywhere, so `film_fourier.wgsl` filters it itself with
//!   `textureLoad`, exactly as the CPU does.
//!
//! The texels come from the OpenEXR files when the manifest lists them, else from the KTX2
//! files baked beside them (`film-lut`: one 3-D `RGBA16F` texture per quantity; `fourier`:
//! one 2-D array `RGBA32F` texture with every level; see `nacre_format::ktx2`), so a
//! manifest whose `files` list only KTX2 files loads too, into identical textures.
//!
//! Every file is checked against its manifest (format, size, SHA-256) before upload, and
//! every texture against the device's limits, so a mismatch is an [`Error`], not a panic.

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu::{check_limit, sampled_texture, write_region};
use half::f16;
use nacre_format::film_lut::FilmLutAxes;
use nacre_format::fourier::FourierAxes;
use nacre_format::rough_film_lut::RoughLutAxes;
use nacre_format::table_io::{self, Table3};
use nacre_format::{Manifest, TableKind};
use nacre_optics::colour::Colorimeter;
use std::path::{Path, PathBuf};

/// A `film-lut` table on the GPU.
pub struct FilmLutTextures {
    /// Table name (from the manifest).
    pub name: String,
    /// The manifest it was loaded from.
    pub manifest_path: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
    /// Axes (counts, ranges, ambient index).
    pub axes: FilmLutAxes,
    /// Reflectance, 3-D `Rgba16Float`.
    pub reflectance: wgpu::Texture,
    /// Transmittance, 3-D `Rgba16Float` (1×1×1 zero when the base is opaque).
    pub transmittance: wgpu::Texture,
    /// Whether the table has a transmittance.
    pub has_transmittance: bool,
}

/// A `rough-film-lut` table on the GPU (`nacre_bake::kinds::rough_film_lut`).
pub struct RoughFilmLutTextures {
    /// Table name (from the manifest).
    pub name: String,
    /// The manifest it was loaded from.
    pub manifest_path: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
    /// Axes (counts, ranges, ambient index).
    pub axes: RoughLutAxes,
    /// Directional albedo of the reflected lobe E_r, 3-D `Rgba16Float`.
    pub reflectance: wgpu::Texture,
    /// Energy transmitted into the base E_t, 3-D `Rgba16Float` (1×1×1 zero when opaque).
    pub transmittance: wgpu::Texture,
    /// Whether the table has a transmittance.
    pub has_transmittance: bool,
}

/// A `fourier` table on the GPU.
pub struct FourierTextures {
    /// Table name.
    pub name: String,
    /// The manifest it was loaded from.
    pub manifest_path: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
    /// Axes (levels, σ per level, carriers, white).
    pub axes: FourierAxes,
    /// 2-D array texture, 2 layers (Re, Im), one mip level per table level.
    pub texture: wgpu::Texture,
}

/// The tables a renderer samples: at most one `film-lut` and one `fourier` table.
#[derive(Default)]
pub struct TableSet {
    /// The `film-lut` table, if loaded.
    pub film_lut: Option<FilmLutTextures>,
    /// The `fourier` table, if loaded.
    pub fourier: Option<FourierTextures>,
    /// The `rough-film-lut` table, if loaded (the exact split-sum path).
    pub rough_film_lut: Option<RoughFilmLutTextures>,
}

impl TableSet {
    /// Reads the manifest at `manifest_path` and its files, validates them and uploads them.
    pub fn load(ctx: &GpuContext, manifest_path: &Path) -> Result<TableSet> {
        let mut set = TableSet::default();
        set.add(ctx, manifest_path)?;
        Ok(set)
    }

    /// Loads another table into the set, replacing a table of the same kind.
    pub fn add(&mut self, ctx: &GpuContext, manifest_path: &Path) -> Result<()> {
        self.add_read(ctx, Manifest::read(manifest_path)?, manifest_path)
    }

    /// [`TableSet::add`] with the manifest already read (from `manifest_path`): checks its
    /// files and uploads them.
    pub fn add_read(
        &mut self,
        ctx: &GpuContext,
        manifest: Manifest,
        manifest_path: &Path,
    ) -> Result<()> {
        verify_files(&manifest, manifest_path)?;
        match manifest.kind {
            TableKind::FILM_LUT => {
                self.film_lut = Some(upload_film_lut(ctx, manifest, manifest_path)?)
            }
            TableKind::FOURIER => {
                self.fourier = Some(upload_fourier(ctx, manifest, manifest_path)?)
            }
            TableKind::ROUGH_FILM_LUT => {
                self.rough_film_lut = Some(upload_rough_film_lut(ctx, manifest, manifest_path)?)
            }
            // Kinds the GPU does not sample (`diffraction` has its own loaders in
            // `crate::diffraction`; a CPU-only kind needs no line here).
            other => {
                return Err(Error::Manifest {
                    path: manifest_path.to_path_buf(),
                    message: format!(
                        "table kind `{other}` has no GPU use (expected `film-lut`, `fourier` or `rough-film-lut`)"
                    ),
                });
            }
        }
        // Finishes the uploads: a device lost meanwhile is reported here, not at first use.
        ctx.wait(&format!("uploading {}", manifest_path.display()))?;
        Ok(())
    }

    /// The colorimeter (observer, illuminant, output space) of the loaded tables; an error
    /// when the film-lut and fourier tables disagree.
    pub fn colorimeter(&self) -> Result<Colorimeter> {
        let mut found: Option<(&Manifest, &Path)> = None;
        for (m, p) in self
            .film_lut
            .iter()
            .map(|t| (&t.manifest, t.manifest_path.as_path()))
            .chain(
                self.fourier
                    .iter()
                    .map(|t| (&t.manifest, t.manifest_path.as_path())),
            )
            .chain(
                self.rough_film_lut
                    .iter()
                    .map(|t| (&t.manifest, t.manifest_path.as_path())),
            )
        {
            if let Some((first, first_path)) = found {
                if (&first.observer, &first.illuminant, &first.space)
                    != (&m.observer, &m.illuminant, &m.space)
                {
                    return Err(Error::Manifest {
                        path: p.to_path_buf(),
                        message: format!(
                            "colour {}/{}/{} differs from {} ({}/{}/{})",
                            m.space,
                            m.illuminant,
                            m.observer,
                            first_path.display(),
                            first.space,
                            first.illuminant,
                            first.observer
                        ),
                    });
                }
            } else {
                found = Some((m, p));
            }
        }
        let (m, p) = found.ok_or_else(|| Error::MissingTable {
            needed_by: "the table set's colorimeter".into(),
            kind: "any",
            example: None,
        })?;
        Ok(m.colorimeter(p)?)
    }
}

/// Checks that every file the manifest lists exists and has the recorded SHA-256.
pub(crate) fn verify_files(manifest: &Manifest, manifest_path: &Path) -> Result<()> {
    let dir = manifest_path.parent().unwrap_or(Path::new("."));
    for f in &manifest.files {
        let path = dir.join(&f.path);
        let sha = table_io::sha256_hex(&path)?;
        if sha != f.sha256 {
            return Err(Error::Manifest {
                path: manifest_path.to_path_buf(),
                message: format!(
                    "{} does not match its manifest (SHA-256 {sha}, manifest says {}): re-bake the table or restore the file",
                    path.display(),
                    f.sha256
                ),
            });
        }
    }
    Ok(())
}

fn upload_film_lut(
    ctx: &GpuContext,
    manifest: Manifest,
    manifest_path: &Path,
) -> Result<FilmLutTextures> {
    let axes = manifest
        .film_lut()
        .cloned()
        .ok_or_else(|| Error::Manifest {
            path: manifest_path.to_path_buf(),
            message: "a film-lut manifest without its `film_lut` axes".into(),
        })?;
    let limit = ctx.device.limits().max_texture_dimension_3d;
    for (name, n) in [
        ("cos θ axis", axes.cos_theta_count),
        ("OPD axis", axes.opd_count),
        ("index axis", axes.ior_count),
    ] {
        check_limit(
            ctx,
            &format!("film-lut `{}` {name}", manifest.name),
            n as u64,
            limit,
        )?;
    }
    let reflectance = manifest
        .load_table(manifest_path, "reflectance")?
        .ok_or_else(|| Error::Manifest {
            path: manifest_path.to_path_buf(),
            message: "the manifest lists no reflectance EXR or KTX2 file".into(),
        })?;
    let transmittance = manifest.load_table(manifest_path, "transmittance")?;
    let has_transmittance = transmittance.is_some();
    let label = manifest.name.clone();
    let (reflectance, transmittance) = ctx.checked("uploading a film-lut table", || {
        let r = upload_table3(ctx, &format!("{label} reflectance"), &reflectance);
        let t = match &transmittance {
            Some(t) => upload_table3(ctx, &format!("{label} transmittance"), t),
            None => upload_table3(ctx, &format!("{label} (opaque)"), &Table3::new(1, 1, 1)),
        };
        (r, t)
    })?;
    Ok(FilmLutTextures {
        name: manifest.name.clone(),
        manifest_path: manifest_path.to_path_buf(),
        manifest,
        axes,
        reflectance,
        transmittance,
        has_transmittance,
    })
}

fn upload_rough_film_lut(
    ctx: &GpuContext,
    manifest: Manifest,
    manifest_path: &Path,
) -> Result<RoughFilmLutTextures> {
    let axes = manifest
        .rough_film_lut()
        .cloned()
        .ok_or_else(|| Error::Manifest {
            path: manifest_path.to_path_buf(),
            message: "a rough-film-lut manifest without its `rough_film_lut` axes".into(),
        })?;
    let limit = ctx.device.limits().max_texture_dimension_3d;
    for (name, n) in [
        ("cos θ axis", axes.cos_theta_count),
        ("OPD axis", axes.opd_count),
        ("α × index depth", axes.depth()),
    ] {
        check_limit(
            ctx,
            &format!("rough-film-lut `{}` {name}", manifest.name),
            n as u64,
            limit,
        )?;
    }
    // The loader of nacre-bake reads the EXR (or KTX2) files in the table's layout.
    let loaded = nacre_format::load::LoadedRoughLut::load(manifest_path)?;
    let label = manifest.name.clone();
    let lut = &loaded.lut;
    let (reflectance, transmittance) = ctx.checked("uploading a rough-film-lut table", || {
        let r = upload_table3(ctx, &format!("{label} reflectance"), &lut.reflectance);
        let t = match &lut.transmittance {
            Some(t) => upload_table3(ctx, &format!("{label} transmittance"), t),
            None => upload_table3(ctx, &format!("{label} (opaque)"), &Table3::new(1, 1, 1)),
        };
        (r, t)
    })?;
    Ok(RoughFilmLutTextures {
        name: manifest.name.clone(),
        manifest_path: manifest_path.to_path_buf(),
        has_transmittance: lut.transmittance.is_some(),
        manifest,
        axes,
        reflectance,
        transmittance,
    })
}

/// Uploads a [`Table3`] as a 3-D `Rgba16Float` texture (alpha 1).
fn upload_table3(ctx: &GpuContext, label: &str, table: &Table3) -> wgpu::Texture {
    let size = wgpu::Extent3d {
        width: table.nx as u32,
        height: table.ny as u32,
        depth_or_array_layers: table.nz as u32,
    };
    let texture = sampled_texture(
        &ctx.device,
        label,
        size,
        wgpu::TextureDimension::D3,
        wgpu::TextureFormat::Rgba16Float,
        1,
    );
    let mut texels: Vec<u16> = Vec::with_capacity(table.data.len() / 3 * 4);
    for rgb in table.data.chunks_exact(3) {
        texels.extend(rgb.iter().map(|&v| f16::from_f32(v).to_bits()));
        texels.push(f16::ONE.to_bits());
    }
    write_region(
        &ctx.queue,
        &texture,
        0,
        0,
        size,
        8,
        bytemuck::cast_slice(&texels),
    );
    texture
}

fn upload_fourier(
    ctx: &GpuContext,
    manifest: Manifest,
    manifest_path: &Path,
) -> Result<FourierTextures> {
    let table = manifest.load_fourier(manifest_path)?;
    let axes = table.axes.clone();
    let levels = axes.level_samples.len();
    if levels == 0 || levels > 32 {
        return Err(Error::Manifest {
            path: manifest_path.to_path_buf(),
            message: format!("{levels} mip levels (expected 1 to 32)"),
        });
    }
    for (k, &n) in axes.level_samples.iter().enumerate() {
        if n != (axes.samples >> k).max(1) {
            return Err(Error::Manifest {
                path: manifest_path.to_path_buf(),
                message: format!(
                    "level {k} has {n} texels; a mip chain of {} texels needs {}",
                    axes.samples,
                    (axes.samples >> k).max(1)
                ),
            });
        }
    }
    check_limit(
        ctx,
        &format!("fourier `{}` width", manifest.name),
        axes.samples as u64,
        ctx.device.limits().max_texture_dimension_2d,
    )?;
    let name = manifest.name.clone();
    let texture = ctx.checked("uploading a fourier table", || {
        let texture = sampled_texture(
            &ctx.device,
            &name,
            wgpu::Extent3d {
                width: axes.samples as u32,
                height: 1,
                depth_or_array_layers: 2,
            },
            wgpu::TextureDimension::D2,
            wgpu::TextureFormat::Rgba32Float,
            levels as u32,
        );
        for (k, level) in table.levels.iter().enumerate() {
            for layer in 0..2u32 {
                let texels: Vec<f32> = level
                    .iter()
                    .flat_map(|a| {
                        let v =
                            |c: nacre_optics::C64| (if layer == 0 { c.re } else { c.im }) as f32;
                        [v(a[0]), v(a[1]), v(a[2]), 0.0]
                    })
                    .collect();
                let size = wgpu::Extent3d {
                    width: level.len() as u32,
                    height: 1,
                    depth_or_array_layers: 1,
                };
                let bytes = bytemuck::cast_slice(&texels);
                write_region(&ctx.queue, &texture, k as u32, layer, size, 16, bytes);
            }
        }
        texture
    })?;
    Ok(FourierTextures {
        name: manifest.name.clone(),
        manifest_path: manifest_path.to_path_buf(),
        manifest,
        axes,
        texture,
    })
}
