//! `nacre spectrum`: the angle × wavelength table of reflectance and transmittance.
//!
//! Columns: `angle_deg,wavelength_nm,R_s,R_p,R,T_s,T_p,T,A` — incidence angle in the
//! ambient (degrees), vacuum wavelength (nm), s/p/unpolarised reflectance, s/p/unpolarised
//! transmittance into the substrate (Byrnes' `tmm` convention, with the Re(ñ cos θ)
//! factor), and absorptance A = 1 − R − T. One row per (angle, wavelength), angle-major.
//!
//! With derivatives ([`compute_jacobian`], [`write_csv_jacobian`]) the row goes on with
//! `dR_dd1 … dR_ddL, dT_dd1 … dT_ddL`: the derivatives of the unpolarised R and T columns
//! by each film's thickness d_j, per nm, films top first (exact: the reverse sweep of
//! [`nacre_optics::jacobian`]).

use crate::commands::grid::MAX_AXIS_SAMPLES;
use crate::error::{Error, Param, Result};
use nacre_optics::elementary;
use nacre_optics::jacobian::{SweepJacobian, Wrt, sweep_jacobian};
use nacre_optics::{Power, SpectrumSweep, Stack};
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
    let exponent = elementary::log10(v.abs()).floor() as i32;
    if (-5..6).contains(&exponent) {
        format!("{:.*}", (DIGITS - 1 - exponent).max(0) as usize, v)
    } else {
        format!("{:.*e}", (DIGITS - 1) as usize, v)
    }
}

/// Computes the table (checks the size limit and the angles first): [`Stack::sweep`]
/// through a [`SpectrumSweep`], which resolves the indices once and gives the phase check
/// of [`check_phases`] without a per-wavelength lookup.
pub fn compute(stack: &Stack, angles_deg: &[f64], wavelengths_nm: &[f64]) -> Result<Vec<Power>> {
    check_axes(angles_deg, wavelengths_nm, 1)?;
    let sweep = match SpectrumSweep::new(stack, angles_deg, wavelengths_nm) {
        Ok(sweep) => sweep,
        Err(e) => {
            // The error the phase check would meet first, else the sweep's.
            check_phases(stack, None, wavelengths_nm)?;
            return Err(optics_error(e));
        }
    };
    if let Some((film, wavelength_nm, d)) = sweep.overflowing_phase(None) {
        return Err(phase_overflow(stack, film, wavelength_nm, d));
    }
    sweep.powers().map_err(optics_error)
}

/// [`compute`] and the derivatives of the powers by every film's thickness
/// ([`sweep_jacobian`]); the size limit counts the 2L derivative columns. A stack with an
/// incoherent layer is refused (its derivatives are not implemented), as an error of
/// [`Param::Jacobian`].
pub fn compute_jacobian(
    stack: &Stack,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
) -> Result<(Vec<Power>, SweepJacobian)> {
    let films = stack.layers().len() as u64;
    // The 2L derivative columns beside the 9 of a row.
    check_axes(angles_deg, wavelengths_nm, 1 + (2 * films).div_ceil(9))?;
    if let Err(e) = stack.require_coherent("derivatives") {
        return Err(Error::optics_in(Param::Jacobian, e));
    }
    let powers = compute(stack, angles_deg, wavelengths_nm)?;
    let jacobian =
        sweep_jacobian(stack, angles_deg, wavelengths_nm, Wrt::Thickness).map_err(optics_error)?;
    Ok((powers, jacobian))
}

/// The CSV header with the derivative columns of `films` films.
pub fn header_jacobian(films: usize) -> String {
    let mut h = HEADER.to_string();
    for q in ["R", "T"] {
        for j in 1..=films {
            h.push_str(&format!(",d{q}_dd{j}"));
        }
    }
    h
}

/// Writes the CSV table with the derivative columns ([`compute_jacobian`]).
pub fn write_csv_jacobian(
    w: &mut dyn Write,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
    powers: &[Power],
    jacobian: &SweepJacobian,
) -> std::io::Result<()> {
    let films = jacobian.films;
    let mut csv = crate::csv_text::writer(w);
    csv.write_record(header_jacobian(films).split(','))?;
    let mut e = 0;
    for &a in angles_deg {
        for &wl in wavelengths_nm {
            let p = &powers[e];
            let d = &jacobian.d_thickness[e * films..(e + 1) * films];
            let mut row = value_cells(a, wl, p).to_vec();
            row.extend(d.iter().map(|x| fmt_sig(x.R())));
            row.extend(d.iter().map(|x| fmt_sig(x.T())));
            csv.write_record(row)?;
            e += 1;
        }
    }
    csv.flush()
}

/// The table over a third axis, film `layer`'s thickness (1-based, top film = 1; the other
/// films keep theirs): [`Stack::sweep_thickness`], element
/// `(a * wavelengths.len() + w) * thicknesses.len() + d`, after the checks of [`compute`]
/// (the size limit counts every thickness).
pub fn compute_thickness(
    stack: &Stack,
    layer: usize,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
    thicknesses_nm: &[f64],
) -> Result<Vec<Power>> {
    check_axes(angles_deg, wavelengths_nm, thicknesses_nm.len() as u64)?;
    for &d in thicknesses_nm {
        if !(d >= 0.0 && d.is_finite()) {
            return Err(Error::value(
                Param::Thicknesses,
                format!("{d}"),
                "thickness must be finite and non-negative",
            ));
        }
    }
    if layer == 0 || layer > stack.layers().len() {
        return Err(Error::optics_in(
            Param::Layer,
            nacre_optics::Error::NoSuchLayer {
                layer,
                count: stack.layers().len(),
            },
        ));
    }
    let thickest = thicknesses_nm.iter().copied().fold(0.0, f64::max);
    check_phases(stack, Some((layer, thickest)), wavelengths_nm)?;
    stack
        .sweep_thickness(layer, angles_deg, wavelengths_nm, thicknesses_nm)
        .map_err(optics_error)
}

