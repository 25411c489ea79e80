//! A stack's media for the vectorised kernel: each medium's index per wavelength as a
//! structure of arrays (padded to whole vectors, a constant medium as one block the kernel
//! reuses), the film thicknesses, and the checks that keep every value inside the kernel's
//! ranges (|ñ| bounds, the phase bound |δ| ≤ [`MAX_PHASE_RAD`] of the argument reduction,
//! Im ñ² without its sign bit). The recurrence that reads them is in the parent module.

use super::{BLOCK, FILM_SLOTS, MEDIA_SLOTS, PAD, SIGN};
use crate::power::wavenumber;
use num_complex::Complex64 as C64;

/// Largest |Re ñ| or |Im ñ| the kernel takes (|ñ² − β²|² stays below 10²⁵).
const MAX_INDEX: f64 = 1e6;
/// Smallest max(|Re ñ|, |Im ñ|) the kernel takes (|ñ² − β²|² stays far above underflow).
const MIN_INDEX: f64 = 1e-6;
/// Largest bound k₀ d (|Re ñ| + |Im ñ| + n₀) on a film's phase |δ| the kernel takes: below
/// it [`sin_cos`]'s argument reduction of 2 Re δ is exact (module docs of [`crate::simd`]).
const MAX_PHASE_RAD: f64 = 5e5;

/// One medium's index over a sweep's wavelengths: the same at every one, or one each.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Column<'a> {
    Constant(C64),
    Varying(&'a [C64]),
}

impl Column<'_> {
    /// The index at wavelength `w`.
    #[inline]
    pub(crate) fn at(&self, w: usize) -> C64 {
        match self {
            Column::Constant(n) => *n,
            Column::Varying(c) => c[w],
        }
    }

    /// Number of wavelengths, `None` for a constant.
    pub(super) fn len(&self) -> Option<usize> {
        match self {
            Column::Constant(_) => None,
            Column::Varying(c) => Some(c.len()),
        }
    }
}

/// A stack's media indices per wavelength, structure of arrays, and its film thicknesses.
pub(crate) struct Media {
    /// Re ñ_j(λ_w) at `re[j][w]`, j = 0 ambient … N+1 substrate; `re[0]` is the real index
    /// n₀ of β = n₀ sin θ₀ (the ambient's, or that of [`Media::from_columns_beta`]).
    pub(super) re: Vec<Vec<f64>>,
    /// ñ_j² as (re, im) and |ñ_j|², computed once per wavelength (angle-independent).
    pub(super) n2_re: Vec<Vec<f64>>,
    pub(super) n2_im: Vec<Vec<f64>>,
    pub(super) n_abs2: Vec<Vec<f64>>,
    /// Vacuum wavenumber k₀ = 2π/λ_w, rad/nm.
    pub(super) k0_per_nm: Vec<f64>,
    /// The largest k₀ over the wavelengths (NaN if any is): the phase check of constant
    /// media ([`phases_in_range`]).
    pub(super) k0_max: f64,
    /// Number of wavelengths (the arrays are padded beyond it to a multiple of [`PAD`]).
    pub(super) wavelengths: usize,
    /// Film thicknesses, top first, nm.
    pub(super) thickness_nm: Vec<f64>,
    /// Per medium: its arrays hold one block ([`BLOCK`] copies of its one index, read for
    /// every block of a row) rather than one value per wavelength.
    pub(super) constant: Vec<bool>,
    /// `re[0]` (β's n₀) likewise.
    pub(super) beta_constant: bool,
    /// Per medium: no Im ñ_j² has its sign bit set, so that Im q_j ≥ +0 in every lane and
    /// the forward-branch correction of [`medium`] changes nothing.
    pub(super) forward: Vec<bool>,
    /// Per medium and block of [`BLOCK`] wavelengths: Im ñ_j² = ±0 at every wavelength of
    /// the block (the lossless root of [`medium`]).
    pub(super) lossless: Vec<Vec<bool>>,
    /// Where each medium's q and each film's e^{2iδ} are kept in a [`Block`] ([`Slots`]).
    pub(super) media_slots: Slots,
    pub(super) film_slots: Slots,
}

/// Where each item (medium, or film) of a stack is kept in a [`Block`], so that repeated
/// items are computed once per element: a medium with the same index bits at every
/// wavelength has the same q, a film of the same medium and thickness the same e^{2iδ}
/// (the H and L of a periodic mirror). Items are computed from the last (the substrate) to
/// the first; a repeated item (up to `shared` of them) keeps a slot of its own from its first
/// computation on, the others share `rotating` slots by position.
pub(super) struct Slots {
    /// Per item: its slot.
    pub(super) slot: Vec<usize>,
    /// Per item: whether an earlier-computed repeat has already filled its slot.
    pub(super) known: Vec<bool>,
    /// Per item: whether its slot, once filled in a row's first block, holds it for the
    /// row's other blocks too (a medium whose index and the ambient's are the same at every
    /// wavelength has the same q along a row).
    pub(super) whole_row: Vec<bool>,
}

