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
//! Both come from one pass of the kernel per group ([`crate::multilayer`], "Both sides in
//! one pass": the second column of the group's characteristic matrix gives r′ = −M₁₂/M₁₁
//! and t′ = det M / M₁₁, Katsidis & Siapkas 2002, Eq. 5–7), so the square roots, sines
//! and exponentials of each film are computed once for both sides. The groups' media and
//! the slabs' −2 k₀ d are prepared once per sweep; each angle's row is then filled and run
//! through the recurrence in one go (rows in parallel, the same bits on any thread count).
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
//! at its internal (complex) angle, the same for s and p (Byrnes §4, `P_list`), computed
//! wavelengths-as-lanes with the kernel's own root and e^{−a}
//! ([`crate::multilayer::slab_passes`]). From the
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
use crate::multilayer::{Media, SlabArrays, slab_passes, stack_powers, stack_powers_both};
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

/// A sweep's set-up, done once for all its (angle, wavelength) pairs: each coherent group's
/// media for the vectorised kernel, and each slab's −2 k₀ d per wavelength.
struct Plan<'a> {
    groups: &'a Groups,
    columns: &'a [Vec<C64>],
    wavelengths_nm: &'a [f64],
    thickness_nm: &'a [f64],
    names: &'a [String],
    scalar: Scalar,
    /// Re ñ₀ per wavelength (β = Re ñ₀ sin θ₀).
    beta_index: Vec<f64>,
    /// Per group: its media for the kernel, or `None` (the scalar recurrence).
    media: Vec<Option<Media>>,
    /// Per slab k (medium m_k): its arrays for [`slab_passes`].
    slabs: Vec<SlabArrays>,
}

/// Everything the recurrence needs at one angle: per group, its powers from above
/// (forward) and, for every group but the last, from below (backward), and the slabs'
/// single passes, each per wavelength.
struct Terms {
    forward: Vec<Vec<Power>>,
    backward: Vec<Vec<Power>>,
    /// [slab k − 1][wavelength].
    passes: Vec<Vec<f64>>,
}

impl<'a> Plan<'a> {
    fn new(
        groups: &'a Groups,
        columns: &'a [Vec<C64>],
        wavelengths_nm: &'a [f64],
        thickness_nm: &'a [f64],
        names: &'a [String],
        scalar: Scalar,
    ) -> Self {
        let beta_index: Vec<f64> = columns[0].iter().map(|n| n.re).collect();
        let media = (0..groups.count())
            .map(|g| {
                let (top, bottom) = (groups.media[g], groups.media[g + 1]);
                Media::from_columns_beta(
                    &columns[top..=bottom],
                    Some(beta_index.as_slice()),
                    wavelengths_nm,
                    &thickness_nm[top..bottom - 1],
                )
            })
            .collect();
        let k0_per_nm: Vec<f64> = wavelengths_nm.iter().map(|&wl| wavenumber(wl)).collect();
        let slabs = groups.media[1..groups.media.len() - 1]
            .iter()
            .map(|&m| SlabArrays::new(&columns[m], &beta_index, &k0_per_nm, thickness_nm[m - 1]))
            .collect();
        Plan {
            groups,
            columns,
            wavelengths_nm,
            thickness_nm,
            names,
            scalar,
            beta_index,
            media,
            slabs,
        }
    }

    /// Room for one angle's [`Terms`].
    fn terms(&self) -> Terms {
        let n = self.wavelengths_nm.len();
        let groups = self.groups.count();
        Terms {
            forward: vec![vec![Power::default(); n]; groups],
            backward: vec![vec![Power::default(); n]; groups - 1],
            passes: self.slabs.iter().map(|a| vec![0.0; a.padded()]).collect(),
        }
    }

    /// Fills `terms` at incidence sin θ₀ = `sin_theta`: each group in one pass of the kernel
    /// for both sides ([`stack_powers_both`]; the last group from above only), then the
    /// slabs' passes. An opaque slab is reported with its slab index k − 1 (the first such
    /// slab, at its first wavelength).
    fn fill(&self, sin_theta: f64, terms: &mut Terms) -> std::result::Result<(), (usize, Error)> {
        let last = self.groups.count() - 1;
        for g in 0..=last {
            let forward = &mut terms.forward[g];
            let backward = terms.backward.get_mut(g);
            match (&self.media[g], backward) {
                (Some(media), Some(backward)) => {
                    stack_powers_both(media, sin_theta, forward, backward, true)
                }
                (Some(media), None) => stack_powers(media, sin_theta, forward, true),
                (None, backward) => self.scalar_group(g, sin_theta, forward, backward),
            }
        }
        for (k, passes) in terms.passes.iter_mut().enumerate() {
            let m = self.groups.media[k + 1];
            let column = &self.columns[m];
            slab_passes(&self.slabs[k], sin_theta, passes);
            for (w, p) in passes.iter_mut().take(column.len()).enumerate() {
                let n = column[w];
                let pass = *p;
                *p = if !(pass < OPAQUE_PASS) {
                    pass
                } else if n.im > 0.0 {
                    let thickness_nm = self.thickness_nm[m - 1];
                    return Err((
                        k,
                        Error::OpaqueSlab {
                            layer: m,
                            material: self.names[m - 1].to_string(),
                            thickness_nm,
                            wavelength_nm: self.wavelengths_nm[w],
                            angle_deg: asin_deg(sin_theta),
                            pass,
                        },
                    ));
                } else {
                    // A lossless slab beyond its critical angle: nothing crosses it.
                    0.0
                };
            }
        }
        Ok(())
    }

