//! Vectorised, deterministic kernel for a multilayer stack over wavelengths: one angle's row
//! of [`crate::stack::Stack::sweep`], wavelengths as SIMD lanes.
//!
//! # Layout
//!
//! The media indices are resolved once per wavelength and medium (a tabulated index by
//! walking its table along the ascending wavelengths, `Material::indices_at`) and stored
//! structure-of-arrays ([`Media`]: Re ñ_j, ñ_j² and |ñ_j|² at `[j][w]` for medium j and
//! wavelength w, with k₀ = 2π/λ per wavelength). A sweep's output is angle-major, so one
//! angle's row is contiguous; each lane evaluates one wavelength of it. Wavelengths rather
//! than angles are the lanes because the sweeps of the colour pipelines (`spectral`,
//! `microfacet`, the bake) ask for one angle at a time over many wavelengths, and because
//! lanes then write neighbouring elements of the output. Nothing is shared between lanes:
//! every element is a pure function of its (angle, wavelength), so the results do not
//! depend on the vector width, the thread count or which elements share a vector.
//!
//! A row runs in blocks of [`BLOCK`] wavelengths, medium by medium from the substrate up:
//! each stage (a medium's q, one film of the recurrence, the powers) is a loop over the
//! block's independent elements, which the CPU overlaps, instead of one element's long
//! chain of square roots through the whole stack. No allocation per evaluation (one
//! [`Block`] of staging arrays per thread).
//!
//! Repeated media are computed once per element ([`Slots`]): a medium with the same index
//! bits at every wavelength as one below it has the same q, and a film of the same medium
//! and thickness the same e^{2iδ} — the H and L layers of a periodic mirror, or the TiO₂
//! twice in TiO₂/MgF₂/TiO₂. The copies are the same bits (tested:
//! `repeats_are_computed_once_with_the_same_bits`).
//!
//! # Determinism
//!
//! As in [`crate::simd`]: one generic kernel over [`pulp::Simd`], dispatched to the CPU's
//! widest vectors (AVX-512 or AVX2 on x86-64, NEON on arm64; a row's last vector padded to
//! whole lanes) or run on [`pulp::Scalar`] (one lane: CPUs without them, and the tests'
//! reference); IEEE 754 operations only, each correctly rounded (+, −, ×, ÷, √, fused
//! multiply–add, comparisons, sign-bit and exponent-bit manipulation) in a fixed order, no
//! platform `libm` (sin/cos and e^{−a} are the kernel's own
//! [`crate::simd::sin_cos_bounded_with`] and [`crate::simd::exp_neg_with`]). The fused
//! multiply–adds are written out ([`crate::simd::madd`]: one rounding, `vfmadd` on x86-64,
//! `fmla` on NEON, `f64::mul_add` on one lane), never left to the compiler, so every path
//! rounds the same way. The shortcuts — decided per block of [`BLOCK`] wavelengths
//! and medium ("is the medium lossless over the block", "has it no Im ñ² of negative sign",
//! "does some lane of the film decay") and compiled as separate loops — only skip
//! operations whose result is known exactly (tested: `shortcuts_match_the_general_formula`).
//!
//! # Method (per element)
//!
//! With β = n₀ sin θ₀ and, for every medium j, q_j = ñ_j cos θ_j = √(ñ_j² − β²):
//!
//! * **Square root** of w = x + iy = ñ² − β² without `hypot` or polar form (Kahan,
//!   "Branch cuts for complex elementary functions", 1987, the `CSQRT` algorithm without
//!   its scaling): t = √((|w| + |x|)/2), then √w = (t, y/2t) for x ≥ 0 and
//!   (|y|/2t, copysign(t, y)) for x < 0 — no cancellation in either part; w = 0 gives 0.
//!   [`Media::new`] keeps |ñ| within [10⁻⁶, 10⁶] (else the sweep takes the scalar
//!   recurrence), so |w|² neither overflows nor underflows.
//! * **Forward branch** by masks, the rule of [`crate::fresnel::forward_branch`]: the
//!   principal root has Re ≥ 0; it is negated where Im q < 0 and |Im q| exceeds
//!   100 ε · max(|Re q|, |Im q|) (a wave decaying into the medium; lossless propagating
//!   media keep Re q ≥ 0).
//! * **Interfaces** i → j = i + 1 (Byrnes, arXiv:1603.02720, Eq. 5–8; [`crate::fresnel`])
//!   as r = ρ/σ = (α − β)/(α + β) with the admittances multiplied through by ñ_i² ñ_j²:
//!   α_s = q_i, β_s = q_j; α_p = ñ_j² q_i, β_p = ñ_i² q_j; and |t σ|² = 4|q_i|² (s),
//!   4|ñ_i ñ_j q_i|² (p), since t_s = 2q_i/σ_s, t_p = 2ñ_iñ_j q_i/σ_p.
//! * **Recurrence** from the substrate up (Heavens 1955 §4; Born & Wolf §1.6.5; the module
//!   docs of [`crate::stack`]):
//!   Γ_j = (r_{j,j+1} + Γ_{j+1} e^{2iδ_{j+1}}) / (1 + r_{j,j+1} Γ_{j+1} e^{2iδ_{j+1}}),
//!   |τ_j|² = |t_{j,j+1}|² |τ_{j+1}|² |e^{iδ_{j+1}}|² / |1 + r_{j,j+1} Γ_{j+1} e^{2iδ_{j+1}}|²
//!   (only |τ|² enters the powers), δ_j = k₀ q_j d_j, carried as fractions Γ = N/D and
//!   |τ|² = U/|D|² so that no film costs a division: with M = N e^{2iδ},
//!
//!   ```text
//!   N' = ρD + σM = α(D + M) − β(D − M),   D' = σD + ρM = α(D + M) + β(D − M),
//!   U' = |tσ|² U |e^{iδ}|²,               starting from N = ρ_N, D = σ_N, U = |tσ|²_N.
//!   ```
//!
//!   e^{2iδ} = e^{−2 Im δ} (cos 2Re δ, sin 2Re δ). Every few media N, D, U are rescaled by
//!   a power of two (exact), so that they neither overflow nor underflow in deep stacks.
//! * **Powers**: R = |N₀|²/|D₀|², T_s = U₀,s/|D₀,s|² · Re q_f / Re q₀,
//!   T_p = U₀,p/|D₀,p|² · Re(ñ_f² conj q_f)/|ñ_f|² ÷ Re(ñ₀² conj q₀)/|ñ₀|² (Byrnes
//!   Eq. 21–22: Re(ñ conj(cos θ)) = Re(ñ² conj q)/|ñ|²), one division for all four.
//!
//! * **Both sides in one pass** ([`stack_powers_both`], for the coherent groups between
//!   incoherent slabs, [`crate::incoherent`]): (D, N) is the first column of the stack's
//!   characteristic matrix in the kernel's scaling, M = A₀ P′₁ A₁ ⋯ A_N with
//!   A_j = [[σ, ρ], [ρ, σ]] and P′ = diag(1, e^{2iδ}); the same steps carried from
//!   (D₂, N₂) = (ρ_N, σ_N) give its second column. For light incident from the last medium
//!   (Katsidis & Siapkas, Appl. Opt. 41, 3978, 2002, Eq. 5–7: r′ = −M₁₂/M₁₁,
//!   t′ = det M / M₁₁), r′ = −D₂/D, and since det A_j = σ² − ρ² = 4αβ and
//!   det P′ = e^{2iδ}, |t′|² = U′/|D|² with U′ the product of |t′σ|² = 16|αβ|²/|tσ|² (the
//!   interface crossed upwards: 4|q_j|² for s, 4|ñ_i ñ_j q_j|² for p) and |e^{iδ}|², as U
//!   is of |tσ|². The media's q and the films' e^{2iδ} — the square roots, sines and
//!   exponentials — are shared by both sides; R′ = |D₂|²/|D|², T′ with the power factors of
//!   the reversed direction (Re q₀/Re q_f, and Re(ñ₀² conj q₀)|ñ_f|² / (|ñ₀|² Re(ñ_f² conj q_f))).
//!
//! Against the scalar recurrence ([`crate::stack::Prepared`], which takes √ through
//! `num_complex`'s polar form and e^{iδ} through `libm`) the powers agree to ~10⁻¹⁴ (tested:
//! `vectorised_sweep_matches_the_recurrence`, 10⁻¹², over total internal reflection,
//! absorbing films and substrates, evanescent substrates, normal and grazing incidence).

