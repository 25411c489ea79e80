//! The textures of a glTF scene ([`crate::gltf_scene`]): the texture records the materials
//! refer to ([`GltfTexture`], [`TextureRef`], [`SamplerSpec`]), and their loading — pictures
//! (PNG and JPEG) from buffer views, `data:` URIs or files, decoded with the `image` crate, or
//! `KHR_texture_basisu` KTX2 files transcoded by `basisu.rs` (a damaged one is an error), the
//! glTF sampler, `KHR_texture_transform`, and the iridescence thickness texture as a
//! [`ThicknessMap`]. What cannot be decoded is skipped with a note, its factor kept.

use super::basisu::basisu_source;
use super::document::base64_decode;
use super::error::{GltfError, Ktx2Error};
use super::limits::MAX_FILE_BYTES;
use crate::thickness_map::ThicknessMap;
use std::path::Path;

/// How a texture's coordinates wrap (glTF sampler `wrapS` / `wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// REPEAT (10497, the default).
    #[default]
    Repeat,
    /// MIRRORED_REPEAT (33648).
    Mirror,
    /// CLAMP_TO_EDGE (33071).
    Clamp,
}

/// A texture's sampler (glTF §3.8.4): wrap modes, linear or nearest filters, mipmaps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SamplerSpec {
    /// Wrap along u (`wrapS`) and v (`wrapT`).
    pub wrap: [Wrap; 2],
    /// Magnification linear (default) or nearest.
    pub mag_linear: bool,
    /// Minification within a level linear (default) or nearest.
    pub min_linear: bool,
    /// Between mip levels linear (default) or nearest.
    pub mip_linear: bool,
    /// Whether minification reads mip levels (false for a `minFilter` of NEAREST or LINEAR).
    pub mipmaps: bool,
}

impl Default for SamplerSpec {
    /// No sampler: repeat, trilinear (the glTF specification leaves the filters to the
    /// client).
    fn default() -> Self {
        SamplerSpec {
            wrap: [Wrap::Repeat; 2],
            mag_linear: true,
            min_linear: true,
            mip_linear: true,
            mipmaps: true,
        }
    }
}

/// A decoded texture: RGBA8 texels, row 0 the picture's first row (glTF's uv (0, 0)).
#[derive(Clone, Debug, PartialEq)]
pub struct GltfTexture {
    /// What it is, for messages (`texture 3 (image 2)`).
    pub name: String,
    /// Width, texels.
    pub width: u32,
    /// Height, texels.
    pub height: u32,
    /// RGBA8 texels, row-major.
    pub rgba: Vec<u8>,
    /// Whether the texels are sRGB-encoded colours (base colour, emissive, specular colour)
    /// rather than data.
    pub srgb: bool,
    /// Its sampler.
    pub sampler: SamplerSpec,
}

/// A material's use of a texture: which, through which coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`crate::gltf_scene::GltfScene::textures`].
    pub texture: usize,
    /// TEXCOORD set (0 or 1; `KHR_texture_transform`'s `texCoord` overrides the texture
    /// info's).
    pub tex_coord: u32,
    /// `KHR_texture_transform` as uv' = (a u + b v + c, d u + e v + f): rows (a, b, c),
    /// (d, e, f) = T(offset) R(rotation) S(scale) (the extension's matrix order).
    pub transform: [[f32; 3]; 2],
}

/// The identity texture transform.
pub const IDENTITY_TRANSFORM: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

pub use super::limits::MAX_TEXTURE_DIMENSION;

/// Why a texture was not read: skipped with a note (a picture format nacre does not read, a
/// PNG that does not decode), or a broken `KHR_texture_basisu` file, which is the scene's
/// error.
#[derive(Debug)]
pub(crate) enum TextureFailure {
    /// Skipped: the note's reason.
    Skip(String),
    /// The file's error.
    Broken(GltfError),
}

impl From<String> for TextureFailure {
    fn from(why: String) -> Self {
        TextureFailure::Skip(why)
    }
}

impl From<&str> for TextureFailure {
    fn from(why: &str) -> Self {
        TextureFailure::Skip(why.to_string())
    }
}

/// A texture's picture decoded to RGBA8: width, height, texels, and the image it came from.
struct Picture {
    width: u32,
    height: u32,
    rgba: Vec<u8>,
    image: usize,
}

