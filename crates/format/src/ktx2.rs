//! KTX 2.0 containers for baked tables: a writer and a small validating reader.
//!
//! KTX 2.0 (Khronos, "KTX File Format Specification", version 2.0) stores a texture ready
//! for upload: the Vulkan format, the dimensions, a Data Format Descriptor (DFD), key/value
//! metadata and one block of texel data per mip level. nacre writes only what its tables
//! need: uncompressed float formats, one face, no supercompression.
//!
//! # File layout (all integers little-endian)
//!
//! ```text
//! offset  size  field
//!      0    12  identifier  «KTX 20»\r\n\x1A\n
//!     12    36  vkFormat, typeSize, pixelWidth, pixelHeight, pixelDepth, layerCount,
//!               faceCount (1), levelCount, supercompressionScheme (0)      (u32 each)
//!     48    16  dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength  (u32 each)
//!     64    16  sgdByteOffset, sgdByteLength (0, 0: no global data)         (u64 each)
//!     80  24·L  level index, level 0 first: byteOffset, byteLength,
//!               uncompressedByteLength (u64 each; byteLength = uncompressedByteLength)
//!      …    92  DFD: dfdTotalSize, then one basic descriptor block (24 bytes) with four
//!               samples (16 bytes each): R, G, B, A, signed float, linear, BT.709 primaries
//!      …     …  key/value data, keys sorted: each entry u32 length, key, NUL, value,
//!               zero padding to 4 bytes
//!      …     …  level data, smallest level first (the spec's order, so that a stream
//!               can show a coarse level early), each level's start aligned to the texel
//!               size (lcm(texel size, 4)) with zero padding
//! ```
//!
//! Within a level the texels are ordered layer, then z slice, then row, then column
//! (x fastest), four components per texel.
//!
//! # What nacre stores
//!
//! * `film-lut` quantity → 3-D texture `VK_FORMAT_R16G16B16A16_SFLOAT` (97), typeSize 2
//!   (`VK_FORMAT_R32G32B32A32_SFLOAT`, typeSize 4, for a recipe's `precision = "float"`),
//!   `pixelWidth` = cos θ count, `pixelHeight` = OPD count, `pixelDepth` = film-index count,
//!   layerCount 0, one level; alpha 1. Texel `(x, y, z)` is [`Table3`] texel `(x, y, z)`,
//!   so the texel order is exactly the EXR atlas order.
//! * `fourier` table → 2-D array texture `VK_FORMAT_R32G32B32A32_SFLOAT` (109), typeSize 4,
//!   `pixelWidth` = N, `pixelHeight` = 1, pixelDepth 0, layerCount 2 (layer 0: Re A_j,
//!   layer 1: Im A_j), every mip level (level k is max(N >> k, 1) texels wide); alpha 0.
//!
//! Key/value data: `KTXwriter` = `nacre <version>` and [`MANIFEST_KEY`] = the table's
//! manifest as pretty JSON without its `files` list (which holds this file's own checksum),
//! both NUL-terminated UTF-8. The same table always gives the same bytes.
//!
//! The reader ([`read_ktx2`]) accepts exactly these two formats and checks every offset,
//! length and size against the file and the header before touching texel data, so a
//! truncated or malformed file is an [`Error::Table`] naming the file, never a panic.

use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::fourier::{FourierAxes, FourierTable};
use crate::table_io::{MAX_TEXELS, Table3};
use half::f16;
use nacre_optics::C64;
use std::path::Path;

/// The 12-byte file identifier `«KTX 20»\r\n\x1A\n`.
pub const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// `VK_FORMAT_R16G16B16A16_SFLOAT`.
pub const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;
/// `VK_FORMAT_R32G32B32A32_SFLOAT`.
pub const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;

/// Key of the embedded manifest (pretty JSON, without `files`, NUL-terminated).
pub const MANIFEST_KEY: &str = "nacre.manifest";
/// The spec's key naming the writing tool.
pub const WRITER_KEY: &str = "KTXwriter";

/// Bytes of the fixed header (identifier, header fields, section index).
const HEADER_LEN: usize = 80;
/// Bytes of one level-index entry.
const LEVEL_INDEX_LEN: usize = 24;
/// Most mip levels a file may declare.
const MAX_LEVELS: u32 = 32;

