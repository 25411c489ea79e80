//! glTF 2.0 / GLB scenes for `nacre render --gltf`: triangle meshes (positions, normals,
//! indexed or not, node transforms applied) and their materials — the core metallic-roughness
//! model, `KHR_materials_iridescence`, `KHR_materials_ior` and `KHR_materials_transmission` —
//! mapped onto nacre's [`MaterialOptions`].
//!
//! # The mapping (glTF → [`MaterialOptions`])
//!
//! | glTF | nacre |
//! |---|---|
//! | `iridescenceIor` (default 1.3) | `film_ior` n₂ |
//! | `iridescenceThicknessMinimum` / `Maximum` (100 / 400 nm) | [`ThicknessMapping::Gltf`] d = mix(d_min, d_max, g) |
//! | `iridescenceThicknessTexture` (PNG) | g = its green channel at the primitive's `texCoord` set; without a texture g = 1, so d = d_max (the extension's rule) |
//! | `iridescenceFactor` (default 0 without the extension) | `film_weight` w: F = mix(F_base, F_film, w) |
//! | `iridescenceTexture` | not read (its red channel would multiply w) |
//! | `ior` (`KHR_materials_ior`, default 1.5) | a dielectric base of real index `ior` |
//! | `metallicFactor` ≥ 0.5 | a metal base from the base colour ([`metal_index_gulbrandsen2014`]) |
//! | `baseColorFactor` (dielectric) | the Lambertian albedo under the film |
//! | `roughnessFactor` r | GGX α = r² |
//! | `transmissionFactor` ≥ 0.5 | a thin transparent shell (`transmission`; what is behind is the environment) |
//!
//! glTF's metallic factor is a blend between a dielectric and a metal; nacre picks one base per
//! material (metal when `metallicFactor` ≥ 0.5). Textures other than the thickness texture are
//! ignored (the factors are used), and so are vertex colours, skins and morph targets.
//!
//! # Metals from a base colour
//!
//! glTF gives a metal only its reflectance at normal incidence F0 (= `baseColorFactor`), while
//! the film needs the metal's complex index n + iκ (the film changes the phase of the metal's
//! reflection). nacre inverts F0 per RGB channel with the "artist-friendly" mapping of
//! O. Gulbrandsen, "Artist Friendly Metallic Fresnel", JCGT 3(4), 2014, Eq. (1)–(2), with the
//! edge tint g equal to the base colour:
//!
//! ```text
//! n = g (1 − r)/(1 + r) + (1 − g) (1 + √r)/(1 − √r)
//! κ = √( (r (n + 1)² − (n − 1)²) / (1 − r) )          r = F0 ∈ [0, 0.99]
//! ```
//!
//! which reproduces F0 exactly at normal incidence. The result is an approximation: a real
//! metal's index varies inside each channel, and its edge tint is not its base colour. The
//! per-channel index becomes a piecewise-constant dispersion (blue below 507.5 nm, green to
//! 580 nm, red above) so that `film_fourier` (one index per channel) and `film_spectral` (one
//! per wavelength) see the same three values.

use crate::error::{Error, Result};
use crate::render::{BaseKind, MaterialOptions, SceneKind, ThicknessMapping};
use crate::thickness_map::ThicknessMap;
use nacre_optics::{C64, Material};
use std::path::{Path, PathBuf};

/// Largest glTF/GLB file read, bytes (and largest external buffer).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Largest number of vertices over all primitives.
pub const MAX_VERTICES: usize = 4_000_000;

/// Largest number of triangle corners (indices) over all primitives.
pub const MAX_INDICES: usize = 12_000_000;

/// Linear base colour of gold at normal incidence (the glTF specification's reference metal
/// table, "gold": 1.000, 0.766, 0.336).
pub const GOLD_F0: [f32; 3] = [1.0, 0.766, 0.336];

/// `KHR_materials_iridescence` of one material (defaults from the extension).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iridescence {
    /// `iridescenceFactor` (default 0), the film weight.
    pub factor: f32,
    /// `iridescenceIor` (default 1.3), the film index.
    pub ior: f32,
    /// `iridescenceThicknessMinimum`, nm (default 100).
    pub thickness_min_nm: f32,
    /// `iridescenceThicknessMaximum`, nm (default 400).
    pub thickness_max_nm: f32,
    /// Whether an `iridescenceThicknessTexture` is given.
    pub has_thickness_texture: bool,
    /// The `iridescenceThicknessTexture`'s texture index and `texCoord` set.
    pub thickness_texture: Option<(usize, u32)>,
    /// Whether an `iridescenceTexture` is given (not read).
    pub has_texture: bool,
}