use crate::power::{Power, PowerSlot};
use crate::simd::{ARCH, exp_neg_with, lane, lane_mut, madd, sin_cos_bounded_with};
use num_complex::Complex64 as C64;
use pulp::{Simd, WithSimd};
use std::cell::RefCell;

pub(crate) mod jacobian;
mod lanes;
mod media;

pub(crate) use media::{Column, Media};

use lanes::{
    Cx, Medium, add, any_nonzero, interface, medium, mul, norm_sqr, reverse_t_sigma2, sub,
};

/// The sign bit of an f64.
const SIGN: u64 = 1 << 63;

/// Writes into `row[w]` the powers at wavelength w and incidence sin θ₀ = `sin_theta`, on
/// the CPU's widest vectors (`vector = true`) or one lane at a time; both give the same bits.
pub(crate) fn stack_powers<T: PowerSlot>(
    media: &Media,
    sin_theta: f64,
    row: &mut [T],
    vector: bool,
) {
    row_powers::<T, true>(media, sin_theta, row, None, vector)
}

/// [`stack_powers`] for light incident from the first medium (`forward`) and from the last
/// (`backward`, the stack upside down) in one pass (module docs, "Both sides in one pass").
pub(crate) fn stack_powers_both(
    media: &Media,
    sin_theta: f64,
    forward: &mut [Power],
    backward: &mut [Power],
    vector: bool,
) {
    assert_eq!(backward.len(), forward.len());
    row_powers::<Power, true>(media, sin_theta, forward, Some(backward), vector)
}

/// The arrays of one incoherent slab for [`slab_passes`], per wavelength and padded with
/// copies of the last to a whole number of [`PAD`]-lane vectors: ñ² (re, im), |ñ|², the
/// ambient's Re ñ₀ (β = Re ñ₀ sin θ₀) and the slab's −2 k₀ d.
pub(crate) struct SlabArrays {
    n2_re: Vec<f64>,
    n2_im: Vec<f64>,
    n_abs2: Vec<f64>,
    n0_re: Vec<f64>,
    scale: Vec<f64>,
}

impl SlabArrays {
    /// The padded length: what [`slab_passes`] writes.
    pub(crate) fn padded(&self) -> usize {
        self.scale.len()
    }

