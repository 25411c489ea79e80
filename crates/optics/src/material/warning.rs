//! What the refractiveindex.info reader repaired or set aside in a page: [`MaterialWarning`]
//! (docs/materials.md gives the policy).

/// κ at the end of a `tabulated k` table, inside n's range, from which the step to κ = 0
/// beyond the table is worth a warning.
pub const K_STEP_WARNING: f64 = 1e-3;

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
    /// resonance): wavelengths there are refused ([`Error::NoPhysicalIndex`](crate::Error::NoPhysicalIndex)).
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
