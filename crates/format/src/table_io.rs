//! Writing and reading 3-D lookup tables as 2-D image *atlases* (OpenEXR and 16-bit PNG).
//!
//! # Table layout
//!
//! A [`Table3`] is a 3-D array of RGB `f32` texels with dimensions `(nx, ny, nz)`, stored
//! x-fastest with three floats per texel:
//!
//! ```text
//! texel index = ((z * ny) + y) * nx + x,   floats data[3 * index .. 3 * index + 3] = R, G, B
//! ```
//!
//! # Atlas layout
//!
//! The table is written as a 2-D image of `width = nx` and `height = ny * nz` texels. The
//! slices are stacked vertically: slice `z` occupies image rows `[z * ny, (z + 1) * ny)`,
//! and row `y` of slice `z` is image row `z * ny + y`, counted from the top (row 0 is the
//! first row stored in the file). Column `x` is image column `x`. Because image rows are
//! themselves stored left to right and top to bottom, the atlas texel order is exactly the
//! table's memory order: atlas texel `(column x, row r)` is table texel `r * nx + x`.
//!
//! ```text
//!            x = 0 .. nx-1
//!          +---------------+
//!  row 0   | z = 0, y = 0  |
//!   ...    |      ...      |
//!  ny-1    | z = 0, y=ny-1 |
//!  ny      | z = 1, y = 0  |
//!   ...    |      ...      |
//!  ny*nz-1 | z=nz-1,y=ny-1 |
//!          +---------------+
//! ```
//!
//! # Formats
//!
//! * **OpenEXR** ([`write_exr`], [`read_exr`], [`read_exr_table`]): one single-part
//!   scan-line image with exactly the channels `R`, `G`, `B` (no alpha), ZIP compression
//!   (lossless, 16 scan lines per block), increasing line order, samples stored as half
//!   (`f16`, converted with round-to-nearest-even) or full (`f32`) float. The encoder runs
//!   sequentially and writes no time stamps, so the same table always gives the same bytes.
//! * **16-bit PNG** ([`write_png16`], [`read_png16_table`]): RGB, 16 bits per channel,
//!   value `v` stored as `round(v * 65535)`; only possible when every value lies in
//!   `[0, 1]`. No colour-space chunks are written: the values are data, not colours to be
//!   gamma-corrected.
//!
//! Every writer refuses non-finite values (and, for half floats, values beyond the `f16`
//! range) before touching the file system, and writes atomically through
//! [`crate::atomic::write_atomic`]: an existing file is replaced only by a complete new
//! one and is left untouched when writing fails. Readers validate the dimensions, channels
//! and values and never panic on malformed or truncated files; every error names the file.

use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use half::f16;
use std::io::{Cursor, Read};
use std::path::Path;

/// Most texels (`width * height` of an atlas, `nx * ny * nz` of a table) a reader accepts
/// from a file, so that a corrupt header cannot request an absurd allocation: 2²⁷ texels
/// (e.g. 512³), 1.5 GiB of `f32` RGB data.
pub const MAX_TEXELS: usize = 1 << 27;

/// Largest width or height of an atlas image (the OpenEXR and PNG limit, 2³¹ − 1).
const MAX_SIDE: usize = i32::MAX as usize;

/// A 3-D table of RGB `f32` texels, stored x-fastest (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct Table3 {
    /// Texels along x (the atlas width).
    pub nx: usize,
    /// Texels along y (rows per slice in the atlas).
    pub ny: usize,
    /// Texels along z (slices stacked vertically in the atlas).
    pub nz: usize,
    /// `nx * ny * nz * 3` floats: R, G, B of texel `((z * ny) + y) * nx + x`.
    pub data: Vec<f32>,
}

impl Table3 {
    /// A table of `nx * ny * nz` texels, all `[0, 0, 0]`.
    ///
    /// # Panics
    /// If `nx * ny * nz * 3` overflows `usize`.
    pub fn new(nx: usize, ny: usize, nz: usize) -> Self {
        let len = nx
            .checked_mul(ny)
            .and_then(|n| n.checked_mul(nz))
            .and_then(|n| n.checked_mul(3))
            .expect("Table3::new: nx * ny * nz * 3 overflows usize");
        Self {
            nx,
            ny,
            nz,
            data: vec![0.0; len],
        }
    }

    /// Offset of texel `(x, y, z)`'s red value in `data`.
    fn offset(&self, x: usize, y: usize, z: usize) -> usize {
        assert!(
            x < self.nx && y < self.ny && z < self.nz,
            "texel ({x}, {y}, {z}) outside a {}x{}x{} table",
            self.nx,
            self.ny,
            self.nz
        );
        (((z * self.ny) + y) * self.nx + x) * 3
    }

    /// The RGB value of texel `(x, y, z)`.
    ///
    /// # Panics
    /// If the coordinates are outside the table.
    pub fn texel(&self, x: usize, y: usize, z: usize) -> [f32; 3] {
        let i = self.offset(x, y, z);
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    /// Sets the RGB value of texel `(x, y, z)`.
    ///
    /// # Panics
    /// If the coordinates are outside the table.
    pub fn set(&mut self, x: usize, y: usize, z: usize, rgb: [f32; 3]) {
        let i = self.offset(x, y, z);
        self.data[i..i + 3].copy_from_slice(&rgb);
    }
}

/// A 2-D RGB atlas as read from an image, before it is cut into slices: `width * height`
/// texels, row-major from the top row, three floats (R, G, B) per texel. With
/// `width == nx` and `height == ny * nz` its `data` is exactly a [`Table3`]'s `data`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table3Atlas {
    /// Image width in texels.
    pub width: usize,
    /// Image height in texels.
    pub height: usize,
    /// `width * height * 3` floats: R, G, B of texel `row * width + column`.
    pub data: Vec<f32>,
}

