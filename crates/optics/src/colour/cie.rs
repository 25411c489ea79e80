//! The CIE data: the standard observers' colour-matching functions and the illuminants'
//! spectral power, bundled from `tables/cie/` and parsed once (CIE 015:2018; ISO/CIE
//! 11664-1:2019, 11664-2), the 1 nm grid of the colour sums, and xy chromaticities.

use crate::error::{Error, Result};
use std::fmt;
use std::str::FromStr;
use std::sync::LazyLock;

/// Shortest wavelength of the colour sums, in nm (CIE 015:2018's 360–830 nm range).
pub const SPECTRAL_MIN_NM: f64 = 360.0;
/// Longest wavelength of the colour sums, in nm.
pub const SPECTRAL_MAX_NM: f64 = 830.0;
/// Wavelength step Δλ of the colour sums, in nm.
pub const SPECTRAL_STEP_NM: f64 = 1.0;
/// Number of samples in the colour sums: λᵢ = 360 + i nm for i = 0 … 470.
pub const SPECTRAL_SAMPLES: usize = 471;

/// The wavelength λᵢ = 360 + i nm of sample `i` of the colour sums
/// ([`Colorimeter::weights_1nm`], [`CmfTable::xyz_bar`]).
pub fn spectral_wavelength_nm(i: usize) -> f64 {
    SPECTRAL_MIN_NM + i as f64 * SPECTRAL_STEP_NM
}

/// Finds the segment of a uniform grid (`len` samples from `start_nm`, 1 nm apart) that
/// holds `at`: returns `(i, t)` with `at = start + i + t`, 0 ≤ t ≤ 1 and `i + 1 < len`.
/// `None` outside the grid or for NaN.
pub(super) fn locate(start_nm: f64, len: usize, at: f64) -> Option<(usize, f64)> {
    let x = (at - start_nm) / SPECTRAL_STEP_NM;
    if !(x >= 0.0 && x <= (len - 1) as f64) {
        return None;
    }
    let i = (x.floor() as usize).min(len - 2);
    Some((i, x - i as f64))
}

/// (1 − t)·a + t·b, which returns a or b exactly at t = 0 or t = 1.
pub(super) fn lerp(a: f64, b: f64, t: f64) -> f64 {
    (1.0 - t) * a + t * b
}

