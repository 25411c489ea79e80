//! Reading a refractiveindex.info database page (YAML): its `DATA` entries, the repairs of
//! imperfect pages (module docs of [`super`], docs/materials.md), and where a formula is
//! physical.

use super::dispersion::Dispersion;
use super::warning::{K_STEP_WARNING, MaterialWarning, WarningKind};
use super::yaml::{Node, parse_yaml_tree};
use super::{Material, parse_numbers, um_to_nm};
use crate::elementary::{self, powf};
use crate::error::{Error, Result};
use yaml_rust2::scanner::TScalarStyle;

impl Material {
    /// Reads the refractiveindex.info database YAML format (see module docs, and the
    /// policy for imperfect pages there). `source_name` labels errors and warnings
    /// (`file:line`); what was repaired or set aside is in [`Material::warnings`].
    pub fn from_refractiveindex_yaml(
        name: impl Into<String>,
        source_name: &str,
        text: &str,
    ) -> Result<Self> {
        let mut page = Page {
            source_name,
            warnings: Vec::new(),
        };
        let root = parse_yaml_tree(text).map_err(|(line, m)| page.error(line, m))?;
        let (items, data_line) = page.data(&root)?;
        let mut n_part: Option<NPart> = None;
        let mut k_part: Option<KPart> = None;
        for item in items {
            let (parsed_n, parsed_k, type_line) = page.entry(item)?;
            if let Some(p) = parsed_n {
                match &n_part {
                    Some(first) => page.warn(
                        type_line,
                        WarningKind::SecondEntry {
                            quantity: 'n',
                            first_line: first.type_line,
                        },
                    ),
                    None => n_part = Some(p),
                }
            }
            if let Some(k) = parsed_k {
                match &k_part {
                    Some(first) => page.warn(
                        k.type_line,
                        WarningKind::SecondEntry {
                            quantity: 'k',
                            first_line: first.type_line,
                        },
                    ),
                    None => k_part = Some(k),
                }
            }
        }
        let n_part = n_part.ok_or_else(|| {
            page.error(
                data_line,
                "no `DATA` entry gives the real index n (only `tabulated k`): the page cannot be used alone".into(),
            )
        })?;
        let (range_nm, gaps_nm) = page.physical_range(&n_part)?;
        let k = match k_part {
            Some(k) => page.k_beyond_its_table(k, range_nm),
            None => Dispersion::Constant(0.0),
        };
        let mut warnings = page.warnings;
        warnings.sort_by_key(|w| w.line);
        Ok(Material {
            name: name.into(),
            n: n_part.n,
            k,
            range_nm,
            gaps_nm,
            warnings,
        })
    }
}

/// The entry that gives n: its dispersion, its range (nm), the line of its range (of its
/// `type` when it states none) and of its `type`.
struct NPart {
    n: Dispersion,
    range_nm: (f64, f64),
    range_line: usize,
    type_line: usize,
}

/// The entry that gives κ: its table and the line of its `type`.
struct KPart {
    table: Table,
    type_line: usize,
}

/// A page being read: where it came from, and what was repaired so far.
struct Page<'a> {
    source_name: &'a str,
    warnings: Vec<MaterialWarning>,
}

