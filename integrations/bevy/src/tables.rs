//! nacre tables as Bevy assets.
//!
//! A table is its manifest (`<name>.json`, `nacre-table/1`) and the KTX 2.0 files it lists;
//! [`NacreTableLoader`] reads the manifest with [`nacre_format::Manifest::parse`], reads each
//! KTX2 file through the asset source (so a change to the manifest or to a texture
//! hot-reloads the table when Bevy's file watcher is on), checks it against the SHA-256 the
//! manifest records and its size against the manifest's axes, and decodes it with Bevy's own
//! KTX2 reader (3-D textures for `film-lut`, a 2-D array with one mip per level for
//! `fourier`). The axes become the uniforms the shaders read ([`FilmLutUniform`],
//! [`FourierUniform`]).
//!
//! The default set (`tables/baked/film-dielectric` and `fourier-srgb`) is compiled into the
//! plugin and available without files under [`DEFAULT_FILM_LUT`] and [`DEFAULT_FOURIER`].

use bevy::asset::io::Reader;
use bevy::asset::{
    Asset, AssetLoader, AssetPath, Handle, LoadContext, RenderAssetUsages, uuid_handle,
};
use bevy::image::{CompressedImageFormats, Image, ImageSampler, ImageType};
use bevy::math::Vec3;
use bevy::reflect::TypePath;
use bevy::render::render_resource::{ShaderType, TextureDimension, TextureFormat};
use nacre_format::film_lut::FilmLutAxes;
use nacre_format::fourier::FourierAxes;
use nacre_format::gpu_params::{FilmLutParams, FourierParams};
use nacre_format::{FileFormat, FileRecord, Manifest, TableKind};
use std::path::Path;

/// The default film-lut table: `tables/baked/film-dielectric` (a film of index 1.0–2.5,
/// 0–1200 nm, in air on a dielectric base of index 1.5, the glTF default; reflectance and
/// transmittance).
pub const DEFAULT_FILM_LUT: Handle<NacreTable> =
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0b01");
/// The default fourier table: `tables/baked/fourier-srgb` (any film on any base, metals
/// included, in linear sRGB).
pub const DEFAULT_FOURIER: Handle<NacreTable> =
    uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0b02");

/// `nacre_format::gpu_params::FilmLutParams` (the mirror of `FilmLutParams` in
/// `shaders/lut_mapping.wgsl`, 48 bytes) as Bevy binds it: the same fields, laid out by
/// [`ShaderType`] to the same bytes (tested). Made only from the format crate's uniform.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType, bevy::reflect::Reflect)]
pub struct FilmLutUniform {
    /// Texels along cos θ (x).
    pub cos_theta_count: u32,
    /// Texels along the optical path difference Δ (y).
    pub opd_count: u32,
    /// Texels along the film index (z).
    pub ior_count: u32,
    /// Smallest thickness baked, nm.
    pub thickness_min_nm: f32,
    /// Largest thickness baked, nm.
    pub thickness_max_nm: f32,
    /// Smallest film index baked.
    pub ior_min: f32,
    /// Largest film index baked.
    pub ior_max: f32,
    /// Ambient index n₀ baked into the table.
    pub ambient_index: f32,
    /// 1 when the table has a transmittance texture, else 0.
    pub has_transmittance: u32,
    /// Padding to 48 bytes.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

impl FilmLutUniform {
    /// From a manifest's film-lut axes ([`FilmLutParams::new`], as the runtime binds them).
    pub fn new(axes: &FilmLutAxes, has_transmittance: bool) -> Self {
        FilmLutParams::new(axes, has_transmittance).into()
    }
}

impl From<FilmLutParams> for FilmLutUniform {
    fn from(p: FilmLutParams) -> Self {
        // Every field named: a field added to the format's uniform fails to build here.
        let FilmLutParams {
            cos_theta_count,
            opd_count,
            ior_count,
            thickness_min_nm,
            thickness_max_nm,
            ior_min,
            ior_max,
            ambient_index,
            has_transmittance,
            _pad: [_pad0, _pad1, _pad2],
        } = p;
        FilmLutUniform {
            cos_theta_count,
            opd_count,
            ior_count,
            thickness_min_nm,
            thickness_max_nm,
            ior_min,
            ior_max,
            ambient_index,
            has_transmittance,
            _pad0,
            _pad1,
            _pad2,
        }
    }
}

/// `nacre_format::gpu_params::FourierParams` (the mirror of `FourierParams` in
/// `shaders/film_fourier.wgsl`, 48 bytes) as Bevy binds it: the same fields, the
/// three-channel ones as [`Vec3`] (a WGSL `vec3<f32>`, where [`ShaderType`] would lay out an
/// `[f32; 3]` as an array of 16-byte strides), to the same bytes (tested).
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType, bevy::reflect::Reflect)]
pub struct FourierUniform {
    /// D_max, nm.
    pub max_opd_nm: f32,
    /// Mip levels of the coefficient texture.
    pub level_count: u32,
    /// `level_sigma_nm[1]`, nm.
    pub sigma1_nm: f32,
    /// Harmonics M (0 = automatic).
    pub harmonics: u32,
    /// Carrier wavenumber ν̄_j per channel, 1/nm.
    pub carrier_nu_per_nm: Vec3,
    /// Padding.
    pub _pad0: f32,
    /// ‖s_j‖ per channel.
    pub white: Vec3,
    /// Padding.
    pub _pad1: f32,
}