/// Decodes texture `index` of `doc` into RGBA8 texels: its `KHR_texture_basisu` KTX2 image
/// where it has the extension (`basisu.rs`), else its core `source` (PNG or JPEG), in a
/// buffer view or a `data:`/file URI.
fn decode_picture(
    doc: &gltf::Document,
    index: usize,
    buffers: &[Vec<u8>],
    path: &Path,
) -> std::result::Result<Picture, TextureFailure> {
    let json = doc
        .as_json()
        .textures
        .get(index)
        .ok_or_else(|| format!("texture {index} does not exist"))?;
    if let Some(source) = basisu_source(json) {
        // `document.rs` has checked the index.
        let image = source.unwrap_or(usize::MAX);
        let broken = |error: Ktx2Error| {
            TextureFailure::Broken(GltfError::Basisu {
                texture: index,
                image,
                error,
            })
        };
        let bytes = image_bytes(doc, image, buffers, path, (&["image/ktx2"], "KTX2"))
            .map_err(|what| broken(Ktx2Error::Image { what }))?;
        let decoded = super::basisu::decode(&bytes).map_err(broken)?;
        return Ok(Picture {
            width: decoded.width,
            height: decoded.height,
            rgba: decoded.rgba,
            image,
        });
    }
    let image = json.source.value();
    let bytes = image_bytes(
        doc,
        image,
        buffers,
        path,
        (&["image/png", "image/jpeg"], "PNG or JPEG"),
    )?;
    let picture =
        crate::image_io::decode_picture(path, "a texture", &bytes).map_err(|e| e.to_string())?;
    let (width, height) = (picture.width(), picture.height());
    if width == 0 || height == 0 || width.max(height) > MAX_TEXTURE_DIMENSION {
        return Err(format!("{width}x{height} texels (at most {MAX_TEXTURE_DIMENSION})").into());
    }
    Ok(Picture {
        width,
        height,
        rgba: picture.into_rgba8().into_raw(),
        image,
    })
}

/// Decodes texture `index` of `doc` into a thickness map holding its green channel (glTF:
/// "the green channel of this texture defines the thickness"), as data in [0, 1] (no sRGB
/// decoding).
pub(crate) fn thickness_texture(
    doc: &gltf::Document,
    index: usize,
    buffers: &[Vec<u8>],
    path: &Path,
) -> std::result::Result<ThicknessMap, TextureFailure> {
    let p = decode_picture(doc, index, buffers, path)?;
    let picture = image::RgbaImage::from_raw(p.width, p.height, p.rgba)
        .ok_or("the decoded picture has the wrong size")?;
    Ok(thickness_map_of(&image::DynamicImage::ImageRgba8(picture))?)
}