/// Sample precision of an OpenEXR table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// 16-bit half float (`f16`): 11 significant bits, finite range ±65504.
    Half,
    /// 32-bit float (`f32`), stored exactly.
    Float,
}

fn table_error(path: &Path, message: impl Into<String>) -> Error {
    Error::Table {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Checks that `table` is well formed and fits an atlas image; returns the atlas height.
fn check_shape(path: &Path, table: &Table3) -> Result<usize> {
    let (nx, ny, nz) = (table.nx, table.ny, table.nz);
    if nx == 0 || ny == 0 || nz == 0 {
        return Err(table_error(
            path,
            format!("cannot write an empty {nx}x{ny}x{nz} table"),
        ));
    }
    let height = ny.checked_mul(nz).filter(|&h| h <= MAX_SIDE);
    let Some(height) = height.filter(|_| nx <= MAX_SIDE) else {
        return Err(table_error(
            path,
            format!(
                "a {nx}x{ny}x{nz} table gives an atlas larger than {MAX_SIDE} texels on a side"
            ),
        ));
    };
    let expected = nx.checked_mul(height).and_then(|n| n.checked_mul(3));
    if expected != Some(table.data.len()) {
        return Err(table_error(
            path,
            format!(
                "a {nx}x{ny}x{nz} table needs {nx}*{ny}*{nz}*3 floats but its data holds {}",
                table.data.len()
            ),
        ));
    }
    Ok(height)
}

/// Describes the location of float `i` of `table.data` for error messages.
fn describe(table: &Table3, i: usize) -> String {
    let texel = i / 3;
    let channel = ["R", "G", "B"][i % 3];
    let x = texel % table.nx;
    let y = (texel / table.nx) % table.ny;
    let z = texel / (table.nx * table.ny);
    format!(
        "texel (x={x}, y={y}, z={z}) channel {channel} (atlas column {x}, row {})",
        texel / table.nx
    )
}

/// Refuses NaN and infinite values.
fn check_finite(path: &Path, table: &Table3) -> Result<()> {
    match table.data.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(table_error(
            path,
            format!(
                "{} is {}; refusing to write a table with non-finite values",
                describe(table, i),
                table.data[i]
            ),
        )),
    }
}

/// Writes `table` as an OpenEXR atlas (see the [module docs](self)) with channels `R`, `G`,
/// `B` in `precision`, ZIP-compressed (lossless) scan lines.
///
/// Half floats are rounded to nearest, ties to even. The output is deterministic (same
/// table, same bytes) and written atomically; `path` `-` writes to standard output.
///
/// # Errors
/// [`Error::Table`] (nothing written) for an empty or inconsistent table, a non-finite
/// value, or, with [`Precision::Half`], a value whose magnitude exceeds the `f16` range
/// (65504 after rounding); [`Error::Io`] when the file cannot be written.
pub fn write_exr(path: &Path, table: &Table3, precision: Precision) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer,
        LayerAttributes, LineOrder, SmallVec, WritableImage,
    };

    let height = check_shape(path, table)?;
    check_finite(path, table)?;
    let channel = |c: usize| table.data.iter().skip(c).step_by(3).copied();
    let samples = |c: usize| -> Result<FlatSamples> {
        Ok(match precision {
            Precision::Float => FlatSamples::F32(channel(c).collect()),
            Precision::Half => {
                let half: Vec<f16> = channel(c).map(f16::from_f32).collect();
                if let Some(j) = half.iter().position(|h| !h.is_finite()) {
                    let i = j * 3 + c;
                    return Err(table_error(
                        path,
                        format!(
                            "{} is {}, beyond the half-float range (±65504); write with float precision",
                            describe(table, i),
                            table.data[i]
                        ),
                    ));
                }
                FlatSamples::F16(half)
            }
        })
    };
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![
        AnyChannel::new("R", samples(0)?),
        AnyChannel::new("G", samples(1)?),
        AnyChannel::new("B", samples(2)?),
    ]));
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (table.nx, height),
        LayerAttributes::default(),
        encoding,
        channels,
    );
    let image = Image::from_layer(layer);

    // Encode in memory (the encoder needs `Seek`), sequentially: never in parallel, so
    // the block order and bytes do not depend on thread scheduling.
    let mut bytes = Vec::new();
    image
        .write()
        .non_parallel()
        .to_buffered(Cursor::new(&mut bytes))
        .map_err(|e| table_error(path, format!("cannot encode OpenEXR: {e}")))?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Reads the file at `path` whole.
fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(io_error(path))
}

/// Runs a decoder, turning a panic inside it (a malformed file the decoder library did not
/// anticipate) into an error naming the file.
fn guarded<T>(path: &Path, format: &str, decode: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode)).unwrap_or_else(|_| {
        Err(table_error(
            path,
            format!("malformed {format} data (the decoder failed)"),
        ))
    })
}