impl Default for Iridescence {
    fn default() -> Self {
        Iridescence {
            factor: 0.0,
            ior: 1.3,
            thickness_min_nm: 100.0,
            thickness_max_nm: 400.0,
            has_thickness_texture: false,
            thickness_texture: None,
            has_texture: false,
        }
    }
}

/// One glTF material's parameters (factors only).
#[derive(Clone, Debug, PartialEq)]
pub struct GltfMaterial {
    /// The material's name, or `material N` / `default material`.
    pub name: String,
    /// `baseColorFactor`, linear RGBA (default 1).
    pub base_colour: [f32; 4],
    /// `metallicFactor` (default 1).
    pub metallic: f32,
    /// `roughnessFactor`, perceptual (default 1).
    pub roughness: f32,
    /// `KHR_materials_ior` `ior` (default 1.5).
    pub ior: f32,
    /// `KHR_materials_transmission` `transmissionFactor` (default 0).
    pub transmission: f32,
    /// `KHR_materials_iridescence`, if present.
    pub iridescence: Option<Iridescence>,
}

impl Default for GltfMaterial {
    /// The glTF default material (no `material` on a primitive).
    fn default() -> Self {
        GltfMaterial {
            name: "default material".into(),
            base_colour: [1.0; 4],
            metallic: 1.0,
            roughness: 1.0,
            ior: 1.5,
            transmission: 0.0,
            iridescence: None,
        }
    }
}

/// The complex index n + iκ whose normal-incidence reflectance from air is `f0`, with edge
/// tint `edge_tint` (both in [0, 1]; f0 clamped to [0, 0.99]): Gulbrandsen 2014, Eq. (1)–(2)
/// (see the module documentation).
pub fn metal_index_gulbrandsen2014(f0: f64, edge_tint: f64) -> C64 {
    let r = if f0.is_finite() {
        f0.clamp(0.0, 0.99)
    } else {
        0.5
    };
    let g = if edge_tint.is_finite() {
        edge_tint.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let sr = r.sqrt();
    let n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr);
    let k2 = (r * (n + 1.0).powi(2) - (n - 1.0).powi(2)) / (1.0 - r);
    C64::new(n.max(1e-3), k2.max(0.0).sqrt())
}

/// Whether a linear base colour is within 0.1 per channel of [`GOLD_F0`].
pub fn is_gold_like(base_colour: [f32; 3]) -> bool {
    base_colour
        .iter()
        .zip(GOLD_F0)
        .all(|(c, g)| (c - g).abs() <= 0.1)
}

/// A metal base with index n_j + iκ_j per RGB channel j (piecewise constant in wavelength:
/// blue below 507.5 nm, green to 580 nm, red above; defined from 200 to 3000 nm).
pub fn rgb_metal(name: &str, index_rgb: [C64; 3]) -> Result<Material> {
    let [r, g, b] = index_rgb;
    let mut csv = String::from("wavelength_nm,n,k\n");
    for (w, n) in [
        (200.0, b),
        (507.4, b),
        (507.6, g),
        (579.9, g),
        (580.1, r),
        (3000.0, r),
    ] {
        csv.push_str(&format!("{w},{},{}\n", n.re, n.im));
    }
    Material::from_nk_csv(name, name, &csv).map_err(Error::from)
}

