//! OpenEXR atlases: one single-part scan-line image with channels `R`, `G`, `B`, ZIP
//! compression, half or full floats; the chunk table checked before the decoder sees it.

use super::table::{
    MAX_TEXELS, Precision, Table3, Table3Atlas, check_finite, check_shape, describe, read_bytes,
    table_dims, table_error,
};
use crate::atomic::write_atomic;
use crate::decode::guarded_table as guarded;
use crate::error::Result;
use half::f16;
use std::io::Cursor;
use std::path::Path;

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