/// Parses a bundled CIE CSV, read with the `csv` crate as material CSVs are (`#` comment
/// and blank lines, a UTF-8 BOM, CRLF, quoted fields and spaces accepted): the header
/// `columns`, then rows of `columns.len()` numbers whose first, the wavelength in nm,
/// starts at an integer and steps by exactly 1 nm. Returns the first wavelength and the
/// remaining columns.
fn parse_table(file: &str, text: &str, columns: &[&str]) -> Result<(f64, Vec<Vec<f64>>)> {
    let perr = |line: usize, message: String| Error::Parse {
        source_name: format!("tables/cie/{file}"),
        line,
        message,
    };
    let mut records = crate::csv_rows::rows(&format!("tables/cie/{file}"), text)?.into_iter();
    let Some(header) = records.next() else {
        return Err(perr(0, "no header or fewer than two rows".into()));
    };
    if header.fields != columns {
        return Err(perr(
            header.line,
            format!(
                "expected the header `{}`, found `{}`",
                columns.join(","),
                header.text()
            ),
        ));
    }
    let mut start_nm = f64::NAN;
    let mut rows = Vec::new();
    for record in records {
        let line_no = record.line;
        let v = record
            .fields
            .iter()
            .map(|f| f.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<Vec<f64>>>()
            .ok_or_else(|| {
                perr(
                    line_no,
                    format!("`{}` is not a row of finite numbers", record.text()),
                )
            })?;
        if v.len() != columns.len() {
            return Err(perr(
                line_no,
                format!("expected {} numbers, found {}", columns.len(), v.len()),
            ));
        }
        if rows.is_empty() {
            if v[0].fract() != 0.0 {
                return Err(perr(
                    line_no,
                    format!("first wavelength {} nm is not whole", v[0]),
                ));
            }
            start_nm = v[0];
        } else if v[0] != start_nm + rows.len() as f64 * SPECTRAL_STEP_NM {
            return Err(perr(
                line_no,
                format!("wavelength {} nm breaks the 1 nm grid", v[0]),
            ));
        }
        rows.push(v[1..].to_vec());
    }
    if rows.len() < 2 {
        return Err(perr(0, "no header or fewer than two rows".into()));
    }
    Ok((start_nm, rows))
}

/// Colour-matching functions x̄(λ), ȳ(λ), z̄(λ) of a CIE standard observer, tabulated
/// every 1 nm from 360 nm to 830 nm (471 samples; dimensionless, ȳ peaks at 1).
#[derive(Clone, Debug, PartialEq)]
pub struct CmfTable {
    xyz_bar: Vec<[f64; 3]>,
}

impl CmfTable {
    pub(super) fn parse(file: &str, text: &str) -> Result<Self> {
        let (start_nm, rows) =
            parse_table(file, text, &["wavelength_nm", "x_bar", "y_bar", "z_bar"])?;
        if start_nm != SPECTRAL_MIN_NM || rows.len() != SPECTRAL_SAMPLES {
            return Err(Error::Parse {
                source_name: format!("tables/cie/{file}"),
                line: 0,
                message: format!(
                    "expected {SPECTRAL_SAMPLES} rows from {SPECTRAL_MIN_NM} nm, found {} from {start_nm} nm",
                    rows.len()
                ),
            });
        }
        let xyz_bar = rows.iter().map(|r| [r[0], r[1], r[2]]).collect();
        Ok(CmfTable { xyz_bar })
    }

    /// The samples (x̄, ȳ, z̄)(λᵢ), λᵢ = 360 + i nm ([`spectral_wavelength_nm`]).
    pub fn xyz_bar(&self) -> &[[f64; 3]] {
        &self.xyz_bar
    }

    /// (x̄, ȳ, z̄) at `wavelength_nm`, linearly interpolated between the 1 nm samples;
    /// (0, 0, 0) outside 360–830 nm, where the standard observers are not defined.
    pub fn at(&self, wavelength_nm: f64) -> [f64; 3] {
        match locate(SPECTRAL_MIN_NM, self.xyz_bar.len(), wavelength_nm) {
            Some((i, t)) => {
                let (a, b) = (self.xyz_bar[i], self.xyz_bar[i + 1]);
                [
                    lerp(a[0], b[0], t),
                    lerp(a[1], b[1], t),
                    lerp(a[2], b[2], t),
                ]
            }
            None => [0.0; 3],
        }
    }
}

/// A relative spectral power distribution tabulated every 1 nm.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct SpdTable {
    start_nm: f64,
    power: Vec<f64>,
}

impl SpdTable {
    pub(super) fn parse(file: &str, text: &str) -> Result<Self> {
        let (start_nm, rows) = parse_table(file, text, &["wavelength_nm", "relative_power"])?;
        let end_nm = start_nm + (rows.len() - 1) as f64 * SPECTRAL_STEP_NM;
        if start_nm > SPECTRAL_MIN_NM || end_nm < SPECTRAL_MAX_NM {
            return Err(Error::Parse {
                source_name: format!("tables/cie/{file}"),
                line: 0,
                message: format!(
                    "covers {start_nm}–{end_nm} nm, not all of {SPECTRAL_MIN_NM}–{SPECTRAL_MAX_NM} nm"
                ),
            });
        }
        Ok(SpdTable {
            start_nm,
            power: rows.iter().map(|r| r[0]).collect(),
        })
    }

    fn at(&self, wavelength_nm: f64) -> f64 {
        match locate(self.start_nm, self.power.len(), wavelength_nm) {
            Some((i, t)) => lerp(self.power[i], self.power[i + 1], t),
            None => 0.0,
        }
    }
}

