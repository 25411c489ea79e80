//! Optical materials: the complex refractive index ñ(λ) = n(λ) + iκ(λ) of a medium.
//!
//! A [`Material`] is a constant index (`1.33`, `0.27+2.9i`) or dispersive data read from
//! text handed to it — this crate does no file I/O:
//!
//! * the [refractiveindex.info database](https://refractiveindex.info) YAML format
//!   ([`Material::from_refractiveindex_yaml`]): a `DATA` list whose entries are
//!   `tabulated nk` (rows `λ n κ`), `tabulated n`, `tabulated k`, or `formula 1` … `formula 9`
//!   with `coefficients` and `wavelength_range`; wavelengths in micrometres. n comes from the
//!   entry that gives n, κ from `tabulated nk`/`tabulated k` (κ = 0 when none does);
//! * a plain CSV ([`Material::from_nk_csv`], read with the `csv` crate): `#` comment lines,
//!   a header line `wavelength_nm,n,k`, then rows in nanometres.
//!
//! Tabulated values are linearly interpolated in wavelength, n and κ separately. A
//! wavelength outside the data (or outside a formula's `wavelength_range`) is an
//! [`Error::WavelengthOutOfRange`] naming the material and its range: nothing is
//! extrapolated.
//!
//! # Imperfect pages (refractiveindex.info YAML)
//!
//! A page is usable wherever its data are sound (docs/materials.md gives the policy and
//! the whole-database figures). Wavelengths in µm become nm exactly as written
//! ([`um_to_nm`]). Rows out of order are sorted; rows repeating a wavelength are merged (the
//! mean of their values); an n ≤ 0 or a κ < 0 is skipped, the row's other value kept. The
//! material covers n's range; κ is 0 outside κ's own table. A second entry giving n (or κ)
//! is ignored. A formula's non-physical stretches are cut off its range's ends, or refused
//! inside it ([`Error::NoPhysicalIndex`], [`Material::gaps_nm`]). Each repair is a
//! [`MaterialWarning`] naming file and line ([`Material::warnings`]). A page without n, and
//! text that is not the format, stay errors. `wavelength_nm,n,k` CSV files stay strict.
//!
//! # Dispersion formulas (refractiveindex.info numbering; λ in µm, C₁… the coefficients)
//!
//! | type | formula |
//! |---|---|
//! | 1 Sellmeier | n² − 1 = C₁ + Σ Cᵢ λ² / (λ² − Cᵢ₊₁²) |
//! | 2 Sellmeier-2 | n² − 1 = C₁ + Σ Cᵢ λ² / (λ² − Cᵢ₊₁) |
//! | 3 Polynomial | n² = C₁ + Σ Cᵢ λ^Cᵢ₊₁ |
//! | 4 RefractiveIndex.INFO | n² = C₁ + C₂ λ^C₃ / (λ² − C₄^C₅) + C₆ λ^C₇ / (λ² − C₈^C₉) + Σᵢ≥₁₀ Cᵢ λ^Cᵢ₊₁ |
//! | 5 Cauchy | n = C₁ + Σ Cᵢ λ^Cᵢ₊₁ |
//! | 6 Gases | n − 1 = C₁ + Σ Cᵢ / (Cᵢ₊₁ − λ⁻²) |
//! | 7 Herzberger | n = C₁ + C₂ / (λ² − 0.028) + C₃ (λ² − 0.028)⁻² + C₄ λ² + C₅ λ⁴ + C₆ λ⁶ |
//! | 8 Retro | (n² − 1) / (n² + 2) = C₁ + C₂ λ² / (λ² − C₃) + C₄ λ² |
//! | 9 Exotic | n² = C₁ + C₂ / (λ² − C₃) + C₄ (λ − C₅) / ((λ − C₅)² + C₆) |
//!
//! (Sums run over i = 2, 4, 6, … pairing Cᵢ with Cᵢ₊₁.) Source: the database's format
//! description, `database/doc/Dispersion formulas.pdf`, M. N. Polyanskiy, Sci. Data 11, 94 (2024).

