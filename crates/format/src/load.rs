//! Reading a table through its manifest: every loader checks the manifest's kind, the
//! files' checksums (where the format records them) and the sizes against the axes, then
//! reads the EXR atlas when the manifest lists one, else the KTX2 texture.

use crate::diffraction::{DiffractionRecord, MAX_INTEGRATED_BYTES};
use crate::error::{Error, Result};
use crate::fourier::FourierTable;
use crate::ktx2::{self, Ktx2Format};
use crate::manifest::{FileFormat, FileRecord, Manifest};
use crate::rough_film_lut::RoughFilmLut;
use crate::table_io::{self, Table3};
use nacre_optics::C64;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::TaylorTerms;
use nacre_optics::diffraction::integrated::{IntegratedTable, MAX_INTEGRATED_SAMPLES, WarpedAxis};
use std::path::{Path, PathBuf};

impl Manifest {
    /// Loads the table of `quantity` listed by this manifest (at `manifest_path`): from its
    /// EXR file when the manifest lists one, else from its KTX2 file; `None` when neither
    /// is listed.
    pub fn load_table(&self, manifest_path: &Path, quantity: &str) -> Result<Option<Table3>> {
        let Some(f) = self
            .file(quantity, FileFormat::Exr)
            .or_else(|| self.file(quantity, FileFormat::Ktx2))
        else {
            return Ok(None);
        };
        let a = self
            .film_lut()
            .ok_or_else(|| self.wrong_kind(manifest_path, "a film-lut"))?;
        let path = self.dir(manifest_path).join(&f.path);
        verify_sha256(manifest_path, &path, f)?;
        let (nx, ny, nz) = (a.cos_theta_count, a.opd_count, a.ior_count);
        if f.format == FileFormat::Ktx2 {
            return crate::ktx2::read_film_lut_ktx2(&path, nx, ny, nz).map(Some);
        }
        let (table, _) = table_io::read_exr_table(&path, nx, ny, nz)?;
        Ok(Some(table))
    }
}

impl Manifest {
    /// Loads the `fourier` table this manifest (at `manifest_path`) describes: from its
    /// per-level EXR files when the manifest lists them all, else from its KTX2 file.
    pub fn load_fourier(&self, manifest_path: &Path) -> Result<FourierTable> {
        let axes = self
            .fourier()
            .cloned()
            .ok_or_else(|| self.wrong_kind(manifest_path, "a fourier table"))?;
        let dir = self.dir(manifest_path);
        let levels = axes.level_samples.len();
        let exr_level = |k: usize| self.file(&format!("level {k}"), FileFormat::Exr);
        if (0..levels).any(|k| exr_level(k).is_none())
            && let Some(f) = self.files.iter().find(|f| f.format == FileFormat::Ktx2)
        {
            let path = dir.join(&f.path);
            verify_sha256(manifest_path, &path, f)?;
            return crate::ktx2::read_fourier_ktx2(&path, axes);
        }
        let paths: Vec<PathBuf> = (0..levels)
            .map(|k| {
                let f = exr_level(k).ok_or_else(|| Error::Invalid {
                    context: manifest_path.display().to_string().into(),
                    message: format!("the manifest lists no file for level {k}").into(),
                })?;
                let path = dir.join(&f.path);
                verify_sha256(manifest_path, &path, f)?;
                Ok(path)
            })
            .collect::<Result<_>>()?;
        FourierTable::read(axes, &paths)
    }
}