impl FourierUniform {
    /// From a manifest's fourier axes, automatic harmonics ([`FourierParams::new`]`(axes,
    /// 0)`, as the runtime binds them by default).
    pub fn new(axes: &FourierAxes) -> Self {
        FourierParams::new(axes, 0).into()
    }
}

impl From<FourierParams> for FourierUniform {
    fn from(p: FourierParams) -> Self {
        // Every field named: a field added to the format's uniform fails to build here.
        let FourierParams {
            max_opd_nm,
            level_count,
            sigma1_nm,
            harmonics,
            carrier_nu_per_nm,
            _pad0,
            white,
            _pad1,
        } = p;
        FourierUniform {
            max_opd_nm,
            level_count,
            sigma1_nm,
            harmonics,
            carrier_nu_per_nm: Vec3::from_array(carrier_nu_per_nm),
            _pad0,
            white: Vec3::from_array(white),
            _pad1,
        }
    }
}

/// What a table holds, by kind.
#[derive(Clone, Debug, PartialEq)]
pub enum NacreTableAxes {
    /// A `film-lut` table: colour of one film stack at (cos θ, Δ, n).
    FilmLut(FilmLutUniform),
    /// A `fourier` table: any film on any base.
    Fourier(FourierUniform),
}

/// A nacre table loaded from its manifest: the textures and the axes the shaders read.
#[derive(Asset, TypePath, Clone, Debug)]
pub struct NacreTable {
    /// The manifest's `name`.
    pub name: String,
    /// The manifest's `description`.
    pub description: String,
    /// The manifest's base material reference (`"1.5"`, `"au"`, …; empty for fourier).
    pub base: String,
    /// Kind and axes.
    pub axes: NacreTableAxes,
    /// film-lut: reflectance (3-D, Rgba16Float or Rgba32Float). fourier: the coefficients
    /// (2-D array of 2 layers, Rgba32Float, one mip per level).
    #[dependency]
    pub texture: Handle<Image>,
    /// film-lut: transmittance, when baked.
    #[dependency]
    pub transmittance: Option<Handle<Image>>,
}

/// Why a table could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// Reading the manifest or a texture failed.
    #[error("{path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// What the asset source said.
        message: String,
    },
    /// The manifest is malformed or invalid.
    #[error(transparent)]
    Format(#[from] nacre_format::Error),
    /// A kind the plugin has no shader for.
    #[error("{manifest}: a {kind} table; bevy_nacre reads film-lut and fourier tables")]
    UnsupportedKind {
        /// The manifest.
        manifest: String,
        /// Its kind.
        kind: String,
    },
    /// The manifest lists no KTX2 file for a quantity the shader needs.
    #[error("{manifest}: no KTX2 file for `{quantity}` (bake with KTX2 output)")]
    MissingFile {
        /// The manifest.
        manifest: String,
        /// The quantity.
        quantity: String,
    },
    /// A file's bytes differ from the manifest's checksum.
    #[error("{path}: SHA-256 {actual} differs from the manifest's {expected}")]
    Checksum {
        /// The file.
        path: String,
        /// Its checksum.
        actual: String,
        /// The manifest's.
        expected: String,
    },
    /// Bevy's KTX2 reader refused the file.
    #[error("{path}: {message}")]
    Texture {
        /// The file.
        path: String,
        /// Bevy's message.
        message: String,
    },
    /// The texture's size or format disagrees with the manifest.
    #[error("{path}: {found}, the manifest's axes need {expected}")]
    Shape {
        /// The file.
        path: String,
        /// What the file holds.
        found: String,
        /// What the axes need.
        expected: String,
    },
}