/// Checks, before the decoder sees them, that the offset table of a single-part OpenEXR
/// file and every chunk it points to lie within the file. The `exr` crate sizes its buffers
/// from a chunk's byte count as declared, so a 500-byte file declaring a 2 GB chunk would
/// otherwise cost 2 GB of memory (found by `fuzz/`, target `exr`).
fn check_exr_chunks(
    path: &Path,
    bytes: &[u8],
    chunk_count: usize,
    blocks: &exr::meta::BlockDescription,
) -> Result<()> {
    let bad = |message: String| table_error(path, format!("not a valid OpenEXR file: {message}"));
    let i32_at = |at: usize| -> Option<i32> {
        Some(i32::from_le_bytes(
            bytes.get(at..at.checked_add(4)?)?.try_into().ok()?,
        ))
    };
    // The header: magic and version, then attributes `name\0type\0size value` up to a NUL.
    let mut at = 8usize;
    loop {
        match bytes.get(at) {
            None => return Err(bad("the header runs past the end of the file".into())),
            Some(0) => break,
            Some(_) => {}
        }
        for _ in 0..2 {
            let nul = bytes[at..]
                .iter()
                .position(|&b| b == 0)
                .ok_or_else(|| bad("an attribute name runs past the end of the file".into()))?;
            at += nul + 1;
        }
        let size = i32_at(at)
            .and_then(|n| usize::try_from(n).ok())
            .ok_or_else(|| bad("an attribute size is missing or negative".into()))?;
        at = at
            .checked_add(4 + size)
            .filter(|&end| end <= bytes.len())
            .ok_or_else(|| bad("an attribute runs past the end of the file".into()))?;
    }
    let table = at + 1;
    let table_end = chunk_count
        .checked_mul(8)
        .and_then(|n| n.checked_add(table))
        .filter(|&end| end <= bytes.len())
        .ok_or_else(|| {
            bad(format!(
                "an offset table of {chunk_count} chunks runs past the end of the file ({} bytes)",
                bytes.len()
            ))
        })?;
    // A chunk: its coordinates (scan line y, or four tile coordinates), its byte count, data.
    let coordinates = match blocks {
        exr::meta::BlockDescription::ScanLines => 4,
        exr::meta::BlockDescription::Tiles(_) => 16,
    };
    for (k, entry) in bytes[table..table_end].chunks_exact(8).enumerate() {
        let offset = u64::from_le_bytes(entry.try_into().unwrap());
        let fits = usize::try_from(offset).ok().and_then(|o| {
            let size = usize::try_from(i32_at(o.checked_add(coordinates)?)?).ok()?;
            o.checked_add(coordinates + 4)?
                .checked_add(size)
                .filter(|&end| end <= bytes.len())
        });
        if fits.is_none() {
            return Err(bad(format!(
                "chunk {k} of {chunk_count} (at byte {offset}) runs past the end of the file ({} bytes)",
                bytes.len()
            )));
        }
    }
    Ok(())
}

/// Decodes an OpenEXR atlas; with `expected = Some((width, height, what))` the image size
/// is checked against it before any pixel data is decoded.
fn decode_exr(
    path: &Path,
    bytes: &[u8],
    expected: Option<(usize, usize, &str)>,
) -> Result<(Table3Atlas, Precision)> {
    use exr::prelude::{FlatSamples, MetaData, ReadChannels, ReadLayers, SampleType, read};

    let invalid =
        |e: exr::error::Error| table_error(path, format!("not a valid OpenEXR file: {e}"));
    let meta = MetaData::read_from_buffered(bytes, false).map_err(invalid)?;
    let [header] = meta.headers.as_slice() else {
        return Err(table_error(
            path,
            format!(
                "OpenEXR file has {} parts; expected a single-part RGB image",
                meta.headers.len()
            ),
        ));
    };
    if header.deep {
        return Err(table_error(
            path,
            "OpenEXR file holds deep data; expected a flat RGB image",
        ));
    }
    for name in ["R", "G", "B"] {
        let Some(channel) = header.channels.list.iter().find(|c| c.name.eq(name)) else {
            let found: Vec<String> = header
                .channels
                .list
                .iter()
                .map(|c| c.name.to_string())
                .collect();
            return Err(table_error(
                path,
                format!(
                    "OpenEXR file has no channel {name} (channels: {}); expected R, G and B",
                    found.join(", ")
                ),
            ));
        };
        if channel.sample_type == SampleType::U32 {
            return Err(table_error(
                path,
                format!(
                    "OpenEXR channel {name} holds 32-bit unsigned integers; expected half or float"
                ),
            ));
        }
        if channel.sampling.0 != 1 || channel.sampling.1 != 1 {
            return Err(table_error(
                path,
                format!("OpenEXR channel {name} is subsampled; expected full resolution"),
            ));
        }
    }
    let (width, height) = (header.layer_size.0, header.layer_size.1);
    match expected {
        Some((w, h, what)) if (w, h) != (width, height) => {
            return Err(table_error(
                path,
                format!("atlas is {width}x{height} texels; expected {w}x{h} ({what})"),
            ));
        }
        _ => {}
    }
    let texels = width
        .checked_mul(height)
        .filter(|&n| n <= MAX_TEXELS)
        .ok_or_else(|| {
            table_error(
                path,
                format!("atlas of {width}x{height} texels exceeds the limit of {MAX_TEXELS}"),
            )
        })?;

    // The `exr` crate's B44 decoder overflows on malformed blocks (found by `fuzz/`,
    // target `exr`); nacre writes ZIP, and B44 is lossy: refuse it.
    if matches!(
        header.compression,
        exr::compression::Compression::B44 | exr::compression::Compression::B44A
    ) {
        return Err(table_error(
            path,
            format!(
                "OpenEXR file uses {}; expected a lossless compression (none, RLE, ZIP, PIZ)",
                header.compression
            ),
        ));
    }
    check_exr_chunks(path, bytes, header.chunk_count, &header.blocks)?;
    // Pedantic: reject duplicate or out-of-range chunk offsets rather than silently leaving
    // blocks of the image unfilled.
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .pedantic()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(invalid)?;
    let layer = &image.layer_data;
    if (layer.size.0, layer.size.1) != (width, height) {
        return Err(table_error(
            path,
            "OpenEXR layer size disagrees with its header",
        ));
    }
    let mut data = vec![0.0f32; texels * 3];
    let mut all_half = true;
    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
        let samples = layer
            .channel_data
            .list
            .iter()
            .find(|ch| ch.name.eq(name))
            .map(|ch| &ch.sample_data)
            .ok_or_else(|| table_error(path, format!("OpenEXR file has no channel {name}")))?;
        if samples.len() != texels {
            return Err(table_error(
                path,
                format!(
                    "OpenEXR channel {name} holds {} samples; expected {texels}",
                    samples.len()
                ),
            ));
        }
        let out = data.iter_mut().skip(c).step_by(3);
        match samples {
            FlatSamples::F16(v) => out.zip(v).for_each(|(o, s)| *o = s.to_f32()),
            FlatSamples::F32(v) => {
                all_half = false;
                out.zip(v).for_each(|(o, s)| *o = *s);
            }
            FlatSamples::U32(_) => {
                return Err(table_error(
                    path,
                    format!("OpenEXR channel {name} holds unsigned integers; expected floats"),
                ));
            }
        }
    }
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        let texel = i / 3;
        return Err(table_error(
            path,
            format!(
                "non-finite value {} at atlas column {}, row {}, channel {}",
                data[i],
                texel % width,
                texel / width,
                ["R", "G", "B"][i % 3]
            ),
        ));
    }
    let precision = if all_half {
        Precision::Half
    } else {
        Precision::Float
    };
    Ok((
        Table3Atlas {
            width,
            height,
            data,
        },
        precision,
    ))
}