mod dispersion;
mod page;
#[cfg(test)]
mod tests;
mod warning;
mod yaml;

pub use warning::{K_STEP_WARNING, MaterialWarning, WarningKind};

use crate::error::{Error, Result};
use dispersion::{Cursor, Dispersion};
use num_complex::Complex64 as C64;

/// What [`Material::constant_over_span`] needs of a list of wavelengths, found in one pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WavelengthSpan {
    /// `(first, smallest, largest)`, nm, when the list is not empty and every wavelength is
    /// positive and finite; `None` otherwise.
    valid: Option<(f64, f64, f64)>,
}

impl WavelengthSpan {
    /// The span of `wavelengths_nm`.
    pub fn of(wavelengths_nm: &[f64]) -> Self {
        let first = wavelengths_nm.first().copied();
        // Four independent lanes of min, max and validity (branch-free, so the loop
        // vectorises), folded at the end: min and max are exact whatever the order.
        let mut ok = [true; 4];
        let mut min = [f64::INFINITY; 4];
        let mut max = [f64::NEG_INFINITY; 4];
        let mut lane = |k: usize, wl: f64| {
            // Negated comparison: NaN fails it.
            ok[k] &= wl > 0.0 && wl < f64::INFINITY;
            min[k] = if wl < min[k] { wl } else { min[k] };
            max[k] = if wl > max[k] { wl } else { max[k] };
        };
        let chunks = wavelengths_nm.chunks_exact(4);
        let rest = chunks.remainder();
        for c in chunks {
            for (k, &wl) in c.iter().enumerate() {
                lane(k, wl);
            }
        }
        for (k, &wl) in rest.iter().enumerate() {
            lane(k, wl);
        }
        let ok = ok.iter().all(|&o| o);
        let min = min.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        let max = max.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        WavelengthSpan {
            valid: first.filter(|_| ok).map(|f| (f, min, max)),
        }
    }
}

/// A medium's complex refractive index ñ(λ) = n(λ) + iκ(λ), κ ≥ 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    name: String,
    n: Dispersion,
    k: Dispersion,
    /// Wavelengths covered, in nm (inclusive).
    range_nm: (f64, f64),
    /// Open intervals (nm) inside the range where a formula gives no physical n.
    gaps_nm: Vec<(f64, f64)>,
    /// What the reader repaired or set aside.
    warnings: Vec<MaterialWarning>,
}

impl Material {
    /// A wavelength-independent index `n + iκ` named `name`.
    ///
    /// Errors unless n > 0 and κ ≥ 0, both finite.
    pub fn constant(name: impl Into<String>, index: C64) -> Result<Self> {
        let name = name.into();
        check_index(&name, index)?;
        Ok(Material {
            name,
            n: Dispersion::Constant(index.re),
            k: Dispersion::Constant(index.im),
            range_nm: (0.0, f64::INFINITY),
            gaps_nm: Vec::new(),
            warnings: Vec::new(),
        })
    }

    /// Parses an index literal: a real number (`1.33`) or a complex `n+κi` (`0.27+2.9i`,
    /// also `0.27+2.9j`, spaces allowed around the sign). The material is named by the text.
    pub fn parse_index(text: &str) -> Result<Self> {
        let index = parse_complex(text)?;
        Material::constant(text.trim(), index)
    }