/// The KTX2 files a manifest's table needs: (quantity, record, required).
fn ktx2_files<'m>(
    manifest: &'m Manifest,
    context: &str,
) -> Result<Vec<(&'static str, &'m FileRecord)>, TableError> {
    let find = |quantity: &'static str| {
        manifest
            .files
            .iter()
            .find(|f| f.format == FileFormat::Ktx2 && f.quantity == quantity)
            .map(|f| (quantity, f))
    };
    match manifest.kind {
        TableKind::FILM_LUT => {
            let r = find("reflectance").ok_or_else(|| TableError::MissingFile {
                manifest: context.to_owned(),
                quantity: "reflectance".into(),
            })?;
            Ok(std::iter::once(r).chain(find("transmittance")).collect())
        }
        TableKind::FOURIER => {
            let f = manifest
                .files
                .iter()
                .find(|f| f.format == FileFormat::Ktx2)
                .ok_or_else(|| TableError::MissingFile {
                    manifest: context.to_owned(),
                    quantity: "all levels".into(),
                })?;
            Ok(vec![("coefficients", f)])
        }
        other => Err(TableError::UnsupportedKind {
            manifest: context.to_owned(),
            kind: other.to_string(),
        }),
    }
}

/// Decodes one KTX2 file of `manifest` after checking its checksum, and checks its size and
/// format against the axes.
fn decode_ktx2(
    manifest: &Manifest,
    f: &FileRecord,
    path: &str,
    bytes: &[u8],
) -> Result<Image, TableError> {
    let actual = nacre_format::checksum::sha256_bytes(bytes);
    if actual != f.sha256 {
        return Err(TableError::Checksum {
            path: path.to_owned(),
            actual,
            expected: f.sha256.clone(),
        });
    }
    let mut image = Image::from_buffer(
        bytes,
        ImageType::Extension("ktx2"),
        CompressedImageFormats::NONE,
        false,
        ImageSampler::linear(),
        RenderAssetUsages::RENDER_WORLD,
    )
    .map_err(|e| TableError::Texture {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    // Bevy 0.19's KTX2 reader makes a texture of height 1 one-dimensional even when it has
    // array layers (and then views it as a 2-D array, which wgpu refuses); a fourier table
    // is a 2-D array of height 1, so it is declared two-dimensional (same texel layout).
    if manifest.fourier().is_some() && image.texture_descriptor.dimension == TextureDimension::D1 {
        image.texture_descriptor.dimension = TextureDimension::D2;
    }
    let d = &image.texture_descriptor;
    let found = format!(
        "{:?} {}×{}×{} ({:?}, {} mips)",
        d.format,
        d.size.width,
        d.size.height,
        d.size.depth_or_array_layers,
        d.dimension,
        d.mip_level_count
    );
    let ok = match (manifest.film_lut(), manifest.fourier()) {
        (Some(a), _) => {
            d.dimension == TextureDimension::D3
                && matches!(
                    d.format,
                    TextureFormat::Rgba16Float | TextureFormat::Rgba32Float
                )
                && (d.size.width, d.size.height, d.size.depth_or_array_layers)
                    == (
                        a.cos_theta_count as u32,
                        a.opd_count as u32,
                        a.ior_count as u32,
                    )
        }
        (None, Some(a)) => {
            d.dimension == TextureDimension::D2
                && d.format == TextureFormat::Rgba32Float
                && d.size.depth_or_array_layers == 2
                && Some(&(d.size.width as usize)) == a.level_samples.first()
                && d.mip_level_count as usize >= a.level_samples.len()
        }
        _ => false,
    };
    if !ok {
        let expected = match (manifest.film_lut(), manifest.fourier()) {
            (Some(a), _) => format!(
                "a 3-D Rgba16Float/Rgba32Float texture of {}×{}×{}",
                a.cos_theta_count, a.opd_count, a.ior_count
            ),
            (None, Some(a)) => format!(
                "a 2-D array Rgba32Float texture of width {:?}, 2 layers, {} mips",
                a.level_samples.first(),
                a.level_samples.len()
            ),
            _ => "a film-lut or fourier manifest".into(),
        };
        return Err(TableError::Shape {
            path: path.to_owned(),
            found,
            expected,
        });
    }
    Ok(image)
}

/// The table of `manifest` from its decoded textures (`images` in [`ktx2_files`]' order,
/// already added as assets).
fn assemble(manifest: &Manifest, images: Vec<(&'static str, Handle<Image>)>) -> NacreTable {
    let mut texture = Handle::default();
    let mut transmittance = None;
    for (quantity, handle) in images {
        match quantity {
            "transmittance" => transmittance = Some(handle),
            _ => texture = handle,
        }
    }
    let axes = match (manifest.film_lut(), manifest.fourier()) {
        (Some(a), _) => NacreTableAxes::FilmLut(FilmLutUniform::new(a, transmittance.is_some())),
        (None, Some(a)) => NacreTableAxes::Fourier(FourierUniform::new(a)),
        // ktx2_files refused every other kind.
        _ => NacreTableAxes::Fourier(FourierUniform::default()),
    };
    NacreTable {
        name: manifest.name.clone(),
        description: manifest.description.clone(),
        base: manifest.base.clone(),
        axes,
        texture,
        transmittance,
    }
}

/// Loads a nacre table from its manifest (`*.json`): see the [module docs](self).
#[derive(Default, TypePath)]
pub struct NacreTableLoader;

impl AssetLoader for NacreTableLoader {
    type Asset = NacreTable;
    type Settings = ();
    type Error = TableError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<NacreTable, TableError> {
        let manifest_path = load_context.path().clone();
        let context = manifest_path.to_string();
        let read_error = |path: &AssetPath, message: String| TableError::Read {
            path: path.to_string(),
            message,
        };
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|e| read_error(&manifest_path, e.to_string()))?;
        let text = String::from_utf8(bytes)
            .map_err(|e| read_error(&manifest_path, format!("not UTF-8: {e}")))?;
        let manifest = Manifest::parse(Path::new(&context), &text)?;
        let mut images = Vec::new();
        for (quantity, f) in ktx2_files(&manifest, &context)? {
            let path = manifest_path
                .resolve_embed_str(&f.path)
                .map_err(|e| read_error(&manifest_path, format!("file `{}`: {e}", f.path)))?;
            let bytes = load_context
                .read_asset_bytes(path.clone())
                .await
                .map_err(|e| read_error(&path, e.to_string()))?;
            let image = decode_ktx2(&manifest, f, &path.to_string(), &bytes)?;
            images.push((quantity, load_context.add_labeled_asset(quantity, image)));
        }
        Ok(assemble(&manifest, images))
    }

    fn extensions(&self) -> &[&str] {
        &["json"]
    }
}

/// A table from a manifest and its files' bytes held in memory (`files`: path as the manifest
/// lists it → bytes); `add` stores each decoded texture.
pub fn table_from_memory(
    manifest_name: &str,
    manifest_text: &str,
    files: &[(&str, &[u8])],
    mut add: impl FnMut(Image) -> Handle<Image>,
) -> Result<NacreTable, TableError> {
    let manifest = Manifest::parse(Path::new(manifest_name), manifest_text)?;
    let mut images = Vec::new();
    for (quantity, f) in ktx2_files(&manifest, manifest_name)? {
        let bytes = files
            .iter()
            .find(|(p, _)| *p == f.path)
            .map(|(_, b)| *b)
            .ok_or_else(|| TableError::Read {
                path: f.path.clone(),
                message: "not among the embedded files".into(),
            })?;
        images.push((quantity, add(decode_ktx2(&manifest, f, &f.path, bytes)?)));
    }
    Ok(assemble(&manifest, images))
}

/// The default set's manifests and KTX2 files, compiled in.
pub(crate) mod default_set {
    /// film-dielectric manifest.
    pub const FILM_LUT_MANIFEST: &str = include_str!("../../../tables/baked/film-dielectric.json");
    /// film-dielectric KTX2 files.
    pub const FILM_LUT_FILES: [(&str, &[u8]); 2] = [
        (
            "film-dielectric.reflectance.ktx2",
            include_bytes!("../../../tables/baked/film-dielectric.reflectance.ktx2"),
        ),
        (
            "film-dielectric.transmittance.ktx2",
            include_bytes!("../../../tables/baked/film-dielectric.transmittance.ktx2"),
        ),
    ];
    /// fourier-srgb manifest.
    pub const FOURIER_MANIFEST: &str = include_str!("../../../tables/baked/fourier-srgb.json");
    /// fourier-srgb KTX2 file.
    pub const FOURIER_FILES: [(&str, &[u8]); 1] = [(
        "fourier-srgb.ktx2",
        include_bytes!("../../../tables/baked/fourier-srgb.ktx2"),
    )];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(name: &str, text: &str, files: &[(&str, &[u8])]) -> Result<NacreTable, TableError> {
        table_from_memory(name, text, files, |_| Handle::default())
    }

    #[test]
    fn the_default_set_decodes() {
        let lut = load(
            "film-dielectric.json",
            default_set::FILM_LUT_MANIFEST,
            &default_set::FILM_LUT_FILES,
        )
        .unwrap();
        let NacreTableAxes::FilmLut(a) = lut.axes else {
            panic!("film-dielectric is a film-lut table")
        };
        assert_eq!((a.cos_theta_count, a.opd_count, a.ior_count), (24, 384, 32));
        assert_eq!(
            (a.ior_min, a.ior_max, a.thickness_max_nm),
            (1.0, 2.5, 1200.0)
        );
        assert_eq!(a.has_transmittance, 1);
        let fourier = load(
            "fourier-srgb.json",
            default_set::FOURIER_MANIFEST,
            &default_set::FOURIER_FILES,
        )
        .unwrap();
        let NacreTableAxes::Fourier(f) = fourier.axes else {
            panic!("fourier-srgb is a fourier table")
        };
        assert_eq!((f.level_count, f.max_opd_nm), (8, 160000.0));
    }

    #[test]
    fn a_damaged_texture_is_refused_by_its_checksum() {
        let mut bytes = default_set::FOURIER_FILES[0].1.to_vec();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        let err = load(
            "fourier-srgb.json",
            default_set::FOURIER_MANIFEST,
            &[("fourier-srgb.ktx2", &bytes)],
        )
        .unwrap_err();
        assert!(matches!(err, TableError::Checksum { .. }), "{err}");
    }

    #[test]
    fn a_missing_file_and_a_bad_manifest_are_errors() {
        let err = load("fourier-srgb.json", default_set::FOURIER_MANIFEST, &[]).unwrap_err();
        assert!(matches!(err, TableError::Read { .. }), "{err}");
        let err = load("x.json", "{ not json", &[]).unwrap_err();
        assert!(matches!(err, TableError::Format(_)), "{err}");
    }

    /// The bytes [`ShaderType`] writes for `uniform`.
    fn shader_bytes<T: ShaderType + bevy::render::render_resource::encase::internal::WriteInto>(
        uniform: &T,
    ) -> Vec<u8> {
        let mut buffer = bevy::render::render_resource::encase::UniformBuffer::new(Vec::new());
        buffer.write(uniform).unwrap();
        buffer.into_inner()
    }

    #[test]
    fn uniforms_are_the_format_crates_bytes() {
        assert_eq!(FilmLutUniform::min_size().get(), 48);
        assert_eq!(FourierUniform::min_size().get(), 48);
        let lut = Manifest::parse(Path::new("lut"), default_set::FILM_LUT_MANIFEST).unwrap();
        let params = FilmLutParams::new(lut.film_lut().unwrap(), true);
        assert_eq!(
            shader_bytes(&FilmLutUniform::from(params)),
            params.as_bytes()
        );
        let fourier = Manifest::parse(Path::new("f"), default_set::FOURIER_MANIFEST).unwrap();
        for harmonics in [0, 5] {
            let params = FourierParams::new(fourier.fourier().unwrap(), harmonics);
            assert_eq!(
                shader_bytes(&FourierUniform::from(params)),
                params.as_bytes()
            );
        }
    }
}
