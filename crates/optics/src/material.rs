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

use crate::error::{Error, Result};
use num_complex::Complex64 as C64;
use yaml_rust2::parser::{Event, MarkedEventReceiver, Parser};
use yaml_rust2::scanner::{Marker, TScalarStyle};

/// One real quantity (n or κ) as a function of vacuum wavelength.
#[derive(Clone, Debug, PartialEq)]
enum Dispersion {
    /// Independent of wavelength.
    Constant(f64),
    /// Samples at strictly increasing wavelengths (nm), linearly interpolated.
    Tabulated {
        wavelength_nm: Vec<f64>,
        value: Vec<f64>,
    },
    /// A refractiveindex.info dispersion formula evaluated with λ in µm; gives n.
    Formula { kind: u8, coefficients: Vec<f64> },
}

impl Dispersion {
    fn eval(&self, wavelength_nm: f64) -> f64 {
        match self {
            Dispersion::Constant(v) => *v,
            Dispersion::Tabulated {
                wavelength_nm: w,
                value,
            } => interpolate(w, value, wavelength_nm),
            Dispersion::Formula { kind, coefficients } => {
                eval_formula(*kind, coefficients, wavelength_nm * 1e-3)
            }
        }
    }
}

/// Linear interpolation in `x` (strictly increasing, `x[0] <= at <= x[last]`).
fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    if x.len() == 1 {
        return y[0];
    }
    // First sample strictly greater than `at`, clamped so that [i-1, i] is a segment.
    let i = x.partition_point(|&v| v <= at).clamp(1, x.len() - 1);
    let (x0, x1, y0, y1) = (x[i - 1], x[i], y[i - 1], y[i]);
    let t = (at - x0) / (x1 - x0);
    y0 + t * (y1 - y0)
}