    /// The arrays of a slab of index `column[w]` and thickness `thickness_nm` at the
    /// vacuum wavenumbers `k0_per_nm[w]`, with the ambient's real index `n0_re[w]`.
    pub(crate) fn new(column: &[C64], n0_re: &[f64], k0_per_nm: &[f64], thickness_nm: f64) -> Self {
        let padded = column.len().next_multiple_of(PAD);
        let pad = |v: Vec<f64>| -> Vec<f64> {
            let last = v.last().copied().unwrap_or(0.0);
            let mut v = v;
            v.resize(padded, last);
            v
        };
        SlabArrays {
            n2_re: pad(column.iter().map(|n| n.re * n.re - n.im * n.im).collect()),
            n2_im: pad(column.iter().map(|n| 2.0 * n.re * n.im).collect()),
            n_abs2: pad(column.iter().map(|n| n.re * n.re + n.im * n.im).collect()),
            n0_re: pad(n0_re.to_vec()),
            scale: pad(k0_per_nm
                .iter()
                .map(|k0| -2.0 * k0 * thickness_nm)
                .collect()),
        }
    }
}

/// A slab's single-pass transmission P = |e^{iδ}|² = e^{−2 k₀ d Im q} at every wavelength
/// for incidence sin θ₀ = `sin_theta` (Byrnes §4, [`crate::incoherent`]), into `out`
/// (at least as long as the padded arrays): q by the kernel's own root on its forward
/// branch ([`medium`], the general formula), e^{−a} by [`crate::simd::exp_neg_with`] — the
/// same bits on every vector width.
pub(crate) fn slab_passes(slab: &SlabArrays, sin_theta: f64, out: &mut [f64]) {
    struct Op<'a>(&'a SlabArrays, f64, &'a mut [f64]);
    impl WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) {
            let Op(a, sin_theta, out) = self;
            let lanes = S::F64_LANES;
            for i in (0..a.scale.len()).step_by(lanes) {
                let beta = s.mul_f64s(lane::<S>(&a.n0_re, i), s.splat_f64s(sin_theta));
                let n2 = Cx::<S> {
                    re: lane::<S>(&a.n2_re, i),
                    im: lane::<S>(&a.n2_im, i),
                };
                let m = medium::<S, 0>(s, lane::<S>(&a.n_abs2, i), n2, s.mul_f64s(beta, beta));
                let decay = s.neg_f64s(s.mul_f64s(lane::<S>(&a.scale, i), m.q.im));
                *lane_mut::<S>(out, i) = exp_neg_with::<S, true>(s, decay);
            }
        }
    }
    ARCH.dispatch(Op(slab, sin_theta, out))
}

/// [`stack_powers`]; `SHORTCUTS = false` never skips an operation whose result is known
/// (the reference the shortcuts are tested against).
fn row_powers<T: PowerSlot, const SHORTCUTS: bool>(
    media: &Media,
    sin_theta: f64,
    row: &mut [T],
    back: Option<&mut [Power]>,
    vector: bool,
) {
    assert_eq!(row.len(), media.wavelengths());
    thread_local! {
        /// The staging arrays, allocated once per thread (zeroing them for every row costs
        /// as much as a stage). What a row leaves in them is never read by the next: every
        /// stage writes the lanes it reads before reading them.
        static BLOCK: RefCell<Box<Block>> = RefCell::new(Box::new(Block::new()));
    }
    BLOCK.with_borrow_mut(|block| {
        let op = RowOp::<T, SHORTCUTS> {
            block,
            media,
            sin_theta,
            row,
            back,
        };
        if vector {
            ARCH.dispatch(op)
        } else {
            op.with_simd(pulp::Scalar::new())
        }
    })
}

struct RowOp<'a, T, const SHORTCUTS: bool> {
    block: &'a mut Block,
    media: &'a Media,
    sin_theta: f64,
    row: &'a mut [T],
    /// The backward powers, when both sides are asked for.
    back: Option<&'a mut [Power]>,
}

/// Wavelengths per block of the staging arrays (a multiple of every vector width).
const BLOCK: usize = 64;
/// The per-wavelength arrays of [`Media`] are padded to a multiple of this (a multiple of
/// every vector width, a divisor of [`BLOCK`]).
const PAD: usize = 8;

/// Media kept in a [`Block`]: two for the media of the interface being added, the rest for
/// repeated media ([`Slots`]).
const MEDIA_SLOTS: usize = 6;
/// Film phases kept in a [`Block`]: one for the film below the interface being added, the
/// rest for repeated films.
const FILM_SLOTS: usize = 4;

/// ñ, ñ², q of one medium over a block, (re, im) arrays.
struct MediumBlock {
    n_abs2: [f64; BLOCK],
    n2_re: [f64; BLOCK],
    n2_im: [f64; BLOCK],
    q_re: [f64; BLOCK],
    q_im: [f64; BLOCK],
}

impl MediumBlock {
    fn new() -> Self {
        MediumBlock {
            n_abs2: [0.0; BLOCK],
            n2_re: [0.0; BLOCK],
            n2_im: [0.0; BLOCK],
            q_re: [0.0; BLOCK],
            q_im: [0.0; BLOCK],
        }
    }

    #[inline(always)]
    fn load<S: Simd>(&self, i: usize) -> Medium<S> {
        Medium {
            n_abs2: lane::<S>(&self.n_abs2, i),
            n2: Cx {
                re: lane::<S>(&self.n2_re, i),
                im: lane::<S>(&self.n2_im, i),
            },
            q: Cx {
                re: lane::<S>(&self.q_re, i),
                im: lane::<S>(&self.q_im, i),
            },
        }
    }

    #[inline(always)]
    fn store<S: Simd>(&mut self, i: usize, m: Medium<S>) {
        *lane_mut::<S>(&mut self.n_abs2, i) = m.n_abs2;
        *lane_mut::<S>(&mut self.n2_re, i) = m.n2.re;
        *lane_mut::<S>(&mut self.n2_im, i) = m.n2.im;
        *lane_mut::<S>(&mut self.q_re, i) = m.q.re;
        *lane_mut::<S>(&mut self.q_im, i) = m.q.im;
    }
}