/// The encoded bytes of image `image` of `doc` (in a buffer view, whose `mimeType` must be
/// one of `mime_types`, named `formats` in the message, or a `data:`/file URI).
pub(crate) fn image_bytes(
    doc: &gltf::Document,
    image: usize,
    buffers: &[Vec<u8>],
    path: &Path,
    (mime_types, formats): (&[&str], &str),
) -> std::result::Result<Vec<u8>, String> {
    let picture = doc
        .images()
        .nth(image)
        .ok_or_else(|| format!("image {image} does not exist"))?;
    let bytes: Vec<u8> = match picture.source() {
        gltf::image::Source::View { view, mime_type } => {
            if !mime_types.contains(&mime_type) {
                return Err(format!(
                    "{mime_type} images are not supported ({formats} only)"
                ));
            }
            let data = buffers.get(view.buffer().index()).ok_or("missing buffer")?;
            data.get(view.offset()..view.offset().saturating_add(view.length()))
                .ok_or("the image's buffer view lies beyond its buffer")?
                .to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => {
            if let Some(rest) = uri.strip_prefix("data:") {
                let (_, b64) = rest
                    .split_once(";base64,")
                    .ok_or("only base64 data: URIs are supported")?;
                base64_decode(b64).ok_or("malformed base64")?
            } else {
                let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                let len = std::fs::metadata(&file)
                    .map_err(|e| format!("{}: {e}", file.display()))?
                    .len();
                if len > MAX_FILE_BYTES {
                    return Err(format!("{}: {len} bytes (too large)", file.display()));
                }
                std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?
            }
        }
    };
    Ok(bytes)
}

/// The green channel of a decoded picture as a thickness map.
pub(crate) fn thickness_map_of(
    picture: &image::DynamicImage,
) -> std::result::Result<ThicknessMap, String> {
    let (width, height) = (picture.width(), picture.height());
    if width == 0 || height == 0 || width.max(height) > MAX_TEXTURE_DIMENSION {
        return Err(format!(
            "{width}x{height} texels (at most {MAX_TEXTURE_DIMENSION})"
        ));
    }
    // The green channel, or the grey of a greyscale image, in 8 bits (16-bit samples keep
    // their high byte).
    let high = |v: u16| f32::from((v >> 8) as u8) / 255.0;
    let byte = |v: u8| f32::from(v) / 255.0;
    let values: Vec<f32> = match picture {
        image::DynamicImage::ImageLuma8(p) => p.pixels().map(|v| byte(v.0[0])).collect(),
        image::DynamicImage::ImageLumaA8(p) => p.pixels().map(|v| byte(v.0[0])).collect(),
        image::DynamicImage::ImageRgb8(p) => p.pixels().map(|v| byte(v.0[1])).collect(),
        image::DynamicImage::ImageRgba8(p) => p.pixels().map(|v| byte(v.0[1])).collect(),
        image::DynamicImage::ImageLuma16(p) => p.pixels().map(|v| high(v.0[0])).collect(),
        image::DynamicImage::ImageLumaA16(p) => p.pixels().map(|v| high(v.0[0])).collect(),
        image::DynamicImage::ImageRgb16(p) => p.pixels().map(|v| high(v.0[1])).collect(),
        image::DynamicImage::ImageRgba16(p) => p.pixels().map(|v| high(v.0[1])).collect(),
        other => other.to_rgb8().pixels().map(|v| byte(v.0[1])).collect(),
    };
    Ok(ThicknessMap {
        width: width as usize,
        height: height as usize,
        values,
        green_blue: None,
    })
}

/// Decodes texture `index` of `doc` into RGBA8 texels with its sampler.
pub(crate) fn decode_texture(
    doc: &gltf::Document,
    index: usize,
    srgb: bool,
    buffers: &[Vec<u8>],
    path: &Path,
) -> std::result::Result<GltfTexture, TextureFailure> {
    let picture = decode_picture(doc, index, buffers, path)?;
    let texture = doc
        .textures()
        .nth(index)
        .ok_or_else(|| format!("texture {index} does not exist"))?;
    Ok(GltfTexture {
        name: format!("texture {index} (image {})", picture.image),
        width: picture.width,
        height: picture.height,
        rgba: picture.rgba,
        srgb,
        sampler: sampler_spec(&texture.sampler()),
    })
}

/// A glTF sampler's wrap modes and filters (§3.8.4; absent filters: linear, trilinear).
pub(crate) fn sampler_spec(sampler: &gltf::texture::Sampler) -> SamplerSpec {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::MirroredRepeat => Wrap::Mirror,
        WrappingMode::ClampToEdge => Wrap::Clamp,
    };
    let (min_linear, mip_linear, mipmaps) = match sampler.min_filter() {
        None | Some(MinFilter::LinearMipmapLinear) => (true, true, true),
        Some(MinFilter::Nearest) => (false, false, false),
        Some(MinFilter::Linear) => (true, false, false),
        Some(MinFilter::NearestMipmapNearest) => (false, false, true),
        Some(MinFilter::LinearMipmapNearest) => (true, false, true),
        Some(MinFilter::NearestMipmapLinear) => (false, true, true),
    };
    SamplerSpec {
        wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
        mag_linear: sampler.mag_filter() != Some(MagFilter::Nearest),
        min_linear,
        mip_linear,
        mipmaps,
    }
}

/// `KHR_texture_transform`'s matrix T(offset) R(rotation) S(scale) as two rows (the
/// extension's definition: rotation counter-clockwise in uv, about the origin).
pub fn texture_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> [[f32; 3]; 2] {
    let finite = |x: f32, d: f32| if x.is_finite() { x } else { d };
    let (sin, cos) = finite(rotation, 0.0).sin_cos();
    let (sx, sy) = (finite(scale[0], 1.0), finite(scale[1], 1.0));
    [
        [cos * sx, sin * sy, finite(offset[0], 0.0)],
        [-sin * sx, cos * sy, finite(offset[1], 0.0)],
    ]
}