    /// Reads a plain CSV: `#` comment lines and blank lines anywhere, one header line
    /// `wavelength_nm,n,k` (any case), then rows of three numbers with strictly increasing
    /// wavelength (nm), n > 0 and κ ≥ 0. A UTF-8 byte-order mark, CRLF line ends, quoted
    /// fields and spaces around fields are accepted. `source_name` labels errors
    /// (`file:line`, the 1-based line the row starts on).
    pub fn from_nk_csv(name: impl Into<String>, source_name: &str, text: &str) -> Result<Self> {
        let name = name.into();
        let perr = |line: usize, message: String| Error::Parse {
            source_name: source_name.to_string(),
            line,
            message,
        };
        let mut records = crate::csv_rows::rows(source_name, text)?.into_iter();
        let Some(header) = records.next() else {
            return Err(perr(0, "no header line `wavelength_nm,n,k` found".into()));
        };
        let cols: Vec<String> = header.fields.iter().map(|c| c.to_lowercase()).collect();
        if cols != ["wavelength_nm", "n", "k"] {
            return Err(perr(
                header.line,
                format!(
                    "expected the header `wavelength_nm,n,k`, found `{}`",
                    header.text()
                ),
            ));
        }
        let mut rows = Vec::new();
        for record in records {
            let line_no = record.line;
            let fields = &record.fields;
            if fields.len() != 3 {
                return Err(perr(
                    line_no,
                    format!(
                        "expected 3 comma-separated numbers (wavelength_nm,n,k), found {} field(s)",
                        fields.len()
                    ),
                ));
            }
            let mut v = [0.0; 3];
            for (slot, (field, what)) in
                v.iter_mut()
                    .zip(fields.iter().zip(["wavelength_nm", "n", "k"]))
            {
                *slot = parse_finite(field).ok_or_else(|| {
                    perr(line_no, format!("{what} `{field}` is not a finite number"))
                })?;
            }
            rows.push((line_no, v));
        }
        Material::from_rows(name, source_name, rows)
    }
    fn from_rows(name: String, source_name: &str, rows: Vec<(usize, [f64; 3])>) -> Result<Self> {
        let perr = |line: usize, message: String| Error::Parse {
            source_name: source_name.to_string(),
            line,
            message,
        };
        if rows.is_empty() {
            return Err(perr(0, "no data rows".into()));
        }
        let mut prev: Option<f64> = None;
        for (line, [w, n, k]) in &rows {
            if !(*w > 0.0) {
                return Err(perr(*line, format!("wavelength {w} nm must be positive")));
            }
            if let Some(p) = prev
                && !(*w > p)
            {
                return Err(perr(
                    *line,
                    format!("wavelengths must strictly increase ({w} nm follows {p} nm)"),
                ));
            }
            if !(*n > 0.0) {
                return Err(perr(*line, format!("n = {n} must be positive")));
            }
            if !(*k >= 0.0) {
                return Err(perr(*line, format!("k = {k} must be non-negative")));
            }
            prev = Some(*w);
        }
        let w: Vec<f64> = rows.iter().map(|(_, r)| r[0]).collect();
        let range_nm = (w[0], w[w.len() - 1]);
        Ok(Material {
            name,
            n: Dispersion::Tabulated {
                wavelength_nm: w.clone(),
                value: rows.iter().map(|(_, r)| r[1]).collect(),
                zero_outside: false,
            },
            k: Dispersion::Tabulated {
                wavelength_nm: w,
                value: rows.iter().map(|(_, r)| r[2]).collect(),
                zero_outside: false,
            },
            range_nm,
            gaps_nm: Vec::new(),
            warnings: Vec::new(),
        })
    }

    /// The material's name (a bundled name, a file name or the literal it was parsed from).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Returns the material renamed to `name`.
    pub fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    /// The wavelengths covered, in nm, inclusive (`(0, ∞)` for constants).
    pub fn range_nm(&self) -> (f64, f64) {
        self.range_nm
    }

    /// What the reader repaired or set aside in the material's data (rows merged, sorted or
    /// skipped, a formula's non-physical stretches, where κ's table ends): the material is
    /// usable, and a front end should show these to the user. Empty for constants, CSV
    /// files and sound pages.
    pub fn warnings(&self) -> &[MaterialWarning] {
        &self.warnings
    }

    /// Open intervals (nm) inside [`Material::range_nm`] where the material's formula gives
    /// no physical n: [`Material::index_at`] refuses them.
    pub fn gaps_nm(&self) -> &[(f64, f64)] {
        &self.gaps_nm
    }

    /// True when the index does not depend on wavelength.
    pub fn is_constant(&self) -> bool {
        matches!(
            (&self.n, &self.k),
            (Dispersion::Constant(_), Dispersion::Constant(_))
        )
    }

