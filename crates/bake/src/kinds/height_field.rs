//! Height-field files for the `diffraction` kind and `nacre diffraction --surface`: 8- or
//! 16-bit greyscale PNG or greyscale JPEG (value / full scale), OpenEXR (one channel `Y`, `Z`,
//! `R` or the only channel) or CSV (rows of comma-separated numbers, row 0 = y = 0), each
//! × the height scale ([`crate::kinds::diffraction`] module docs). The picture and OpenEXR
//! decoders run under [`nacre_format::decode::guarded`]: a panic in a decoder library is an
//! error naming the file.

use crate::error::{Error, Result};
use nacre_format::decode::guarded;
use nacre_optics::diffraction::HeightField;
use std::path::Path;

/// Most samples per axis of a synthetic field or height-field file.
pub const MAX_AXIS: usize = 4096;

/// Reads a height-field file (PNG, JPEG, OpenEXR or CSV by extension; module docs) with
/// `pitch_um` µm per sample and heights scaled by `height_scale_um`.
///
/// # Errors
/// [`nacre_format::Error::Io`]; [`nacre_format::Error::Table`] (PNG, JPEG, EXR) or [`nacre_format::Error::Parse`] (CSV, with the line)
/// naming the file for malformed content; [`nacre_format::Error::OpticsIn`] for a bad pitch.
pub fn read_height_field(path: &Path, pitch_um: f64, height_scale_um: f64) -> Result<HeightField> {
    if !(height_scale_um.is_finite() && height_scale_um >= 0.0) {
        return Err(Error::invalid(
            path.display().to_string(),
            format!("height scale {height_scale_um} µm must be finite and non-negative"),
        ));
    }
    let bytes = std::fs::read(path).map_err(|source| nacre_format::Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let (nx, ny, values) = match ext.as_str() {
        "png" => decode_picture(path, &bytes, image::ImageFormat::Png)?,
        "jpg" | "jpeg" => decode_picture(path, &bytes, image::ImageFormat::Jpeg)?,
        "exr" => decode_exr(path, &bytes)?,
        "csv" | "txt" => decode_csv(path, &bytes)?,
        _ => {
            return Err(nacre_format::Error::Table {
                path: path.to_path_buf(),
                message: "unknown height-field format: expected a .png, .jpg, .exr or .csv file"
                    .into(),
            }
            .into());
        }
    };
    if nx > MAX_AXIS || ny > MAX_AXIS {
        return Err(nacre_format::Error::TooLarge {
            what: format!("{}: samples per axis", path.display()).into(),
            count: nx.max(ny) as u64,
            limit: MAX_AXIS as u64,
        }
        .into());
    }
    HeightField::new(
        nx,
        ny,
        pitch_um,
        values.into_iter().map(|v| v * height_scale_um).collect(),
    )
    .map_err(|source| Error::optics_in(path.display().to_string(), source))
}

fn table_err(path: &Path, message: String) -> Error {
    nacre_format::Error::Table {
        path: path.to_path_buf(),
        message,
    }
    .into()
}

/// Greyscale picture (PNG 8 or 16 bits, JPEG 8 bits), read with the `image` crate:
/// value / full scale.
fn decode_picture(
    path: &Path,
    bytes: &[u8],
    format: image::ImageFormat,
) -> Result<(usize, usize, Vec<f64>)> {
    let name = if format == image::ImageFormat::Png {
        "PNG"
    } else {
        "JPEG"
    };
    let decode = || -> Result<(usize, usize, Vec<f64>)> {
        let bad = |e: image::ImageError| table_err(path, format!("not a valid {name} file: {e}"));
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(1 << 29);
        reader.limits(limits);
        let picture = reader.decode().map_err(bad)?;
        let (w, h) = (picture.width() as usize, picture.height() as usize);
        // Greyscale (with or without alpha): the grey channel.
        let values: Vec<f64> = match &picture {
            image::DynamicImage::ImageLuma8(p) => {
                p.pixels().map(|p| f64::from(p.0[0]) / 255.0).collect()
            }
            image::DynamicImage::ImageLumaA8(p) => {
                p.pixels().map(|p| f64::from(p.0[0]) / 255.0).collect()
            }
            image::DynamicImage::ImageLuma16(p) => {
                p.pixels().map(|p| f64::from(p.0[0]) / 65535.0).collect()
            }
            image::DynamicImage::ImageLumaA16(p) => {
                p.pixels().map(|p| f64::from(p.0[0]) / 65535.0).collect()
            }
            other => {
                let colour = match other.color() {
                    image::ColorType::Rgb8 | image::ColorType::Rgb16 | image::ColorType::Rgb32F => {
                        "Rgb"
                    }
                    image::ColorType::Rgba8
                    | image::ColorType::Rgba16
                    | image::ColorType::Rgba32F => "Rgba",
                    _ => "non-greyscale",
                };
                return Err(table_err(
                    path,
                    format!("a {colour} {name}; a height field must be greyscale (8 or 16 bits)"),
                ));
            }
        };
        Ok((w, h, values))
    };
    guarded(decode, || {
        table_err(path, format!("malformed {name} data (the decoder failed)"))
    })
}

/// OpenEXR: the channel `Y`, `Z`, `R` or the only one.
fn decode_exr(path: &Path, bytes: &[u8]) -> Result<(usize, usize, Vec<f64>)> {
    use exr::prelude::{FlatSamples, ReadChannels, ReadLayers, read};
    let decode = || -> Result<(usize, usize, Vec<f64>)> {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .non_parallel()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(|e| table_err(path, format!("not a valid OpenEXR file: {e}")))?;
        let layer = &image.layer_data;
        let list = &layer.channel_data.list;
        let names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
        let channel = ["Y", "Z", "R"]
            .iter()
            .find_map(|n| list.iter().find(|c| c.name.eq(n)))
            .or(if list.len() == 1 { list.first() } else { None })
            .ok_or_else(|| {
                table_err(
                    path,
                    format!(
                        "OpenEXR channels {}: expected a channel Y, Z or R, or a single channel",
                        names.join(", ")
                    ),
                )
            })?;
        let (w, h) = (layer.size.0, layer.size.1);
        let values: Vec<f64> = match &channel.sample_data {
            FlatSamples::F16(v) => v.iter().map(|s| f64::from(s.to_f32())).collect(),
            FlatSamples::F32(v) => v.iter().map(|s| f64::from(*s)).collect(),
            FlatSamples::U32(v) => v.iter().map(|s| f64::from(*s)).collect(),
        };
        if values.len() != w * h {
            return Err(table_err(
                path,
                "OpenEXR channel size disagrees with the image".into(),
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(table_err(
                path,
                format!("non-finite height at column {}, row {}", i % w, i / w),
            ));
        }
        Ok((w, h, values))
    };
    guarded(decode, || {
        table_err(path, "malformed OpenEXR data (the decoder failed)".into())
    })
}

/// CSV: rows of comma-separated numbers (row 0 = y = 0); `#` comments (whole lines, or
/// the end of a row), blank lines, quoted fields, a UTF-8 BOM, CRLF and spaces around
/// fields are accepted (see [`nacre_optics::csv_rows`]).
fn decode_csv(path: &Path, bytes: &[u8]) -> Result<(usize, usize, Vec<f64>)> {
    let bad = |line: usize, message: String| Error::recipe(path.to_path_buf(), line, message);
    let text = std::str::from_utf8(bytes).map_err(|e| bad(1, format!("not UTF-8 text: {e}")))?;
    let mut values = Vec::new();
    let (mut nx, mut ny) = (0, 0);
    for row in crate::csv_text::rows(path, text) {
        let row = row?;
        let line_no = row.line;
        let mut fields = row.fields;
        // A `#` ends the row: the rest of the line is a comment.
        if let Some(k) = fields.iter().position(|f| f.contains('#')) {
            fields.truncate(k + 1);
            let kept = fields[k].split('#').next().unwrap_or("").trim().to_string();
            fields[k] = kept;
        }
        let row: Vec<f64> = fields
            .iter()
            .map(|c| {
                c.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(line_no, format!("`{c}` is not a finite number")))
            })
            .collect::<Result<_>>()?;
        if ny == 0 {
            nx = row.len();
        } else if row.len() != nx {
            return Err(bad(
                line_no,
                format!("{} values; the first row has {nx}", row.len()),
            ));
        }
        if nx > MAX_AXIS || ny >= MAX_AXIS {
            return Err(bad(
                line_no,
                format!("more than {MAX_AXIS} samples per axis"),
            ));
        }
        values.extend(row);
        ny += 1;
    }
    if ny == 0 {
        return Err(bad(1, "no height values".into()));
    }
    Ok((nx, ny, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_height_fields_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.csv");
        std::fs::write(&p, "# heights\n0,1,2\n3,4,5\n").unwrap();
        let f = read_height_field(&p, 0.1, 2.0).unwrap();
        assert_eq!((f.nx(), f.ny()), (3, 2));
        assert_eq!(f.mean_removed_um(), 5.0);
        std::fs::write(&p, "0,1,2\n3,4\n").unwrap();
        let e = read_height_field(&p, 0.1, 1.0).unwrap_err().to_string();
        assert!(e.contains("h.csv:2:"), "{e}");
        std::fs::write(&p, "0,x\n").unwrap();
        let e = read_height_field(&p, 0.1, 1.0).unwrap_err().to_string();
        assert!(e.contains("h.csv:1:") && e.contains("`x`"), "{e}");
    }

    #[test]
    fn csv_height_fields_accept_csv_conventions() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.csv");
        // BOM, CRLF, comment and blank lines, quoted fields, spaces, a comment after a row.
        std::fs::write(
            &p,
            "\u{feff}# heights\r\n\r\n 0 , \"1\" ,2\r\n# between\r\n\"3\",4, 5 # last row\r\n",
        )
        .unwrap();
        let f = read_height_field(&p, 0.1, 2.0).unwrap();
        assert_eq!((f.nx(), f.ny()), (3, 2));
        assert_eq!(f.mean_removed_um(), 5.0);
        std::fs::write(&p, "# a\r\n\r\n0,1,2\r\n# b\r\n3,4\r\n").unwrap();
        let e = read_height_field(&p, 0.1, 1.0).unwrap_err().to_string();
        assert!(e.contains("h.csv:5:"), "{e}");
    }

    #[test]
    fn png_height_fields_scale_to_full_range() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.png");
        let sixteen = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(2, 1, vec![0, 65535]);
        sixteen.unwrap().save(&p).unwrap();
        let f = read_height_field(&p, 0.1, 0.2).unwrap();
        assert_eq!(f.heights_um(), &[-0.1, 0.1]);
        // 16 bits keep full precision: one step of 65535 is resolved.
        let steps = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(2, 1, vec![1000, 1001]);
        steps.unwrap().save(&p).unwrap();
        let f = read_height_field(&p, 0.1, 65535.0).unwrap();
        let h = f.heights_um();
        assert!((h[1] - h[0] - 1.0).abs() < 1e-9, "{h:?}");
        // A colour picture is not a height field.
        image::RgbImage::new(2, 2).save(&p).unwrap();
        let e = read_height_field(&p, 0.1, 0.2).unwrap_err().to_string();
        assert!(
            e.contains("a Rgb PNG; a height field must be greyscale"),
            "{e}"
        );
        std::fs::write(&p, b"not a png").unwrap();
        assert!(
            read_height_field(&p, 0.1, 0.2)
                .unwrap_err()
                .to_string()
                .contains("h.png")
        );
    }

    #[test]
    fn jpeg_height_fields_are_accepted() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.jpg");
        // A left half at 64 and a right half at 192, 16 × 16 (whole 8 × 8 JPEG blocks).
        let grey =
            image::GrayImage::from_fn(16, 16, |x, _| image::Luma([if x < 8 { 64 } else { 192 }]));
        grey.save(&p).unwrap();
        let f = read_height_field(&p, 0.1, 1.0).unwrap();
        assert_eq!((f.nx(), f.ny()), (16, 16));
        let h = f.heights_um();
        let (left, right) = (h[0] + f.mean_removed_um(), h[15] + f.mean_removed_um());
        assert!((left - 64.0 / 255.0).abs() < 0.02, "{left}");
        assert!((right - 192.0 / 255.0).abs() < 0.02, "{right}");
        let jpeg = dir.path().join("h.jpeg");
        std::fs::copy(&p, &jpeg).unwrap();
        assert_eq!(read_height_field(&jpeg, 0.1, 1.0).unwrap().nx(), 16);
        std::fs::write(&p, b"not a jpeg").unwrap();
        let e = read_height_field(&p, 0.1, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("h.jpg") && e.contains("not a valid JPEG file"),
            "{e}"
        );
    }
}