/// The staging arrays of one block of wavelengths. The recurrence runs medium by medium
/// over the whole block (loops of independent elements, which the CPU overlaps), rather
/// than element by element through the stack (one long dependency chain).
struct Block {
    /// The media ([`Media::media_slots`]): j + 1 (below the interface being added) and j
    /// at `media[c.below]` and `media[c.above]`.
    media: [MediumBlock; MEDIA_SLOTS],
    /// β² = (n₀ sin θ₀)² per wavelength.
    beta2: [f64; BLOCK],
    /// The films' e^{2iδ} ([`Media::film_slots`]), (re, im), and decay e^{−2 Im δ} (not
    /// written where no lane of the block decays): film j + 1's at `phase[c.film]`.
    phase: [[[f64; BLOCK]; 3]; FILM_SLOTS],
    /// Γ = N / D per polarisation (s, p): N and D as (re, im) pairs.
    num: [[f64; BLOCK]; 4],
    den: [[f64; BLOCK]; 4],
    /// |τ|² = U / |D|² per polarisation.
    u: [[f64; BLOCK]; 2],
    /// Re q_f, Re(ñ_f² conj q_f), |ñ_f|² of the substrate.
    substrate: [[f64; BLOCK]; 3],
    /// R_s, R_p, T_s, T_p.
    out: [[f64; BLOCK]; 4],
    /// The second column (D₂, N₂) and U′ ([`BOTH`]), as `num`, `den`, `u`.
    num2: [[f64; BLOCK]; 4],
    den2: [[f64; BLOCK]; 4],
    u2: [[f64; BLOCK]; 2],
    /// R′_s, R′_p, T′_s, T′_p ([`BOTH`]).
    out2: [[f64; BLOCK]; 4],
}

/// What one stage of [`Block`] reads besides the block: the block's wavelengths of medium
/// j's arrays and of k₀.
#[derive(Clone, Copy)]
struct Ctx<'a> {
    n2_re: &'a [f64],
    n2_im: &'a [f64],
    n_abs2: &'a [f64],
    k0_per_nm: &'a [f64],
    /// Re ñ₀ (the ambient's, for β).
    n0_re: &'a [f64],
    /// 2 d of the film below the interface (j + 1), nm; 0 where there is none.
    two_d_nm: f64,
    /// Which of [`Block::media`] hold media j and j + 1, and which of [`Block::phase`] film
    /// j + 1 (0 where there is none).
    above: usize,
    below: usize,
    film: usize,
    sin_theta: f64,
}

/// Stages of the recurrence over a block.
const SUBSTRATE: u8 = 0;
const FIRST: u8 = 1;
const MEDIUM_PHASE: u8 = 2;
const STEP: u8 = 3;
const POWERS: u8 = 4;
/// The halves of `MEDIUM_PHASE`, for when the other is known (a repeat, [`Slots`]): medium
/// j alone, film j + 1's phase alone.
const MEDIUM: u8 = 5;
const PHASE: u8 = 6;

/// Flags of a stage, uniform over a block (`const`, so that each combination is its own
/// loop without branches); each only skips operations whose result is known exactly
/// (tested: `shortcuts_match_the_general_formula`).
/// Medium j is lossless over the block ([`Media::lossless`]).
const LOSSLESS: u8 = 1;
/// Medium j has no Im ñ² with its sign bit set ([`Media::forward`]).
const FORWARD: u8 = 2;
/// Some lane of the block has Im q ≠ 0 in the film below (else its decay is exactly 1).
const DECAY: u8 = 4;
/// N, D, U are rescaled after this interface ([`Block::put`]).
const RESCALE: u8 = 8;
/// Medium j is known (a repeat, [`Slots`]): `FIRST` only adds the interface.
const KNOWN: u8 = 16;
/// Both sides: `FIRST`, `STEP` and `POWERS` also carry the second column
/// ([`stack_powers_both`]).
const BOTH: u8 = 32;

/// Calls `$f::<F>` with `F` = `$flags` as a constant, for flags within `LOSSLESS | FORWARD |
/// DECAY`, `DECAY | RESCALE` or `KNOWN`, each with or without `BOTH`.
macro_rules! with_flags {
    ($flags:expr, $f:ident, $($arg:expr),*) => {
        match $flags {
            0 => $f::<0>($($arg),*),
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            12 => $f::<12>($($arg),*),
            16 => $f::<16>($($arg),*),
            32 => $f::<32>($($arg),*),
            33 => $f::<33>($($arg),*),
            34 => $f::<34>($($arg),*),
            35 => $f::<35>($($arg),*),
            36 => $f::<36>($($arg),*),
            40 => $f::<40>($($arg),*),
            44 => $f::<44>($($arg),*),
            48 => $f::<48>($($arg),*),
            _ => unreachable!(),
        }
    };
}

impl Block {
    fn new() -> Self {
        let z = [0.0; BLOCK];
        Block {
            media: std::array::from_fn(|_| MediumBlock::new()),
            beta2: z,
            phase: [[z; 3]; FILM_SLOTS],
            num: [z; 4],
            den: [z; 4],
            u: [z; 2],
            substrate: [z; 3],
            out: [z; 4],
            num2: [z; 4],
            den2: [z; 4],
            u2: [z; 2],
            out2: [z; 4],
        }
    }