    /// The complex index ñ = n + iκ at vacuum wavelength `wavelength_nm`.
    ///
    /// Errors outside the covered range or where a formula is non-physical.
    pub fn index_at(&self, wavelength_nm: f64) -> Result<C64> {
        self.index_from(wavelength_nm, &mut [Cursor::default(); 2])
    }

    /// [`Material::index_at`] at each of `wavelengths_nm` (the same values, and the error of
    /// the first wavelength that has one); ascending wavelengths walk a tabulated index's
    /// table once.
    pub fn indices_at(&self, wavelengths_nm: &[f64]) -> Result<Vec<C64>> {
        let mut cursors = [Cursor::default(); 2];
        wavelengths_nm
            .iter()
            .map(|&wl| self.index_from(wl, &mut cursors))
            .collect()
    }

    /// The one index of a constant material when [`Material::index_at`] gives it, without
    /// an error, at every one of `wavelengths_nm` (none empty); `None` otherwise (a
    /// dispersive material, or some wavelength with an error: [`Material::indices_at`] then
    /// gives the values or the error). A constant's index does not depend on the
    /// wavelength, so this is [`Material::indices_at`]'s every value, checked once.
    pub fn constant_over(&self, wavelengths_nm: &[f64]) -> Option<C64> {
        self.constant_over_span(&WavelengthSpan::of(wavelengths_nm))
    }

    /// [`Material::constant_over`] for wavelengths summarised by `span` (one pass over them
    /// for every medium of a stack, not one per medium).
    pub fn constant_over_span(&self, span: &WavelengthSpan) -> Option<C64> {
        let (lo, hi) = self.range_nm;
        if !self.is_constant() || !self.gaps_nm.is_empty() {
            return None;
        }
        let (first, min, max) = span.valid?;
        // Every wavelength is positive and finite; each lies in [lo, hi] iff the extremes do.
        if !(min >= lo && max <= hi) {
            return None;
        }
        self.index_at(first).ok()
    }

    /// [`Material::index_at`] with the tables' cursors (n, κ) of [`Dispersion::eval_from`].
    fn index_from(&self, wavelength_nm: f64, cursors: &mut [Cursor; 2]) -> Result<C64> {
        if !(wavelength_nm > 0.0) || !wavelength_nm.is_finite() {
            return Err(Error::InvalidWavelength { wavelength_nm });
        }
        let (lo, hi) = self.range_nm;
        if wavelength_nm < lo || wavelength_nm > hi {
            return Err(Error::WavelengthOutOfRange {
                material: self.name.clone(),
                wavelength_nm,
                min_nm: lo,
                max_nm: hi,
            });
        }
        if let Some(&(from_nm, to_nm)) = self
            .gaps_nm
            .iter()
            .find(|(a, b)| wavelength_nm > *a && wavelength_nm < *b)
        {
            return Err(Error::NoPhysicalIndex {
                material: self.name.clone(),
                wavelength_nm,
                from_nm,
                to_nm,
            });
        }
        let index = C64::new(
            self.n.eval_from(wavelength_nm, &mut cursors[0]),
            self.k.eval_from(wavelength_nm, &mut cursors[1]),
        );
        if !(index.re > 0.0 && index.re.is_finite() && index.im >= 0.0 && index.im.is_finite()) {
            return Err(Error::NonPhysicalIndex {
                material: self.name.clone(),
                wavelength_nm,
                value: format!("{}{:+}i", index.re, index.im),
            });
        }
        Ok(index)
    }
}

/// The real parts n a constant index may have, [10⁻⁶, 10⁶]: every measured material lies
/// well inside (epsilon-near-zero films reach n ≈ 0.01, metals in the far infrared
/// n ≈ 100), and beyond it the Fresnel and transfer-matrix terms over- or underflow f64 (a
/// film of n = 10⁻²⁰ or 10¹⁰⁰ gives NaN where [10⁻⁶, 10⁶] stays finite for every angle,
/// wavelength 10⁻³–10⁶ nm and thickness 0–10⁹ nm).
pub const INDEX_RANGE: (f64, f64) = (1e-6, 1e6);