/// Parses a bundled table; the tables are checked by this module's tests, so a failure
/// here is a build defect and panics with the file and line.
fn bundled<T>(parsed: Result<T>) -> T {
    parsed.unwrap_or_else(|e| panic!("bundled CIE table is malformed: {e}"))
}

static CMF_1931: LazyLock<CmfTable> = LazyLock::new(|| {
    bundled(CmfTable::parse(
        "cmf-cie1931-2deg.csv",
        include_str!("../../../../tables/cie/cmf-cie1931-2deg.csv"),
    ))
});
static CMF_1964: LazyLock<CmfTable> = LazyLock::new(|| {
    bundled(CmfTable::parse(
        "cmf-cie1964-10deg.csv",
        include_str!("../../../../tables/cie/cmf-cie1964-10deg.csv"),
    ))
});
static SPD_D65: LazyLock<SpdTable> = LazyLock::new(|| {
    bundled(SpdTable::parse(
        "illuminant-d65.csv",
        include_str!("../../../../tables/cie/illuminant-d65.csv"),
    ))
});
static SPD_D50: LazyLock<SpdTable> = LazyLock::new(|| {
    bundled(SpdTable::parse(
        "illuminant-d50.csv",
        include_str!("../../../../tables/cie/illuminant-d50.csv"),
    ))
});
static SPD_A: LazyLock<SpdTable> = LazyLock::new(|| {
    bundled(SpdTable::parse(
        "illuminant-a.csv",
        include_str!("../../../../tables/cie/illuminant-a.csv"),
    ))
});

/// A CIE standard colorimetric observer (CIE 015:2018; ISO/CIE 11664-1:2019).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Observer {
    /// CIE 1931 standard colorimetric observer, 2° field. Parsed from `1931`.
    Cie1931_2Deg,
    /// CIE 1964 supplementary standard colorimetric observer, 10° field. Parsed from `1964`.
    Cie1964_10Deg,
}

impl Observer {
    /// Both observers.
    pub const ALL: [Observer; 2] = [Observer::Cie1931_2Deg, Observer::Cie1964_10Deg];

    /// The short name that [`FromStr`] accepts: `1931` or `1964`.
    pub fn name(&self) -> &'static str {
        match self {
            Observer::Cie1931_2Deg => "1931",
            Observer::Cie1964_10Deg => "1964",
        }
    }

    /// The observer's colour-matching functions, 360–830 nm every 1 nm.
    pub fn cmf(&self) -> &'static CmfTable {
        match self {
            Observer::Cie1931_2Deg => &CMF_1931,
            Observer::Cie1964_10Deg => &CMF_1964,
        }
    }

    /// (x̄, ȳ, z̄) at `wavelength_nm`, linearly interpolated between the 1 nm samples;
    /// (0, 0, 0) outside 360–830 nm.
    pub fn xyz_bar_at(&self, wavelength_nm: f64) -> [f64; 3] {
        self.cmf().at(wavelength_nm)
    }
}

impl fmt::Display for Observer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Observer {
    type Err = Error;

    /// `1931` or `1964` (surrounding spaces ignored).
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "1931" => Ok(Observer::Cie1931_2Deg),
            "1964" => Ok(Observer::Cie1964_10Deg),
            _ => Err(Error::UnknownName {
                what: "observer",
                name: s.to_string(),
                expected: "1931 (CIE 1931 2°), 1964 (CIE 1964 10°)",
            }),
        }
    }
}

/// A CIE illuminant: the light under which a reflectance is seen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Illuminant {
    /// CIE standard illuminant D65, average daylight (correlated colour temperature
    /// ≈ 6504 K). Parsed from `d65`.
    D65,
    /// CIE illuminant D50, horizon daylight (≈ 5003 K), the ICC profile connection
    /// space illuminant. Parsed from `d50`.
    D50,
    /// CIE standard illuminant A, incandescent tungsten: a Planckian radiator at
    /// ≈ 2856 K. Parsed from `a`.
    A,
    /// The equal-energy illuminant E, S(λ) ≡ 1. Parsed from `e`.
    E,
}