impl Slots {
    /// Slots for `count` items, `same(i, j)` saying whether items i and j have the same
    /// value and `constant(j)` whether item j's value is the same along a row: item j
    /// takes slot j mod `rotating` unless it is repeated or constant, and the first `shared`
    /// repeated or constant values take slots `rotating`, `rotating` + 1, ….
    pub(super) fn new(
        count: usize,
        rotating: usize,
        shared: usize,
        same: impl Fn(usize, usize) -> bool,
        constant: impl Fn(usize) -> bool,
    ) -> Self {
        let mut slot: Vec<usize> = (0..count).map(|j| j % rotating).collect();
        let mut known = vec![false; count];
        let mut whole_row = vec![false; count];
        let mut next = rotating;
        let mut assigned = vec![false; count];
        for j in (0..count).rev() {
            if assigned[j] || next == rotating + shared {
                continue;
            }
            let repeats: Vec<usize> = (0..j).filter(|&i| !assigned[i] && same(i, j)).collect();
            let constant = constant(j);
            if repeats.is_empty() && !constant {
                continue;
            }
            for &i in repeats.iter().chain([&j]) {
                slot[i] = next;
                assigned[i] = true;
                known[i] = i != j;
                whole_row[i] = constant;
            }
            next += 1;
        }
        Slots {
            slot,
            known,
            whole_row,
        }
    }
}

impl Media {
    /// [`Media::from_columns`] for indices given per wavelength (ambient, films top first,
    /// substrate).
    #[cfg(test)]
    pub(crate) fn new(
        indices: &[Vec<C64>],
        wavelengths_nm: &[f64],
        thickness_nm: &[f64],
    ) -> Option<Self> {
        let columns: Vec<Vec<C64>> = (0..thickness_nm.len() + 2)
            .map(|j| indices.iter().map(|idx| idx[j]).collect())
            .collect();
        Self::from_columns(&columns, wavelengths_nm, thickness_nm)
    }

    /// The media of `columns` (per medium — ambient, films top first, substrate — its index
    /// at each of `wavelengths_nm`), or `None` when an index or a film's phase is outside the
    /// ranges the kernel takes (see the constants; the caller then runs the scalar
    /// recurrence).
    #[cfg(test)]
    pub(crate) fn from_columns(
        columns: &[Vec<C64>],
        wavelengths_nm: &[f64],
        thickness_nm: &[f64],
    ) -> Option<Self> {
        Self::from_columns_beta(columns, None, wavelengths_nm, thickness_nm)
    }

    /// [`Media::from_columns`] for a stack whose tangential component β is set by another
    /// medium than its first one: `beta_index[w]` is the real index n₀ with β = n₀ sin θ₀
    /// (a coherent group between incoherent slabs, [`crate::incoherent`], whose first
    /// medium may absorb); `None` takes the first medium's Re ñ.
    pub(crate) fn from_columns_beta(
        columns: &[Vec<C64>],
        beta_index: Option<&[f64]>,
        wavelengths_nm: &[f64],
        thickness_nm: &[f64],
    ) -> Option<Self> {
        let columns: Vec<Column> = columns.iter().map(|c| Column::Varying(c)).collect();
        Self::from_compact(&columns, beta_index, wavelengths_nm, thickness_nm)
    }