/// The largest extinction coefficient κ a constant index may have (see [`INDEX_RANGE`]).
pub const MAX_KAPPA: f64 = 1e6;
/// A decimal number of micrometres (`0.017586`, `1.5E-2`) in nanometres, correctly rounded:
/// the decimal point is moved three places in the text before parsing, so a page's own
/// wavelengths print back as written (`17.586`, not `17.586000000000002`). None unless a
/// finite number.
pub fn um_to_nm(token: &str) -> Option<f64> {
    let t = token.trim();
    parse_finite(t)?;
    let (mantissa, exponent) = match t.find(['e', 'E']) {
        Some(i) => (&t[..i], t[i + 1..].parse::<i64>().ok()?),
        None => (t, 0),
    };
    parse_finite(&format!("{mantissa}e{}", exponent + 3))
}
fn check_index(name: &str, index: C64) -> Result<()> {
    if !(index.re > 0.0 && index.re.is_finite()) {
        return Err(Error::InvalidIndex {
            text: name.to_string(),
            reason: "the real part n must be finite and positive".into(),
        });
    }
    if !(INDEX_RANGE.0..=INDEX_RANGE.1).contains(&index.re) {
        return Err(Error::InvalidIndex {
            text: name.to_string(),
            reason: format!(
                "the real part n must lie in [{:e}, {:e}]",
                INDEX_RANGE.0, INDEX_RANGE.1
            ),
        });
    }
    if !(index.im >= 0.0 && index.im.is_finite()) {
        return Err(Error::InvalidIndex {
            text: name.to_string(),
            reason:
                "the extinction coefficient κ must be finite and non-negative (κ < 0 would be gain)"
                    .into(),
        });
    }
    if index.im > MAX_KAPPA {
        return Err(Error::InvalidIndex {
            text: name.to_string(),
            reason: format!("the extinction coefficient κ must be at most {MAX_KAPPA:e}"),
        });
    }
    Ok(())
}

/// Parses a finite `f64`, rejecting `inf`/`nan` spellings.
fn parse_finite(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Whitespace-separated finite numbers; on failure returns the offending token.
fn parse_numbers(s: &str) -> std::result::Result<Vec<f64>, String> {
    s.split_whitespace()
        .map(|t| parse_finite(t).ok_or_else(|| t.to_string()))
        .collect()
}

/// Parses `n`, `n+κi`, `n-κi` (i or j, optional spaces around the sign).
fn parse_complex(text: &str) -> Result<C64> {
    let err = |reason: &str| Error::InvalidIndex {
        text: text.trim().to_string(),
        reason: reason.to_string(),
    };
    let s: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    if s.is_empty() {
        return Err(err(
            "empty; expected a number such as `1.5` or a complex index such as `0.27+2.9i`",
        ));
    }
    let expected = "expected a number such as `1.5` or a complex index such as `0.27+2.9i`";
    if let Some(body) = s.strip_suffix(['i', 'j', 'I', 'J']) {
        // Split at the last sign that is not the start and not part of an exponent.
        let bytes = body.as_bytes();
        let split = (1..bytes.len())
            .rev()
            .find(|&i| matches!(bytes[i], b'+' | b'-') && !matches!(bytes[i - 1], b'e' | b'E'))
            .ok_or_else(|| err(expected))?;
        let re = body[..split].parse::<f64>().map_err(|_| err(expected))?;
        let im_text = &body[split..];
        let im = if im_text == "+" || im_text == "-" {
            return Err(err(expected));
        } else {
            im_text.parse::<f64>().map_err(|_| err(expected))?
        };
        if !re.is_finite() || !im.is_finite() {
            return Err(err("both parts must be finite"));
        }
        Ok(C64::new(re, im))
    } else {
        let re = s.parse::<f64>().map_err(|_| err(expected))?;
        if !re.is_finite() {
            return Err(err("must be finite"));
        }
        Ok(C64::new(re, 0.0))
    }
}