    /// Runs stage `STAGE` with flags `F` over the first `n` elements: whole vectors, then one
    /// lane at a time. Returns whether a lane of the medium computed has Im q ≠ 0.
    #[inline(always)]
    fn run<S: Simd, const STAGE: u8, const F: u8>(&mut self, s: S, c: Ctx, n: usize) -> bool {
        let lanes = S::F64_LANES;
        let head = n - n % lanes;
        let mut decays = false;
        for i in (0..head).step_by(lanes) {
            decays |= self.stage::<S, STAGE, F>(s, c, i);
        }
        for i in head..n {
            decays |= self.stage::<pulp::Scalar, STAGE, F>(pulp::Scalar::new(), c, i);
        }
        decays
    }

    /// Stores Γ = N/D and |τ|² = U/|D|² of polarisation `pol` for the lanes at `i`, all
    /// three scaled by the power of two that brings |Re D| + |Im D| into [1, 2) (U by its
    /// square): exact, and keeps N, D, U from over- or underflowing however many films.
    ///
    /// The scaling is done when `rescale` (at every [`RESCALE_EVERY`]-th medium and at the
    /// ambient: a function of the medium index only, so the same for every lane and path);
    /// between, N, D and U grow or shrink by at most (|σ| + |ρ|)^[`RESCALE_EVERY`]
    /// per polarisation (≤ 10⁷⁶ for indices within the kernel's range).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn put<S: Simd>(
        &mut self,
        s: S,
        i: usize,
        pol: usize,
        n: Cx<S>,
        d: Cx<S>,
        u: S::f64s,
        rescale: bool,
    ) {
        let (n, d, u) = if rescale {
            let scale = power_of_two_scale(s, s.add_f64s(s.abs_f64s(d.re), s.abs_f64s(d.im)));
            let scale2 = s.mul_f64s(scale, scale);
            (
                Cx::<S> {
                    re: s.mul_f64s(n.re, scale),
                    im: s.mul_f64s(n.im, scale),
                },
                Cx::<S> {
                    re: s.mul_f64s(d.re, scale),
                    im: s.mul_f64s(d.im, scale),
                },
                s.mul_f64s(u, scale2),
            )
        } else {
            (n, d, u)
        };
        *lane_mut::<S>(&mut self.num[2 * pol], i) = n.re;
        *lane_mut::<S>(&mut self.num[2 * pol + 1], i) = n.im;
        *lane_mut::<S>(&mut self.den[2 * pol], i) = d.re;
        *lane_mut::<S>(&mut self.den[2 * pol + 1], i) = d.im;
        *lane_mut::<S>(&mut self.u[pol], i) = u;
    }

    /// [`Block::put`] of both columns: (N, D, U) and the second column's (N₂, D₂, U′), all
    /// scaled by the power of two chosen from D (the same for both, so that D₂/D and
    /// U′/|D|² are unchanged).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn put_both<S: Simd>(
        &mut self,
        s: S,
        i: usize,
        pol: usize,
        [n, d, n2, d2]: [Cx<S>; 4],
        [u, u2]: [S::f64s; 2],
        rescale: bool,
    ) {
        let (scale, scale2) = if rescale {
            let scale = power_of_two_scale(s, s.add_f64s(s.abs_f64s(d.re), s.abs_f64s(d.im)));
            (scale, s.mul_f64s(scale, scale))
        } else {
            (s.splat_f64s(1.0), s.splat_f64s(1.0))
        };
        let scaled = |c: Cx<S>| Cx::<S> {
            re: s.mul_f64s(c.re, scale),
            im: s.mul_f64s(c.im, scale),
        };
        let (n, d, n2, d2) = if rescale {
            (scaled(n), scaled(d), scaled(n2), scaled(d2))
        } else {
            (n, d, n2, d2)
        };
        let (u, u2) = if rescale {
            (s.mul_f64s(u, scale2), s.mul_f64s(u2, scale2))
        } else {
            (u, u2)
        };
        for (arrays, (n, d)) in [(0, (n, d)), (1, (n2, d2))] {
            let (num, den) = if arrays == 0 {
                (&mut self.num, &mut self.den)
            } else {
                (&mut self.num2, &mut self.den2)
            };
            *lane_mut::<S>(&mut num[2 * pol], i) = n.re;
            *lane_mut::<S>(&mut num[2 * pol + 1], i) = n.im;
            *lane_mut::<S>(&mut den[2 * pol], i) = d.re;
            *lane_mut::<S>(&mut den[2 * pol + 1], i) = d.im;
        }
        *lane_mut::<S>(&mut self.u[pol], i) = u;
        *lane_mut::<S>(&mut self.u2[pol], i) = u2;
    }

    /// Medium j (the one `c` describes) for the lanes at `i`.
    #[inline(always)]
    fn medium_j<S: Simd, const F: u8>(&self, s: S, c: Ctx, i: usize) -> Medium<S> {
        let n2 = Cx::<S> {
            re: lane::<S>(c.n2_re, i),
            im: lane::<S>(c.n2_im, i),
        };
        medium::<S, F>(s, lane::<S>(c.n_abs2, i), n2, lane::<S>(&self.beta2, i))
    }

    /// Stage `STAGE` for the lanes of elements `i ..`; returns whether a lane of the medium
    /// it computes has Im q ≠ 0.
    #[inline(always)]
    fn stage<S: Simd, const STAGE: u8, const F: u8>(&mut self, s: S, c: Ctx, i: usize) -> bool {
        let ld = |v: &[f64; BLOCK]| lane::<S>(v, i);
        match STAGE {
            SUBSTRATE => {
                let beta = s.mul_f64s(lane::<S>(c.n0_re, i), s.splat_f64s(c.sin_theta));
                *lane_mut::<S>(&mut self.beta2, i) = s.mul_f64s(beta, beta);
                let sub = self.medium_j::<S, F>(s, c, i);
                self.media[c.above].store(i, sub);
                let re_n2_conj_q =
                    madd::<S, true>(s, sub.n2.im, sub.q.im, s.mul_f64s(sub.n2.re, sub.q.re));
                *lane_mut::<S>(&mut self.substrate[0], i) = sub.q.re;
                *lane_mut::<S>(&mut self.substrate[1], i) = re_n2_conj_q;
                *lane_mut::<S>(&mut self.substrate[2], i) = sub.n_abs2;
                any_nonzero(s, sub.q.im)
            }
            FIRST => {
                // Γ_N = r_{N,N+1} = ρ/σ, |τ_N|² = |t_{N,N+1}|² = |tσ|²/|σ|².
                let above = if F & KNOWN != 0 {
                    self.media[c.above].load::<S>(i)
                } else {
                    let above = self.medium_j::<S, F>(s, c, i);
                    self.media[c.above].store(i, above);
                    above
                };
                let below = self.media[c.below].load::<S>(i);
                let f = interface(s, &above, &below);
                let back = if F & BOTH != 0 {
                    reverse_t_sigma2(s, &above, &below)
                } else {
                    f.t_sigma2
                };
                for (pol, back) in back.into_iter().enumerate() {
                    let (alpha, beta) = (f.alpha[pol], f.beta[pol]);
                    let (rho, sigma) = (sub(s, alpha, beta), add(s, alpha, beta));
                    if F & BOTH != 0 {
                        // The second column: (D₂, N₂) = A_N (0, 1)ᵀ = (ρ, σ).
                        let cols = [rho, sigma, sigma, rho];
                        self.put_both(s, i, pol, cols, [f.t_sigma2[pol], back], true);
                    } else {
                        self.put(s, i, pol, rho, sigma, f.t_sigma2[pol], true);
                    }
                }
                any_nonzero(s, above.q.im)
            }
            MEDIUM_PHASE | MEDIUM | PHASE => {
                // Medium j, and e^{2iδ} of film j + 1 (medium `below`), δ = k₀ q d:
                // e^{−2 Im δ} (cos, sin)(2 Re δ) — independent chains, side by side.
                let mut decays = false;
                if STAGE != PHASE {
                    let above = self.medium_j::<S, F>(s, c, i);
                    self.media[c.above].store(i, above);
                    decays = any_nonzero(s, above.q.im);
                }
                if STAGE != MEDIUM {
                    let kd2 = s.mul_f64s(lane::<S>(c.k0_per_nm, i), s.splat_f64s(c.two_d_nm));
                    let q = &self.media[c.below];
                    let (q_re, q_im) = (lane::<S>(&q.q_re, i), lane::<S>(&q.q_im, i));
                    let phase = &mut self.phase[c.film];
                    let (sin_x, cos_x) = sin_cos_bounded_with::<S, true>(s, s.mul_f64s(q_re, kd2));
                    let (re, im) = if F & DECAY != 0 {
                        let a = exp_neg_with::<S, true>(s, s.mul_f64s(q_im, kd2));
                        *lane_mut::<S>(&mut phase[2], i) = a;
                        (s.mul_f64s(a, cos_x), s.mul_f64s(a, sin_x))
                    } else {
                        (cos_x, sin_x)
                    };
                    *lane_mut::<S>(&mut phase[0], i) = re;
                    *lane_mut::<S>(&mut phase[1], i) = im;
                }
                decays
            }
            STEP => {
                let above = self.media[c.above].load::<S>(i);
                let below = self.media[c.below].load::<S>(i);
                let f = interface(s, &above, &below);
                let e2 = Cx::<S> {
                    re: ld(&self.phase[c.film][0]),
                    im: ld(&self.phase[c.film][1]),
                };
                let back = if F & BOTH != 0 {
                    reverse_t_sigma2(s, &above, &below)
                } else {
                    f.t_sigma2
                };
                for (pol, back) in back.into_iter().enumerate() {
                    let n = Cx::<S> {
                        re: ld(&self.num[2 * pol]),
                        im: ld(&self.num[2 * pol + 1]),
                    };
                    let d = Cx::<S> {
                        re: ld(&self.den[2 * pol]),
                        im: ld(&self.den[2 * pol + 1]),
                    };
                    // Γ_j = (r + Γ e^{2iδ})/(1 + r Γ e^{2iδ}) with r = ρ/σ, Γ = N/D, M = N e^{2iδ}:
                    // N' = ρD + σM, D' = σD + ρM, U' = |tσ|² U |e^{iδ}|²; with ρ = α − β,
                    // σ = α + β: D' = α(D + M) + β(D − M), N' = α(D + M) − β(D − M).
                    let m = mul(s, n, e2);
                    let (alpha, beta) = (f.alpha[pol], f.beta[pol]);
                    let a = mul(s, alpha, add(s, d, m));
                    let b = mul(s, beta, sub(s, d, m));
                    let (n_new, d_new) = (sub(s, a, b), add(s, a, b));
                    let u = s.mul_f64s(f.t_sigma2[pol], ld(&self.u[pol]));
                    // Where no lane decays, |e^{iδ}|² = 1 exactly.
                    let u = if F & DECAY != 0 {
                        s.mul_f64s(u, ld(&self.phase[c.film][2]))
                    } else {
                        u
                    };
                    if F & BOTH == 0 {
                        self.put(s, i, pol, n_new, d_new, u, F & RESCALE != 0);
                        continue;
                    }
                    // The second column through the same step, U′ with |t′σ|².
                    let n2 = Cx::<S> {
                        re: ld(&self.num2[2 * pol]),
                        im: ld(&self.num2[2 * pol + 1]),
                    };
                    let d2 = Cx::<S> {
                        re: ld(&self.den2[2 * pol]),
                        im: ld(&self.den2[2 * pol + 1]),
                    };
                    let m2 = mul(s, n2, e2);
                    let a2 = mul(s, alpha, add(s, d2, m2));
                    let b2 = mul(s, beta, sub(s, d2, m2));
                    let u2 = s.mul_f64s(back, ld(&self.u2[pol]));
                    let u2 = if F & DECAY != 0 {
                        s.mul_f64s(u2, ld(&self.phase[c.film][2]))
                    } else {
                        u2
                    };
                    let cols = [n_new, d_new, sub(s, a2, b2), add(s, a2, b2)];
                    self.put_both(s, i, pol, cols, [u, u2], F & RESCALE != 0);
                }
                false
            }
            POWERS => {
                // Power factors Re q_f / Re q₀ and
                // Re(ñ_f² conj q_f)/|ñ_f|² ÷ Re(ñ₀² conj q₀)/|ñ₀|²; `above` is the ambient.
                let amb = self.media[c.above].load::<S>(i);
                let re_n2_conj_q =
                    madd::<S, true>(s, amb.n2.im, amb.q.im, s.mul_f64s(amb.n2.re, amb.q.re));
                let cx = |v: &[[f64; BLOCK]; 4], pol: usize| Cx::<S> {
                    re: ld(&v[2 * pol]),
                    im: ld(&v[2 * pol + 1]),
                };
                // One division for the four denominators X = Re q₀,
                // Y = |ñ_f|² Re(ñ₀² conj q₀) and |D_s|², |D_p|² (|D|² in [0.5, 4) after the
                // last rescaling; X and Y within 10^±60 for indices within the kernel's
                // range and |θ₀| < 90°, so their product neither over- nor underflows).
                let x = amb.q.re;
                let y = s.mul_f64s(ld(&self.substrate[2]), re_n2_conj_q);
                let d2 = [norm_sqr(s, cx(&self.den, 0)), norm_sqr(s, cx(&self.den, 1))];
                let xy = s.mul_f64s(x, y);
                let dd = s.mul_f64s(d2[0], d2[1]);
                let inv_all = s.div_f64s(s.splat_f64s(1.0), s.mul_f64s(xy, dd));
                let inv_dd = s.mul_f64s(xy, inv_all);
                let inv_xy = s.mul_f64s(dd, inv_all);
                let inv = [s.mul_f64s(d2[1], inv_dd), s.mul_f64s(d2[0], inv_dd)];
                // Re q_f / Re q₀ and Re(ñ_f² conj q_f) |ñ₀|² / (|ñ_f|² Re(ñ₀² conj q₀)).
                let factor_s = s.mul_f64s(ld(&self.substrate[0]), s.mul_f64s(y, inv_xy));
                let factor_p = s.mul_f64s(
                    s.mul_f64s(ld(&self.substrate[1]), amb.n_abs2),
                    s.mul_f64s(x, inv_xy),
                );
                let p = [
                    s.mul_f64s(norm_sqr(s, cx(&self.num, 0)), inv[0]),
                    s.mul_f64s(norm_sqr(s, cx(&self.num, 1)), inv[1]),
                    s.mul_f64s(s.mul_f64s(ld(&self.u[0]), inv[0]), factor_s),
                    s.mul_f64s(s.mul_f64s(ld(&self.u[1]), inv[1]), factor_p),
                ];
                for (k, v) in p.into_iter().enumerate() {
                    *lane_mut::<S>(&mut self.out[k], i) = v;
                }
                if F & BOTH != 0 {
                    // Backwards: R′ = |D₂|²/|D|², T′ = U′/|D|² times Re q₀ / Re q_f (s) and
                    // Re(ñ₀² conj q₀) |ñ_f|² / (|ñ₀|² Re(ñ_f² conj q_f)) (p) = y / (|ñ₀|² ·
                    // Re(ñ_f² conj q_f)), one division for both.
                    let re_qf = ld(&self.substrate[0]);
                    let re_nf2_conj_qf = s.mul_f64s(ld(&self.substrate[1]), amb.n_abs2);
                    let inv_f = s.div_f64s(s.splat_f64s(1.0), s.mul_f64s(re_qf, re_nf2_conj_qf));
                    let back_s = s.mul_f64s(s.mul_f64s(x, re_nf2_conj_qf), inv_f);
                    let back_p = s.mul_f64s(s.mul_f64s(y, re_qf), inv_f);
                    let p2 = [
                        s.mul_f64s(norm_sqr(s, cx(&self.den2, 0)), inv[0]),
                        s.mul_f64s(norm_sqr(s, cx(&self.den2, 1)), inv[1]),
                        s.mul_f64s(s.mul_f64s(ld(&self.u2[0]), inv[0]), back_s),
                        s.mul_f64s(s.mul_f64s(ld(&self.u2[1]), inv[1]), back_p),
                    ];
                    for (k, v) in p2.into_iter().enumerate() {
                        *lane_mut::<S>(&mut self.out2[k], i) = v;
                    }
                }
                false
            }
            _ => unreachable!(),
        }
    }
}

