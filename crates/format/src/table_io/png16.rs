//! 16-bit PNG atlases: RGB, 16 bits per channel, `v` stored as `round(v * 65535)`.

use super::table::{Table3, check_finite, check_shape, read_bytes, table_dims, table_error};
use crate::atomic::write_atomic;
use crate::decode::guarded_table as guarded;
use crate::error::Result;
use std::io::Cursor;
use std::path::Path;

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