impl Manifest {
    /// Loads the Taylor terms of a `diffraction` table (from its EXR file, else its KTX2
    /// file) as stored (f32 values).
    pub fn load_diffraction(
        &self,
        manifest_path: &Path,
    ) -> Result<(DiffractionRecord, TaylorTerms)> {
        let r = self
            .diffraction()
            .cloned()
            .ok_or_else(|| self.wrong_kind(manifest_path, "a diffraction table"))?;
        if r.layout != "terms" {
            return Err(Error::Invalid {
                context: manifest_path.display().to_string().into(),
                message: format!(
                    "diffraction table `{}` has the layout \"{}\", which stores colours summed over wavelengths, not the Taylor terms",
                    self.name, r.layout
                ).into(),
            });
        }
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        let layers = r.taylor_order + 1;
        let find = |format| self.file("terms", format);
        let mut terms = vec![vec![C64::new(0.0, 0.0); r.nx * r.ny]; layers];
        if let Some(f) = find(FileFormat::Exr) {
            let (t, _) = table_io::read_exr_table(&dir.join(&f.path), r.nx, r.ny, layers)?;
            for (n, layer) in terms.iter_mut().enumerate() {
                for (i, v) in layer.iter_mut().enumerate() {
                    let [re, im, _] = t.texel(i % r.nx, i / r.nx, n);
                    *v = C64::new(f64::from(re), f64::from(im));
                }
            }
        } else if let Some(f) = find(FileFormat::Ktx2) {
            let path = dir.join(&f.path);
            let image = ktx2::read_ktx2(&path)?;
            if image.format != Ktx2Format::Rgba32Float
                || (
                    image.width as usize,
                    image.height as usize,
                    image.layers as usize,
                ) != (r.nx, r.ny, layers.div_ceil(2))
                || image.levels.len() != 1
            {
                return Err(Error::Table {
                    path,
                    message: format!(
                        "texture is {:?} {}x{} with {} layers; expected Rgba32Float {}x{} with {} layers",
                        image.format,
                        image.width,
                        image.height,
                        image.layers,
                        r.nx,
                        r.ny,
                        layers.div_ceil(2)
                    ),
                });
            }
            let data = image.level_f32(0);
            for (n, layer) in terms.iter_mut().enumerate() {
                for (i, v) in layer.iter_mut().enumerate() {
                    let at = ((n / 2) * r.nx * r.ny + i) * 4 + 2 * (n % 2);
                    *v = C64::new(f64::from(data[at]), f64::from(data[at + 1]));
                }
            }
        } else {
            return Err(Error::Invalid {
                context: manifest_path.display().to_string().into(),
                message: "the manifest lists no terms file".into(),
            });
        }
        let t = TaylorTerms::from_terms(r.nx, r.ny, r.pitch_um, &terms).map_err(|source| {
            Error::OpticsIn {
                context: manifest_path.display().to_string().into(),
                source,
            }
        })?;
        Ok((r, t))
    }
}

impl Manifest {
    /// Loads an integrated `diffraction` table (from its EXR file, else its KTX2 file) as
    /// stored (f32 values).
    ///
    /// # Errors
    /// [`Error::Invalid`] for another kind or layout, or sizes a bake could not have
    /// written; file errors.
    pub fn load_diffraction_integrated(
        &self,
        manifest_path: &Path,
    ) -> Result<(DiffractionRecord, IntegratedTable)> {
        let invalid = |message: String| Error::Invalid {
            context: manifest_path.display().to_string().into(),
            message: message.into(),
        };
        let r = self
            .diffraction()
            .cloned()
            .ok_or_else(|| self.wrong_kind(manifest_path, "a diffraction table"))?;
        let s = match (&r.integrated, r.layout.as_str()) {
            (Some(s), "integrated") => s.clone(),
            _ => {
                return Err(invalid(format!(
                    "diffraction table `{}` has the layout \"{}\", not \"integrated\"",
                    self.name, r.layout
                )));
            }
        };
        let n = s.samples_v;
        let bytes = (s.layers as u64)
            .saturating_mul(n as u64)
            .saturating_mul(s.samples_u as u64)
            .saturating_mul(16);
        if !(4..=MAX_INTEGRATED_SAMPLES).contains(&n)
            || n % 2 == 1
            || s.samples_u != n / 2
            || s.layers != 2 * r.taylor_order + 1
            || bytes > MAX_INTEGRATED_BYTES
        {
            return Err(invalid(format!(
                "integrated table of {} × {n} texels and {} layers for N = {}: expected n even from 4 to {MAX_INTEGRATED_SAMPLES}, n/2 columns, 2N + 1 layers, at most {MAX_INTEGRATED_BYTES} bytes",
                s.samples_u, s.layers, r.taylor_order
            )));
        }
        let axis = WarpedAxis::new(s.max_uv, s.gamma, n).map_err(|source| Error::OpticsIn {
            context: manifest_path.display().to_string().into(),
            source,
        })?;
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        let find = |format| self.file("integrated", format);
        let (cols, layers) = (s.samples_u, s.layers);
        let mut values = vec![[0.0f32; 3]; layers * n * cols];
        if let Some(f) = find(FileFormat::Exr) {
            let (t, _) = table_io::read_exr_table(&dir.join(&f.path), cols, n, layers)?;
            for p in 0..layers {
                for iv in 0..n {
                    for c in 0..cols {
                        values[(p * n + iv) * cols + c] = t.texel(c, iv, p);
                    }
                }
            }
        } else if let Some(f) = find(FileFormat::Ktx2) {
            let path = dir.join(&f.path);
            let image = ktx2::read_ktx2(&path)?;
            if image.format != Ktx2Format::Rgba32Float
                || (
                    image.width as usize,
                    image.height as usize,
                    image.layers as usize,
                ) != (cols, n, layers)
                || image.levels.len() != 1
            {
                return Err(Error::Table {
                    path,
                    message: format!(
                        "texture is {:?} {}x{} with {} layers; expected Rgba32Float {cols}x{n} with {layers} layers",
                        image.format, image.width, image.height, image.layers
                    ),
                });
            }
            let data = image.level_f32(0);
            for (i, v) in values.iter_mut().enumerate() {
                *v = [data[4 * i], data[4 * i + 1], data[4 * i + 2]];
            }
        } else {
            return Err(invalid("the manifest lists no integrated file".into()));
        }
        let optics = |source| Error::OpticsIn {
            context: manifest_path.display().to_string().into(),
            source,
        };
        let mut table =
            IntegratedTable::from_values(axis, r.taylor_order, values).map_err(optics)?;
        // With Stam's k² (issue 37) the manifest carries the unweighted zeroth order; a table
        // without the field (an older bake) is read as it was: no k², its own peak.
        if let Some(reference_nm) = s.k_squared_reference_nm {
            table = table
                .with_k_squared(
                    reference_nm,
                    s.zeroth_order_layers
                        .iter()
                        .map(|j| j.map(|x| x as f32))
                        .collect(),
                )
                .map_err(optics)?;
        }
        Ok((r, table))
    }
}