    /// Group g's powers by the scalar recurrence (media outside the kernel's ranges): from
    /// above, and from below into `backward` (the group upside down) where asked.
    fn scalar_group(
        &self,
        g: usize,
        sin_theta: f64,
        forward: &mut [Power],
        backward: Option<&mut Vec<Power>>,
    ) {
        let (top, bottom) = (self.groups.media[g], self.groups.media[g + 1]);
        let cols = &self.columns[top..=bottom];
        let thick = &self.thickness_nm[top..bottom - 1];
        let rev_thick: Vec<f64> = thick.iter().rev().copied().collect();
        let mut backward = backward;
        for (w, &wl) in self.wavelengths_nm.iter().enumerate() {
            let beta = self.beta_index[w] * sin_theta;
            let mut indices: Vec<C64> = cols.iter().map(|c| c[w]).collect();
            forward[w] = (self.scalar)(&indices, beta, wl, thick);
            if let Some(b) = backward.as_deref_mut() {
                indices.reverse();
                b[w] = (self.scalar)(&indices, beta, wl, &rev_thick);
            }
        }
    }

    /// Runs `each(terms, sin θ₀, row)` over the angles' rows of `out` (angle-major, one
    /// row per angle, in parallel) after filling the terms; the first error in the order
    /// slab, angle.
    fn rows<T: Send>(
        &self,
        sines: &[f64],
        out: &mut [T],
        each: impl Fn(&Terms, &mut [T]) + Sync,
    ) -> Result<()> {
        let per_angle = self.wavelengths_nm.len();
        if per_angle == 0 {
            return Ok(());
        }
        let errors: Vec<Option<(usize, Error)>> = out
            .par_chunks_mut(per_angle)
            .zip(sines)
            .map_init(
                || self.terms(),
                |terms, (row, &sin_theta)| match self.fill(sin_theta, terms) {
                    Ok(()) => {
                        each(terms, row);
                        None
                    }
                    Err(e) => Some(e),
                },
            )
            .collect();
        match errors.into_iter().flatten().min_by_key(|(k, _)| *k) {
            Some((_, e)) => Err(e),
            None => Ok(()),
        }
    }
}

impl Terms {
    /// (R_g, T_g, R′_g, T′_g) of group g at wavelength w, polarisation `pol` (0 s, 1 p);
    /// the backward pair is (0, 0) for the last group.
    #[inline]
    fn group(&self, g: usize, w: usize, pol: usize) -> [f64; 4] {
        let f = &self.forward[g][w];
        let (rf, tf) = if pol == 0 {
            (f.R_s, f.T_s)
        } else {
            (f.R_p, f.T_p)
        };
        match self.backward.get(g) {
            Some(b) => {
                let b = &b[w];
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

    /// X_g for g = 0 … K (reflectance below medium m_g seen from it) and Y₀ = T, at
    /// wavelength w, polarisation `pol`, written into `x`.
    #[inline]
    fn recurrence(&self, w: usize, pol: usize, x: &mut [f64]) -> f64 {
        let last = self.forward.len() - 1;
        let [rf, tf, _, _] = self.group(last, w, pol);
        x[last] = rf;
        let mut y = tf;
        for g in (0..last).rev() {
            let p = self.passes[g][w];
            let [rf, tf, rb, tb] = self.group(g, w, pol);
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
    let plan = Plan::new(groups, columns, wavelengths_nm, thickness_nm, names, scalar);
    let mut out = vec![Power::default(); sines.len() * wavelengths_nm.len()];
    plan.rows(sines, &mut out, |terms, row| {
        let mut x = vec![0.0; groups.count()];
        for (w, slot) in row.iter_mut().enumerate() {
            let t_s = terms.recurrence(w, 0, &mut x);
            let r_s = x[0];
            let t_p = terms.recurrence(w, 1, &mut x);
            *slot = Power {
                R_s: r_s,
                R_p: x[0],
                T_s: t_s,
                T_p: t_p,
            };
        }
    })?;
    Ok(out)
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
    let plan = Plan::new(groups, columns, wavelengths_nm, thickness_nm, names, scalar);
    let last = groups.count() - 1;
    let empty = Absorbed {
        power: Power::default(),
        parts_s: Vec::new(),
        parts_p: Vec::new(),
    };
    let mut out = vec![empty; sines.len() * wavelengths_nm.len()];
    plan.rows(sines, &mut out, |terms, row| {
        let mut x = vec![0.0; groups.count()];
        for (w, slot) in row.iter_mut().enumerate() {
            let mut pols = [(0.0, 0.0, Vec::new()), (0.0, 0.0, Vec::new())];
            for (pol, out) in pols.iter_mut().enumerate() {
                let t = terms.recurrence(w, pol, &mut x);
                let mut parts = Vec::with_capacity(2 * last + 1);
                let mut incoming = 1.0;
                for g in 0..=last {
                    let [rf, tf, rb, tb] = terms.group(g, w, pol);
                    if g == last {
                        parts.push(incoming * (1.0 - rf - tf));
                        break;
                    }
                    let p = terms.passes[g][w];
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
            *slot = Absorbed {
                power: Power {
                    R_s: r_s,
                    R_p: r_p,
                    T_s: t_s,
                    T_p: t_p,
                },
                parts_s,
                parts_p,
            };
        }
    })?;
    Ok(out)
}

/// θ₀ in degrees from sin θ₀, for messages.
fn asin_deg(sin_theta: f64) -> f64 {
    let cos_theta = (1.0 - sin_theta * sin_theta).max(0.0).sqrt();
    elementary::atan2(sin_theta, cos_theta).to_degrees()
}