impl Illuminant {
    /// All four illuminants.
    pub const ALL: [Illuminant; 4] = [
        Illuminant::D65,
        Illuminant::D50,
        Illuminant::A,
        Illuminant::E,
    ];

    /// The short name that [`FromStr`] accepts: `d65`, `d50`, `a` or `e`.
    pub fn name(&self) -> &'static str {
        match self {
            Illuminant::D65 => "d65",
            Illuminant::D50 => "d50",
            Illuminant::A => "a",
            Illuminant::E => "e",
        }
    }

    /// Relative spectral power S(λ) at `wavelength_nm` (dimensionless).
    ///
    /// D65, D50 and A are the bundled 1 nm tables (300–830 nm, S(560 nm) = 100),
    /// linearly interpolated, and 0 outside 300–830 nm. E is 1 at every wavelength. The
    /// overall scale never matters: every use normalises by Σ S ȳ.
    pub fn power_at(&self, wavelength_nm: f64) -> f64 {
        match self {
            Illuminant::D65 => SPD_D65.at(wavelength_nm),
            Illuminant::D50 => SPD_D50.at(wavelength_nm),
            Illuminant::A => SPD_A.at(wavelength_nm),
            Illuminant::E => 1.0,
        }
    }

    /// The white point XYZ (Y = 1) for `observer`: the tristimulus values of the
    /// perfect reflector, summed at 1 nm over 360–830 nm as CIE 015 prescribes,
    ///
    /// ```text
    /// (X, Y, Z)_w = Σᵢ S(λᵢ) (x̄, ȳ, z̄)(λᵢ) / Σᵢ S(λᵢ) ȳ(λᵢ),   λᵢ = 360, 361, …, 830 nm.
    /// ```
    ///
    /// This computed white, not a rounded published chromaticity, is what
    /// [`Colorimeter`] adapts from, so that a perfect reflector maps exactly to
    /// RGB (1, 1, 1). With the 1931 observer it gives D65 (0.31273, 0.32902),
    /// D50 (0.34568, 0.35850), A (0.44757, 0.40744) in xy, within 2 × 10⁻⁵ of the CIE's
    /// published values.
    pub fn white_xyz(&self, observer: Observer) -> [f64; 3] {
        let cmf = observer.cmf().xyz_bar();
        let mut sum = [0.0; 3];
        for (i, xyz_bar) in cmf.iter().enumerate() {
            let s = self.power_at(spectral_wavelength_nm(i));
            for (acc, v) in sum.iter_mut().zip(xyz_bar) {
                *acc += s * v;
            }
        }
        let y = sum[1];
        [sum[0] / y, 1.0, sum[2] / y]
    }

    /// The white point's chromaticity (x, y) = (X, Y) / (X + Y + Z) for `observer`
    /// (see [`Illuminant::white_xyz`]).
    pub fn white_xy(&self, observer: Observer) -> [f64; 2] {
        xyz_to_xy(self.white_xyz(observer))
    }
}

impl fmt::Display for Illuminant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Illuminant {
    type Err = Error;

    /// `d65`, `d50`, `a` or `e`, in any case (surrounding spaces ignored).
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "d65" => Ok(Illuminant::D65),
            "d50" => Ok(Illuminant::D50),
            "a" => Ok(Illuminant::A),
            "e" => Ok(Illuminant::E),
            _ => Err(Error::UnknownName {
                what: "illuminant",
                name: s.to_string(),
                expected: "d65, d50, a, e",
            }),
        }
    }
}

/// Chromaticity (x, y) = (X, Y) / (X + Y + Z).
pub fn xyz_to_xy(xyz: [f64; 3]) -> [f64; 2] {
    let sum = xyz[0] + xyz[1] + xyz[2];
    [xyz[0] / sum, xyz[1] / sum]
}

/// XYZ with luminance Y = 1 of the chromaticity (x, y): (x/y, 1, (1 − x − y)/y).
pub fn xy_to_xyz(xy: [f64; 2]) -> [f64; 3] {
    let [x, y] = xy;
    [x / y, 1.0, (1.0 - x - y) / y]
}