impl Page<'_> {
    fn error(&self, line: usize, message: String) -> Error {
        Error::Parse {
            source_name: self.source_name.to_string(),
            line,
            message,
        }
    }

    fn warn(&mut self, line: usize, kind: WarningKind) {
        self.warnings.push(MaterialWarning {
            source_name: self.source_name.to_string(),
            line,
            kind,
        });
    }

    /// The entries of the top-level `DATA` list, and the list's line.
    fn data<'n>(&self, root: &'n Node) -> Result<(&'n [Node], usize)> {
        let Node::Map(entries, _) = root else {
            return Err(self.error(
                root.line(),
                "expected a mapping with a `DATA` key at the top level".into(),
            ));
        };
        let data = entries
            .iter()
            .find(|(k, _)| k == "DATA")
            .map(|(_, v)| v)
            .ok_or_else(|| {
                self.error(
                    1,
                    "no `DATA` key: not a refractiveindex.info material file".into(),
                )
            })?;
        let Node::Seq(items, data_line) = data else {
            return Err(self.error(data.line(), "`DATA` must be a list of entries".into()));
        };
        if items.is_empty() {
            return Err(self.error(*data_line, "`DATA` is empty".into()));
        }
        Ok((items, *data_line))
    }

    /// One `DATA` entry: a formula (n) or a table (n, κ or both).
    /// Returns n's part, κ's part and the entry's `type` line.
    fn entry(&mut self, item: &Node) -> Result<(Option<NPart>, Option<KPart>, usize)> {
        let Node::Map(fields, item_line) = item else {
            return Err(self.error(
                item.line(),
                "each `DATA` entry must be a mapping with a `type`".into(),
            ));
        };
        let item_line = *item_line;
        let get = |key: &str| fields.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let ty = match get("type") {
            Some(Node::Scalar(s, _, _)) => s.trim().to_string(),
            _ => return Err(self.error(item_line, "`DATA` entry without a `type`".into())),
        };
        let type_line = get("type").map_or(item_line, Node::line);
        if let Some(kind) = ty.strip_prefix("formula ") {
            let n = self.formula(&ty, kind, &get, item_line, type_line)?;
            return Ok((Some(n), None, type_line));
        }
        let (n, k) = self.tabulated(&ty, get("data"), item_line, type_line)?;
        Ok((n, k, type_line))
    }

    /// A `formula 1` … `formula 9` entry: its coefficients and `wavelength_range`.
    fn formula<'n>(
        &self,
        ty: &str,
        kind: &str,
        get: &dyn Fn(&str) -> Option<&'n Node>,
        item_line: usize,
        type_line: usize,
    ) -> Result<NPart> {
        let kind: u8 = match kind.trim().parse() {
            Ok(k @ 1..=9) => k,
            _ => {
                return Err(self.error(
                    type_line,
                    format!(
                        "unsupported type `{ty}`: expected `formula 1` … `formula 9`, `tabulated nk`, `tabulated n` or `tabulated k`"
                    ),
                ));
            }
        };
        let coefficients = match get("coefficients") {
            Some(Node::Scalar(s, _, line)) => parse_numbers(s).map_err(|tok| {
                self.error(*line, format!("coefficient `{tok}` is not a finite number"))
            })?,
            _ => {
                return Err(self.error(item_line, format!("`{ty}` entry without `coefficients`")));
            }
        };
        if coefficients.is_empty() {
            return Err(self.error(item_line, "`coefficients` is empty".into()));
        }
        let (range_nm, range_line) = match get("wavelength_range") {
            Some(Node::Scalar(s, _, line)) => {
                let v = s
                    .split_whitespace()
                    .map(|t| um_to_nm(t).ok_or_else(|| t.to_string()))
                    .collect::<std::result::Result<Vec<f64>, String>>()
                    .map_err(|tok| {
                        self.error(
                            *line,
                            format!("wavelength_range value `{tok}` is not a finite number"),
                        )
                    })?;
                if v.len() != 2 || !(v[0] > 0.0 && v[1] > v[0]) {
                    return Err(self.error(
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
                return Err(self.error(
                    other.line(),
                    "`wavelength_range` must be two numbers".into(),
                ));
            }
            None => ((0.0, f64::INFINITY), type_line),
        };
        Ok(NPart {
            n: Dispersion::Formula { kind, coefficients },
            range_nm,
            range_line,
            type_line,
        })
    }

    /// A `tabulated nk`, `tabulated n` or `tabulated k` entry: n's part and κ's table, rows
    /// sorted, repeated wavelengths merged and unphysical values skipped (each named).
    fn tabulated(
        &mut self,
        ty: &str,
        data: Option<&Node>,
        item_line: usize,
        type_line: usize,
    ) -> Result<(Option<NPart>, Option<KPart>)> {
        let (n_col, k_col) = match ty {
            "tabulated nk" => (Some(0), Some(1)),
            "tabulated n" => (Some(0), None),
            "tabulated k" => (None, Some(0)),
            _ => {
                return Err(self.error(
                    type_line,
                    format!(
                        "unsupported type `{ty}`: expected `tabulated nk`, `tabulated n`, `tabulated k` or `formula 1` … `formula 9`"
                    ),
                ));
            }
        };
        let columns = 1 + usize::from(n_col.is_some()) + usize::from(k_col.is_some());
        let (block, first_line) = match data {
            Some(Node::Scalar(s, style, line)) => {
                // yaml-rust2 marks a block scalar at its first non-blank content line;
                // leading blank lines appear as leading newlines.
                let first = if matches!(style, TScalarStyle::Literal | TScalarStyle::Folded) {
                    line - s.bytes().take_while(|&b| b == b'\n').count()
                } else {
                    *line
                };
                (s.as_str(), first)
            }
            _ => {
                return Err(self.error(item_line, format!("`{ty}` entry without a `data` block")));
            }
        };
        let rows = self.rows(ty, block, first_line, columns)?;
        let n = n_col.map(|c| {
            tabulate(
                &rows,
                c,
                |v| v > 0.0,
                |row, v| {
                    self.warn(
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
                    self.warn(
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
                return Err(self.error(first_line, format!("`{ty}` entry has no row with n > 0")));
            }
            Some(Some(t)) => Some(NPart {
                range_nm: t.range(),
                n: t.into_dispersion(),
                range_line: type_line,
                type_line,
            }),
            None => None,
        };
        // A k table whose every value is negative gives no k: k = 0 (each row named).
        Ok((n, k.flatten().map(|table| KPart { table, type_line })))
    }

    /// The rows of a `data` block starting at `first_line`, sorted by wavelength (stably:
    /// rows at one wavelength keep their order); rows out of order, and rows repeating a
    /// wavelength with other values, are named once each.
    fn rows(
        &mut self,
        ty: &str,
        block: &str,
        first_line: usize,
        columns: usize,
    ) -> Result<Vec<TableRow>> {
        let mut rows: Vec<TableRow> = Vec::new();
        for (i, row) in block.lines().enumerate() {
            let line = first_line + i;
            if row.trim().is_empty() {
                continue;
            }
            let tokens: Vec<&str> = row.split_whitespace().collect();
            let v = parse_numbers(row)
                .map_err(|tok| self.error(line, format!("`{tok}` is not a finite number")))?;
            if v.len() != columns {
                return Err(self.error(
                    line,
                    format!("`{ty}` rows need {columns} numbers, found {}", v.len()),
                ));
            }
            if !(v[0] > 0.0) {
                return Err(self.error(line, format!("wavelength {} µm must be positive", v[0])));
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
            return Err(self.error(first_line, format!("`{ty}` entry has no data rows")));
        }
        for pair in rows.windows(2) {
            if pair[1].wavelength_nm < pair[0].wavelength_nm {
                self.warn(
                    pair[1].line,
                    WarningKind::OutOfOrder {
                        wavelength_um: pair[1].wavelength_um,
                        previous_um: pair[0].wavelength_um,
                    },
                );
            }
        }
        rows.sort_by(|a, b| a.wavelength_nm.total_cmp(&b.wavelength_nm));
        for group in rows.chunk_by(|a, b| a.wavelength_nm == b.wavelength_nm) {
            for r in &group[1..] {
                if r.values != group[0].values {
                    self.warn(
                        r.line,
                        WarningKind::Repeated {
                            wavelength_um: r.wavelength_um,
                            first_line: group[0].line,
                        },
                    );
                }
            }
        }
        Ok(rows)
    }

    /// n's usable range and the gaps inside it: a formula non-physical somewhere inside its
    /// stated range has its ends cut off (named), a gap inside is refused there (named).
    fn physical_range(&mut self, part: &NPart) -> Result<(Range, Vec<Range>)> {
        let (n, range_nm, n_line) = (&part.n, part.range_nm, part.range_line);
        if !(matches!(n, Dispersion::Formula { .. }) && range_nm.1.is_finite()) {
            return Ok((range_nm, Vec::new()));
        }
        let physical = |w: f64| {
            let v = n.eval(w);
            v > 0.0 && v.is_finite()
        };
        let Some((usable, gaps)) = formula_gaps(&physical, range_nm) else {
            return Err(self.error(
                n_line,
                format!(
                    "the formula gives no physical n (n > 0) anywhere in its wavelength_range {}–{} nm",
                    range_nm.0, range_nm.1
                ),
            ));
        };
        if usable != range_nm {
            self.warn(
                n_line,
                WarningKind::FormulaRangeCut {
                    stated_nm: range_nm,
                    usable_nm: usable,
                },
            );
        }
        for &(from_nm, to_nm) in &gaps {
            self.warn(n_line, WarningKind::FormulaGap { from_nm, to_nm });
        }
        Ok((usable, gaps))
    }

    /// κ from its table, 0 outside it; named when the table ends inside n's range at a κ
    /// that is not negligible, or lies wholly outside n's range.
    fn k_beyond_its_table(&mut self, part: KPart, range_nm: Range) -> Dispersion {
        let (k, k_line) = (part.table, part.type_line);
        let (w, v) = (&k.wavelength_nm, &k.value);
        let (first, last) = (0, w.len() - 1);
        for (i, lower, inside) in [
            (first, true, w[first] > range_nm.0),
            (last, false, w[last] < range_nm.1),
        ] {
            if inside && v[i] >= K_STEP_WARNING && w[i] >= range_nm.0 && w[i] <= range_nm.1 {
                self.warn(
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
            self.warn(
                k_line,
                WarningKind::KOutsideN {
                    k_range_nm: (w[first], w[last]),
                    n_range_nm: range_nm,
                },
            );
        }
        k.into_dispersion_zero_outside()
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

/// Samples a formula's stated range at this many points (logarithmically spaced) to find
/// where it turns non-physical, then bisects each edge.
const FORMULA_SCAN_POINTS: usize = 8192;

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