/// Reads an OpenEXR RGB atlas of any size (at most [`MAX_TEXELS`] texels) and reports its
/// precision: [`Precision::Half`] when `R`, `G` and `B` are all half floats, otherwise
/// [`Precision::Float`]. Other channels (e.g. alpha) are ignored.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::Table`] when it is not a valid
/// single-part flat OpenEXR image, lacks a float `R`, `G` or `B` channel, is truncated or
/// corrupt, is too large, or holds a non-finite value.
pub fn read_exr(path: &Path) -> Result<(Table3Atlas, Precision)> {
    let bytes = read_bytes(path)?;
    decode_exr_bytes(path, &bytes)
}

/// [`read_exr`] on bytes already in memory; `path` names them in errors.
///
/// # Errors
/// As [`read_exr`], less the I/O errors.
pub fn decode_exr_bytes(path: &Path, bytes: &[u8]) -> Result<(Table3Atlas, Precision)> {
    guarded(path, "OpenEXR", || decode_exr(path, bytes, None))
}

/// Checks requested table dimensions; returns `(height, texels)`.
fn table_dims(path: &Path, nx: usize, ny: usize, nz: usize) -> Result<(usize, usize)> {
    let dims = ny
        .checked_mul(nz)
        .and_then(|h| Some((h, h.checked_mul(nx)?)));
    match dims {
        Some((h, n)) if n > 0 && n <= MAX_TEXELS => Ok((h, n)),
        _ => Err(table_error(
            path,
            format!(
                "cannot read a {nx}x{ny}x{nz} table: expected between 1 and {MAX_TEXELS} texels"
            ),
        )),
    }
}

/// Reads an OpenEXR atlas as an `nx` x `ny` x `nz` table (see the [module docs](self)).
///
/// # Errors
/// As [`read_exr`], and [`Error::Table`] when the image is not `nx` wide and `ny * nz`
/// high (checked before the pixel data is decoded).
pub fn read_exr_table(path: &Path, nx: usize, ny: usize, nz: usize) -> Result<(Table3, Precision)> {
    let (height, _) = table_dims(path, nx, ny, nz)?;
    let what = format!("nx={nx}, ny*nz={ny}*{nz}");
    let bytes = read_bytes(path)?;
    let (atlas, precision) = guarded(path, "OpenEXR", || {
        decode_exr(path, &bytes, Some((nx, height, &what)))
    })?;
    Ok((
        Table3 {
            nx,
            ny,
            nz,
            data: atlas.data,
        },
        precision,
    ))
}

/// Writes `table` as a 16-bit RGB PNG atlas (see the [module docs](self)), each value `v`
/// stored as `round(v * 65535)`, when every value lies within `[0, 1]`.
///
/// Returns `Ok(true)` once written (atomically; `-` writes to standard output), or
/// `Ok(false)`, writing nothing, when some value is below 0 or above 1. The output is
/// deterministic.
///
/// # Errors
/// [`Error::Table`] (nothing written) for an empty or inconsistent table or a non-finite
/// value; [`Error::Io`] when the file cannot be written.
pub fn write_png16(path: &Path, table: &Table3) -> Result<bool> {
    let height = check_shape(path, table)?;
    check_finite(path, table)?;
    if table.data.iter().any(|v| !(0.0..=1.0).contains(v)) {
        return Ok(false);
    }
    let pixels: Vec<u8> = table
        .data
        .iter()
        .flat_map(|&v| ((f64::from(v) * 65535.0).round() as u16).to_be_bytes())
        .collect();
    let encode_error = |e: png::EncodingError| table_error(path, format!("cannot encode PNG: {e}"));
    let (width, height) = (table.nx as u32, height as u32); // both ≤ i32::MAX, checked above
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Sixteen);
        encoder.set_compression(png::Compression::Balanced);
        let mut writer = encoder.write_header().map_err(encode_error)?;
        writer.write_image_data(&pixels).map_err(encode_error)?;
        writer.finish().map_err(encode_error)?;
    }
    write_atomic(path, |w| w.write_all(&bytes))?;
    Ok(true)
}