    /// [`Media::from_columns_beta`] for media given as [`Column`]s: a medium whose index is
    /// the same at every wavelength is kept as one block of copies (the kernel reads the
    /// same lanes for every block of a row), so a stack of constant media costs nothing per
    /// wavelength to set up. The same values, hence the same bits, as the full columns.
    pub(crate) fn from_compact(
        columns: &[Column],
        beta_index: Option<&[f64]>,
        wavelengths_nm: &[f64],
        thickness_nm: &[f64],
    ) -> Option<Self> {
        let media = thickness_nm.len() + 2;
        debug_assert_eq!(columns.len(), media);
        let wavelengths = wavelengths_nm.len();
        // β's real index n₀: one value (`beta_constant`) or one per wavelength.
        let (beta_column, beta_constant): (Vec<f64>, bool) = match (beta_index, columns[0]) {
            (Some(b), _) => (b.to_vec(), false),
            (None, Column::Constant(n)) => (vec![n.re], true),
            (None, Column::Varying(c)) => (c.iter().map(|n| n.re).collect(), false),
        };
        let beta_at = |w: usize| beta_column[if beta_constant { 0 } else { w }];
        // Room for the padding below from the start (no reallocation and copy).
        let mut k0_per_nm: Vec<f64> = Vec::with_capacity(wavelengths.next_multiple_of(PAD));
        k0_per_nm.extend(wavelengths_nm.iter().map(|&wl| wavenumber(wl)));
        // The largest k₀ (NaN if any is): a film's phase bound k₀ d (|Re ñ| + |Im ñ| + n₀)
        // with ñ and n₀ the same at every wavelength is largest there (a correctly rounded
        // product is monotonic in each factor), so one check stands for every wavelength.
        let k0_max = largest(&k0_per_nm);
        for column in columns {
            debug_assert!(column.len().is_none_or(|l| l == wavelengths));
            let in_range = |w: usize, n: C64| {
                let (a, b) = (n.re.abs(), n.im.abs());
                // Negated comparisons: NaN fails them.
                if !(a <= MAX_INDEX && b <= MAX_INDEX && a.max(b) >= MIN_INDEX) {
                    return false;
                }
                let n0 = beta_at(w).abs();
                n0 <= MAX_INDEX
            };
            let ok = match column {
                Column::Constant(n) if beta_constant => wavelengths == 0 || in_range(0, *n),
                _ => (0..wavelengths).all(|w| in_range(w, column.at(w))),
            };
            if !ok {
                return None;
            }
        }
        if !phases_in_range(
            columns,
            beta_at,
            beta_constant,
            &k0_per_nm,
            k0_max,
            thickness_nm,
        ) {
            return None;
        }
        // Each varying array padded to a multiple of `PAD` with its last wavelength's values,
        // so that a row's last vector is whole (its extra lanes repeat a real one, and are
        // dropped); a constant one is one block of copies.
        let padded = wavelengths.next_multiple_of(PAD);
        let pad = |mut v: Vec<f64>| {
            if let Some(&last) = v.last() {
                v.resize(padded, last);
            }
            v
        };
        let map = |f: fn(&C64) -> f64| -> Vec<Vec<f64>> {
            columns
                .iter()
                .map(|c| match c {
                    Column::Constant(n) => vec![f(n); BLOCK],
                    Column::Varying(c) => pad(c.iter().map(f).collect()),
                })
                .collect()
        };
        let constant: Vec<bool> = columns
            .iter()
            .map(|c| matches!(c, Column::Constant(_)))
            .collect();
        let mut re = map(|n| n.re);
        re[0] = if beta_constant {
            vec![beta_column[0]; BLOCK]
        } else {
            pad(beta_column.clone())
        };
        let n2_re = map(|n| (n * n).re);
        let n2_im = map(|n| (n * n).im);
        let n_abs2 = map(|n| n.norm_sqr());
        let k0_per_nm = pad(k0_per_nm);
        let bits = |n: C64| (n.re.to_bits(), n.im.to_bits());
        let same_medium = |i: usize, j: usize| same_medium(columns, wavelengths, i, j);
        // q = √(ñ² − β²) is the same along a row where ñ and the ambient's index (β = n₀ sin θ₀)
        // are.
        let uniform = |j: usize| match columns[j] {
            Column::Constant(_) => true,
            c => (0..wavelengths).all(|w| bits(c.at(w)) == bits(c.at(0))),
        };
        let beta_uniform = beta_constant
            || beta_column
                .iter()
                .all(|b| b.to_bits() == beta_column[0].to_bits());
        let constant_q = |j: usize| uniform(j) && beta_uniform;
        let media_slots = Slots::new(media, 2, MEDIA_SLOTS - 2, same_medium, constant_q);
        let film_slots = film_slots(columns, wavelengths, thickness_nm);
        let forward = n2_im
            .iter()
            .map(|y| y.iter().all(|y| y.to_bits() & SIGN == 0))
            .collect();
        let blocks = padded.div_ceil(BLOCK);
        let lossless = n2_im
            .iter()
            .zip(&constant)
            .map(|(y, &constant)| {
                if constant {
                    vec![y.iter().all(|&y| y == 0.0); blocks]
                } else {
                    y.chunks(BLOCK)
                        .map(|b| b.iter().all(|&y| y == 0.0))
                        .collect()
                }
            })
            .collect();
        Some(Media {
            re,
            n2_re,
            n2_im,
            n_abs2,
            k0_per_nm,
            k0_max,
            wavelengths,
            thickness_nm: thickness_nm.to_vec(),
            constant,
            beta_constant,
            forward,
            lossless,
            media_slots,
            film_slots,
        })
    }

    /// Number of wavelengths.
    pub(crate) fn wavelengths(&self) -> usize {
        self.wavelengths
    }

    /// Number of films.
    pub(crate) fn films(&self) -> usize {
        self.thickness_nm.len()
    }