/// Media between rescalings of the recurrence's N, D, U ([`Block::put`]).
const RESCALE_EVERY: usize = 4;

/// Exponent field of an f64 (bits 52–62).
const EXPONENT: u64 = 0x7ff << 52;

/// 2^{−e} for v = f × 2^e (1 ≤ f < 2), so that v × 2^{−e} lies in [1, 2); 1 for v = 0,
/// subnormal, infinite or NaN.
#[inline(always)]
fn power_of_two_scale<S: Simd>(s: S, v: S::f64s) -> S::f64s {
    let e = s.and_u64s(s.transmute_u64s_f64s(v), s.splat_u64s(EXPONENT));
    // Biased exponent E ↦ 2046 − E: the bits of 2^{−(E − 1023)}.
    let scale = s.transmute_f64s_u64s(s.sub_u64s(s.splat_u64s(2046 << 52), e));
    let special = s.or_m64s(
        s.equal_u64s(e, s.splat_u64s(0)),
        s.equal_u64s(e, s.splat_u64s(EXPONENT)),
    );
    s.select_f64s(special, s.splat_f64s(1.0), scale)
}

impl<T: PowerSlot, const SHORTCUTS: bool> WithSimd for RowOp<'_, T, SHORTCUTS> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) {
        let media = self.media;
        let count = media.re.len();
        let b: &mut Block = self.block;
        let mut back = self.back;
        let both = if back.is_some() { BOTH } else { 0 };
        // Per media slot: whether a lane of the medium in it has Im q ≠ 0.
        let mut decays = [false; MEDIA_SLOTS];
        for (k, row) in self.row.chunks_mut(BLOCK).enumerate() {
            // Whole vectors: the last one's extra lanes are padding ([`Media::from_columns`]),
            // computed like real lanes (each lane is independent) and dropped.
            let n = row.len().next_multiple_of(S::F64_LANES);
            let w = k * BLOCK..k * BLOCK + n;
            // The flags of medium j over this block; none for the general formula.
            let flags = |j: usize| {
                if !SHORTCUTS {
                    return 0;
                }
                let lossless = if media.lossless[j][k] { LOSSLESS } else { 0 };
                let forward = if media.forward[j] { FORWARD } else { 0 };
                lossless | forward
            };
            // Interface j between media j and j + 1 (the substrate alone for j = N + 1).
            // A constant medium's arrays are one block, the same for every block of the row.
            let at = |constant: bool| if constant { 0..n } else { w.clone() };
            let ctx = |j: usize| Ctx {
                n2_re: &media.n2_re[j][at(media.constant[j])],
                n2_im: &media.n2_im[j][at(media.constant[j])],
                n_abs2: &media.n_abs2[j][at(media.constant[j])],
                k0_per_nm: &media.k0_per_nm[w.clone()],
                n0_re: &media.re[0][at(media.beta_constant)],
                two_d_nm: if j + 1 < count - 1 {
                    2.0 * media.thickness_nm[j]
                } else {
                    0.0
                },
                above: media.media_slots.slot[j],
                below: media.media_slots.slot[(j + 1).min(count - 1)],
                film: if j + 1 < count - 1 {
                    media.film_slots.slot[j]
                } else {
                    0
                },
                sin_theta: self.sin_theta,
            };
            macro_rules! run {
                ($stage:ident, $flags:expr, $c:expr) => {{
                    let c = $c;
                    let (b, s) = (&mut *b, s);
                    #[inline(always)]
                    fn go<const F: u8>(b: &mut Block, s: impl Simd, c: Ctx, n: usize) -> bool {
                        b.run::<_, $stage, F>(s, c, n)
                    }
                    with_flags!($flags, go, b, s, c, n)
                }};
            }
            // Medium j is in its slot already: a repeat's, or a constant medium's from the
            // row's first block (which has the most lanes).
            let slots = &media.media_slots;
            let known = |j: usize| slots.known[j] || (k > 0 && slots.whole_row[j]);
            let sub = ctx(count - 1);
            decays[sub.above] = run!(SUBSTRATE, flags(count - 1), sub);
            // Substrate up: interface j between medium j (above) and j + 1 (below).
            for j in (0..count - 1).rev() {
                let c = ctx(j);
                let known = known(j);
                if j == count - 2 {
                    // Γ_N = r_{N,N+1}, |τ_N|² = |t_{N,N+1}|².
                    if known {
                        run!(FIRST, KNOWN | both, c);
                    } else {
                        decays[c.above] = run!(FIRST, flags(j) | both, c);
                    }
                    continue;
                }
                let decay = if SHORTCUTS && !decays[c.below] {
                    0
                } else {
                    DECAY
                };
                // Film j + 1 is film item j.
                match (known, media.film_slots.known[j]) {
                    (false, false) => decays[c.above] = run!(MEDIUM_PHASE, flags(j) | decay, c),
                    (false, true) => decays[c.above] = run!(MEDIUM, flags(j), c),
                    (true, false) => {
                        run!(PHASE, decay, c);
                    }
                    (true, true) => {}
                }
                let rescale = if j.is_multiple_of(RESCALE_EVERY) {
                    RESCALE
                } else {
                    0
                };
                run!(STEP, rescale | decay | both, c);
            }
            if both != 0 {
                b.run::<S, POWERS, BOTH>(s, ctx(0), n);
            } else {
                b.run::<S, POWERS, 0>(s, ctx(0), n);
            }
            for (k, slot) in row.iter_mut().enumerate() {
                slot.put(Power {
                    R_s: b.out[0][k],
                    R_p: b.out[1][k],
                    T_s: b.out[2][k],
                    T_p: b.out[3][k],
                });
            }
            if let Some(back) = back.as_deref_mut() {
                for (j, slot) in back[k * BLOCK..k * BLOCK + row.len()]
                    .iter_mut()
                    .enumerate()
                {
                    *slot = Power {
                        R_s: b.out2[0][j],
                        R_p: b.out2[1][j],
                        T_s: b.out2[2][j],
                        T_p: b.out2[3][j],
                    };
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
