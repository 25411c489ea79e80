//! `KHR_texture_basisu`: textures whose picture is a KTX 2.0 file holding Basis Universal
//! data, ETC1S (BasisLZ supercompression) or UASTC (no supercompression or Zstandard),
//! transcoded on the CPU to RGBA8 by the `basisu` crate (a pure-Rust port of Binomial's
//! reference transcoder) and then handed to the same texture path as PNG and JPEG: the
//! material's slot says whether the texels are sRGB colours or data, and mipmaps are made on
//! upload (only the file's level 0 is read).
//!
//! The extension (KHR_texture_basisu, "KTX2 image requirements") asks of the file: a 2-D
//! texture (pixelDepth 0, faceCount 1, no array), `vkFormat` VK_FORMAT_UNDEFINED (0), and a
//! supercompression scheme of BasisLZ (1) for ETC1S, none (0) or Zstandard (2) for UASTC.
//! [`decode`] checks those and the level index (KTX 2.0 specification §3: the 80-byte header
//! and index, then `levelCount` × (byteOffset, byteLength, uncompressedByteLength) as u64)
//! (a Zstandard level's uncompressed length that of its UASTC blocks) before the transcoder
//! sees the bytes, and the transcoder runs under
//! [`nacre_format::decode::guarded`], so a damaged file is a [`Ktx2Error`], never a panic.
//!
//! A texture names its KTX2 image in `extensions.KHR_texture_basisu.source`
//! ([`basisu_source`]); its core `source` is optional (a fallback picture for clients without
//! the extension), which `gltf-json` 1.4 does not allow: `document.rs` accepts a missing
//! `source` where the extension gives one, and `textures.rs` reads the extension's image.

use super::error::Ktx2Error;
use super::limits::MAX_TEXTURE_DIMENSION;

/// The extension's name.
pub const EXTENSION: &str = "KHR_texture_basisu";

/// The KTX 2.0 file identifier (KTX 2.0 §3.1): «KTX 20»\r\n\x1A\n.
const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// Bytes of the KTX 2.0 header and index before the level index (KTX 2.0 §3.1–§3.7).
const HEADER_BYTES: usize = 80;

/// Bytes of one level index entry (byteOffset, byteLength, uncompressedByteLength; u64 each).
const LEVEL_ENTRY_BYTES: usize = 24;

/// A KTX2 / Basis Universal picture decoded to RGBA8 (level 0).
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedKtx2 {
    /// Width, texels.
    pub width: u32,
    /// Height, texels.
    pub height: u32,
    /// RGBA8 texels, row-major, row 0 first (the file's first row: glTF's v = 0).
    pub rgba: Vec<u8>,
    /// The Basis codec: `"ETC1S"` or `"UASTC"`.
    pub codec: &'static str,
}

/// The image index a texture's `KHR_texture_basisu` extension names, if it has one.
pub fn basisu_source(texture: &gltf::json::Texture) -> Option<Result<usize, String>> {
    let ext = texture.extensions.as_ref()?.others.get(EXTENSION)?;
    Some(
        ext.get("source")
            .and_then(serde_json::Value::as_u64)
            .and_then(|s| usize::try_from(s).ok())
            .ok_or_else(|| format!("{EXTENSION}.source is missing or not an index: {ext}")),
    )
}

fn u32_at(bytes: &[u8], offset: usize) -> u32 {
    u32::from_le_bytes(bytes[offset..offset + 4].try_into().expect("4 bytes"))
}

fn u64_at(bytes: &[u8], offset: usize) -> u64 {
    u64::from_le_bytes(bytes[offset..offset + 8].try_into().expect("8 bytes"))
}