/// The texel formats nacre writes and reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ktx2Format {
    /// `VK_FORMAT_R16G16B16A16_SFLOAT`: four half floats.
    Rgba16Float,
    /// `VK_FORMAT_R32G32B32A32_SFLOAT`: four floats.
    Rgba32Float,
}

impl Ktx2Format {
    /// The Vulkan format number.
    pub fn vk_format(self) -> u32 {
        match self {
            Ktx2Format::Rgba16Float => VK_FORMAT_R16G16B16A16_SFLOAT,
            Ktx2Format::Rgba32Float => VK_FORMAT_R32G32B32A32_SFLOAT,
        }
    }

    /// The format of a Vulkan format number, if nacre reads it.
    pub fn from_vk_format(vk_format: u32) -> Option<Self> {
        match vk_format {
            VK_FORMAT_R16G16B16A16_SFLOAT => Some(Ktx2Format::Rgba16Float),
            VK_FORMAT_R32G32B32A32_SFLOAT => Some(Ktx2Format::Rgba32Float),
            _ => None,
        }
    }

    /// Bytes of one component (the header's `typeSize`).
    pub fn type_size(self) -> u32 {
        match self {
            Ktx2Format::Rgba16Float => 2,
            Ktx2Format::Rgba32Float => 4,
        }
    }

    /// Bytes of one texel (four components).
    pub fn texel_bytes(self) -> usize {
        4 * self.type_size() as usize
    }
}

/// A KTX 2.0 texture as nacre writes it: uncompressed, one face.
#[derive(Clone, Debug, PartialEq)]
pub struct Ktx2Image {
    /// Texel format.
    pub format: Ktx2Format,
    /// `pixelWidth` of level 0 (≥ 1).
    pub width: u32,
    /// `pixelHeight` of level 0 (≥ 1 for nacre's textures).
    pub height: u32,
    /// `pixelDepth` of level 0: 0 for a 2-D texture, the slice count of a 3-D one.
    pub depth: u32,
    /// `layerCount`: 0 when not an array texture.
    pub layers: u32,
    /// Texel data of each level, level 0 first, laid out as the [module docs](self) say.
    pub levels: Vec<Vec<u8>>,
    /// Key/value pairs (written sorted by key).
    pub key_values: Vec<(String, Vec<u8>)>,
}

impl Ktx2Image {
    /// Width, height and depth of level `k` (each max(size >> k, 1)).
    pub fn level_extent(&self, k: usize) -> (u32, u32, u32) {
        let at = |n: u32| n.checked_shr(k as u32).unwrap_or(0).max(1);
        (at(self.width), at(self.height), at(self.depth))
    }

    /// Bytes of level `k`'s texel data (`None` on overflow).
    pub fn level_byte_length(&self, k: usize) -> Option<u64> {
        let (w, h, d) = self.level_extent(k);
        u64::from(w)
            .checked_mul(u64::from(h))?
            .checked_mul(u64::from(d))?
            .checked_mul(u64::from(self.layers.max(1)))?
            .checked_mul(self.format.texel_bytes() as u64)
    }

