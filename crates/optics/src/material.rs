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

use crate::elementary::{self, powf};
use crate::error::{Error, Result};
use num_complex::Complex64 as C64;
use yaml_rust2::parser::{Event, MarkedEventReceiver, Parser};
use yaml_rust2::scanner::{Marker, TScalarStyle};

/// One real quantity (n or κ) as a function of vacuum wavelength.
#[derive(Clone, Debug, PartialEq)]
enum Dispersion {
    /// Independent of wavelength.
    Constant(f64),
    /// Samples at strictly increasing wavelengths (nm), linearly interpolated; outside
    /// them 0 when `zero_outside` (κ beyond its own table), else never asked for (n: the
    /// material's range is the table's).
    Tabulated {
        wavelength_nm: Vec<f64>,
        value: Vec<f64>,
        zero_outside: bool,
    },
    /// A refractiveindex.info dispersion formula evaluated with λ in µm; gives n.
    Formula { kind: u8, coefficients: Vec<f64> },
}

impl Dispersion {
    fn eval(&self, wavelength_nm: f64) -> f64 {
        self.eval_from(wavelength_nm, &mut Cursor::default())
    }

    /// [`Dispersion::eval`] (the same bits), a tabulated value found from `cursor` (the
    /// segment of the previous wavelength asked for) when the wavelengths ascend, so that a
    /// sweep walks the table once instead of searching it per wavelength.
    fn eval_from(&self, wavelength_nm: f64, cursor: &mut Cursor) -> f64 {
        match self {
            Dispersion::Constant(v) => *v,
            Dispersion::Tabulated {
                wavelength_nm: w,
                value,
                zero_outside,
            } => {
                if *zero_outside && !(wavelength_nm >= w[0] && wavelength_nm <= w[w.len() - 1]) {
                    0.0
                } else {
                    cursor.interpolate(w, value, wavelength_nm)
                }
            }
            Dispersion::Formula { kind, coefficients } => {
                eval_formula(*kind, coefficients, wavelength_nm * 1e-3)
            }
        }
    }
}

/// Where the previous interpolation in a table was: the first sample strictly greater than
/// the previous wavelength `at` (+∞ before any, so that the first is searched for).
#[derive(Clone, Copy, Debug)]
struct Cursor {
    first_above: usize,
    at: f64,
}

impl Default for Cursor {
    fn default() -> Self {
        Cursor {
            first_above: 0,
            at: f64::INFINITY,
        }
    }
}

impl Cursor {
    /// Linear interpolation in `x` (strictly increasing, `x[0] <= at <= x[last]`).
    fn interpolate(&mut self, x: &[f64], y: &[f64], at: f64) -> f64 {
        if x.len() == 1 {
            return y[0];
        }
        // First sample strictly greater than `at`: a few steps on from the previous one while
        // the wavelengths ascend, else searched for (the same index either way).
        let mut first_above = 0;
        if at >= self.at {
            first_above = self.first_above;
            for _ in 0..4 {
                if first_above < x.len() && x[first_above] <= at {
                    first_above += 1;
                }
            }
        }
        if first_above < x.len() && x[first_above] <= at {
            first_above += x[first_above..].partition_point(|&v| v <= at);
        }
        *self = Cursor { first_above, at };
        // Clamped so that [i-1, i] is a segment.
        let i = first_above.clamp(1, x.len() - 1);
        let (x0, x1, y0, y1) = (x[i - 1], x[i], y[i - 1], y[i]);
        let t = (at - x0) / (x1 - x0);
        y0 + t * (y1 - y0)
    }
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
        3 => (coef(0) + pairs(1).map(|(a, b)| a * powf(l, b)).sum::<f64>()).sqrt(),
        4 => {
            let mut n2 = coef(0)
                + coef(1) * powf(l, coef(2)) / (l2 - powf(coef(3), coef(4)))
                + coef(5) * powf(l, coef(6)) / (l2 - powf(coef(7), coef(8)));
            n2 += pairs(9).map(|(a, b)| a * powf(l, b)).sum::<f64>();
            n2.sqrt()
        }
        5 => coef(0) + pairs(1).map(|(a, b)| a * powf(l, b)).sum::<f64>(),
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