impl GltfMaterial {
    /// The material as nacre renders it (the module's mapping table), plus notes about what
    /// was approximated or ignored.
    pub fn material_options(&self) -> Result<(MaterialOptions, Vec<String>)> {
        let mut notes = Vec::new();
        let mut m = MaterialOptions::for_scene(SceneKind::Sphere);
        let clamp01 = |x: f32| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                0.0
            }
        };
        let rgb = [0, 1, 2].map(|j| clamp01(self.base_colour[j]));
        let iri = self.iridescence.unwrap_or_default();
        m.film_ior = iri.ior;
        m.thickness = ThicknessMapping::Gltf {
            min_nm: iri.thickness_min_nm,
            max_nm: iri.thickness_max_nm,
        };
        m.film_weight = clamp01(iri.factor);
        if iri.has_texture {
            notes.push(format!(
                "{}: iridescenceTexture is not read; the film weight is iridescenceFactor",
                self.name
            ));
        }
        m.thickness_roughness_nm = 0.0;
        m.drain_nm = 0.0;
        m.ambient_ior = 1.0;
        let r = clamp01(self.roughness);
        m.roughness_alpha = r * r;
        if clamp01(self.metallic) >= 0.5 {
            let index = rgb.map(|c| metal_index_gulbrandsen2014(f64::from(c), f64::from(c)));
            m.base = rgb_metal(&format!("{} (Gulbrandsen 2014)", self.name), index)?;
            m.base_kind = BaseKind::Metal;
            m.base_colour = [0.0; 3];
            m.transmission = false;
        } else {
            let ior = if self.ior.is_finite() && self.ior >= 1.0 {
                self.ior
            } else {
                // glTF allows ior = 0 (a "perfect mirror" hint); nacre needs a real index.
                notes.push(format!(
                    "{}: ior {} is not an index ≥ 1; using 1.5",
                    self.name, self.ior
                ));
                1.5
            };
            m.base = Material::constant(format!("{ior}"), C64::new(f64::from(ior), 0.0))
                .map_err(crate::Error::from)?;
            m.base_kind = BaseKind::Dielectric;
            m.transmission = clamp01(self.transmission) >= 0.5;
            m.base_colour = if m.transmission { [0.0; 3] } else { rgb };
        }
        m.validate().map_err(|e| Error::Invalid {
            context: format!("glTF material `{}`", self.name),
            message: e.to_string(),
        })?;
        Ok((m, notes))
    }
}

/// One triangle list in world space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfPrimitive {
    /// World-space positions.
    pub positions: Vec<[f32; 3]>,
    /// World-space unit normals (one per position).
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates of the material's thickness texture set (one per position; zeros
    /// when the primitive has none).
    pub uvs: Vec<[f32; 2]>,
    /// Triangle corners (three per triangle), indices into `positions`.
    pub indices: Vec<u32>,
    /// Index into [`GltfScene::materials`].
    pub material: usize,
}

/// A glTF scene flattened to world-space triangle lists.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfScene {
    /// The file it came from.
    pub path: PathBuf,
    /// The primitives of every mesh instance of the default scene (or of every root node when
    /// the file has no scene).
    pub primitives: Vec<GltfPrimitive>,
    /// The document's materials, then the default material.
    pub materials: Vec<GltfMaterial>,
    /// Per material, its decoded `iridescenceThicknessTexture` (green channel → g), if any.
    pub thickness_maps: Vec<Option<ThicknessMap>>,
    /// What the loader could not read (textures it skipped), one line each.
    pub notes: Vec<String>,
}

fn invalid(path: &Path, message: impl Into<String>) -> Error {
    Error::Invalid {
        context: format!("glTF {}", path.display()),
        message: message.into(),
    }
}

/// Decodes standard base64 (RFC 4648, `=` padding optional, no whitespace).
fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        })
    };
    let bytes = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let mut acc = 0u32;
        for (i, &c) in chunk.iter().enumerate() {
            acc |= value(c)? << (18 - 6 * i);
        }
        let n = match chunk.len() {
            4 => 3,
            3 => 2,
            2 => 1,
            _ => return None,
        };
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Some(out)
}

fn mat_mul(a: &[[f32; 4]; 4], b: &[[f32; 4]; 4]) -> [[f32; 4]; 4] {
    // Column-major: (a b)[c][r] = Σ_k a[k][r] b[c][k].
    std::array::from_fn(|c| std::array::from_fn(|r| (0..4).map(|k| a[k][r] * b[c][k]).sum()))
}