    /// The value of key `key`, if present.
    pub fn value(&self, key: &str) -> Option<&[u8]> {
        self.key_values
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_slice())
    }

    /// The value of key `key` as a string (the trailing NUL removed), if present and UTF-8.
    pub fn value_str(&self, key: &str) -> Option<&str> {
        let v = self.value(key)?;
        std::str::from_utf8(v.strip_suffix(&[0]).unwrap_or(v)).ok()
    }

    /// The level count a full mip chain of this size would have.
    fn max_levels(&self) -> u32 {
        let largest = self.width.max(self.height).max(self.depth).max(1);
        32 - largest.leading_zeros()
    }

    /// The basic Data Format Descriptor (with its leading `dfdTotalSize`): RGBSDA colour
    /// model, BT.709 primaries, linear transfer, straight alpha, 1×1×1×1 texel blocks,
    /// samples R, G, B, A at bit offsets 0, b, 2b, 3b, signed float, range [-1, 1].
    fn dfd(&self) -> Vec<u8> {
        const KHR_DF_MODEL_RGBSDA: u8 = 1;
        const KHR_DF_PRIMARIES_BT709: u8 = 1;
        const KHR_DF_TRANSFER_LINEAR: u8 = 1;
        const QUALIFIER_FLOAT: u8 = 0x80;
        const QUALIFIER_SIGNED: u8 = 0x40;
        const CHANNELS: [u8; 4] = [0, 1, 2, 15]; // R, G, B, A in the RGBSDA model
        let bits = 8 * self.format.type_size();
        let block_size = 24 + 16 * CHANNELS.len() as u32;
        let mut d = Vec::with_capacity(4 + block_size as usize);
        d.extend_from_slice(&(4 + block_size).to_le_bytes()); // dfdTotalSize
        d.extend_from_slice(&0u32.to_le_bytes()); // vendorId 0 (Khronos), descriptorType 0
        d.extend_from_slice(&(2u32 | (block_size << 16)).to_le_bytes()); // version 2, size
        d.extend_from_slice(&[
            KHR_DF_MODEL_RGBSDA,
            KHR_DF_PRIMARIES_BT709,
            KHR_DF_TRANSFER_LINEAR,
            0, // flags: straight alpha
        ]);
        d.extend_from_slice(&[0, 0, 0, 0]); // texelBlockDimension0..3 (minus 1)
        let mut planes = [0u8; 8];
        planes[0] = self.format.texel_bytes() as u8;
        d.extend_from_slice(&planes);
        for (i, channel) in CHANNELS.into_iter().enumerate() {
            let bit_offset = (i as u32 * bits) as u16;
            d.extend_from_slice(&bit_offset.to_le_bytes());
            d.push((bits - 1) as u8);
            d.push(channel | QUALIFIER_FLOAT | QUALIFIER_SIGNED);
            d.extend_from_slice(&[0, 0, 0, 0]); // samplePosition0..3
            d.extend_from_slice(&(-1.0f32).to_bits().to_le_bytes()); // sampleLower
            d.extend_from_slice(&1.0f32.to_bits().to_le_bytes()); // sampleUpper
        }
        d
    }

    /// Encodes the file (see the [module docs](self)).
    ///
    /// # Errors
    /// [`Error::Table`] naming `path` when the image is inconsistent: a zero width or
    /// height, no level or more than a full mip chain, or level data of the wrong size.
    pub fn encode(&self, path: &Path) -> Result<Vec<u8>> {
        let bad = |message: String| table_error(path, message);
        if self.width == 0 || self.height == 0 {
            return Err(bad(format!(
                "cannot write a {}x{} texture",
                self.width, self.height
            )));
        }
        let level_count = self.levels.len();
        if level_count == 0 || level_count as u32 > self.max_levels() {
            return Err(bad(format!(
                "{level_count} levels for a {}x{}x{} texture (expected 1 to {})",
                self.width,
                self.height,
                self.depth,
                self.max_levels()
            )));
        }
        for (k, level) in self.levels.iter().enumerate() {
            if Some(level.len() as u64) != self.level_byte_length(k) {
                return Err(bad(format!(
                    "level {k} holds {} bytes; expected {:?}",
                    level.len(),
                    self.level_byte_length(k)
                )));
            }
        }
        let dfd = self.dfd();
        let mut keys: Vec<&(String, Vec<u8>)> = self.key_values.iter().collect();
        keys.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
        let mut kvd = Vec::new();
        for (key, value) in keys {
            let len = key.len() + 1 + value.len();
            kvd.extend_from_slice(&(len as u32).to_le_bytes());
            kvd.extend_from_slice(key.as_bytes());
            kvd.push(0);
            kvd.extend_from_slice(value);
            kvd.resize(kvd.len().next_multiple_of(4), 0);
        }
        let dfd_offset = HEADER_LEN + LEVEL_INDEX_LEN * level_count;
        let kvd_offset = dfd_offset + dfd.len();
        let align = self.format.texel_bytes(); // lcm(texel size, 4)
        // Level data, smallest level first.
        let mut offsets = vec![0usize; level_count];
        let mut end = kvd_offset + kvd.len();
        for k in (0..level_count).rev() {
            end = end.next_multiple_of(align);
            offsets[k] = end;
            end += self.levels[k].len();
        }
        let u32_of = |n: usize| -> Result<u32> {
            u32::try_from(n).map_err(|_| bad("metadata larger than 4 GiB".into()))
        };
        let mut out = Vec::with_capacity(end);
        out.extend_from_slice(&IDENTIFIER);
        for v in [
            self.format.vk_format(),
            self.format.type_size(),
            self.width,
            self.height,
            self.depth,
            self.layers,
            1, // faceCount
            level_count as u32,
            0, // supercompressionScheme: none
            u32_of(dfd_offset)?,
            u32_of(dfd.len())?,
            if kvd.is_empty() {
                0
            } else {
                u32_of(kvd_offset)?
            },
            u32_of(kvd.len())?,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&0u64.to_le_bytes()); // sgdByteOffset
        out.extend_from_slice(&0u64.to_le_bytes()); // sgdByteLength
        for (k, level) in self.levels.iter().enumerate() {
            let len = level.len() as u64;
            for v in [offsets[k] as u64, len, len] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        out.extend_from_slice(&dfd);
        out.extend_from_slice(&kvd);
        for k in (0..level_count).rev() {
            out.resize(offsets[k], 0);
            out.extend_from_slice(&self.levels[k]);
        }
        Ok(out)
    }

    /// Decodes and validates a file's bytes; `path` names it in errors.
    ///
    /// # Errors
    /// [`Error::Table`] naming `path` for anything but a well-formed, uncompressed,
    /// one-face `RGBA16F`/`RGBA32F` KTX 2.0 file whose sections and levels lie within the
    /// file and have the sizes its header implies.
    pub fn decode(path: &Path, bytes: &[u8]) -> Result<Self> {
        let bad = |message: String| table_error(path, message);
        if bytes.len() < HEADER_LEN {
            return Err(bad(format!(
                "truncated KTX2 file: {} bytes, shorter than the {HEADER_LEN}-byte header",
                bytes.len()
            )));
        }
        if bytes[..12] != IDENTIFIER {
            return Err(bad("not a KTX 2.0 file (wrong identifier)".into()));
        }
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
        let [
            vk_format,
            type_size,
            width,
            height,
            depth,
            layers,
            faces,
            level_count,
            supercompression,
            dfd_offset,
            dfd_length,
            kvd_offset,
            kvd_length,
        ] = std::array::from_fn(|i| u32_at(12 + 4 * i));
        let (sgd_offset, sgd_length) = (u64_at(64), u64_at(72));
        let format = Ktx2Format::from_vk_format(vk_format).ok_or_else(|| {
            bad(format!(
                "vkFormat {vk_format} is not supported: expected {VK_FORMAT_R16G16B16A16_SFLOAT} (R16G16B16A16_SFLOAT) or {VK_FORMAT_R32G32B32A32_SFLOAT} (R32G32B32A32_SFLOAT)"
            ))
        })?;
        if type_size != format.type_size() {
            return Err(bad(format!(
                "typeSize {type_size} does not match vkFormat {vk_format} (expected {})",
                format.type_size()
            )));
        }
        if supercompression != 0 {
            return Err(bad(format!(
                "supercompressionScheme {supercompression} is not supported (expected 0, none)"
            )));
        }
        if sgd_offset != 0 || sgd_length != 0 {
            return Err(bad(
                "unexpected supercompression global data in an uncompressed file".into(),
            ));
        }
        if faces != 1 {
            return Err(bad(format!("faceCount {faces}; expected 1")));
        }
        if width == 0 || height == 0 {
            return Err(bad(format!(
                "a {width}x{height} texture; expected a width and height of at least 1"
            )));
        }
        let mut image = Ktx2Image {
            format,
            width,
            height,
            depth,
            layers,
            levels: Vec::new(),
            key_values: Vec::new(),
        };
        if level_count == 0 || level_count > MAX_LEVELS.min(image.max_levels()) {
            return Err(bad(format!(
                "levelCount {level_count} for a {width}x{height}x{depth} texture (expected 1 to {})",
                image.max_levels()
            )));
        }
        let texels = u64::from(width)
            .checked_mul(u64::from(height))
            .and_then(|n| n.checked_mul(u64::from(depth.max(1))))
            .and_then(|n| n.checked_mul(u64::from(layers.max(1))));
        if texels.is_none_or(|n| n > MAX_TEXELS as u64) {
            return Err(bad(format!(
                "a {width}x{height}x{depth} texture of {layers} layers exceeds the limit of {MAX_TEXELS} texels"
            )));
        }
        let section = |what: &str, offset: u64, length: u64| -> Result<std::ops::Range<usize>> {
            match offset.checked_add(length) {
                Some(end) if end <= bytes.len() as u64 => Ok(offset as usize..end as usize),
                _ => Err(bad(format!(
                    "truncated KTX2 file: the {what} (bytes {offset} + {length}) runs past its end ({} bytes)",
                    bytes.len()
                ))),
            }
        };
        let index = section(
            "level index",
            HEADER_LEN as u64,
            LEVEL_INDEX_LEN as u64 * u64::from(level_count),
        )?;

        // The DFD: one basic block matching the format.
        let dfd = &bytes[section(
            "data format descriptor",
            dfd_offset.into(),
            dfd_length.into(),
        )?];
        let expected_dfd = image.dfd();
        if dfd != expected_dfd.as_slice() {
            return Err(bad(format!(
                "the data format descriptor does not describe linear {format:?} RGBA (vkFormat {vk_format})"
            )));
        }

        // Key/value data.
        let mut kvd = if kvd_length == 0 {
            &[][..]
        } else {
            &bytes[section("key/value data", kvd_offset.into(), kvd_length.into())?]
        };
        while !kvd.is_empty() {
            let Some(len) = kvd.get(..4) else {
                return Err(bad("truncated key/value entry".into()));
            };
            let len = u32::from_le_bytes(len.try_into().unwrap()) as usize;
            let entry = kvd.get(4..4usize.saturating_add(len)).ok_or_else(|| {
                bad(format!(
                    "a key/value entry of {len} bytes runs past the key/value data"
                ))
            })?;
            let nul = entry
                .iter()
                .position(|&b| b == 0)
                .ok_or_else(|| bad("a key without its terminating NUL".into()))?;
            let key = std::str::from_utf8(&entry[..nul])
                .map_err(|_| bad("a key that is not UTF-8".into()))?;
            // KTX 2.0 §3.11: keys sorted by codepoint, each once (the writer's order).
            if let Some((last, _)) = image.key_values.last()
                && last.as_str() >= key
            {
                return Err(bad(format!(
                    "key `{key}` after `{last}`: expected the keys sorted and unique"
                )));
            }
            image
                .key_values
                .push((key.to_string(), entry[nul + 1..].to_vec()));
            let next = (4 + len).next_multiple_of(4);
            kvd = kvd.get(next..).unwrap_or(&[]);
        }

        // Levels.
        for k in 0..level_count as usize {
            let at = index.start + LEVEL_INDEX_LEN * k;
            let (offset, length, uncompressed) = (u64_at(at), u64_at(at + 8), u64_at(at + 16));
            let expected = image.level_byte_length(k);
            if Some(length) != expected || uncompressed != length {
                return Err(bad(format!(
                    "level {k} holds {length} bytes ({uncompressed} uncompressed); a {:?} level of {format:?} needs {}",
                    image.level_extent(k),
                    expected.unwrap_or(u64::MAX)
                )));
            }
            if !offset.is_multiple_of(format.texel_bytes() as u64) {
                return Err(bad(format!(
                    "level {k} starts at byte {offset}, not aligned to {} bytes",
                    format.texel_bytes()
                )));
            }
            let range = section(&format!("level {k}"), offset, length)?;
            image.levels.push(bytes[range].to_vec());
        }
        Ok(image)
    }

    /// The components of level `k` as `f32` (four per texel).
    pub fn level_f32(&self, k: usize) -> Vec<f32> {
        let level = &self.levels[k];
        match self.format {
            Ktx2Format::Rgba16Float => level
                .chunks_exact(2)
                .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
                .collect(),
            Ktx2Format::Rgba32Float => level
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        }
    }
}