/// Decodes level 0 of the KTX2 file `bytes` to RGBA8, after checking what
/// `KHR_texture_basisu` asks of it (see the module).
pub fn decode(bytes: &[u8]) -> Result<DecodedKtx2, Ktx2Error> {
    let truncated = |need: usize| Ktx2Error::Truncated {
        bytes: bytes.len(),
        need,
    };
    if bytes.len() < IDENTIFIER.len() || bytes[..IDENTIFIER.len()] != IDENTIFIER {
        return Err(Ktx2Error::NotKtx2);
    }
    if bytes.len() < HEADER_BYTES {
        return Err(truncated(HEADER_BYTES));
    }
    let vk_format = u32_at(bytes, 12);
    let (width, height, depth) = (u32_at(bytes, 20), u32_at(bytes, 24), u32_at(bytes, 28));
    let (layers, faces, levels) = (u32_at(bytes, 32), u32_at(bytes, 36), u32_at(bytes, 40));
    let scheme = u32_at(bytes, 44);
    if vk_format != 0 {
        return Err(Ktx2Error::VkFormat { vk_format });
    }
    if depth != 0 || faces != 1 || layers > 1 {
        return Err(Ktx2Error::NotTwoD {
            depth,
            layers,
            faces,
        });
    }
    if width == 0 || height == 0 || width.max(height) > MAX_TEXTURE_DIMENSION {
        return Err(Ktx2Error::Dimensions {
            width,
            height,
            max: MAX_TEXTURE_DIMENSION,
        });
    }
    if scheme > 2 {
        return Err(Ktx2Error::Supercompression {
            scheme,
            codec: None,
        });
    }
    // levelCount 0 asks the loader to make the mipmaps: level 0 is still stored.
    let stored = levels.max(1) as usize;
    if stored > 32 {
        return Err(Ktx2Error::LevelCount { levels });
    }
    let index_end = HEADER_BYTES + stored * LEVEL_ENTRY_BYTES;
    if bytes.len() < index_end {
        return Err(truncated(index_end));
    }
    for level in 0..stored {
        let entry = HEADER_BYTES + level * LEVEL_ENTRY_BYTES;
        let (offset, length) = (u64_at(bytes, entry), u64_at(bytes, entry + 8));
        if offset
            .checked_add(length)
            .is_none_or(|end| end > bytes.len() as u64)
        {
            return Err(Ktx2Error::LevelOutside {
                level: level as u32,
                offset,
                length,
                bytes: bytes.len(),
            });
        }
        // A Zstandard level inflates to its UASTC blocks, 16 bytes per 4 × 4 texels; the
        // transcoder allocates what the file says (KTX 2.0 §3.9.7 uncompressedByteLength).
        let uncompressed = u64_at(bytes, entry + 16);
        let blocks = |side: u32| u64::from((side >> level).max(1).div_ceil(4));
        let expected = 16 * blocks(width) * blocks(height);
        if scheme == 2 && uncompressed != expected {
            return Err(Ktx2Error::LevelSize {
                level: level as u32,
                uncompressed,
                expected,
            });
        }
    }
    nacre_format::decode::guarded(|| transcode(bytes, scheme), || Ktx2Error::Panicked)
}

/// Level 0 of a checked KTX2 file through the `basisu` transcoder.
fn transcode(bytes: &[u8], scheme: u32) -> Result<DecodedKtx2, Ktx2Error> {
    use basisu::{DecodeFlags, SourceFormat, TargetFormat, Transcoder};
    let refused = |e: basisu::Error| Ktx2Error::Transcoder {
        reason: format!("{e:?}"),
    };
    let transcoder = Transcoder::new(bytes).map_err(refused)?;
    let codec = match transcoder.source_format() {
        SourceFormat::Etc1s => "ETC1S",
        SourceFormat::UastcLdr => "UASTC",
        other => {
            return Err(Ktx2Error::Codec {
                codec: format!("{other:?}"),
            });
        }
    };
    // ETC1S must be BasisLZ; UASTC none or Zstandard (the extension's requirements).
    if (codec == "ETC1S") != (scheme == 1) {
        return Err(Ktx2Error::Supercompression {
            scheme,
            codec: Some(codec),
        });
    }
    let info = transcoder.image_level_info(0).map_err(refused)?;
    let rgba = transcoder
        .transcode(0, TargetFormat::Rgba32, DecodeFlags::NONE)
        .map_err(refused)?;
    let expected = info.width as usize * info.height as usize * 4;
    if rgba.len() != expected {
        return Err(Ktx2Error::Transcoder {
            reason: format!(
                "{} bytes for {}x{} RGBA8 texels (expected {expected})",
                rgba.len(),
                info.width,
                info.height
            ),
        });
    }
    Ok(DecodedKtx2 {
        width: info.width,
        height: info.height,
        rgba,
        codec,
    })
}
