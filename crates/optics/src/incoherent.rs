//! Stacks with thick *incoherent* layers: a coated glass pane, a lens, a window. Light
//! reflected back and forth inside a slab millimetres thick adds in intensity, not in
//! amplitude (its fringes are far finer than any spectrometer or eye resolves), so the
//! slab is described by powers while the thin films around it keep their exact coherent
//! amplitudes.
//!
//! # Method
//!
//! The intensity (power) recurrence of Byrnes' `inc_tmm` (S. J. Byrnes, "Multilayer optical
//! calculations", arXiv:1603.02720, §4; equivalent to the incoherent transfer matrices of
//! Katsidis & Siapkas, Appl. Opt. 41, 3978, 2002, Eq. 13–16). The media are numbered as in
//! [`crate::stack`]: 0 the ambient, 1 … N the films, N+1 the substrate. The ambient, the
//! substrate and every incoherent film are the *incoherent media* m₀ = 0 < m₁ < … < m_K <
//! m_{K+1} = N+1; between m_g and m_{g+1} lies the coherent group G_g (its films, possibly
//! none: a bare interface). For each group the existing coherent kernels give, per
//! polarisation and with the power conventions of [`crate::fresnel`] (Byrnes Eq. 21–22),
//!
//! * R_g, T_g: reflectance and transmittance for light incident from medium m_g (forward);
//! * R′_g, T′_g: the same for light incident from medium m_{g+1} (backward, the group
//!   reversed), needed for every group but the last.
//!
//! Each group is computed as a stack of its own whose tangential component is that of the
//! whole stack, β = n₀ sin θ₀ (Snell's law holds across incoherent slabs too); its first
//! medium may absorb. Incoherent slab m_k (k = 1 … K) of thickness d and complex index ñ
//! passes, in one crossing, the fraction
//!
//! ```text
//! P_k = |e^{iδ}|² = exp(−2 Im δ) = exp(−4π d Im(ñ cos θ) / λ),    δ = k₀ q d, q = ñ cos θ
//! ```
//!
//! at its internal (complex) angle, the same for s and p (Byrnes §4, `P_list`). From the
//! substrate up, X_g and Y_g being the reflectance and transmittance of everything below
//! medium m_g seen from inside it, X_K = R_K, Y_K = T_K (the last group), and for
//! g = K−1 … 0
//!
//! ```text
//!                T_g T′_g P² X_{g+1}                      T_g P Y_{g+1}
//! X_g = R_g + ─────────────────────────,       Y_g = ─────────────────────────,   P = P_{g+1}
//!              1 − R′_g P² X_{g+1}                      1 − R′_g P² X_{g+1}
//! ```
//!
//! (the geometric series of the slab's round trips summed in intensity; Byrnes' product of
//! the matrices L_k = (1/T_{k,k+1}) diag(1/P_k, P_k) [[1, −R_{k+1,k}], [R_{k,k+1},
//! T_{k+1,k}T_{k,k+1} − R_{k+1,k}R_{k,k+1}]] written as a recurrence). The stack's powers
//! are R = X₀ and T = Y₀.
//!
//! A slab that lets less than [`OPAQUE_PASS`] through in one pass (a metal, or glass metres
//! thick) is refused ([`crate::Error::OpaqueSlab`]): nothing of what lies below it matters,
//! and `tmm` clamps P there. A lossless slab beyond its critical angle (an evanescent wave,
//! P = 0 exactly) reflects everything its top group does not transmit: X_g = R_g, Y_g = 0.

use crate::elementary;
use crate::error::{Error, Result};
use crate::fresnel::normal_component;
use crate::multilayer::{Media, stack_powers};
use crate::power::{Power, wavenumber};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// The smallest single-pass transmission P of an incoherent slab: below it the slab is
/// opaque ([`crate::Error::OpaqueSlab`]); `tmm.inc_tmm` clamps P to the same value.
pub const OPAQUE_PASS: f64 = 1e-30;

/// Which films of a stack are incoherent, and the groups of coherent films between them.
#[derive(Clone, Debug)]
pub(crate) struct Groups {
    /// The incoherent media, as medium indices (0 the ambient … N+1 the substrate).
    pub(crate) media: Vec<usize>,
}