/// Evaluates refractiveindex.info formula `kind` at `lambda_um`; returns n (NaN when the
/// formula yields n² < 0 there).
fn eval_formula(kind: u8, c: &[f64], lambda_um: f64) -> f64 {
    let l = lambda_um;
    let l2 = l * l;
    let coef = |i: usize| c.get(i).copied().unwrap_or(0.0);
    // Pairs (C_i, C_{i+1}) for i = start, start+2, … (0-based indices).
    let pairs = |start: usize| {
        (start..c.len())
            .step_by(2)
            .map(move |i| (coef(i), coef(i + 1)))
    };
    match kind {
        1 => (1.0 + coef(0) + pairs(1).map(|(a, b)| a * l2 / (l2 - b * b)).sum::<f64>()).sqrt(),
        2 => (1.0 + coef(0) + pairs(1).map(|(a, b)| a * l2 / (l2 - b)).sum::<f64>()).sqrt(),
        3 => (coef(0) + pairs(1).map(|(a, b)| a * l.powf(b)).sum::<f64>()).sqrt(),
        4 => {
            let mut n2 = coef(0)
                + coef(1) * l.powf(coef(2)) / (l2 - coef(3).powf(coef(4)))
                + coef(5) * l.powf(coef(6)) / (l2 - coef(7).powf(coef(8)));
            n2 += pairs(9).map(|(a, b)| a * l.powf(b)).sum::<f64>();
            n2.sqrt()
        }
        5 => coef(0) + pairs(1).map(|(a, b)| a * l.powf(b)).sum::<f64>(),
        6 => 1.0 + coef(0) + pairs(1).map(|(a, b)| a / (b - 1.0 / l2)).sum::<f64>(),
        7 => {
            let u = 1.0 / (l2 - 0.028);
            coef(0)
                + coef(1) * u
                + coef(2) * u * u
                + coef(3) * l2
                + coef(4) * l2 * l2
                + coef(5) * l2 * l2 * l2
        }
        8 => {
            let a = coef(0) + coef(1) * l2 / (l2 - coef(2)) + coef(3) * l2;
            // (n² − 1)/(n² + 2) = a  ⇒  n² = (1 + 2a)/(1 − a)
            ((1.0 + 2.0 * a) / (1.0 - a)).sqrt()
        }
        9 => {
            let d = l - coef(4);
            (coef(0) + coef(1) / (l2 - coef(2)) + coef(3) * d / (d * d + coef(5))).sqrt()
        }
        _ => f64::NAN,
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

    /// Reads the refractiveindex.info database YAML format (see module docs).
    /// `source_name` labels errors (`file:line`).
    pub fn from_refractiveindex_yaml(
        name: impl Into<String>,
        source_name: &str,
        text: &str,
    ) -> Result<Self> {
        let name = name.into();
        let perr = |line: usize, message: String| Error::Parse {
            source_name: source_name.to_string(),
            line,
            message,
        };
        let root = parse_yaml_tree(text).map_err(|(line, m)| perr(line, m))?;
        let Node::Map(entries, _) = &root else {
            return Err(perr(
                root.line(),
                "expected a mapping with a `DATA` key at the top level".into(),
            ));
        };
        let data = entries
            .iter()
            .find(|(k, _)| k == "DATA")
            .map(|(_, v)| v)
            .ok_or_else(|| {
                perr(
                    1,
                    "no `DATA` key: not a refractiveindex.info material file".into(),
                )
            })?;
        let Node::Seq(items, data_line) = data else {
            return Err(perr(data.line(), "`DATA` must be a list of entries".into()));
        };
        if items.is_empty() {
            return Err(perr(*data_line, "`DATA` is empty".into()));
        }
        let mut n_part: Option<(Dispersion, (f64, f64))> = None;
        let mut k_part: Option<(Dispersion, (f64, f64))> = None;
        for item in items {
            let Node::Map(fields, item_line) = item else {
                return Err(perr(
                    item.line(),
                    "each `DATA` entry must be a mapping with a `type`".into(),
                ));
            };
            let get = |key: &str| fields.iter().find(|(k, _)| k == key).map(|(_, v)| v);
            let ty = match get("type") {
                Some(Node::Scalar(s, _, _)) => s.trim().to_string(),
                _ => return Err(perr(*item_line, "`DATA` entry without a `type`".into())),
            };
            let type_line = get("type").map_or(*item_line, Node::line);
            let (parsed_n, parsed_k) = if let Some(kind) = ty.strip_prefix("formula ") {
                let kind: u8 = match kind.trim().parse() {
                    Ok(k @ 1..=9) => k,
                    _ => {
                        return Err(perr(
                            type_line,
                            format!(
                                "unsupported type `{ty}`: expected `formula 1` … `formula 9`, `tabulated nk`, `tabulated n` or `tabulated k`"
                            ),
                        ));
                    }
                };
                let coefficients = match get("coefficients") {
                    Some(Node::Scalar(s, _, line)) => parse_numbers(s).map_err(|tok| {
                        perr(*line, format!("coefficient `{tok}` is not a finite number"))
                    })?,
                    _ => {
                        return Err(perr(
                            *item_line,
                            format!("`{ty}` entry without `coefficients`"),
                        ));
                    }
                };
                if coefficients.is_empty() {
                    return Err(perr(*item_line, "`coefficients` is empty".into()));
                }
                let range_nm = match get("wavelength_range") {
                    Some(Node::Scalar(s, _, line)) => {
                        let v = parse_numbers(s).map_err(|tok| {
                            perr(
                                *line,
                                format!("wavelength_range value `{tok}` is not a finite number"),
                            )
                        })?;
                        if v.len() != 2 || !(v[0] > 0.0 && v[1] > v[0]) {
                            return Err(perr(
                                *line,
                                format!(
                                    "`wavelength_range` must be two increasing positive wavelengths in µm, found `{}`",
                                    s.trim()
                                ),
                            ));
                        }
                        (v[0] * 1e3, v[1] * 1e3)
                    }
                    Some(other) => {
                        return Err(perr(
                            other.line(),
                            "`wavelength_range` must be two numbers".into(),
                        ));
                    }
                    None => (0.0, f64::INFINITY),
                };
                (
                    Some((Dispersion::Formula { kind, coefficients }, range_nm)),
                    None,
                )
            } else {
                let columns = match ty.as_str() {
                    "tabulated nk" => 3,
                    "tabulated n" | "tabulated k" => 2,
                    _ => {
                        return Err(perr(
                            type_line,
                            format!(
                                "unsupported type `{ty}`: expected `tabulated nk`, `tabulated n`, `tabulated k` or `formula 1` … `formula 9`"
                            ),
                        ));
                    }
                };
                let (block, first_line) = match get("data") {
                    Some(Node::Scalar(s, style, line)) => {
                        // yaml-rust2 marks a block scalar at its first non-blank content
                        // line; leading blank lines appear as leading newlines.
                        let first = if matches!(style, TScalarStyle::Literal | TScalarStyle::Folded)
                        {
                            line - s.bytes().take_while(|&b| b == b'\n').count()
                        } else {
                            *line
                        };
                        (s.as_str(), first)
                    }
                    _ => {
                        return Err(perr(
                            *item_line,
                            format!("`{ty}` entry without a `data` block"),
                        ));
                    }
                };
                let mut w = Vec::new();
                let mut a = Vec::new();
                let mut b = Vec::new();
                for (i, row) in block.lines().enumerate() {
                    let line_no = first_line + i;
                    if row.trim().is_empty() {
                        continue;
                    }
                    let v = parse_numbers(row)
                        .map_err(|tok| perr(line_no, format!("`{tok}` is not a finite number")))?;
                    if v.len() != columns {
                        return Err(perr(
                            line_no,
                            format!("`{ty}` rows need {columns} numbers, found {}", v.len()),
                        ));
                    }
                    if !(v[0] > 0.0) {
                        return Err(perr(
                            line_no,
                            format!("wavelength {} µm must be positive", v[0]),
                        ));
                    }
                    if let Some(&prev) = w.last()
                        && !(v[0] * 1e3 > prev)
                    {
                        return Err(perr(
                            line_no,
                            format!(
                                "wavelengths must strictly increase ({} µm follows {} µm)",
                                v[0],
                                prev * 1e-3
                            ),
                        ));
                    }
                    let (is_n, is_k) = match ty.as_str() {
                        "tabulated nk" => (Some(v[1]), Some(v[2])),
                        "tabulated n" => (Some(v[1]), None),
                        _ => (None, Some(v[1])),
                    };
                    if let Some(n) = is_n
                        && !(n > 0.0)
                    {
                        return Err(perr(line_no, format!("n = {n} must be positive")));
                    }
                    if let Some(k) = is_k
                        && !(k >= 0.0)
                    {
                        return Err(perr(line_no, format!("k = {k} must be non-negative")));
                    }
                    w.push(v[0] * 1e3);
                    a.push(v[1]);
                    if columns == 3 {
                        b.push(v[2]);
                    }
                }
                if w.is_empty() {
                    return Err(perr(first_line, format!("`{ty}` entry has no data rows")));
                }
                let range = (w[0], *w.last().unwrap_or(&w[0]));
                let tab = |value: Vec<f64>| Dispersion::Tabulated {
                    wavelength_nm: w.clone(),
                    value,
                };
                match ty.as_str() {
                    "tabulated nk" => (Some((tab(a), range)), Some((tab(b), range))),
                    "tabulated n" => (Some((tab(a), range)), None),
                    _ => (None, Some((tab(a), range))),
                }
            };
            if let Some(p) = parsed_n {
                if n_part.is_some() {
                    return Err(perr(type_line, "more than one `DATA` entry gives n".into()));
                }
                n_part = Some(p);
            }
            if let Some(p) = parsed_k {
                if k_part.is_some() {
                    return Err(perr(type_line, "more than one `DATA` entry gives k".into()));
                }
                k_part = Some(p);
            }
        }
        let (n, n_range) = n_part.ok_or_else(|| {
            perr(
                *data_line,
                "no `DATA` entry gives the real index n (only `tabulated k`)".into(),
            )
        })?;
        let (k, range_nm) = match k_part {
            Some((k, k_range)) => {
                let range = (n_range.0.max(k_range.0), n_range.1.min(k_range.1));
                if range.0 > range.1 {
                    return Err(perr(
                        *data_line,
                        format!(
                            "the n data ({}–{} nm) and k data ({}–{} nm) do not overlap",
                            n_range.0, n_range.1, k_range.0, k_range.1
                        ),
                    ));
                }
                (k, range)
            }
            None => (Dispersion::Constant(0.0), n_range),
        };
        Ok(Material {
            name,
            n,
            k,
            range_nm,
        })
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
            },
            k: Dispersion::Tabulated {
                wavelength_nm: w,
                value: rows.iter().map(|(_, r)| r[2]).collect(),
            },
            range_nm,
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
        let index = C64::new(self.n.eval(wavelength_nm), self.k.eval(wavelength_nm));
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

/// A minimal YAML document tree with the line of each node, enough for material files.
#[derive(Debug)]
enum Node {
    Scalar(String, TScalarStyle, usize),
    Seq(Vec<Node>, usize),
    Map(Vec<(String, Node)>, usize),
}

impl Node {
    fn line(&self) -> usize {
        match self {
            Node::Scalar(_, _, l) | Node::Seq(_, l) | Node::Map(_, l) => *l,
        }
    }
}

#[derive(Default)]
struct TreeBuilder {
    /// Open containers: (node, pending key for maps).
    stack: Vec<(Node, Option<String>)>,
    root: Option<Node>,
    error: Option<(usize, String)>,
}

impl TreeBuilder {
    fn push_value(&mut self, node: Node) {
        let line = node.line();
        match self.stack.last_mut() {
            None => {
                if self.root.is_none() {
                    self.root = Some(node);
                }
            }
            Some((Node::Seq(items, _), _)) => items.push(node),
            Some((Node::Map(entries, _), pending)) => match pending.take() {
                None => match node {
                    Node::Scalar(key, _, _) => *pending = Some(key),
                    _ => {
                        self.error
                            .get_or_insert((line, "mapping keys must be plain scalars".into()));
                    }
                },
                Some(key) => entries.push((key, node)),
            },
            Some((Node::Scalar(..), _)) => {}
        }
    }
}

impl MarkedEventReceiver for TreeBuilder {
    fn on_event(&mut self, ev: Event, mark: Marker) {
        let line = mark.line();
        match ev {
            Event::Scalar(value, style, _, _) => self.push_value(Node::Scalar(value, style, line)),
            Event::SequenceStart(..) => self.stack.push((Node::Seq(Vec::new(), line), None)),
            Event::MappingStart(..) => self.stack.push((Node::Map(Vec::new(), line), None)),
            Event::SequenceEnd | Event::MappingEnd => {
                if let Some((node, _)) = self.stack.pop() {
                    self.push_value(node);
                }
            }
            Event::Alias(_) => {
                self.error.get_or_insert((
                    line,
                    "YAML aliases are not supported in material files".into(),
                ));
            }
            _ => {}
        }
    }
}

fn parse_yaml_tree(text: &str) -> std::result::Result<Node, (usize, String)> {
    let mut builder = TreeBuilder::default();
    let mut parser = Parser::new_from_str(text);
    parser
        .load(&mut builder, false)
        .map_err(|e| (e.marker().line(), format!("malformed YAML: {}", e.info())))?;
    if let Some(e) = builder.error {
        return Err(e);
    }
    builder.root.ok_or_else(|| {
        (
            1,
            "empty document: expected a mapping with a `DATA` key".into(),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SILICA: &str = "\
# test file
REFERENCES: \"Malitson 1965\"
DATA:
  - type: formula 1
    wavelength_range: 0.21 6.7
    coefficients: 0 0.6961663 0.0684043 0.4079426 0.1162414 0.8974794 9.896161
";

    const METAL: &str = "\
REFERENCES: test
DATA:
  - type: tabulated nk
    data: |
        0.40 1.5 1.9
        0.50 1.0 2.0
        0.60 0.5 3.0
";

    #[test]
    fn sellmeier_fused_silica_at_sodium_d() {
        let m = Material::from_refractiveindex_yaml("silica", "s.yml", SILICA).unwrap();
        let n = m.index_at(587.56).unwrap();
        assert!((n.re - 1.4585).abs() < 1e-4, "{n}");
        assert_eq!(n.im, 0.0);
        assert_eq!(m.range_nm(), (210.0, 6700.0));
        let e = m.index_at(200.0).unwrap_err();
        assert!(matches!(e, Error::WavelengthOutOfRange { .. }), "{e}");
        assert!(e.to_string().contains("silica") && e.to_string().contains("210"));
    }

    #[test]
    fn tabulated_interpolates_linearly_and_refuses_extrapolation() {
        let m = Material::from_refractiveindex_yaml("m", "m.yml", METAL).unwrap();
        let n = m.index_at(450.0).unwrap();
        assert!((n.re - 1.25).abs() < 1e-15 && (n.im - 1.95).abs() < 1e-15);
        assert_eq!(m.index_at(600.0).unwrap(), C64::new(0.5, 3.0));
        assert_eq!(m.index_at(400.0).unwrap(), C64::new(1.5, 1.9));
        assert!(m.index_at(600.0001).is_err());
        assert!(m.index_at(399.9).is_err());
    }

    #[test]
    fn yaml_errors_name_the_line() {
        let bad = METAL.replace("0.50 1.0 2.0", "0.50 1.0 x2.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(e.to_string(), "m.yml:6: `x2.0` is not a finite number");
        let bad = METAL.replace("0.50 1.0 2.0", "0.30 1.0 2.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("m.yml:6: wavelengths must strictly increase"),
            "{e}"
        );
        let bad = METAL.replace("data: |\n", "data: |\n\n");
        let bad = bad.replace("0.50 1.0 2.0", "0.50 1.0 x2.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(e.to_string(), "m.yml:7: `x2.0` is not a finite number");
        let bad = METAL.replace("0.60 0.5 3.0", "0.60 0.5 -3.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("m.yml:7: k = -3 must be non-negative"),
            "{e}"
        );
        let e = Material::from_refractiveindex_yaml("m", "m.yml", "DATA: [").unwrap_err();
        assert!(e.to_string().contains("malformed YAML"), "{e}");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", "FOO: 1").unwrap_err();
        assert!(e.to_string().contains("no `DATA` key"), "{e}");
        let bad = SILICA.replace("formula 1", "formula 12");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert!(
            e.to_string().starts_with("m.yml:4: unsupported type"),
            "{e}"
        );
    }

    #[test]
    fn formula_with_tabulated_k_combines() {
        let text = "\
DATA:
  - type: formula 5
    wavelength_range: 0.3 0.9
    coefficients: 1.5 0.01 -2
  - type: tabulated k
    data: |
        0.35 0.1
        0.80 0.2
";
        let m = Material::from_refractiveindex_yaml("c", "c.yml", text).unwrap();
        assert_eq!(m.range_nm(), (350.0, 800.0));
        let n = m.index_at(500.0).unwrap();
        assert!((n.re - (1.5 + 0.01 / 0.25)).abs() < 1e-14);
        assert!((n.im - (0.1 + 0.1 * 150.0 / 450.0)).abs() < 1e-14);
    }

    #[test]
    fn csv_reads_and_reports_lines() {
        let text = "# source: test\nwavelength_nm,n,k\n400,1.5,0\n500,1.6,0.1\n";
        let m = Material::from_nk_csv("c", "c.csv", text).unwrap();
        let n = m.index_at(450.0).unwrap();
        assert!((n.re - 1.55).abs() < 1e-15 && (n.im - 0.05).abs() < 1e-15);
        let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n400,1.5\n").unwrap_err();
        assert!(e.to_string().starts_with("c.csv:2: expected 3"), "{e}");
        let e = Material::from_nk_csv("c", "c.csv", "lambda,n,k\n").unwrap_err();
        assert!(
            e.to_string().starts_with("c.csv:1: expected the header"),
            "{e}"
        );
        let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n400,1.5,0\n300,1.5,0\n")
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("c.csv:3: wavelengths must strictly increase"),
            "{e}"
        );
        let e =
            Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n400,1.5,nan\n").unwrap_err();
        assert!(e.to_string().starts_with("c.csv:2: k `nan`"), "{e}");
    }

    #[test]
    fn csv_accepts_bom_crlf_comments_quotes_and_spaces() {
        let plain = "wavelength_nm,n,k\n400,1.5,0\n500,1.6,0.1\n650,1.7,0.25\n";
        let fancy = "\u{feff}# measured by hand\r\n\r\n  Wavelength_nm , \"n\", k \r\n\
                     # visible\r\n400, 1.5 ,0\r\n  # indented comment\r\n\
                     \"500\",\"1.6\" , \"0.1\"\r\n   \r\n 650 ,1.7,\t0.25";
        let a = Material::from_nk_csv("c", "c.csv", plain).unwrap();
        let b = Material::from_nk_csv("c", "c.csv", fancy).unwrap();
        assert_eq!(a, b);
        // Errors name the line the row is on, past the BOM, comments and CRLF.
        let e = Material::from_nk_csv("c", "c.csv", &fancy.replace("1.7", "1.7x")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.csv:9: n `1.7x` is not a finite number",
            "{fancy:?}"
        );
        let e = Material::from_nk_csv("c", "c.csv", &fancy.replace("1.6", "-1.6")).unwrap_err();
        assert!(e.to_string().starts_with("c.csv:7: n = -1.6"), "{e}");
        let e = Material::from_nk_csv("c", "c.csv", "\u{feff}#\r\nlambda,n,k\r\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.csv:2: expected the header `wavelength_nm,n,k`, found `lambda,n,k`"
        );
        let e = Material::from_nk_csv("c", "c.csv", "# nothing\n\n").unwrap_err();
        assert!(e.to_string().starts_with("c.csv:0: no header"), "{e}");
        let e = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n# none\n").unwrap_err();
        assert!(e.to_string().starts_with("c.csv:0: no data rows"), "{e}");
    }

    #[test]
    fn index_literals() {
        assert_eq!(
            Material::parse_index("1.33")
                .unwrap()
                .index_at(500.0)
                .unwrap(),
            C64::new(1.33, 0.0)
        );
        for text in ["0.27+2.9i", "0.27 + 2.9i", "0.27+2.9j", "2.7e-1+2.9i"] {
            let m = Material::parse_index(text).unwrap();
            assert_eq!(m.index_at(500.0).unwrap(), C64::new(0.27, 2.9), "{text}");
        }
        assert_eq!(
            Material::parse_index("1.5+1e-2i")
                .unwrap()
                .index_at(1.0)
                .unwrap(),
            C64::new(1.5, 0.01)
        );
        for bad in [
            "", "abc", "1.5-0.1i", "-1.5", "0", "1.5+i", "inf", "nan", "1.5+2.0",
        ] {
            assert!(Material::parse_index(bad).is_err(), "{bad} accepted");
        }
        let e = Material::parse_index("1.5-0.1i").unwrap_err();
        assert!(e.to_string().contains("κ"), "{e}");
    }
}
