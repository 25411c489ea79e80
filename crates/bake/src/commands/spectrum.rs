//! `nacre spectrum`: the angle × wavelength table of reflectance and transmittance.
//!
//! Columns: `angle_deg,wavelength_nm,R_s,R_p,R,T_s,T_p,T,A` — incidence angle in the
//! ambient (degrees), vacuum wavelength (nm), s/p/unpolarised reflectance, s/p/unpolarised
//! transmittance into the substrate (Byrnes' `tmm` convention, with the Re(ñ cos θ)
//! factor), and absorptance A = 1 − R − T. One row per (angle, wavelength), angle-major.

use crate::commands::grid::MAX_AXIS_SAMPLES;
use crate::error::{Error, Param, Result};
use nacre_optics::{Power, Stack};
use std::io::Write;

/// Most rows one spectrum table may have (about 1 GB of CSV).
pub const MAX_ROWS: u64 = 10_000_000;

/// The CSV header line.
pub const HEADER: &str = "angle_deg,wavelength_nm,R_s,R_p,R,T_s,T_p,T,A";

/// Formats `v` with 12 significant digits: fixed notation for magnitudes in [1e-5, 1e6),
/// scientific otherwise.
pub fn fmt_sig(v: f64) -> String {
    const DIGITS: i32 = 12;
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let exponent = v.abs().log10().floor() as i32;
    if (-5..6).contains(&exponent) {
        format!("{:.*}", (DIGITS - 1 - exponent).max(0) as usize, v)
    } else {
        format!("{:.*e}", (DIGITS - 1) as usize, v)
    }
}

/// Computes the table (checks the size limit and the angles first).
pub fn compute(stack: &Stack, angles_deg: &[f64], wavelengths_nm: &[f64]) -> Result<Vec<Power>> {
    let rows = angles_deg.len() as u64 * wavelengths_nm.len() as u64;
    if rows > MAX_ROWS {
        return Err(nacre_format::Error::TooLarge {
            what: "rows (angles × wavelengths)".into(),
            count: rows,
            limit: MAX_ROWS,
        }
        .into());
    }
    debug_assert!(angles_deg.len() <= MAX_AXIS_SAMPLES);
    for &a in angles_deg {
        if !(a.abs() < 90.0) {
            return Err(Error::value(
                Param::Angles,
                format!("{a}"),
                "incidence angles must lie strictly between −90° and 90°",
            ));
        }
    }
    for &w in wavelengths_nm {
        if !(w > 0.0) {
            return Err(Error::value(
                Param::Wavelengths,
                format!("{w}"),
                "wavelengths must be positive (vacuum nm)",
            ));
        }
    }
    stack
        .sweep(angles_deg, wavelengths_nm)
        .map_err(|source| match source {
            nacre_optics::Error::WavelengthOutOfRange { .. }
            | nacre_optics::Error::NonPhysicalIndex { .. }
            | nacre_optics::Error::NoPhysicalIndex { .. }
            | nacre_optics::Error::AbsorbingAmbient { .. } => {
                Error::optics_in(Param::Wavelengths, source)
            }
            other => other.into(),
        })
}

/// Writes the CSV table.
pub fn write_csv(
    w: &mut dyn Write,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
    powers: &[Power],
) -> std::io::Result<()> {
    let mut csv = crate::csv_text::writer(w);
    csv.write_record(HEADER.split(','))?;
    let mut cells = powers.iter();
    for &a in angles_deg {
        for &wl in wavelengths_nm {
            let p = cells.next().expect("one power per (angle, wavelength)");
            csv.write_record([
                a.to_string(),
                wl.to_string(),
                fmt_sig(p.R_s),
                fmt_sig(p.R_p),
                fmt_sig(p.R()),
                fmt_sig(p.T_s),
                fmt_sig(p.T_p),
                fmt_sig(p.T()),
                fmt_sig(p.A()),
            ])?;
        }
    }
    csv.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twelve_significant_digits() {
        assert_eq!(fmt_sig(0.04), "0.0400000000000");
        assert_eq!(fmt_sig(1.0), "1.00000000000");
        assert_eq!(fmt_sig(0.123456789012345), "0.123456789012");
        assert_eq!(fmt_sig(1.5e-9), "1.50000000000e-9");
        assert_eq!(fmt_sig(0.0), "0");
        assert_eq!(fmt_sig(-2.5e-17), "-2.50000000000e-17");
    }
}