impl Groups {
    /// The groups of a stack of `films` films whose film j (1-based) is incoherent where
    /// `incoherent[j − 1]`.
    pub(crate) fn new(incoherent: &[bool]) -> Self {
        let films = incoherent.len();
        let mut media = vec![0];
        media.extend((1..=films).filter(|&j| incoherent[j - 1]));
        media.push(films + 1);
        Groups { media }
    }

    /// Number of coherent groups (K + 1).
    fn count(&self) -> usize {
        self.media.len() - 1
    }
}

/// Per (angle, wavelength): the stack's powers and, per polarisation, the power absorbed in
/// each part of the stack ([`Groups::parts`]: the coherent groups and the slabs, top
/// first), as fractions of the incident power.
#[derive(Clone, Debug, PartialEq)]
pub struct Absorbed {
    /// Reflectance and transmittance of the whole stack.
    pub power: Power,
    /// Absorptance of each part, s polarisation.
    pub parts_s: Vec<f64>,
    /// Absorptance of each part, p polarisation.
    pub parts_p: Vec<f64>,
}

/// One part of a stack with incoherent layers: a coherent group of films (possibly none: a
/// bare interface) or an incoherent slab.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Part {
    /// The coherent films `first ..= last` (1-based; empty when `first > last`) between two
    /// incoherent media.
    Coherent {
        /// First film, 1-based.
        first: usize,
        /// Last film, 1-based.
        last: usize,
    },
    /// Incoherent film `layer` (1-based).
    Slab {
        /// The film, 1-based.
        layer: usize,
    },
}

impl Groups {
    /// The parts, top first: group 0, slab m₁, group 1, …, slab m_K, group K.
    pub(crate) fn parts(&self) -> Vec<Part> {
        let mut out = Vec::new();
        for g in 0..self.count() {
            if g > 0 {
                out.push(Part::Slab {
                    layer: self.media[g],
                });
            }
            out.push(Part::Coherent {
                first: self.media[g] + 1,
                last: self.media[g + 1] - 1,
            });
        }
        out
    }
}

/// The scalar recurrence of one coherent stack: its powers for media `indices` (first to
/// last), tangential component β, vacuum wavelength (nm) and film thicknesses (nm). Handed in
/// by [`crate::stack`] (its `Prepared`), for media outside the vectorised kernel's ranges.
pub(crate) type Scalar = fn(&[C64], f64, f64, &[f64]) -> Power;

/// Everything the recurrence needs at every (angle, wavelength): the groups' forward and
/// backward powers and the slabs' single passes.
struct Terms {
    forward: Vec<Vec<Power>>,
    backward: Vec<Vec<Power>>,
    /// [slab k − 1][element].
    passes: Vec<Vec<f64>>,
}

