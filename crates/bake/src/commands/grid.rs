//! Parsing of sampling ranges (`START:END:STEP`) and film thicknesses (`635`, `635nm`).

use crate::error::{Error, Origin, Result};

/// Most samples one axis may have.
pub const MAX_AXIS_SAMPLES: usize = 1_000_000;

/// Grid values are rounded to 1/GRID_SCALE units (1e-9 nm or degree) so that
/// `380:780:0.1` yields `380.1`, not `380.09999999999997`.
const GRID_SCALE: f64 = 1e9;

/// Parses `START:END:STEP` (inclusive of END when it falls on the grid, within 1e-9 of a
/// step) or a single value `X`. Errors name `origin` (a parameter or a recipe line).
pub fn parse_range(origin: impl Into<Origin>, text: &str) -> Result<Vec<f64>> {
    let origin = origin.into();
    let err = |message: String| Error::value(origin.clone(), text, message);
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    let num = |s: &str, what: &str| -> Result<f64> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                err(format!(
                    "{what} `{s}` is not a finite number; expected START:END:STEP, e.g. 380:780:5"
                ))
            })
    };
    match parts.as_slice() {
        [single] => Ok(vec![num(single, "value")?]),
        [start, end, step] => {
            let (start, end, step) = (num(start, "START")?, num(end, "END")?, num(step, "STEP")?);
            if !(step > 0.0) {
                return Err(err("STEP must be positive".into()));
            }
            if end < start {
                return Err(err("END must not be below START".into()));
            }
            let intervals = ((end - start) / step * (1.0 + 1e-12) + 1e-9).floor();
            if intervals + 1.0 > MAX_AXIS_SAMPLES as f64 {
                return Err(err(format!(
                    "{} samples exceed the limit of {MAX_AXIS_SAMPLES} per axis",
                    intervals + 1.0
                )));
            }
            let count = intervals as usize + 1;
            Ok((0..count)
                .map(|i| ((start + i as f64 * step) * GRID_SCALE).round() / GRID_SCALE)
                .collect())
        }
        _ => Err(err(
            "expected START:END:STEP (e.g. 0:89:1) or a single value".into(),
        )),
    }
}

/// Parses a thickness in nanometres: `635`, `635nm`, `635 nm`, or micrometres `1.2um`/`1.2µm`.
/// Errors (naming `context`) for malformed, negative or non-finite values.
pub fn parse_thickness_nm(context: impl Into<Origin>, text: &str) -> Result<f64> {
    let context = context.into();
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    let (number, scale) = if let Some(v) = lower.strip_suffix("nm") {
        (v, 1.0)
    } else if let Some(v) = lower.strip_suffix("um") {
        (v, 1e3)
    } else if let Some(v) = t.strip_suffix("µm") {
        (v, 1e3)
    } else if let Some(v) = lower.strip_suffix("mm") {
        (v, 1e6)
    } else {
        (lower.as_str(), 1.0)
    };
    let err = |message: &str| Error::value(context.clone(), text, message);
    let v = number.trim().parse::<f64>().map_err(|_| {
        err("thickness must be a number of nanometres, e.g. `635` or `635nm` (or `1.2um`, `2mm`)")
    })?;
    let v = v * scale;
    if !v.is_finite() || v < 0.0 {
        return Err(err("thickness must be finite and non-negative"));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Param;

    #[test]
    fn ranges() {
        assert_eq!(parse_range(Param::Angles, "0:89:1").unwrap().len(), 90);
        assert_eq!(
            parse_range(Param::Wavelengths, "380:780:5").unwrap().len(),
            81
        );
        let v = parse_range(Param::Wavelengths, "380:381:0.1").unwrap();
        assert_eq!(v.len(), 11);
        assert_eq!(v[1], 380.1);
        assert_eq!(v[10], 381.0);
        assert_eq!(parse_range(Param::Angles, "45").unwrap(), vec![45.0]);
        assert_eq!(
            parse_range(Param::Angles, "0:10:3").unwrap(),
            vec![0.0, 3.0, 6.0, 9.0]
        );
        assert_eq!(
            parse_range(Param::Angles, "0:60:30").unwrap(),
            vec![0.0, 30.0, 60.0]
        );
        assert_eq!(parse_range(Param::Angles, "0:1:0.1").unwrap()[3], 0.3);
        for bad in [
            "",
            "a:b:c",
            "0:10",
            "0:10:0",
            "0:10:-1",
            "10:0:1",
            "0:1e9:1e-3",
            "0:inf:1",
            "1:2:3:4",
        ] {
            let e = parse_range(Param::Angles, bad).unwrap_err().to_string();
            assert!(e.starts_with("angles `"), "{bad}: {e}");
        }
    }

    #[test]
    fn thicknesses() {
        assert_eq!(parse_thickness_nm(Param::Layer, "635").unwrap(), 635.0);
        assert_eq!(parse_thickness_nm(Param::Layer, "635nm").unwrap(), 635.0);
        assert_eq!(parse_thickness_nm(Param::Layer, "635 nm").unwrap(), 635.0);
        assert_eq!(parse_thickness_nm(Param::Layer, "1.2um").unwrap(), 1200.0);
        assert_eq!(parse_thickness_nm(Param::Layer, "2mm").unwrap(), 2e6);
        assert_eq!(parse_thickness_nm(Param::Layer, "0").unwrap(), 0.0);
        for bad in ["-5", "abc", "nan", "inf", "5cm", ""] {
            assert!(parse_thickness_nm(Param::Layer, bad).is_err(), "{bad}");
        }
    }
}