    /// Reads the refractiveindex.info database YAML format (see module docs, and the
    /// policy for imperfect pages there). `source_name` labels errors and warnings
    /// (`file:line`); what was repaired or set aside is in [`Material::warnings`].
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
        let mut warnings = Vec::new();
        let mut warn = |line: usize, kind: WarningKind| {
            warnings.push(MaterialWarning {
                source_name: source_name.to_string(),
                line,
                kind,
            });
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
        // (dispersion, range nm, line of its range, line of the entry's `type`)
        let mut n_part: Option<(Dispersion, (f64, f64), usize, usize)> = None;
        let mut k_part: Option<(Table, usize)> = None;
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
                let (range_nm, range_line) = match get("wavelength_range") {
                    Some(Node::Scalar(s, _, line)) => {
                        let v = s
                            .split_whitespace()
                            .map(|t| um_to_nm(t).ok_or_else(|| t.to_string()))
                            .collect::<std::result::Result<Vec<f64>, String>>()
                            .map_err(|tok| {
                                perr(
                                    *line,
                                    format!(
                                        "wavelength_range value `{tok}` is not a finite number"
                                    ),
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
                        ((v[0], v[1]), *line)
                    }
                    Some(other) => {
                        return Err(perr(
                            other.line(),
                            "`wavelength_range` must be two numbers".into(),
                        ));
                    }
                    None => ((0.0, f64::INFINITY), type_line),
                };
                (
                    Some((
                        Dispersion::Formula { kind, coefficients },
                        range_nm,
                        range_line,
                        type_line,
                    )),
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
                let mut rows: Vec<TableRow> = Vec::new();
                for (i, row) in block.lines().enumerate() {
                    let line = first_line + i;
                    if row.trim().is_empty() {
                        continue;
                    }
                    let tokens: Vec<&str> = row.split_whitespace().collect();
                    let v = parse_numbers(row)
                        .map_err(|tok| perr(line, format!("`{tok}` is not a finite number")))?;
                    if v.len() != columns {
                        return Err(perr(
                            line,
                            format!("`{ty}` rows need {columns} numbers, found {}", v.len()),
                        ));
                    }
                    if !(v[0] > 0.0) {
                        return Err(perr(
                            line,
                            format!("wavelength {} µm must be positive", v[0]),
                        ));
                    }
                    let wavelength_nm = um_to_nm(tokens[0]).expect("parsed above");
                    rows.push(TableRow {
                        line,
                        wavelength_um: v[0],
                        wavelength_nm,
                        values: v[1..].to_vec(),
                    });
                }
                if rows.is_empty() {
                    return Err(perr(first_line, format!("`{ty}` entry has no data rows")));
                }
                // Rows out of order are sorted (stably: rows at one wavelength keep their
                // order), each named once.
                for pair in rows.windows(2) {
                    if pair[1].wavelength_nm < pair[0].wavelength_nm {
                        warn(
                            pair[1].line,
                            WarningKind::OutOfOrder {
                                wavelength_um: pair[1].wavelength_um,
                                previous_um: pair[0].wavelength_um,
                            },
                        );
                    }
                }
                rows.sort_by(|a, b| a.wavelength_nm.total_cmp(&b.wavelength_nm));
                // Rows repeating a wavelength with other values: named once each.
                for group in rows.chunk_by(|a, b| a.wavelength_nm == b.wavelength_nm) {
                    for r in &group[1..] {
                        if r.values != group[0].values {
                            warn(
                                r.line,
                                WarningKind::Repeated {
                                    wavelength_um: r.wavelength_um,
                                    first_line: group[0].line,
                                },
                            );
                        }
                    }
                }
                let (n_col, k_col) = match ty.as_str() {
                    "tabulated nk" => (Some(0), Some(1)),
                    "tabulated n" => (Some(0), None),
                    _ => (None, Some(0)),
                };
                let n = n_col.map(|c| {
                    tabulate(
                        &rows,
                        c,
                        |v| v > 0.0,
                        |row, v| {
                            warn(
                                row.line,
                                WarningKind::NonPositiveN {
                                    wavelength_um: row.wavelength_um,
                                    n: v,
                                },
                            )
                        },
                    )
                });
                let k = k_col.map(|c| {
                    tabulate(
                        &rows,
                        c,
                        |v| v >= 0.0,
                        |row, v| {
                            warn(
                                row.line,
                                WarningKind::NegativeK {
                                    wavelength_um: row.wavelength_um,
                                    k: v,
                                },
                            )
                        },
                    )
                });
                let n = match n {
                    Some(None) => {
                        return Err(perr(
                            first_line,
                            format!("`{ty}` entry has no row with n > 0"),
                        ));
                    }
                    Some(Some(t)) => {
                        let range = t.range();
                        Some((t.into_dispersion(), range, type_line, type_line))
                    }
                    None => None,
                };
                // A k table whose every value is negative gives no k: k = 0 (each row named).
                let k = k.flatten().map(|t| (t, type_line));
                (n, k)
            };
            if let Some(p) = parsed_n {
                match &n_part {
                    Some((_, _, _, first)) => warn(
                        type_line,
                        WarningKind::SecondEntry {
                            quantity: 'n',
                            first_line: *first,
                        },
                    ),
                    None => n_part = Some(p),
                }
            }
            if let Some((table, line)) = parsed_k {
                match &k_part {
                    Some((_, first)) => warn(
                        line,
                        WarningKind::SecondEntry {
                            quantity: 'k',
                            first_line: *first,
                        },
                    ),
                    None => k_part = Some((table, line)),
                }
            }
        }
        let (n, mut range_nm, n_line, _) = n_part.ok_or_else(|| {
            perr(
                *data_line,
                "no `DATA` entry gives the real index n (only `tabulated k`): the page cannot be used alone".into(),
            )
        })?;
        // A formula non-physical somewhere inside its stated range: its ends are cut off,
        // a gap inside is refused.
        let mut gaps_nm = Vec::new();
        if matches!(n, Dispersion::Formula { .. }) && range_nm.1.is_finite() {
            let physical = |w: f64| {
                let v = n.eval(w);
                v > 0.0 && v.is_finite()
            };
            match formula_gaps(&physical, range_nm) {
                None => {
                    return Err(perr(
                        n_line,
                        format!(
                            "the formula gives no physical n (n > 0) anywhere in its wavelength_range {}–{} nm",
                            range_nm.0, range_nm.1
                        ),
                    ));
                }
                Some((usable, gaps)) => {
                    if usable != range_nm {
                        warn(
                            n_line,
                            WarningKind::FormulaRangeCut {
                                stated_nm: range_nm,
                                usable_nm: usable,
                            },
                        );
                    }
                    for &(from_nm, to_nm) in &gaps {
                        warn(n_line, WarningKind::FormulaGap { from_nm, to_nm });
                    }
                    range_nm = usable;
                    gaps_nm = gaps;
                }
            }
        }
        let k = match k_part {
            Some((k, k_line)) => {
                // k = 0 outside k's table; named when the table ends inside n's range at a
                // k that is not negligible.
                let (w, v) = (&k.wavelength_nm, &k.value);
                let (first, last) = (0, w.len() - 1);
                for (i, lower, inside) in [
                    (first, true, w[first] > range_nm.0),
                    (last, false, w[last] < range_nm.1),
                ] {
                    if inside && v[i] >= K_STEP_WARNING && w[i] >= range_nm.0 && w[i] <= range_nm.1
                    {
                        warn(
                            k.lines[i],
                            WarningKind::KTableEnds {
                                wavelength_nm: w[i],
                                lower,
                                k: v[i],
                                n_range_nm: range_nm,
                            },
                        );
                    }
                }
                if w[last] < range_nm.0 || w[first] > range_nm.1 {
                    warn(
                        k_line,
                        WarningKind::KOutsideN {
                            k_range_nm: (w[first], w[last]),
                            n_range_nm: range_nm,
                        },
                    );
                }
                k.into_dispersion_zero_outside()
            }
            None => Dispersion::Constant(0.0),
        };
        warnings.sort_by_key(|w| w.line);
        Ok(Material {
            name,
            n,
            k,
            range_nm,
            gaps_nm,
            warnings,
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

/// κ at the end of a `tabulated k` table, inside n's range, from which the step to κ = 0
/// beyond the table is worth a warning.
pub const K_STEP_WARNING: f64 = 1e-3;

/// Samples a formula's stated range at this many points (logarithmically spaced) to find
/// where it turns non-physical, then bisects each edge.
const FORMULA_SCAN_POINTS: usize = 8192;

/// Something in a material file that the reader repaired or set aside; the material is
/// usable (docs/materials.md, "Pages of the refractiveindex.info database").
/// `Display` writes `file:line: what was done`.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialWarning {
    /// The file (or other label) the text came from.
    pub source_name: String,
    /// The 1-based line concerned.
    pub line: usize,
    /// What was found and done.
    pub kind: WarningKind,
}

/// What a [`MaterialWarning`] reports.
#[derive(Clone, Debug, PartialEq)]
pub enum WarningKind {
    /// A row whose wavelength is below the previous row's: the table is sorted.
    OutOfOrder {
        /// The row's wavelength, µm.
        wavelength_um: f64,
        /// The previous row's, µm.
        previous_um: f64,
    },
    /// A row at the wavelength of an earlier row, with other values: the rows are merged
    /// into their mean (identical repeated rows are merged without a warning).
    Repeated {
        /// The wavelength, µm.
        wavelength_um: f64,
        /// The first row at that wavelength.
        first_line: usize,
    },
    /// A row's n ≤ 0: that n is skipped (the row's κ is kept).
    NonPositiveN {
        /// The row's wavelength, µm.
        wavelength_um: f64,
        /// The value found.
        n: f64,
    },
    /// A row's κ < 0 (gain): that κ is skipped (the row's n is kept).
    NegativeK {
        /// The row's wavelength, µm.
        wavelength_um: f64,
        /// The value found.
        k: f64,
    },
    /// A second `DATA` entry giving n (or κ): the first one's is used, this one's ignored.
    SecondEntry {
        /// `'n'` or `'k'`.
        quantity: char,
        /// The `type` line of the entry used.
        first_line: usize,
    },
    /// κ's table ends inside n's range at κ ≥ [`K_STEP_WARNING`]: κ = 0 beyond it.
    KTableEnds {
        /// The table's end, nm.
        wavelength_nm: f64,
        /// Whether it is the table's lower end (κ = 0 below it) or its upper end.
        lower: bool,
        /// κ there.
        k: f64,
        /// n's range (the material's), nm.
        n_range_nm: (f64, f64),
    },
    /// κ's table lies wholly outside n's range: κ = 0 throughout.
    KOutsideN {
        /// κ's table, nm.
        k_range_nm: (f64, f64),
        /// n's range, nm.
        n_range_nm: (f64, f64),
    },
    /// A formula that gives no physical n (n ≤ 0 or n² < 0) at an end of its stated
    /// `wavelength_range`: the range is cut to where it does.
    FormulaRangeCut {
        /// The stated range, nm.
        stated_nm: (f64, f64),
        /// The range kept, nm.
        usable_nm: (f64, f64),
    },
    /// A formula that gives no physical n over an interval inside its range (e.g. across a
    /// resonance): wavelengths there are refused ([`Error::NoPhysicalIndex`]).
    FormulaGap {
        /// Start of the interval, nm (exclusive).
        from_nm: f64,
        /// End of the interval, nm (exclusive).
        to_nm: f64,
    },
}

impl std::fmt::Display for MaterialWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: ", self.source_name, self.line)?;
        match &self.kind {
            WarningKind::OutOfOrder {
                wavelength_um,
                previous_um,
            } => write!(
                f,
                "wavelength {wavelength_um} µm follows {previous_um} µm: the rows are sorted by wavelength"
            ),
            WarningKind::Repeated {
                wavelength_um,
                first_line,
            } => write!(
                f,
                "wavelength {wavelength_um} µm repeats line {first_line} with other values: their mean is used"
            ),
            WarningKind::NonPositiveN { wavelength_um, n } => write!(
                f,
                "n = {n} at {wavelength_um} µm is not positive: this n is skipped"
            ),
            WarningKind::NegativeK { wavelength_um, k } => write!(
                f,
                "k = {k} at {wavelength_um} µm is negative (gain): this k is skipped"
            ),
            WarningKind::SecondEntry {
                quantity,
                first_line,
            } => write!(
                f,
                "a second entry giving {quantity}: the entry of line {first_line} gives it, this one's {quantity} is ignored"
            ),
            WarningKind::KTableEnds {
                wavelength_nm,
                lower,
                k,
                n_range_nm,
            } => write!(
                f,
                "k is tabulated only {} {wavelength_nm} nm (k = {k} there) inside n's range {}–{} nm: k = 0 beyond its table",
                if *lower { "from" } else { "up to" },
                n_range_nm.0,
                n_range_nm.1
            ),
            WarningKind::KOutsideN {
                k_range_nm,
                n_range_nm,
            } => write!(
                f,
                "k is tabulated over {}–{} nm, outside n's range {}–{} nm: k = 0 throughout",
                k_range_nm.0, k_range_nm.1, n_range_nm.0, n_range_nm.1
            ),
            WarningKind::FormulaRangeCut {
                stated_nm,
                usable_nm,
            } => write!(
                f,
                "the formula gives no physical n at the ends of its wavelength_range {}–{} nm: only {}–{} nm is used",
                stated_nm.0, stated_nm.1, usable_nm.0, usable_nm.1
            ),
            WarningKind::FormulaGap { from_nm, to_nm } => write!(
                f,
                "the formula gives no physical n between {from_nm} and {to_nm} nm, inside its wavelength_range: wavelengths there are refused"
            ),
        }
    }
}

/// One row of a `tabulated` block.
struct TableRow {
    line: usize,
    wavelength_um: f64,
    wavelength_nm: f64,
    values: Vec<f64>,
}

/// One quantity's samples from a table: wavelengths (nm, strictly increasing), values, and
/// the line each sample came from (the first row at that wavelength).
struct Table {
    wavelength_nm: Vec<f64>,
    value: Vec<f64>,
    lines: Vec<usize>,
}

impl Table {
    fn range(&self) -> (f64, f64) {
        (
            self.wavelength_nm[0],
            self.wavelength_nm[self.wavelength_nm.len() - 1],
        )
    }

    fn into_dispersion(self) -> Dispersion {
        Dispersion::Tabulated {
            wavelength_nm: self.wavelength_nm,
            value: self.value,
            zero_outside: false,
        }
    }

    fn into_dispersion_zero_outside(self) -> Dispersion {
        Dispersion::Tabulated {
            wavelength_nm: self.wavelength_nm,
            value: self.value,
            zero_outside: true,
        }
    }
}

/// Column `col` of `rows` (sorted by wavelength) as a table: values failing `valid` are
/// skipped (each reported to `skipped`), values at one wavelength merged into their mean.
/// None when no value is valid.
fn tabulate(
    rows: &[TableRow],
    col: usize,
    valid: impl Fn(f64) -> bool,
    mut skipped: impl FnMut(&TableRow, f64),
) -> Option<Table> {
    let mut t = Table {
        wavelength_nm: Vec::new(),
        value: Vec::new(),
        lines: Vec::new(),
    };
    for group in rows.chunk_by(|a, b| a.wavelength_nm == b.wavelength_nm) {
        let mut sum = 0.0;
        let mut count = 0u32;
        for r in group {
            let v = r.values[col];
            if valid(v) {
                sum += v;
                count += 1;
            } else {
                skipped(r, v);
            }
        }
        if count > 0 {
            t.wavelength_nm.push(group[0].wavelength_nm);
            t.value.push(sum / f64::from(count));
            t.lines.push(group[0].line);
        }
    }
    (!t.value.is_empty()).then_some(t)
}

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

/// A wavelength interval, nm: (from, to).
type Range = (f64, f64);

/// Where a formula is physical over `range` (nm): the usable range (the stated one with any
/// non-physical ends cut off) and the non-physical open intervals inside it. None when it
/// is physical nowhere. The range is sampled at [`FORMULA_SCAN_POINTS`] points, each edge
/// found by bisection and moved to a short decimal on the physical side.
fn formula_gaps(physical: &dyn Fn(f64) -> bool, range: (f64, f64)) -> Option<(Range, Vec<Range>)> {
    let (lo, hi) = range;
    let last = FORMULA_SCAN_POINTS - 1;
    let at = |i: usize| match i {
        0 => lo,
        i if i == last => hi,
        i => lo * powf(hi / lo, i as f64 / last as f64),
    };
    let ok: Vec<bool> = (0..FORMULA_SCAN_POINTS).map(|i| physical(at(i))).collect();
    if ok.iter().all(|&b| b) {
        return Some((range, Vec::new()));
    }
    let first_ok = ok.iter().position(|&b| b)?;
    let last_ok = ok.iter().rposition(|&b| b)?;
    // The edge between a physical `good` and a non-physical `bad` wavelength, on the
    // physical side, as a short decimal when one is physical and between them.
    let edge = |good: f64, bad: f64| {
        let (mut g, mut b) = (good, bad);
        for _ in 0..200 {
            let m = 0.5 * (g + b);
            if m == g || m == b {
                break;
            }
            if physical(m) {
                g = m;
            } else {
                b = m;
            }
        }
        (7..=15)
            .map(|digits| round_away(g, b, digits))
            .find(|&c| physical(c) && (c - good) * (c - b) <= 0.0 && (c - g) * (c - b) >= 0.0)
            .unwrap_or(g)
    };
    let usable = (
        if first_ok == 0 {
            lo
        } else {
            edge(at(first_ok), at(first_ok - 1))
        },
        if last_ok == last {
            hi
        } else {
            edge(at(last_ok), at(last_ok + 1))
        },
    );
    let mut gaps = Vec::new();
    let mut i = first_ok;
    while i < last_ok {
        if ok[i] && !ok[i + 1] {
            let j = (i + 1..=last_ok)
                .find(|&j| ok[j])
                .expect("last_ok is physical");
            gaps.push((edge(at(i), at(i + 1)), edge(at(j), at(j - 1))));
            i = j;
        } else {
            i += 1;
        }
    }
    Some((usable, gaps))
}

/// `x` rounded to `digits` significant decimal digits, away from `from` (so that the result
/// is not nearer to `from` than `x` is).
fn round_away(x: f64, from: f64, digits: i32) -> f64 {
    let scale = elementary::powi(10.0, digits - 1 - elementary::log10(x.abs()).floor() as i32);
    let r = if x > from {
        (x * scale).ceil() / scale
    } else {
        (x * scale).floor() / scale
    };
    // Print-friendly: the shortest decimal of r.
    format!("{r:.*e}", (digits - 1) as usize)
        .parse()
        .unwrap_or(r)
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

    /// The table walk of `indices_at` gives `index_at`'s bits and errors in any order of
    /// wavelengths: ascending (walked), descending and shuffled (searched), repeated,
    /// on the samples, between them, and outside the range.
    #[test]
    fn indices_at_is_index_at_in_any_order() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tables/materials/au.yml"
        ))
        .unwrap();
        let gold = Material::from_refractiveindex_yaml("au", "au.yml", &text).unwrap();
        let metal = Material::from_refractiveindex_yaml("m", "m.yml", METAL).unwrap();
        let silica = Material::from_refractiveindex_yaml("s", "s.yml", SILICA).unwrap();
        let ascending: Vec<f64> = (0..2000).map(|k| 200.0 + 0.37 * k as f64).collect();
        let mut shuffled = ascending.clone();
        // A fixed permutation (multiplicative, 2000 and 1237 coprime).
        for (k, w) in shuffled.iter_mut().enumerate() {
            *w = ascending[(k * 1237) % ascending.len()];
        }
        let descending: Vec<f64> = ascending.iter().rev().copied().collect();
        let mut sparse: Vec<f64> = vec![400.0, 400.0, 400.0, 450.0, 500.0, 500.0, 600.0];
        sparse.extend([401.0, 599.9, 600.0, 1e-3, 0.0, -5.0, f64::NAN, 800.0, 430.0]);
        for m in [&gold, &metal, &silica] {
            for list in [&ascending, &shuffled, &descending, &sparse] {
                // Every prefix: the values' bits, or the first wavelength's error.
                let one: Vec<Result<C64>> = list.iter().map(|&w| m.index_at(w)).collect();
                for k in 0..list.len() {
                    let want: Result<Vec<C64>> = one[..=k].iter().cloned().collect();
                    let bits = |v: Vec<C64>| -> Vec<(u64, u64)> {
                        v.iter().map(|n| (n.re.to_bits(), n.im.to_bits())).collect()
                    };
                    let got = m.indices_at(&list[..=k]);
                    assert_eq!(
                        want.map(bits).map_err(|e| e.to_string()),
                        got.map(bits).map_err(|e| e.to_string()),
                        "{} at {} nm",
                        m.name(),
                        list[k]
                    );
                }
            }
        }
    }