/// Checks that the file at `path`, listed in the manifest at `manifest_path` as `f`, has
/// the SHA-256 the manifest records: a table whose files were replaced or damaged after the
/// bake is refused rather than read.
pub fn verify_sha256(manifest_path: &Path, path: &Path, f: &FileRecord) -> Result<()> {
    let sha = table_io::sha256_hex(path)?;
    if sha != f.sha256 {
        return Err(Error::Checksum {
            path: path.to_path_buf(),
            manifest: manifest_path.to_path_buf(),
            actual: sha,
            expected: f.sha256.clone(),
        });
    }
    Ok(())
}

/// A rough-film LUT loaded through its manifest, for CPU lookups (`nacre color --method
/// rough-lut:`).
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedRoughLut {
    /// The manifest.
    pub manifest: Manifest,
    /// The table.
    pub lut: RoughFilmLut,
    /// The table's colorimeter.
    pub colorimeter: Colorimeter,
}

impl LoadedRoughLut {
    /// Loads the table at `path` (a manifest), from its EXR files or else its KTX2 files.
    pub fn load(path: &Path) -> Result<Self> {
        let manifest = Manifest::read(path)?;
        let axes = manifest
            .rough_film_lut()
            .cloned()
            .ok_or_else(|| manifest.wrong_kind(path, "a rough-film-lut"))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let (nx, ny, nz) = (axes.cos_theta_count, axes.opd_count, axes.depth());
        let load = |quantity: &str| -> Result<Option<Table3>> {
            match (
                manifest.file(quantity, FileFormat::Exr),
                manifest.file(quantity, FileFormat::Ktx2),
            ) {
                (Some(f), _) => Ok(Some(
                    table_io::read_exr_table(&dir.join(&f.path), nx, ny, nz)?.0,
                )),
                (None, Some(f)) => Ok(Some(crate::ktx2::read_film_lut_ktx2(
                    &dir.join(&f.path),
                    nx,
                    ny,
                    nz,
                )?)),
                (None, None) => Ok(None),
            }
        };
        let reflectance = load("reflectance")?.ok_or_else(|| Error::Invalid {
            context: path.display().to_string().into(),
            message: "the manifest lists no reflectance EXR or KTX2 file".into(),
        })?;
        let transmittance = load("transmittance")?;
        let colorimeter = manifest.colorimeter(path)?;
        Ok(LoadedRoughLut {
            lut: RoughFilmLut {
                axes,
                reflectance,
                transmittance,
            },
            manifest,
            colorimeter,
        })
    }
}