/// The size limit (`per_row` values per (angle, wavelength)), the angles and the
/// wavelengths of a table.
fn check_axes(angles_deg: &[f64], wavelengths_nm: &[f64], per_row: u64) -> Result<()> {
    let rows = (angles_deg.len() as u64)
        .saturating_mul(wavelengths_nm.len() as u64)
        .saturating_mul(per_row);
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
    Ok(())
}

/// Refuses films whose phase overflows ([`SpectrumSweep::overflowing_phase`] computes the
/// same, in the same order, from its index table): a film of thickness d and index ñ under an ambient
/// n₀ has the phase 2π ñ cos θ d / λ with |ñ cos θ| ≤ |ñ| + n₀, and a phase beyond f64
/// (a 10³⁰⁰ nm film at 10⁻³⁰⁰ nm) would make the sweep return NaN. `swept` is the film
/// (1-based) whose thickness a sweep varies, with its largest thickness.
fn check_phases(stack: &Stack, swept: Option<(usize, f64)>, wavelengths_nm: &[f64]) -> Result<()> {
    for &wavelength_nm in wavelengths_nm {
        let indices = stack.indices_at(wavelength_nm).map_err(optics_error)?;
        let ambient = elementary::norm(indices[0]);
        for (j, layer) in stack.layers().iter().enumerate() {
            let d = match swept {
                Some((k, d)) if k == j + 1 => d,
                _ => layer.thickness_nm,
            };
            let phase =
                2.0 * std::f64::consts::PI * (elementary::norm(indices[j + 1]) + ambient) * d
                    / wavelength_nm;
            if !phase.is_finite() {
                return Err(phase_overflow(stack, j + 1, wavelength_nm, d));
            }
        }
    }
    Ok(())
}

/// The error of [`check_phases`]: film `film`'s (1-based) phase at `wavelength_nm` for
/// thickness `d` overflows.
fn phase_overflow(stack: &Stack, film: usize, wavelength_nm: f64, d: f64) -> Error {
    Error::invalid(
        Param::Wavelengths,
        format!(
            "film {} (`{}`, {} nm) at {} nm: its phase 2π ñ d / λ overflows; the film is too thick for the wavelength",
            film,
            stack.layers()[film - 1].material.name(),
            short(d),
            short(wavelength_nm)
        ),
    )
}

/// `v` for a message: plain (`400`, `0.5`) in [10⁻⁴, 10¹⁵), else scientific (`1e300`).
fn short(v: f64) -> String {
    if v == 0.0 || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Errors of a sweep: a wavelength outside a material's data or an absorbing ambient are
/// said to come from the wavelengths.
fn optics_error(source: nacre_optics::Error) -> Error {
    match source {
        nacre_optics::Error::WavelengthOutOfRange { .. }
        | nacre_optics::Error::NonPhysicalIndex { .. }
        | nacre_optics::Error::NoPhysicalIndex { .. }
        | nacre_optics::Error::AbsorbingAmbient { .. } => {
            Error::optics_in(Param::Wavelengths, source)
        }
        other => other.into(),
    }
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
            csv.write_record(value_cells(a, wl, p))?;
        }
    }
    csv.flush()
}

/// The value columns of one row ([`HEADER`]): angle, wavelength, R_s, R_p, R, T_s, T_p, T, A.
fn value_cells(angle_deg: f64, wavelength_nm: f64, p: &Power) -> [String; 9] {
    [
        angle_deg.to_string(),
        wavelength_nm.to_string(),
        fmt_sig(p.R_s),
        fmt_sig(p.R_p),
        fmt_sig(p.R()),
        fmt_sig(p.T_s),
        fmt_sig(p.T_p),
        fmt_sig(p.T()),
        fmt_sig(p.A()),
    ]
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

    /// The errors of `compute` come in the order of the per-wavelength checks: a film's
    /// phase overflowing at one wavelength before a material's range ends at a later one,
    /// and the other way round.
    #[test]
    fn phase_and_index_errors_in_wavelength_order() {
        use nacre_optics::{C64, Layer, Material};
        let constant = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
        let tabulated = Material::from_nk_csv(
            "tab",
            "tab.csv",
            "wavelength_nm,n,k\n1e-310,1.5,0\n600,1.5,0\n",
        )
        .unwrap();
        let stack = |film: Material, d: f64| {
            Stack::new(
                constant(1.0),
                vec![Layer {
                    material: film,
                    thickness_nm: d,
                }],
                constant(1.5),
            )
            .unwrap()
        };
        let message = |stack: &Stack, wl: &[f64]| match compute(stack, &[0.0], wl) {
            Ok(_) => "ok".to_string(),
            Err(e) => e.to_string(),
        };
        let thick = stack(constant(2.0), 1e307);
        assert!(message(&thick, &[500.0]).contains("film 1 (`2`, 1e307 nm) at 500 nm"));
        let tab = stack(tabulated, 100.0);
        // 1e-310 nm overflows the phase; 700 nm is beyond the table.
        let first = message(&tab, &[1e-310, 700.0]);
        assert!(first.contains("its phase 2π ñ d / λ overflows"), "{first}");
        let first = message(&tab, &[700.0, 1e-310]);
        assert!(first.contains("700"), "{first}");
        assert!(!first.contains("overflows"), "{first}");
        assert_eq!(message(&tab, &[400.0, 500.0]), "ok");
    }
}