fn table_error(path: &Path, message: impl Into<String>) -> Error {
    Error::Table {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Writes `image` to `path` atomically (see [`crate::atomic::write_atomic`]).
///
/// # Errors
/// As [`Ktx2Image::encode`]; [`Error::Io`] when the file cannot be written.
pub fn write_ktx2(path: &Path, image: &Ktx2Image) -> Result<()> {
    let bytes = image.encode(path)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Reads and validates the KTX 2.0 file at `path`.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; otherwise as [`Ktx2Image::decode`].
pub fn read_ktx2(path: &Path) -> Result<Ktx2Image> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ktx2Image::decode(path, &bytes)
}

/// The key/value pairs nacre embeds: the writer and the manifest JSON.
fn key_values(manifest_json: &str) -> Vec<(String, Vec<u8>)> {
    let nul = |s: &str| {
        let mut v = s.as_bytes().to_vec();
        v.push(0);
        v
    };
    vec![
        (
            WRITER_KEY.into(),
            nul(&format!("nacre {}", env!("CARGO_PKG_VERSION"))),
        ),
        (MANIFEST_KEY.into(), nul(manifest_json)),
    ]
}

/// The KTX2 image of a `film-lut` quantity: a 3-D `RGBA16F` texture, alpha 1
/// ([`film_lut_image_as`] with [`Ktx2Format::Rgba16Float`]).
///
/// # Errors
/// As [`film_lut_image_as`].
pub fn film_lut_image(path: &Path, table: &Table3, manifest_json: &str) -> Result<Ktx2Image> {
    film_lut_image_as(path, table, manifest_json, Ktx2Format::Rgba16Float)
}

/// The KTX2 image of a `film-lut` quantity as a 3-D texture of `format` (`RGBA16F` for a
/// recipe's `precision = "half"`, `RGBA32F` for `"float"`), alpha 1.
///
/// # Errors
/// [`Error::Table`] naming `path` for an empty or inconsistent table, a non-finite value,
/// or (half floats) a value beyond the half-float range.
pub fn film_lut_image_as(
    path: &Path,
    table: &Table3,
    manifest_json: &str,
    format: Ktx2Format,
) -> Result<Ktx2Image> {
    let dims = [table.nx, table.ny, table.nz].map(u32::try_from);
    let [Ok(nx), Ok(ny), Ok(nz)] = dims else {
        return Err(table_error(path, "table too large for a KTX2 texture"));
    };
    if nx == 0
        || ny == 0
        || nz == 0
        || table.data.len() as u64 != 3 * u64::from(nx) * u64::from(ny) * u64::from(nz)
    {
        return Err(table_error(
            path,
            format!(
                "cannot write a {nx}x{ny}x{nz} table holding {} floats",
                table.data.len()
            ),
        ));
    }
    let mut level = Vec::with_capacity(table.data.len() / 3 * format.texel_bytes());
    for (i, rgb) in table.data.chunks_exact(3).enumerate() {
        for (c, &v) in rgb.iter().enumerate() {
            let h = f16::from_f32(v);
            let representable = match format {
                Ktx2Format::Rgba16Float => h.is_finite(),
                Ktx2Format::Rgba32Float => v.is_finite(),
            };
            if !representable {
                let (x, y, z) = (
                    i % table.nx,
                    (i / table.nx) % table.ny,
                    i / (table.nx * table.ny),
                );
                let range = match format {
                    Ktx2Format::Rgba16Float => " within the half-float range (±65504)",
                    Ktx2Format::Rgba32Float => "",
                };
                return Err(table_error(
                    path,
                    format!(
                        "texel (x={x}, y={y}, z={z}) channel {} is {v}: not finite{range}",
                        ["R", "G", "B"][c]
                    ),
                ));
            }
            match format {
                Ktx2Format::Rgba16Float => level.extend_from_slice(&h.to_le_bytes()),
                Ktx2Format::Rgba32Float => level.extend_from_slice(&v.to_le_bytes()),
            }
        }
        match format {
            Ktx2Format::Rgba16Float => level.extend_from_slice(&f16::ONE.to_le_bytes()),
            Ktx2Format::Rgba32Float => level.extend_from_slice(&1f32.to_le_bytes()),
        }
    }
    Ok(Ktx2Image {
        format,
        width: nx,
        height: ny,
        depth: nz,
        layers: 0,
        levels: vec![level],
        key_values: key_values(manifest_json),
    })
}

/// The KTX2 image of a `fourier` table: a 2-D array `RGBA32F` texture of two layers
/// (Re, Im), height 1, every level; alpha 0.
///
/// # Errors
/// [`Error::Table`] naming `path` when the levels do not form a mip chain
/// (level k = max(N >> k, 1) texels) or hold a non-finite value.
pub fn fourier_image(path: &Path, table: &FourierTable, manifest_json: &str) -> Result<Ktx2Image> {
    let n = table.levels.first().map_or(0, Vec::len);
    let width = u32::try_from(n)
        .ok()
        .filter(|&w| w > 0)
        .ok_or_else(|| table_error(path, format!("cannot write a fourier table of {n} texels")))?;
    let mut levels = Vec::with_capacity(table.levels.len());
    for (k, level) in table.levels.iter().enumerate() {
        if level.len() != (n >> k).max(1) {
            return Err(table_error(
                path,
                format!(
                    "level {k} has {} texels; a mip chain of {n} needs {}",
                    level.len(),
                    (n >> k).max(1)
                ),
            ));
        }
        let mut bytes = Vec::with_capacity(level.len() * 32);
        for imaginary in [false, true] {
            for a in level {
                for c in a {
                    let v = (if imaginary { c.im } else { c.re }) as f32;
                    if !v.is_finite() {
                        return Err(table_error(
                            path,
                            format!("level {k} holds a non-finite value {v}"),
                        ));
                    }
                    bytes.extend_from_slice(&v.to_le_bytes());
                }
                bytes.extend_from_slice(&0f32.to_le_bytes());
            }
        }
        levels.push(bytes);
    }
    Ok(Ktx2Image {
        format: Ktx2Format::Rgba32Float,
        width,
        height: 1,
        depth: 0,
        layers: 2,
        levels,
        key_values: key_values(manifest_json),
    })
}

/// Reads a `film-lut` quantity written by [`film_lut_image`] as an `nx` × `ny` × `nz`
/// table (alpha dropped).
///
/// # Errors
/// As [`read_ktx2`], and [`Error::Table`] when the file is not a one-level, non-array 3-D
/// texture of exactly `nx` × `ny` × `nz` texels or holds a non-finite value.
pub fn read_film_lut_ktx2(path: &Path, nx: usize, ny: usize, nz: usize) -> Result<Table3> {
    let image = read_ktx2(path)?;
    let found = (
        image.width as usize,
        image.height as usize,
        image.depth as usize,
    );
    if found != (nx, ny, nz) || image.layers != 0 || image.levels.len() != 1 {
        return Err(table_error(
            path,
            format!(
                "texture is {}x{}x{} with {} layers and {} levels; expected a {nx}x{ny}x{nz} 3-D texture with 0 layers and 1 level",
                image.width,
                image.height,
                image.depth,
                image.layers,
                image.levels.len()
            ),
        ));
    }
    let rgba = image.level_f32(0);
    let data: Vec<f32> = rgba
        .chunks_exact(4)
        .flat_map(|t| [t[0], t[1], t[2]])
        .collect();
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        return Err(table_error(
            path,
            format!("non-finite value {} at texel {}", data[i], i / 3),
        ));
    }
    Ok(Table3 { nx, ny, nz, data })
}

/// Reads a `fourier` table written by [`fourier_image`], checking it against `axes`.
///
/// # Errors
/// As [`read_ktx2`], and [`Error::Table`] when the file is not an `RGBA32F` 2-D array
/// texture of two layers, height 1, with one level per entry of `axes.level_samples` of
/// those sizes, or holds a non-finite value.
pub fn read_fourier_ktx2(path: &Path, axes: FourierAxes) -> Result<FourierTable> {
    let image = read_ktx2(path)?;
    let sizes: Vec<usize> = (0..image.levels.len())
        .map(|k| image.level_extent(k).0 as usize)
        .collect();
    if image.format != Ktx2Format::Rgba32Float
        || image.height != 1
        || image.depth != 0
        || image.layers != 2
        || sizes != axes.level_samples
    {
        return Err(table_error(
            path,
            format!(
                "texture is {:?} {}x{}x{}, {} layers, level widths {sizes:?}; expected Rgba32Float, height 1, 2 layers, level widths {:?}",
                image.format,
                image.width,
                image.height,
                image.depth,
                image.layers,
                axes.level_samples
            ),
        ));
    }
    let mut levels = Vec::with_capacity(sizes.len());
    for (k, &n) in sizes.iter().enumerate() {
        let v = image.level_f32(k);
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(table_error(
                path,
                format!("non-finite value {} in level {k} (component {i})", v[i]),
            ));
        }
        let (re, im) = v.split_at(4 * n);
        levels.push(
            (0..n)
                .map(|i| {
                    std::array::from_fn(|j| {
                        C64::new(f64::from(re[4 * i + j]), f64::from(im[4 * i + j]))
                    })
                })
                .collect(),
        );
    }
    Ok(FourierTable { axes, levels })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(nx: usize, ny: usize, nz: usize) -> Table3 {
        let mut t = Table3::new(nx, ny, nz);
        for (i, v) in t.data.iter_mut().enumerate() {
            *v = f16::from_f32((i as f32 * 0.37).sin() * 3.0).to_f32();
        }
        t
    }

    fn fourier(n: usize, levels: usize) -> FourierTable {
        let level_samples: Vec<usize> = (0..levels).map(|k| (n >> k).max(1)).collect();
        let axes = FourierAxes {
            samples: n,
            max_opd_nm: 1000.0,
            level_samples: level_samples.clone(),
            level_sigma_nm: vec![0.0; levels],
            carrier_nu_per_nm: [0.0; 3],
            white: [1.0; 3],
        };
        let levels = level_samples
            .iter()
            .enumerate()
            .map(|(k, &m)| {
                (0..m)
                    .map(|i| {
                        std::array::from_fn(|j| {
                            let x = (k * 1000 + i * 3 + j) as f32;
                            C64::new(f64::from(x * 0.5), f64::from(-x * 0.25))
                        })
                    })
                    .collect()
            })
            .collect();
        FourierTable { axes, levels }
    }

    #[test]
    fn film_lut_round_trip_is_exact_and_deterministic() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ktx2");
        let t = table(5, 3, 4);
        let image = film_lut_image(&path, &t, "{}").unwrap();
        write_ktx2(&path, &image).unwrap();
        let first = std::fs::read(&path).unwrap();
        write_ktx2(&path, &film_lut_image(&path, &t, "{}").unwrap()).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), first);
        assert_eq!(read_film_lut_ktx2(&path, 5, 3, 4).unwrap(), t);
        let back = read_ktx2(&path).unwrap();
        assert_eq!(back, image);
        assert_eq!(back.value_str(MANIFEST_KEY), Some("{}"));
        assert_eq!(back.value_str(WRITER_KEY), Some("nacre 0.1.0"));
        assert!(read_film_lut_ktx2(&path, 5, 4, 3).is_err());
    }

    #[test]
    fn fourier_round_trip_stores_levels_smallest_first() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.ktx2");
        let f = fourier(64, 5);
        write_ktx2(&path, &fourier_image(&path, &f, "{\"a\": 1}").unwrap()).unwrap();
        let back = read_fourier_ktx2(&path, f.axes.clone()).unwrap();
        assert_eq!(back, f);
        let bytes = std::fs::read(&path).unwrap();
        let offset = |k: usize| {
            let at = HEADER_LEN + LEVEL_INDEX_LEN * k;
            u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
        };
        for k in 1..5 {
            assert!(
                offset(k) < offset(k - 1),
                "level {k} before level {}",
                k - 1
            );
            assert_eq!(offset(k) % 16, 0);
        }
        let mut short = f.axes.clone();
        short.level_samples.pop();
        assert!(read_fourier_ktx2(&path, short).is_err());
    }

    #[test]
    fn truncated_or_corrupt_files_are_errors_not_panics() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.ktx2");
        write_ktx2(&path, &fourier_image(&path, &fourier(32, 3), "{}").unwrap()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        for len in 0..bytes.len() {
            let err = Ktx2Image::decode(&path, &bytes[..len]).unwrap_err();
            assert!(err.to_string().contains("c.ktx2"), "{len}: {err}");
        }
        for i in 0..bytes.len() {
            for flip in [0x01u8, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[i] ^= flip;
                let _ = Ktx2Image::decode(&path, &b); // must not panic
            }
        }
    }

    #[test]
    fn wrong_format_or_sizes_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.ktx2");
        let image = film_lut_image(&path, &table(4, 2, 2), "{}").unwrap();
        let bytes = image.encode(&path).unwrap();
        let patch = |at: usize, v: u32| {
            let mut b = bytes.clone();
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            Ktx2Image::decode(&path, &b).unwrap_err().to_string()
        };
        assert!(patch(12, 37).contains("vkFormat 37"));
        assert!(patch(12, VK_FORMAT_R32G32B32A32_SFLOAT).contains("typeSize"));
        assert!(patch(16, 4).contains("typeSize"));
        assert!(patch(20, 5).contains("level 0"));
        assert!(patch(28, 3).contains("level 0"));
        assert!(patch(36, 2).contains("faceCount"));
        assert!(patch(40, 0).contains("levelCount"));
        assert!(patch(44, 1).contains("supercompression"));
        assert!(patch(0, 0).contains("identifier"));
        // Inconsistent images are refused by the writer too.
        let mut broken = image.clone();
        broken.levels[0].pop();
        assert!(broken.encode(&path).is_err());
        let mut bad = table(2, 2, 2);
        bad.data[4] = 1e6;
        assert!(film_lut_image(&path, &bad, "{}").is_err());
        bad.data[4] = f32::NAN;
        assert!(film_lut_image(&path, &bad, "{}").is_err());
    }
}