/// Decodes a 16-bit RGB PNG atlas of exactly `nx` x `height` texels.
fn decode_png16(
    path: &Path,
    bytes: &[u8],
    nx: usize,
    height: usize,
    texels: usize,
    what: &str,
) -> Result<Vec<f32>> {
    let invalid = |e: png::DecodingError| table_error(path, format!("not a valid PNG file: {e}"));
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    let info = decoder.read_header_info().map_err(invalid)?;
    let (width, h) = (info.width as usize, info.height as usize);
    if (width, h) != (nx, height) {
        return Err(table_error(
            path,
            format!("atlas is {width}x{h} texels; expected {nx}x{height} ({what})"),
        ));
    }
    if info.color_type != png::ColorType::Rgb || info.bit_depth != png::BitDepth::Sixteen {
        return Err(table_error(
            path,
            format!(
                "PNG is {:?} with {} bits per sample; expected RGB with 16 bits per sample",
                info.color_type, info.bit_depth as u8
            ),
        ));
    }
    let mut reader = decoder.read_info().map_err(invalid)?;
    if reader.output_buffer_size() != Some(texels * 6) {
        return Err(table_error(path, "unexpected PNG output size"));
    }
    let mut pixels = vec![0u8; texels * 6];
    reader.next_frame(&mut pixels).map_err(invalid)?;
    // Read to the end so that a truncated or corrupt tail is noticed too.
    reader.finish().map_err(invalid)?;
    Ok(pixels
        .chunks_exact(2)
        .map(|b| f32::from(u16::from_be_bytes([b[0], b[1]])) / 65535.0)
        .collect())
}

/// Reads a 16-bit RGB PNG atlas (as written by [`write_png16`]) as an `nx` x `ny` x `nz`
/// table, each stored integer `n` becoming `n / 65535`.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::Table`] when it is not a valid PNG,
/// is not 16-bit RGB, is not `nx` wide and `ny * nz` high, or is truncated or corrupt.
pub fn read_png16_table(path: &Path, nx: usize, ny: usize, nz: usize) -> Result<Table3> {
    table_dims(path, nx, ny, nz)?;
    let bytes = read_bytes(path)?;
    decode_png16_table(path, &bytes, nx, ny, nz)
}

/// [`read_png16_table`] on bytes already in memory; `path` names them in errors.
///
/// # Errors
/// As [`read_png16_table`], less the I/O errors.
pub fn decode_png16_table(
    path: &Path,
    bytes: &[u8],
    nx: usize,
    ny: usize,
    nz: usize,
) -> Result<Table3> {
    let (height, texels) = table_dims(path, nx, ny, nz)?;
    let what = format!("nx={nx}, ny*nz={ny}*{nz}");
    let data = guarded(path, "PNG", || {
        decode_png16(path, bytes, nx, height, texels, &what)
    })?;
    Ok(Table3 { nx, ny, nz, data })
}