/// `KHR_texture_transform` from its JSON (`offset`, `rotation`, `scale`, `texCoord`).
pub(crate) fn transform_from_json(ext: Option<&serde_json::Value>) -> ([[f32; 3]; 2], Option<u32>) {
    let Some(ext) = ext else {
        return (IDENTITY_TRANSFORM, None);
    };
    let pair = |key: &str, d: f32| {
        ext.get(key)
            .and_then(serde_json::Value::as_array)
            .map_or([d, d], |a| {
                [0, 1].map(|i| {
                    a.get(i)
                        .and_then(serde_json::Value::as_f64)
                        .map_or(d, |v| v as f32)
                })
            })
    };
    let rotation = ext
        .get("rotation")
        .and_then(serde_json::Value::as_f64)
        .map_or(0.0, |v| v as f32);
    let set = ext
        .get("texCoord")
        .and_then(serde_json::Value::as_u64)
        .map(|v| v.min(u64::from(u32::MAX)) as u32);
    (
        texture_transform(pair("offset", 0.0), rotation, pair("scale", 1.0)),
        set,
    )
}

/// Decodes textures on first use, once per (texture, colour space); notes what it skips.
pub(crate) struct TextureLoader<'a> {
    pub(crate) doc: &'a gltf::Document,
    pub(crate) buffers: &'a [Vec<u8>],
    pub(crate) path: &'a Path,
    pub(crate) textures: Vec<GltfTexture>,
    pub(crate) cache: std::collections::BTreeMap<(usize, bool), Option<usize>>,
    pub(crate) notes: Vec<String>,
    /// The first broken `KHR_texture_basisu` texture met (the scene's error).
    pub(crate) broken: Option<GltfError>,
}

impl TextureLoader<'_> {
    /// The texture reference of texture `index` read through `set` with `transform`, or
    /// `None` (with a note naming the material and the slot) when it cannot be decoded.
    pub(crate) fn get(
        &mut self,
        material: &str,
        slot: &str,
        index: usize,
        set: u32,
        transform: ([[f32; 3]; 2], Option<u32>),
        srgb: bool,
    ) -> Option<TextureRef> {
        let texture = match self.cache.get(&(index, srgb)) {
            Some(t) => *t,
            None => {
                let t = match decode_texture(self.doc, index, srgb, self.buffers, self.path) {
                    Ok(t) => {
                        self.textures.push(t);
                        Some(self.textures.len() - 1)
                    }
                    Err(TextureFailure::Skip(why)) => {
                        self.notes.push(format!(
                            "{material}: {slot} (texture {index}) not read ({why}); its factor is used"
                        ));
                        None
                    }
                    Err(TextureFailure::Broken(error)) => {
                        self.broken.get_or_insert(error);
                        None
                    }
                };
                self.cache.insert((index, srgb), t);
                t
            }
        }?;
        let tex_coord = transform.1.unwrap_or(set);
        if tex_coord > 1 {
            self.notes.push(format!(
                "{material}: {slot} reads TEXCOORD_{tex_coord} (only 0 and 1 are read); texture ignored"
            ));
            return None;
        }
        Some(TextureRef {
            texture,
            tex_coord,
            transform: transform.0,
        })
    }

    /// [`TextureLoader::get`] for a core texture info (typed `KHR_texture_transform`).
    pub(crate) fn info(
        &mut self,
        material: &str,
        slot: &str,
        info: Option<gltf::texture::Info>,
        srgb: bool,
    ) -> Option<TextureRef> {
        let info = info?;
        let transform = info
            .texture_transform()
            .map_or((IDENTITY_TRANSFORM, None), |t| {
                (
                    texture_transform(t.offset(), t.rotation(), t.scale()),
                    t.tex_coord(),
                )
            });
        self.get(
            material,
            slot,
            info.texture().index(),
            info.tex_coord(),
            transform,
            srgb,
        )
    }

    /// [`TextureLoader::get`] for a texture info given as extension JSON
    /// (`{"index", "texCoord", "extensions": {"KHR_texture_transform": …}}`).
    pub(crate) fn json(
        &mut self,
        material: &str,
        slot: &str,
        info: Option<&serde_json::Value>,
        srgb: bool,
    ) -> Option<TextureRef> {
        let info = info?;
        let index = info.get("index")?.as_u64()? as usize;
        let set = info
            .get("texCoord")
            .and_then(serde_json::Value::as_u64)
            .map_or(0, |v| v.min(u64::from(u32::MAX)) as u32);
        let transform = transform_from_json(
            info.get("extensions")
                .and_then(|e| e.get("KHR_texture_transform")),
        );
        self.get(material, slot, index, set, transform, srgb)
    }
}