    /// New film thicknesses for media made by [`Media::from_compact`] from the same
    /// `columns` (and no `beta_index`): only what depends on a thickness is redone — the
    /// films' phase check and which films repeat ([`film_slots`]); the index arrays, k₀ and
    /// the lossless flags stay. The same values, hence the same bits, as new media made from
    /// scratch; `false` (nothing changed) when a film's phase leaves the kernel's range,
    /// where `from_compact` gives `None`.
    pub(crate) fn set_thicknesses(&mut self, columns: &[Column], thickness_nm: &[f64]) -> bool {
        debug_assert_eq!(columns.len(), thickness_nm.len() + 2);
        debug_assert_eq!(thickness_nm.len(), self.thickness_nm.len());
        let wavelengths = self.wavelengths;
        // β's n₀ as `from_compact` kept it: the ambient's real index in `re[0]` (one block of
        // copies when constant).
        let beta = &self.re[0];
        let beta_constant = self.beta_constant;
        let beta_at = |w: usize| beta[if beta_constant { 0 } else { w }];
        if !phases_in_range(
            columns,
            beta_at,
            beta_constant,
            &self.k0_per_nm[..wavelengths],
            self.k0_max,
            thickness_nm,
        ) {
            return false;
        }
        self.film_slots = film_slots(columns, wavelengths, thickness_nm);
        self.thickness_nm.copy_from_slice(thickness_nm);
        true
    }
}

/// Whether every film's phase bound k₀ d_j (|Re ñ_j| + |Im ñ_j| + n₀) stays within
/// [`MAX_PHASE_RAD`] at every wavelength (`k0_per_nm` one per wavelength, `beta_at(w)` the
/// ambient's n₀). A film whose index and n₀ are the same at every wavelength is checked
/// once, at `k0_max` (a correctly rounded product is monotonic in each factor).
pub(super) fn phases_in_range(
    columns: &[Column],
    beta_at: impl Fn(usize) -> f64,
    beta_constant: bool,
    k0_per_nm: &[f64],
    k0_max: f64,
    thickness_nm: &[f64],
) -> bool {
    let wavelengths = k0_per_nm.len();
    thickness_nm.iter().enumerate().all(|(i, &d)| {
        let phase_ok = |w: usize, n: C64, k0: f64| {
            let (a, b) = (n.re.abs(), n.im.abs());
            let n0 = beta_at(w).abs();
            // Negated comparison: NaN fails it.
            k0 * d * (a + b + n0) <= MAX_PHASE_RAD
        };
        match columns[i + 1] {
            Column::Constant(n) if beta_constant => wavelengths == 0 || phase_ok(0, n, k0_max),
            column => (0..wavelengths).all(|w| phase_ok(w, column.at(w), k0_per_nm[w])),
        }
    })
}

/// The largest of `values` and 0, or NaN when any is NaN: four independent lanes
/// (branch-free, so the loop vectorises) folded at the end, the same value as one
/// left-to-right fold (the largest number is the largest whatever the order, and a NaN
/// anywhere sticks).
pub(super) fn largest(values: &[f64]) -> f64 {
    let step = |m: f64, k: f64| if k > m || k.is_nan() { k } else { m };
    let mut lanes = [0.0_f64; 4];
    let chunks = values.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for (lane, &v) in lanes.iter_mut().zip(c) {
            *lane = step(*lane, v);
        }
    }
    for (k, &v) in rest.iter().enumerate() {
        lanes[k] = step(lanes[k], v);
    }
    lanes.into_iter().fold(0.0, step)
}

/// Whether media `i` and `j` have the same index (bit for bit) at every wavelength.
pub(super) fn same_medium(columns: &[Column], wavelengths: usize, i: usize, j: usize) -> bool {
    let bits = |n: C64| (n.re.to_bits(), n.im.to_bits());
    match (columns[i], columns[j]) {
        (Column::Constant(a), Column::Constant(b)) => bits(a) == bits(b),
        (a, b) => (0..wavelengths).all(|w| bits(a.at(w)) == bits(b.at(w))),
    }
}

/// The films' slots: films 1..=N as items 0..N − 1, a film repeating an earlier one (same
/// thickness and medium) sharing its slot; none is constant along a row (a film's phase
/// depends on the wavelength).
pub(super) fn film_slots(columns: &[Column], wavelengths: usize, thickness_nm: &[f64]) -> Slots {
    Slots::new(
        thickness_nm.len(),
        1,
        FILM_SLOTS - 1,
        |i, j| {
            thickness_nm[i].to_bits() == thickness_nm[j].to_bits()
                && same_medium(columns, wavelengths, i + 1, j + 1)
        },
        |_| false,
    )
}