/// The SHA-256 digest of the file at `path` as 64 lowercase hexadecimal digits, for
/// manifests.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read.
pub fn sha256_hex(path: &Path) -> Result<String> {
    use sha2::{Digest, Sha256};

    let mut file = std::fs::File::open(path).map_err(io_error(path))?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => hasher.update(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io_error(path)(e)),
        }
    }
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let digest = hasher.finalize();
    let mut hex = String::with_capacity(2 * digest.len());
    for &b in digest.iter() {
        hex.push(char::from(HEX[usize::from(b >> 4)]));
        hex.push(char::from(HEX[usize::from(b & 0xf)]));
    }
    Ok(hex)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A table with distinct, awkward values (negative, tiny, huge, non-representable).
    fn sample_table(nx: usize, ny: usize, nz: usize) -> Table3 {
        let mut t = Table3::new(nx, ny, nz);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let i = (((z * ny) + y) * nx + x) as f32;
                    t.set(
                        x,
                        y,
                        z,
                        [0.1 + i / 7.0, -(i * 1.000_1).sqrt() / 3.0, 1e-7 * (i + 1.0)],
                    );
                }
            }
        }
        t
    }

    /// A table whose values all lie in [0, 1].
    fn unit_table(nx: usize, ny: usize, nz: usize) -> Table3 {
        let mut t = Table3::new(nx, ny, nz);
        let n = t.data.len();
        for (i, v) in t.data.iter_mut().enumerate() {
            *v = ((i * 7919) % n) as f32 / (n - 1) as f32;
        }
        t.data[0] = 0.0;
        t.data[1] = 1.0;
        t.data[2] = 1.0 / 65535.0;
        t
    }

    fn names_file(err: &Error, path: &Path) -> bool {
        let name = path.file_name().unwrap().to_str().unwrap();
        err.to_string().contains(name)
    }

    fn dir_entries(dir: &Path) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn table_indexing_is_x_fastest() {
        let mut t = Table3::new(3, 4, 5);
        t.set(2, 1, 3, [1.0, 2.0, 3.0]);
        let i = ((3 * 4) + 1) * 3 + 2;
        assert_eq!(&t.data[i * 3..i * 3 + 3], &[1.0, 2.0, 3.0]);
        assert_eq!(t.texel(2, 1, 3), [1.0, 2.0, 3.0]);
        assert_eq!(t.texel(0, 0, 0), [0.0; 3]);
    }

    #[test]
    fn precision_serde_names_are_lowercase() {
        #[derive(serde::Deserialize)]
        struct W {
            p: Precision,
        }
        let w: W = serde_json::from_str(r#"{"p": "float"}"#).unwrap();
        assert_eq!(w.p, Precision::Float);
        let w: W = serde_json::from_str(r#"{"p": "half"}"#).unwrap();
        assert_eq!(w.p, Precision::Half);
        assert!(serde_json::from_str::<W>(r#"{"p": "Half"}"#).is_err());
    }

    #[test]
    fn exr_float_round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.exr");
        let mut t = sample_table(5, 3, 4);
        t.data[7] = -0.0;
        t.data[8] = f32::MAX;
        t.data[9] = f32::from_bits(1); // smallest subnormal
        write_exr(&path, &t, Precision::Float).unwrap();
        let (back, precision) = read_exr_table(&path, 5, 3, 4).unwrap();
        assert_eq!(precision, Precision::Float);
        assert_eq!((back.nx, back.ny, back.nz), (5, 3, 4));
        let bits = |d: &[f32]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.data), bits(&t.data));

        let (atlas, precision) = read_exr(&path).unwrap();
        assert_eq!(precision, Precision::Float);
        assert_eq!((atlas.width, atlas.height), (5, 12));
        assert_eq!(bits(&atlas.data), bits(&t.data));
    }

    #[test]
    fn exr_half_round_trip_rounds_to_nearest_even() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.exr");
        let mut t = sample_table(4, 2, 3);
        let one_ulp = 2f32.powi(-10); // f16 spacing just above 1
        t.data[0] = 1.0 + one_ulp / 2.0; // tie: rounds down to 1 (even)
        t.data[1] = 1.0 + 1.5 * one_ulp; // tie: rounds up to 1 + 2 ulp (even)
        t.data[2] = 65504.0; // f16::MAX
        t.data[3] = -65519.0; // rounds to -65504
        t.data[4] = 1e-7; // f16 subnormal
        write_exr(&path, &t, Precision::Half).unwrap();
        let (back, precision) = read_exr_table(&path, 4, 2, 3).unwrap();
        assert_eq!(precision, Precision::Half);
        for (a, b) in t.data.iter().zip(&back.data) {
            assert_eq!(f16::from_f32(*a).to_f32().to_bits(), b.to_bits(), "{a}");
        }
        assert_eq!(back.data[0], 1.0);
        assert_eq!(back.data[1], 1.0 + 2.0 * one_ulp);
        assert_eq!(back.data[3], -65504.0);
    }

    #[test]
    fn exr_half_refuses_values_beyond_range() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.exr");
        let mut t = sample_table(2, 2, 2);
        t.set(1, 0, 1, [0.0, 70000.0, 0.0]);
        let err = write_exr(&path, &t, Precision::Half).unwrap_err();
        let msg = err.to_string();
        assert!(
            names_file(&err, &path) && msg.contains("half-float range"),
            "{msg}"
        );
        assert!(
            msg.contains("x=1, y=0, z=1") && msg.contains("channel G"),
            "{msg}"
        );
        assert!(!path.exists());
        write_exr(&path, &t, Precision::Float).unwrap();
    }

    #[test]
    fn atlas_layout_matches_docs() {
        // Verified with exr's own position-based reader and the raw PNG rows, independent
        // of this module's readers.
        let dir = tempfile::tempdir().unwrap();
        let (nx, ny, nz) = (3, 2, 4);
        let mut t = Table3::new(nx, ny, nz);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    t.set(x, y, z, [x as f32 / 4.0, y as f32 / 4.0, z as f32 / 4.0]);
                }
            }
        }
        let exr_path = dir.path().join("layout.exr");
        write_exr(&exr_path, &t, Precision::Float).unwrap();
        let image = exr::prelude::read_first_rgba_layer_from_file(
            &exr_path,
            |res, _| vec![[f32::NAN; 3]; res.0 * res.1],
            move |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.1 * nx + pos.0] = [r, g, b];
            },
        )
        .unwrap();
        assert_eq!(
            (image.layer_data.size.0, image.layer_data.size.1),
            (nx, ny * nz)
        );
        let px = &image.layer_data.channel_data.pixels;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    assert_eq!(px[(z * ny + y) * nx + x], t.texel(x, y, z));
                }
            }
        }

        let png_path = dir.path().join("layout.png");
        assert!(write_png16(&png_path, &t).unwrap());
        let file = std::io::BufReader::new(std::fs::File::open(&png_path).unwrap());
        let mut reader = png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0u8; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (nx as u32, (ny * nz) as u32));
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let row = &buf[(z * ny + y) * info.line_size..];
                    let at =
                        |c: usize| u16::from_be_bytes([row[x * 6 + 2 * c], row[x * 6 + 2 * c + 1]]);
                    let expect = t.texel(x, y, z).map(|v| (v * 65535.0).round() as u16);
                    assert_eq!([at(0), at(1), at(2)], expect);
                }
            }
        }
    }

    #[test]
    fn exr_dimension_mismatch_names_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("dims.exr");
        write_exr(&path, &sample_table(4, 3, 2), Precision::Float).unwrap();
        for (nx, ny, nz) in [
            (5, 3, 2),
            (4, 3, 3),
            (4, 2, 2),
            (0, 3, 2),
            (usize::MAX, 2, 2),
        ] {
            let err = read_exr_table(&path, nx, ny, nz).unwrap_err();
            assert!(names_file(&err, &path), "{err}");
        }
        let err = read_exr_table(&path, 4, 2, 4).unwrap_err(); // same texel count, 4x8 ≠ 4x6
        assert!(
            err.to_string().contains("4x6") && err.to_string().contains("4x8"),
            "{err}"
        );
        // A reshaped read of the same atlas is fine.
        assert!(read_exr_table(&path, 4, 6, 1).is_ok());
    }

    #[test]
    fn exr_truncated_or_corrupt_files_give_errors_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let full = dir.path().join("full.exr");
        write_exr(&full, &sample_table(6, 5, 4), Precision::Float).unwrap();
        let bytes = std::fs::read(&full).unwrap();
        let cut = dir.path().join("cut.exr");
        for len in [
            0,
            3,
            4,
            20,
            bytes.len() / 3,
            bytes.len() / 2,
            bytes.len() - 1,
        ] {
            std::fs::write(&cut, &bytes[..len]).unwrap();
            let err = read_exr_table(&cut, 6, 5, 4).unwrap_err();
            assert!(names_file(&err, &cut), "{len}: {err}");
            let err = read_exr(&cut).unwrap_err();
            assert!(names_file(&err, &cut), "{len}: {err}");
        }
        // Arbitrary single-byte corruption never panics (errors or, rarely, still decodes).
        let bad = dir.path().join("bad.exr");
        for i in (0..bytes.len()).step_by(3) {
            let mut b = bytes.clone();
            b[i] ^= 0xa5;
            std::fs::write(&bad, &b).unwrap();
            if let Err(err) = read_exr_table(&bad, 6, 5, 4) {
                assert!(names_file(&err, &bad), "{i}: {err}");
            }
        }
        let err = read_exr(&dir.path().join("missing.exr")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }) && err.to_string().contains("missing.exr"));
    }

    #[test]
    fn exr_without_rgb_or_with_non_finite_values_is_refused() {
        use exr::prelude::{
            AnyChannel, AnyChannels, Encoding, FlatSamples, Image, SmallVec, WritableImage,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("y.exr");
        let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
            "Y",
            FlatSamples::F32(vec![0.5; 4]),
        )]));
        Image::from_encoded_channels((2, 2), Encoding::UNCOMPRESSED, channels)
            .write()
            .to_file(&path)
            .unwrap();
        let err = read_exr_table(&path, 2, 2, 1).unwrap_err();
        assert!(
            names_file(&err, &path) && err.to_string().contains("no channel R"),
            "{err}"
        );

        let path = dir.path().join("nan.exr");
        let mut r = vec![0.5f32; 4];
        r[3] = f32::INFINITY;
        let channels = AnyChannels::sort(SmallVec::from_vec(vec![
            AnyChannel::new("R", FlatSamples::F32(r)),
            AnyChannel::new("G", FlatSamples::F32(vec![0.5; 4])),
            AnyChannel::new("B", FlatSamples::F32(vec![0.5; 4])),
        ]));
        Image::from_encoded_channels((2, 2), Encoding::UNCOMPRESSED, channels)
            .write()
            .to_file(&path)
            .unwrap();
        let err = read_exr_table(&path, 2, 1, 2).unwrap_err();
        let msg = err.to_string();
        assert!(
            names_file(&err, &path) && msg.contains("non-finite"),
            "{msg}"
        );
        assert!(msg.contains("column 1, row 1, channel R"), "{msg}");
    }

    #[test]
    fn writes_are_byte_identical_across_runs_and_thread_counts() {
        let dir = tempfile::tempdir().unwrap();
        let t = sample_table(37, 9, 11); // several 16-line ZIP blocks
        let u = unit_table(37, 9, 11);
        let write_all = |tag: &str| {
            let a = dir.path().join(format!("{tag}-f.exr"));
            let b = dir.path().join(format!("{tag}-h.exr"));
            let c = dir.path().join(format!("{tag}.png"));
            write_exr(&a, &t, Precision::Float).unwrap();
            write_exr(&b, &t, Precision::Half).unwrap();
            assert!(write_png16(&c, &u).unwrap());
            [a, b, c].map(|p| std::fs::read(p).unwrap())
        };
        let first = write_all("1");
        assert_eq!(write_all("2"), first);
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(pool.install(|| write_all(&format!("pool{threads}"))), first);
        }
        assert_eq!(
            sha256_hex(&dir.path().join("1-f.exr")).unwrap(),
            sha256_hex(&dir.path().join("2-f.exr")).unwrap()
        );
    }

    #[test]
    fn failed_writes_leave_existing_files_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let exr_path = dir.path().join("keep.exr");
        let png_path = dir.path().join("keep.png");
        write_exr(&exr_path, &sample_table(3, 2, 2), Precision::Float).unwrap();
        assert!(write_png16(&png_path, &unit_table(3, 2, 2)).unwrap());
        let before = [&exr_path, &png_path].map(|p| std::fs::read(p).unwrap());
        let entries = dir_entries(dir.path());

        let mut bad = unit_table(3, 2, 2);
        bad.set(2, 1, 0, [0.5, f32::NAN, 0.5]);
        for precision in [Precision::Float, Precision::Half] {
            let err = write_exr(&exr_path, &bad, precision).unwrap_err();
            assert!(names_file(&err, &exr_path) && err.to_string().contains("non-finite"));
        }
        let err = write_png16(&png_path, &bad).unwrap_err();
        assert!(names_file(&err, &png_path) && err.to_string().contains("x=2, y=1, z=0"));
        bad.data[4] = f32::NEG_INFINITY;
        assert!(write_exr(&exr_path, &bad, Precision::Float).is_err());

        // Inconsistent and empty tables are refused as well.
        let mut short = unit_table(3, 2, 2);
        short.data.pop();
        assert!(write_exr(&exr_path, &short, Precision::Float).is_err());
        assert!(write_png16(&png_path, &short).is_err());
        assert!(write_exr(&exr_path, &Table3::new(0, 2, 2), Precision::Float).is_err());
        assert!(write_png16(&png_path, &Table3::new(3, 0, 2)).is_err());

        // Out-of-range values: PNG is skipped, nothing written.
        let mut over = unit_table(3, 2, 2);
        over.data[5] = 1.000_001;
        assert!(!write_png16(&png_path, &over).unwrap());

        assert_eq!(
            [&exr_path, &png_path].map(|p| std::fs::read(p).unwrap()),
            before
        );
        assert_eq!(
            dir_entries(dir.path()),
            entries,
            "no temporary files left behind"
        );
    }

    #[test]
    fn png_is_skipped_for_values_outside_unit_range() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("skip.png");
        for v in [-1e-9f32, -0.5, 1.0 + f32::EPSILON, 2.0] {
            let mut t = unit_table(2, 2, 2);
            t.set(1, 1, 1, [0.5, v, 0.5]);
            assert!(!write_png16(&path, &t).unwrap(), "{v}");
            assert!(!path.exists());
        }
        let mut t = unit_table(2, 2, 2);
        t.data[0] = -0.0; // within [0, 1]
        assert!(write_png16(&path, &t).unwrap());
    }

    #[test]
    fn png_round_trip_within_one_step() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rt.png");
        let t = unit_table(7, 5, 3);
        assert!(write_png16(&path, &t).unwrap());
        let back = read_png16_table(&path, 7, 5, 3).unwrap();
        assert_eq!((back.nx, back.ny, back.nz), (7, 5, 3));
        assert_eq!(back.data.len(), t.data.len());
        for (a, b) in t.data.iter().zip(&back.data) {
            assert!((a - b).abs() <= 1.0 / 65535.0, "{a} vs {b}");
            // Exactly the documented quantisation.
            assert_eq!(*b, ((f64::from(*a) * 65535.0).round() / 65535.0) as f32);
        }
        assert_eq!(back.data[0], 0.0);
        assert_eq!(back.data[1], 1.0);
        assert_eq!(back.data[2], 1.0 / 65535.0);
    }

    #[test]
    fn png_reader_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.png");
        assert!(write_png16(&path, &unit_table(4, 3, 2)).unwrap());
        for (nx, ny, nz) in [(5, 3, 2), (4, 3, 3), (4, 2, 2), (0, 1, 1)] {
            let err = read_png16_table(&path, nx, ny, nz).unwrap_err();
            assert!(names_file(&err, &path), "{err}");
        }
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.path().join("cut.png");
        for len in [0, 8, 20, 40, bytes.len() / 2, bytes.len() - 1] {
            std::fs::write(&cut, &bytes[..len]).unwrap();
            let err = read_png16_table(&cut, 4, 3, 2).unwrap_err();
            assert!(names_file(&err, &cut), "{len}: {err}");
        }
        let bad = dir.path().join("bad.png");
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x5a;
            std::fs::write(&bad, &b).unwrap();
            if let Err(err) = read_png16_table(&bad, 4, 3, 2) {
                assert!(names_file(&err, &bad), "{i}: {err}");
            }
        }

        // An 8-bit PNG is refused.
        let eight = dir.path().join("eight.png");
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, 4, 6);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[0u8; 4 * 6 * 3]).unwrap();
            w.finish().unwrap();
        }
        std::fs::write(&eight, &out).unwrap();
        let err = read_png16_table(&eight, 4, 3, 2).unwrap_err();
        assert!(
            names_file(&err, &eight) && err.to_string().contains("16 bits"),
            "{err}"
        );
        // An EXR is not a PNG and vice versa.
        let exr_path = dir.path().join("x.exr");
        write_exr(&exr_path, &unit_table(4, 3, 2), Precision::Half).unwrap();
        assert!(names_file(
            &read_png16_table(&exr_path, 4, 3, 2).unwrap_err(),
            &exr_path
        ));
        assert!(names_file(&read_exr(&path).unwrap_err(), &path));
    }

    #[test]
    fn sha256_of_known_content() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("abc.txt");
        std::fs::write(&path, b"abc").unwrap();
        assert_eq!(
            sha256_hex(&path).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        std::fs::write(&path, b"").unwrap();
        assert_eq!(
            sha256_hex(&path).unwrap(),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        let big = vec![0x61u8; 200_000]; // spans several read buffers
        std::fs::write(&path, &big).unwrap();
        assert_eq!(sha256_hex(&path).unwrap().len(), 64);
        let err = sha256_hex(&dir.path().join("nope")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }) && err.to_string().contains("nope"));
    }
}