fn transform_point(m: &[[f32; 4]; 4], p: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// The normal matrix (inverse transpose of the upper 3×3) applied to n, normalised.
fn transform_normal(m: &[[f32; 4]; 4], n: [f32; 3]) -> [f32; 3] {
    let a = |r: usize, c: usize| f64::from(m[c][r]);
    // Cofactor matrix of the 3×3 = det × inverse transpose (the sign of det does not matter
    // after normalising, but a mirroring transform flips it: keep det's sign).
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let det: f64 = (0..3).map(|c| a(0, c) * cof(0, c)).sum();
    let s = if det < 0.0 { -1.0 } else { 1.0 };
    let v: [f64; 3] =
        std::array::from_fn(|r| s * (0..3).map(|c| cof(r, c) * f64::from(n[c])).sum::<f64>());
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len > 1e-30 && len.is_finite() {
        v.map(|x| (x / len) as f32)
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// Checks that an accessor lies inside its buffer view and the view inside its buffer (the
/// `gltf` crate's reader would panic otherwise).
fn check_accessor(path: &Path, accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<()> {
    if accessor.sparse().is_some() {
        return Err(invalid(
            path,
            format!("accessor {} is sparse (not supported)", accessor.index()),
        ));
    }
    let Some(view) = accessor.view() else {
        return Err(invalid(
            path,
            format!("accessor {} has no buffer view", accessor.index()),
        ));
    };
    let data_len = buffers.get(view.buffer().index()).map_or(0, Vec::len) as u64;
    let view_end = (view.offset() as u64).saturating_add(view.length() as u64);
    if view_end > data_len {
        return Err(invalid(
            path,
            format!(
                "buffer view {} ends at byte {view_end}, beyond its buffer's {data_len} bytes (truncated file?)",
                view.index()
            ),
        ));
    }
    let elem = accessor.size() as u64;
    let stride = view.stride().map_or(elem, |s| s as u64);
    let count = accessor.count() as u64;
    let end = if count == 0 {
        0
    } else {
        (accessor.offset() as u64)
            .saturating_add((count - 1).saturating_mul(stride))
            .saturating_add(elem)
    };
    if end > view.length() as u64 {
        return Err(invalid(
            path,
            format!(
                "accessor {} needs {end} bytes of its buffer view's {}",
                accessor.index(),
                view.length()
            ),
        ));
    }
    Ok(())
}

fn read_iridescence(material: &gltf::Material) -> Option<Iridescence> {
    let ext = material.extension_value("KHR_materials_iridescence")?;
    let num = |key: &str, default: f32| {
        ext.get(key)
            .and_then(serde_json::Value::as_f64)
            .map_or(default, |v| v as f32)
    };
    let d = Iridescence::default();
    Some(Iridescence {
        factor: num("iridescenceFactor", d.factor),
        ior: num("iridescenceIor", d.ior),
        thickness_min_nm: num("iridescenceThicknessMinimum", d.thickness_min_nm),
        thickness_max_nm: num("iridescenceThicknessMaximum", d.thickness_max_nm),
        has_thickness_texture: ext.get("iridescenceThicknessTexture").is_some(),
        thickness_texture: ext.get("iridescenceThicknessTexture").and_then(|t| {
            let index = t.get("index")?.as_u64()? as usize;
            let set = t
                .get("texCoord")
                .and_then(serde_json::Value::as_u64)
                .unwrap_or(0);
            Some((index, set as u32))
        }),
        has_texture: ext.get("iridescenceTexture").is_some(),
    })
}

/// Largest width or height of a thickness texture, texels.
pub const MAX_TEXTURE_DIMENSION: u32 = 8192;

/// Decodes texture `index` of `doc` (a PNG, in a buffer view or a `data:`/file URI) into a
/// thickness map holding its green channel (glTF: "the green channel of this texture defines
/// the thickness"), as data in [0, 1] (no sRGB decoding).
fn thickness_texture(
    doc: &gltf::Document,
    index: usize,
    buffers: &[Vec<u8>],
    path: &Path,
) -> std::result::Result<ThicknessMap, String> {
    let texture = doc
        .textures()
        .nth(index)
        .ok_or_else(|| format!("texture {index} does not exist"))?;
    let bytes: Vec<u8> = match texture.source().source() {
        gltf::image::Source::View { view, mime_type } => {
            if mime_type != "image/png" && mime_type != "image/jpeg" {
                return Err(format!(
                    "{mime_type} images are not supported (PNG or JPEG only)"
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
    let picture = crate::image_io::decode_picture(path, "a thickness texture", &bytes)
        .map_err(|e| e.to_string())?;
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
    let values: Vec<f32> = match &picture {
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

impl GltfScene {
    /// Reads a `.gltf` (JSON, buffers embedded as `data:` URIs or in files beside it) or a
    /// `.glb` file.
    pub fn load(path: &Path) -> Result<GltfScene> {
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let size = std::fs::metadata(path).map_err(io)?.len();
        if size > MAX_FILE_BYTES {
            return Err(invalid(
                path,
                format!("{size} bytes (at most {MAX_FILE_BYTES})"),
            ));
        }
        let bytes = std::fs::read(path).map_err(io)?;
        GltfScene::from_bytes(&bytes, path)
    }

    /// Parses glTF or GLB bytes; `path` names the file in errors and locates external buffers.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<GltfScene> {
        let not_valid =
            |e: gltf::Error| invalid(path, format!("not a valid glTF 2.0 / GLB file: {e}"));
        let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(not_valid)?;
        let json = raw.document.as_json();
        let version = &json.asset.version;
        if !version.starts_with("2.") {
            return Err(invalid(
                path,
                format!("asset version `{version}`: expected a glTF 2.x file"),
            ));
        }
        // gltf-json 1.4 validates a primitive by indexing its POSITION accessor before
        // checking that it exists (a panic): check every attribute's accessor first.
        for (m, mesh) in json.meshes.iter().enumerate() {
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                if let Some(index) = primitive
                    .attributes
                    .values()
                    .find(|i| i.value() >= json.accessors.len())
                {
                    return Err(invalid(
                        path,
                        format!(
                            "meshes[{m}].primitives[{p}].attributes: accessor {} does not exist (the file has {})",
                            index.value(),
                            json.accessors.len()
                        ),
                    ));
                }
            }
        }
        let gltf = gltf::Gltf {
            document: gltf::Document::from_json(raw.document.into_json()).map_err(not_valid)?,
            blob: raw.blob,
        };
        let doc = &gltf.document;
        let mut buffers = Vec::new();
        for buffer in doc.buffers() {
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => gltf
                    .blob
                    .clone()
                    .ok_or_else(|| invalid(path, "the GLB binary chunk is missing"))?,
                gltf::buffer::Source::Uri(uri) => {
                    if let Some(rest) = uri.strip_prefix("data:") {
                        let (_, b64) = rest.split_once(";base64,").ok_or_else(|| {
                            invalid(path, "only base64 `data:` URIs are supported")
                        })?;
                        base64_decode(b64)
                            .ok_or_else(|| invalid(path, "a buffer's base64 data is malformed"))?
                    } else {
                        let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                        let len = std::fs::metadata(&file)
                            .map_err(|source| Error::Io {
                                path: file.clone(),
                                source,
                            })?
                            .len();
                        if len > MAX_FILE_BYTES {
                            return Err(invalid(&file, format!("{len} bytes (too large)")));
                        }
                        std::fs::read(&file).map_err(|source| Error::Io {
                            path: file.clone(),
                            source,
                        })?
                    }
                }
            };
            if data.len() < buffer.length() {
                return Err(invalid(
                    path,
                    format!(
                        "buffer {} holds {} bytes, the file declares {} (truncated?)",
                        buffer.index(),
                        data.len(),
                        buffer.length()
                    ),
                ));
            }
            buffers.push(data);
        }

        let mut materials: Vec<GltfMaterial> = doc
            .materials()
            .map(|m| {
                let pbr = m.pbr_metallic_roughness();
                GltfMaterial {
                    name: m.name().map_or_else(
                        || format!("material {}", m.index().unwrap_or(0)),
                        String::from,
                    ),
                    base_colour: pbr.base_color_factor(),
                    metallic: pbr.metallic_factor(),
                    roughness: pbr.roughness_factor(),
                    ior: m.ior().unwrap_or(1.5),
                    transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
                    iridescence: read_iridescence(&m),
                }
            })
            .collect();
        let default_material = materials.len();
        materials.push(GltfMaterial::default());
        let mut notes = Vec::new();
        let mut thickness_maps = Vec::with_capacity(materials.len());
        for m in &materials {
            let iri = m.iridescence.unwrap_or_default();
            let map = match iri.thickness_texture {
                Some((index, _)) => match thickness_texture(doc, index, &buffers, path) {
                    Ok(map) => Some(map),
                    Err(why) => {
                        notes.push(format!(
                            "{}: iridescenceThicknessTexture not read ({why}); the film is d_max = {} nm",
                            m.name, iri.thickness_max_nm
                        ));
                        None
                    }
                },
                None => None,
            };
            thickness_maps.push(map);
        }

        // Mesh instances: the default scene's (or the first scene's) node trees, or every root
        // node when the file has no scene.
        let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                let mut is_child = vec![false; doc.nodes().len()];
                for n in doc.nodes() {
                    for c in n.children() {
                        is_child[c.index()] = true;
                    }
                }
                doc.nodes().filter(|n| !is_child[n.index()]).collect()
            }
        };
        let identity: [[f32; 4]; 4] =
            std::array::from_fn(|c| std::array::from_fn(|r| if r == c { 1.0 } else { 0.0 }));
        let mut stack: Vec<(gltf::Node, [[f32; 4]; 4], usize)> =
            roots.into_iter().map(|n| (n, identity, 0)).collect();
        let mut primitives = Vec::new();
        let (mut vertices, mut corners) = (0usize, 0usize);
        while let Some((node, parent, depth)) = stack.pop() {
            if depth > 64 {
                return Err(invalid(path, "node hierarchy deeper than 64 levels"));
            }
            let world = mat_mul(&parent, &node.transform().matrix());
            if !world.iter().flatten().all(|x| x.is_finite()) {
                return Err(invalid(
                    path,
                    format!("node {} has a non-finite transform", node.index()),
                ));
            }
            for child in node.children() {
                stack.push((child, world, depth + 1));
            }
            let Some(mesh) = node.mesh() else { continue };
            for prim in mesh.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    return Err(invalid(
                        path,
                        format!(
                            "mesh {} primitive {} has mode {:?}; only triangle lists are supported",
                            mesh.index(),
                            prim.index(),
                            prim.mode()
                        ),
                    ));
                }
                let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
                    return Err(invalid(
                        path,
                        format!(
                            "mesh {} primitive {} has no POSITION",
                            mesh.index(),
                            prim.index()
                        ),
                    ));
                };
                check_accessor(path, &pos_acc, &buffers)?;
                let float3 = |a: &gltf::Accessor, what: &str| {
                    if a.data_type() == gltf::accessor::DataType::F32
                        && a.dimensions() == gltf::accessor::Dimensions::Vec3
                    {
                        Ok(())
                    } else {
                        Err(invalid(
                            path,
                            format!(
                                "{what} accessor {} is {:?} {:?} (expected float VEC3)",
                                a.index(),
                                a.data_type(),
                                a.dimensions()
                            ),
                        ))
                    }
                };
                float3(&pos_acc, "POSITION")?;
                let normal_acc = prim.get(&gltf::Semantic::Normals);
                if let Some(a) = &normal_acc {
                    check_accessor(path, a, &buffers)?;
                    float3(a, "NORMAL")?;
                    if a.count() != pos_acc.count() {
                        return Err(invalid(path, "NORMAL and POSITION counts differ"));
                    }
                }
                if let Some(a) = prim.indices() {
                    check_accessor(path, &a, &buffers)?;
                }
                let n_vertices = pos_acc.count();
                let n_corners = prim.indices().map_or(n_vertices, |a| a.count());
                vertices = vertices.saturating_add(n_vertices);
                corners = corners.saturating_add(n_corners);
                if vertices > MAX_VERTICES || corners > MAX_INDICES {
                    return Err(invalid(
                        path,
                        format!(
                            "more than {MAX_VERTICES} vertices or {MAX_INDICES} triangle corners"
                        ),
                    ));
                }
                if !n_corners.is_multiple_of(3) {
                    return Err(invalid(
                        path,
                        format!("{n_corners} triangle corners is not a multiple of 3"),
                    ));
                }
                let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
                let positions: Vec<[f32; 3]> = reader
                    .read_positions()
                    .ok_or_else(|| invalid(path, "POSITION cannot be read"))?
                    .map(|p| transform_point(&world, p))
                    .collect();
                if !positions.iter().flatten().all(|x| x.is_finite()) {
                    return Err(invalid(path, "non-finite vertex positions"));
                }
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(ix) => ix.into_u32().collect(),
                    None => (0..n_vertices as u32).collect(),
                };
                if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                    return Err(invalid(
                        path,
                        format!("index {bad} beyond {} vertices", positions.len()),
                    ));
                }
                let material = prim.material().index().unwrap_or(default_material);
                let set = materials[material]
                    .iridescence
                    .and_then(|i| i.thickness_texture)
                    .map_or(0, |t| t.1);
                let uvs: Vec<[f32; 2]> = match prim.get(&gltf::Semantic::TexCoords(set)) {
                    Some(a) => {
                        check_accessor(path, &a, &buffers)?;
                        if a.count() != positions.len() {
                            return Err(invalid(path, "TEXCOORD and POSITION counts differ"));
                        }
                        reader
                            .read_tex_coords(set)
                            .map(|t| t.into_f32().collect())
                            .unwrap_or_default()
                    }
                    None => Vec::new(),
                };
                let uvs = if uvs.len() == positions.len() {
                    uvs
                } else {
                    vec![[0.0; 2]; positions.len()]
                };
                let mut out = match reader.read_normals() {
                    Some(normals) => GltfPrimitive {
                        normals: normals.map(|n| transform_normal(&world, n)).collect(),
                        positions,
                        uvs,
                        indices,
                        material,
                    },
                    None => flat_shaded(&positions, &uvs, &indices, material),
                };
                if out.normals.len() != out.positions.len() {
                    out = flat_shaded(&out.positions, &out.uvs, &out.indices, material);
                }
                primitives.push(out);
            }
        }
        if primitives.iter().all(|p| p.indices.is_empty()) {
            return Err(invalid(path, "the scene has no triangles"));
        }
        Ok(GltfScene {
            path: path.to_path_buf(),
            primitives,
            materials,
            thickness_maps,
            notes,
        })
    }

    /// The axis-aligned bounds (min, max) of every vertex, world units.
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in self.primitives.iter().flat_map(|p| &p.positions) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}

/// Flat normals (glTF: "when normals are not specified, client implementations MUST
/// calculate flat normals"): every triangle gets its own three vertices.
fn flat_shaded(
    positions: &[[f32; 3]],
    uvs: &[[f32; 2]],
    indices: &[u32],
    material: usize,
) -> GltfPrimitive {
    let mut out = GltfPrimitive {
        material,
        ..Default::default()
    };
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| positions[tri[k] as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = if len > 0.0 && len.is_finite() {
            n.map(|x| x / len)
        } else {
            [0.0, 1.0, 0.0]
        };
        for (k, p) in [a, b, c].into_iter().enumerate() {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(p);
            out.normals.push(n);
            out.uvs
                .push(uvs.get(tri[k] as usize).copied().unwrap_or([0.0; 2]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gulbrandsen_reproduces_f0_at_normal_incidence() {
        for f0 in [0.0, 0.04, 0.3, 0.5, 0.766, 0.95, 0.99] {
            for g in [0.0, 0.3, 1.0] {
                let n = metal_index_gulbrandsen2014(f0, g);
                let r = ((n.re - 1.0).powi(2) + n.im * n.im) / ((n.re + 1.0).powi(2) + n.im * n.im);
                assert!((r - f0).abs() < 1e-9, "f0 {f0} g {g}: {n} gives {r}");
            }
        }
    }

    #[test]
    fn base64_round_trips_known_strings() {
        assert_eq!(base64_decode("TWFu").unwrap(), b"Man");
        assert_eq!(base64_decode("TWE=").unwrap(), b"Ma");
        assert_eq!(base64_decode("TQ==").unwrap(), b"M");
        assert!(base64_decode("T").is_none());
        assert!(base64_decode("T$==").is_none());
    }

    #[test]
    fn materials_map_to_nacre() {
        let mut g = GltfMaterial {
            metallic: 0.0,
            roughness: 0.3,
            ior: 1.7,
            iridescence: Some(Iridescence {
                factor: 0.5,
                ior: 1.8,
                thickness_min_nm: 200.0,
                thickness_max_nm: 900.0,
                ..Default::default()
            }),
            ..Default::default()
        };
        let (m, _) = g.material_options().unwrap();
        assert_eq!(m.film_ior, 1.8);
        assert_eq!(m.film_weight, 0.5);
        assert!((m.roughness_alpha - 0.09).abs() < 1e-6);
        assert_eq!(m.base_kind, BaseKind::Dielectric);
        assert_eq!(m.base.index_at(550.0).unwrap().re, 1.7f32 as f64);
        assert_eq!(m.max_thickness_nm(), 900.0);
        g.metallic = 1.0;
        g.base_colour = [1.0, 0.766, 0.336, 1.0];
        let (m, _) = g.material_options().unwrap();
        assert_eq!(m.base_kind, BaseKind::Metal);
        assert!(is_gold_like([1.0, 0.766, 0.336]));
        // Red above 580 nm reproduces F0 = 1.0 → clamped 0.99, blue 0.336.
        let blue = m.base.index_at(450.0).unwrap();
        let r = ((blue.re - 1.0).powi(2) + blue.im.powi(2))
            / ((blue.re + 1.0).powi(2) + blue.im.powi(2));
        assert!((r - 0.336).abs() < 1e-6, "{r}");
    }
}