    #[test]
    fn yaml_errors_name_the_line() {
        let bad = METAL.replace("0.50 1.0 2.0", "0.50 1.0 x2.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(e.to_string(), "m.yml:6: `x2.0` is not a finite number");
        let bad = METAL.replace("0.50 1.0 2.0", "0.50 1.0 2.0 7");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.yml:6: `tabulated nk` rows need 3 numbers, found 4"
        );
        let bad = METAL.replace("0.50 1.0 2.0", "-0.50 1.0 2.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.yml:6: wavelength -0.5 µm must be positive"
        );
        let bad = METAL.replace("data: |\n", "data: |\n\n");
        let bad = bad.replace("0.50 1.0 2.0", "0.50 1.0 x2.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(e.to_string(), "m.yml:7: `x2.0` is not a finite number");
        let bad = METAL
            .replace("1.5 1.9", "-1.5 1.9")
            .replace("1.0 2.0", "0 2.0");
        let bad = bad.replace("0.5 3.0", "-0.5 3.0");
        let e = Material::from_refractiveindex_yaml("m", "m.yml", &bad).unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.yml:5: `tabulated nk` entry has no row with n > 0"
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
        // n's range; κ = 0 outside κ's table (its ends, 0.1 and 0.2, are named).
        assert_eq!(m.range_nm(), (300.0, 900.0));
        assert_eq!(m.index_at(300.0).unwrap().im, 0.0);
        assert_eq!(m.warnings().len(), 2);
        let n = m.index_at(500.0).unwrap();
        assert!((n.re - (1.5 + 0.01 / 0.25)).abs() < 1e-14);
        assert!((n.im - (0.1 + 0.1 * 150.0 / 450.0)).abs() < 1e-14);
    }

    fn warnings_of(m: &Material) -> Vec<String> {
        m.warnings().iter().map(ToString::to_string).collect()
    }

    #[test]
    fn repeated_rows_are_merged_and_unordered_rows_sorted() {
        // Line 5 repeats line 4 exactly (merged silently); line 7 repeats line 6 with other
        // values (merged into their mean, named); line 9 is out of order (sorted, named).
        let text = "\
DATA:
  - type: tabulated nk
    data: |
        0.40 1.5 1.9
        0.40 1.5 1.9
        0.50 1.0 2.0
        0.50 1.2 2.2
        0.70 0.5 3.0
        0.60 0.7 2.5
";
        let m = Material::from_refractiveindex_yaml("m", "m.yml", text).unwrap();
        assert_eq!(
            warnings_of(&m),
            [
                "m.yml:7: wavelength 0.5 µm repeats line 6 with other values: their mean is used",
                "m.yml:9: wavelength 0.6 µm follows 0.7 µm: the rows are sorted by wavelength",
            ]
        );
        assert_eq!(m.range_nm(), (400.0, 700.0));
        let at = |w: f64| m.index_at(w).unwrap();
        assert!((at(500.0) - C64::new(1.1, 2.1)).norm() < 1e-15);
        assert_eq!(at(600.0), C64::new(0.7, 2.5));
        assert_eq!(at(400.0), C64::new(1.5, 1.9));
    }

    #[test]
    fn unphysical_values_are_skipped_with_their_lines() {
        // k < 0 at line 4 (k skipped, n kept); n ≤ 0 at the last row (n skipped: the range
        // ends at the row before; k kept but beyond n's range unused).
        let text = "\
DATA:
  - type: tabulated nk
    data: |
        0.40 1.5 -0.2
        0.50 1.0 2.0
        0.60 0.5 3.0
        900 -256 1265
";
        let m = Material::from_refractiveindex_yaml("m", "m.yml", text).unwrap();
        assert_eq!(
            warnings_of(&m),
            [
                "m.yml:4: k = -0.2 at 0.4 µm is negative (gain): this k is skipped",
                "m.yml:5: k is tabulated only from 500 nm (k = 2 there) inside n's range 400–600 nm: k = 0 beyond its table",
                "m.yml:7: n = -256 at 900 µm is not positive: this n is skipped",
            ]
        );
        assert_eq!(m.range_nm(), (400.0, 600.0));
        // κ's table now starts at 500 nm (κ = 2, named): κ = 0 below it.
        assert_eq!(m.index_at(400.0).unwrap(), C64::new(1.5, 0.0));
        assert_eq!(m.index_at(550.0).unwrap(), C64::new(0.75, 2.5));
    }

    #[test]
    fn micrometres_convert_to_the_decimal_nanometres() {
        assert_eq!(um_to_nm("0.017586"), Some(17.586));
        assert_eq!(um_to_nm("2.479684"), Some(2479.684));
        assert_eq!(um_to_nm("1.5E-2"), Some(15.0));
        assert_eq!(um_to_nm("2.36e-3"), Some(2.36));
        assert_eq!(um_to_nm("7e5"), Some(7e8));
        assert_eq!(um_to_nm("x"), None);
        assert_eq!(um_to_nm("inf"), None);
        let text = "DATA:\n  - type: tabulated nk\n    data: |\n        0.017586 0.9 0.3\n        2.479684 0.2 14\n";
        let m = Material::from_refractiveindex_yaml("m", "m.yml", text).unwrap();
        assert_eq!(m.range_nm(), (17.586, 2479.684));
        m.index_at(17.586).unwrap();
        m.index_at(2479.684).unwrap();
    }

    #[test]
    fn formula_n_with_a_narrower_k_table_covers_the_formula_range() {
        // κ tabulated over 0.5–0.8 µm only: κ = 0 outside it (κ = 0.2 at its upper end is
        // not negligible: named); the formula's whole range is usable.
        let text = "\
DATA:
  - type: formula 5
    wavelength_range: 0.4 13.9
    coefficients: 2.4 0.01 -2
  - type: tabulated k
    data: |
        0.50 0.0001
        0.80 0.2
";
        let m = Material::from_refractiveindex_yaml("c", "c.yml", text).unwrap();
        assert_eq!(m.range_nm(), (400.0, 13900.0));
        assert_eq!(m.index_at(450.0).unwrap().im, 0.0);
        assert!((m.index_at(650.0).unwrap().im - 0.10005).abs() < 1e-12);
        assert_eq!(m.index_at(13900.0).unwrap().im, 0.0);
        assert_eq!(
            warnings_of(&m),
            [
                "c.yml:8: k is tabulated only up to 800 nm (k = 0.2 there) inside n's range 400–13900 nm: k = 0 beyond its table"
            ]
        );
    }

    #[test]
    fn a_second_entry_giving_n_is_ignored() {
        let text = "\
DATA:
  - type: formula 5
    wavelength_range: 0.375 1
    coefficients: 1.5 0.002 -2
  - type: tabulated nk
    data: |
        0.375 1.9 0.004
        1.0 1.9 0.001
";
        let m = Material::from_refractiveindex_yaml("c", "c.yml", text).unwrap();
        assert_eq!(
            warnings_of(&m),
            [
                "c.yml:5: a second entry giving n: the entry of line 2 gives it, this one's n is ignored"
            ]
        );
        let n = m.index_at(500.0).unwrap();
        assert!((n.re - 1.508).abs() < 1e-12 && n.im > 0.001, "{n}");
    }

    #[test]
    fn a_formula_non_physical_inside_its_range_is_cut_or_refused_there() {
        // Formula 2 with a pole at λ² = 4 (2 µm): n² < 0 just above it, down to where
        // 1 + 1·λ²/(λ² − 4) = 0, i.e. λ² = 2 … 4: n is non-physical for √2 < λ < 2 µm.
        let text = "\
DATA:
  - type: formula 2
    wavelength_range: 0.5 5
    coefficients: 0 1 4
";
        let m = Material::from_refractiveindex_yaml("p", "p.yml", text).unwrap();
        assert_eq!(m.range_nm(), (500.0, 5000.0));
        let &[(a, b)] = m.gaps_nm() else {
            panic!("{:?}", m.gaps_nm())
        };
        assert!(
            a <= 2f64.sqrt() * 1e3 && a > 1414.2 && (2000.0..2000.01).contains(&b),
            "{a} {b}"
        );
        m.index_at(a).unwrap();
        m.index_at(b).unwrap();
        let e = m.index_at(1700.0).unwrap_err();
        assert!(matches!(e, Error::NoPhysicalIndex { .. }), "{e}");
        assert_eq!(
            e.to_string(),
            format!(
                "material `p` has no physical index at 1700 nm: its formula gives none between {a} and {b} nm (choose wavelengths outside that interval or another page)"
            )
        );
        assert_eq!(
            warnings_of(&m),
            [format!(
                "p.yml:3: the formula gives no physical n between {a} and {b} nm, inside its wavelength_range: wavelengths there are refused"
            )]
        );
        // Non-physical at an end: the range is cut.
        let cut = text.replace("0.5 5", "1.5 5");
        let m = Material::from_refractiveindex_yaml("p", "p.yml", &cut).unwrap();
        assert_eq!(m.range_nm().0, b);
        assert!(m.gaps_nm().is_empty());
        assert!(warnings_of(&m)[0].contains("only"), "{:?}", warnings_of(&m));
        // Nowhere physical: an error naming the line.
        let none = text.replace("0.5 5", "1.5 1.9");
        let e = Material::from_refractiveindex_yaml("p", "p.yml", &none).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("p.yml:3: the formula gives no physical n"),
            "{e}"
        );
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