impl Terms {
    fn new(
        groups: &Groups,
        sines: &[f64],
        columns: &[Vec<C64>],
        wavelengths_nm: &[f64],
        thickness_nm: &[f64],
        names: &[String],
        scalar: Scalar,
    ) -> Result<Self> {
        let beta_index: Vec<f64> = columns[0].iter().map(|n| n.re).collect();
        let passes = groups.media[1..groups.media.len() - 1]
            .iter()
            .map(|&m| {
                slab_passes(
                    &columns[m],
                    &beta_index,
                    sines,
                    wavelengths_nm,
                    thickness_nm[m - 1],
                    m,
                    &names[m - 1],
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let last = groups.count() - 1;
        let mut forward = Vec::with_capacity(groups.count());
        let mut backward = Vec::with_capacity(last);
        for g in 0..=last {
            let (top, bottom) = (groups.media[g], groups.media[g + 1]);
            let cols = &columns[top..=bottom];
            let thick = &thickness_nm[top..bottom - 1];
            forward.push(group_powers(
                cols,
                &beta_index,
                sines,
                wavelengths_nm,
                thick,
                scalar,
            ));
            if g < last {
                let rev_cols: Vec<Vec<C64>> = cols.iter().rev().cloned().collect();
                let rev_thick: Vec<f64> = thick.iter().rev().copied().collect();
                backward.push(group_powers(
                    &rev_cols,
                    &beta_index,
                    sines,
                    wavelengths_nm,
                    &rev_thick,
                    scalar,
                ));
            }
        }
        Ok(Terms {
            forward,
            backward,
            passes,
        })
    }

    /// (R_g, T_g, R′_g, T′_g) of group g at element e, polarisation `pol` (0 s, 1 p); the
    /// backward pair is (0, 0) for the last group.
    #[inline]
    fn group(&self, g: usize, e: usize, pol: usize) -> [f64; 4] {
        let f = &self.forward[g][e];
        let (rf, tf) = if pol == 0 {
            (f.R_s, f.T_s)
        } else {
            (f.R_p, f.T_p)
        };
        match self.backward.get(g) {
            Some(b) => {
                let b = &b[e];
                let (rb, tb) = if pol == 0 {
                    (b.R_s, b.T_s)
                } else {
                    (b.R_p, b.T_p)
                };
                [rf, tf, rb, tb]
            }
            None => [rf, tf, 0.0, 0.0],
        }
    }

    /// X_g for g = 0 … K (reflectance below medium m_g seen from it) and Y₀ = T, at element
    /// e, polarisation `pol`, written into `x`.
    #[inline]
    fn recurrence(&self, e: usize, pol: usize, x: &mut [f64]) -> f64 {
        let last = self.forward.len() - 1;
        let [rf, tf, _, _] = self.group(last, e, pol);
        x[last] = rf;
        let mut y = tf;
        for g in (0..last).rev() {
            let p = self.passes[g][e];
            let [rf, tf, rb, tb] = self.group(g, e, pol);
            if p == 0.0 {
                // An evanescent lossless slab: nothing crosses it.
                x[g] = rf;
                y = 0.0;
                continue;
            }
            let a = p * p * x[g + 1];
            let den = 1.0 - rb * a;
            x[g] = rf + tf * tb * a / den;
            y = tf * p * y / den;
        }
        y
    }
}

/// Powers of every (angle, wavelength) pair, angle-major, of the stack whose media indices
/// are `columns` (per medium, per wavelength; the ambient real), films `thickness_nm` (top
/// first) and incoherent media `groups`. `sines[a]` = sin θ₀. `names[j − 1]` names film j in
/// errors.
pub(crate) fn sweep(
    groups: &Groups,
    sines: &[f64],
    columns: &[Vec<C64>],
    wavelengths_nm: &[f64],
    thickness_nm: &[f64],
    names: &[String],
    scalar: Scalar,
) -> Result<Vec<Power>> {
    let terms = Terms::new(
        groups,
        sines,
        columns,
        wavelengths_nm,
        thickness_nm,
        names,
        scalar,
    )?;
    let total = sines.len() * wavelengths_nm.len();
    let mut x = vec![0.0; groups.count()];
    Ok((0..total)
        .map(|e| {
            let t_s = terms.recurrence(e, 0, &mut x);
            let r_s = x[0];
            let t_p = terms.recurrence(e, 1, &mut x);
            Power {
                R_s: r_s,
                R_p: x[0],
                T_s: t_s,
                T_p: t_p,
            }
        })
        .collect())
}

/// [`sweep`] with the power absorbed in each part. Walking down from the ambient with
/// I_g the power arriving at group g from above (I₀ = 1), and for slab m_{g+1} below it
/// (single pass P, X = X_{g+1} below):
///
/// ```text
/// D = T_g I_g / (1 − R′_g P² X)        entering the slab downwards at its top
/// U = P² X D                           returning up to group g from the slab
/// A(group g) = I_g (1 − R_g − T_g) + U (1 − R′_g − T′_g)
/// A(slab)    = (1 − P) D (1 + P X),    I_{g+1} = P D
/// ```
///
/// and A(group K) = I_K (1 − R_K − T_K); with R and T these sum to 1 (tested).
pub(crate) fn sweep_absorbed(
    groups: &Groups,
    sines: &[f64],
    columns: &[Vec<C64>],
    wavelengths_nm: &[f64],
    thickness_nm: &[f64],
    names: &[String],
    scalar: Scalar,
) -> Result<Vec<Absorbed>> {
    let terms = Terms::new(
        groups,
        sines,
        columns,
        wavelengths_nm,
        thickness_nm,
        names,
        scalar,
    )?;
    let total = sines.len() * wavelengths_nm.len();
    let last = groups.count() - 1;
    let mut x = vec![0.0; groups.count()];
    Ok((0..total)
        .map(|e| {
            let mut pols = [(0.0, 0.0, Vec::new()), (0.0, 0.0, Vec::new())];
            for (pol, out) in pols.iter_mut().enumerate() {
                let t = terms.recurrence(e, pol, &mut x);
                let mut parts = Vec::with_capacity(2 * last + 1);
                let mut incoming = 1.0;
                for g in 0..=last {
                    let [rf, tf, rb, tb] = terms.group(g, e, pol);
                    if g == last {
                        parts.push(incoming * (1.0 - rf - tf));
                        break;
                    }
                    let p = terms.passes[g][e];
                    let below = x[g + 1];
                    let a = p * p * below;
                    let down = tf * incoming / (1.0 - rb * a);
                    let up = a * down;
                    parts.push(incoming * (1.0 - rf - tf) + up * (1.0 - rb - tb));
                    parts.push((1.0 - p) * down * (1.0 + p * below));
                    incoming = p * down;
                }
                *out = (x[0], t, parts);
            }
            let [(r_s, t_s, parts_s), (r_p, t_p, parts_p)] = pols;
            Absorbed {
                power: Power {
                    R_s: r_s,
                    R_p: r_p,
                    T_s: t_s,
                    T_p: t_p,
                },
                parts_s,
                parts_p,
            }
        })
        .collect())
}

/// P = exp(−2 k₀ d Im q) of slab `medium` (index `column` per wavelength, thickness
/// `thickness_nm`) at every (angle, wavelength), angle-major; an error where the slab
/// absorbs and P < [`OPAQUE_PASS`]; exactly 0 where a lossless slab is evanescent and
/// P underflows past it.
fn slab_passes(
    column: &[C64],
    beta_index: &[f64],
    sines: &[f64],
    wavelengths_nm: &[f64],
    thickness_nm: f64,
    medium: usize,
    name: &str,
) -> Result<Vec<f64>> {
    let mut out = Vec::with_capacity(sines.len() * wavelengths_nm.len());
    for &sin_theta in sines {
        for (w, &wl) in wavelengths_nm.iter().enumerate() {
            let n = column[w];
            let q = normal_component(n, beta_index[w] * sin_theta);
            let p = elementary::exp(-2.0 * wavenumber(wl) * thickness_nm * q.im);
            if p < OPAQUE_PASS {
                if n.im > 0.0 {
                    return Err(Error::OpaqueSlab {
                        layer: medium,
                        material: name.to_string(),
                        thickness_nm,
                        wavelength_nm: wl,
                        angle_deg: asin_deg(sin_theta),
                        pass: p,
                    });
                }
                out.push(0.0);
            } else {
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// θ₀ in degrees from sin θ₀, for messages.
fn asin_deg(sin_theta: f64) -> f64 {
    let cos_theta = (1.0 - sin_theta * sin_theta).max(0.0).sqrt();
    elementary::atan2(sin_theta, cos_theta).to_degrees()
}

/// Powers of one coherent group (media `columns`, first to last, films `thickness_nm`) at
/// every (angle, wavelength), angle-major, with β = `beta_index[w]` sin θ₀: the vectorised
/// kernel of [`crate::multilayer`] where its ranges allow, else the scalar recurrence
/// `scalar`.
fn group_powers(
    columns: &[Vec<C64>],
    beta_index: &[f64],
    sines: &[f64],
    wavelengths_nm: &[f64],
    thickness_nm: &[f64],
    scalar: Scalar,
) -> Vec<Power> {
    let per_angle = wavelengths_nm.len();
    let mut out = vec![Power::default(); sines.len() * per_angle];
    if per_angle == 0 {
        return out;
    }
    match Media::from_columns_beta(columns, Some(beta_index), wavelengths_nm, thickness_nm) {
        Some(media) => out
            .par_chunks_mut(per_angle)
            .zip(sines)
            .for_each(|(row, &sin_theta)| stack_powers(&media, sin_theta, row, true)),
        None => out
            .par_chunks_mut(per_angle)
            .zip(sines)
            .for_each(|(row, &sin_theta)| {
                for (w, (slot, &wl)) in row.iter_mut().zip(wavelengths_nm).enumerate() {
                    let indices: Vec<C64> = columns.iter().map(|c| c[w]).collect();
                    *slot = scalar(&indices, beta_index[w] * sin_theta, wl, thickness_nm);
                }
            }),
    }
    out
}
