//! The "integrated" (fast path) layout of diffraction tables: wavelength-integrated colour
//! tables Iₚ(u, v), p = 0 … 2N, from which a shader rebuilds the colour of Stam's BRDF with
//! one bilinear fetch per table and no loop over wavelengths (issue 7; the idea of
//! precomputing what does not depend on w is Dhillon et al. 2014's, carried one step
//! further here: the wavelength sum is done at bake time too).
//!
//! # Derivation
//!
//! With the windowed transform of term n alone (the module [`super`] docs),
//!
//! ```text
//! P̃ₙ(q) = Σ_j Tₙ[j] exp(−σ_s²|q − κ_j|²/2),   P̃(ku, kv) = Σₙ (kw)ⁿ/n! · P̃ₙ(ku, kv),
//! ```
//!
//! the squared modulus expands as a double sum whose imaginary parts cancel pairwise
//! (the (n, m) and (m, n) terms are complex conjugates):
//!
//! ```text
//! |P̃|² = Σ_{n,m=0}^{N} (kw)^{n+m}/(n! m!) · Re(P̃ₙ P̃ₘ*)
//!      = Σ_{p=0}^{2N} wᵖ · kᵖ Σ_{n+m=p, n,m≤N} Re(P̃ₙ(ku, kv) P̃ₘ(ku, kv)*)/(n! m!).
//! ```
//!
//! The relative reflectance is ρ = F²(θ_h) · G/w² · |P̃|². When F² does not depend on the
//! wavelength ([`FresnelTerm::Unity`], or [`FresnelTerm::Index`] of one index, as
//! `nacre diffraction --fresnel` evaluates it at 550 nm), neither does
//! C(ω_i, ω_r) = F²(θ_h) · G/w², and the colour XYZ_c = Σ_λ u_c(λ) ρ(λ) of a
//! [`SpectralGrid`] (weights u_c, perfect reflector Y = 1) factors as
//!
//! ```text
//! colour_c(ω_i, ω_r) = C(ω_i, ω_r) · Σ_{p=0}^{2N} wᵖ · I_{p,c}(u, v),
//! I_{p,c}(u, v) = Σ_λ u_c(λ) kᵖ Σ_{n+m=p} Re(P̃ₙ(ku, kv) P̃ₘ(ku, kv)*)/(n! m!),   k = 2π/λ.
//! ```
//!
//! **Stam's k².** The BRDF is f = ρ (σ_s k)²/π, not ρ: a flat mirror's lobe |P̃|² =
//! exp(−σ_s²k²|Δ(u, v)|²) integrates to π/(σ_s k)² over (u, v), so its energy is the same
//! at every wavelength only with the k² (Stam 1999, eq. 11; issue 37). A renderer passes
//! the light's gain (σ_s k_ref)²/π at one reference wavelength λ_ref
//! (`nacre_runtime::diffraction::lobe_gain`) and puts back (k/k_ref)² = (λ_ref/λ)² per
//! wavelength; the terms technique does that in its wavelength loop, and a table of this
//! layout must do it at bake time, where the wavelengths are summed:
//!
//! ```text
//! I_{p,c}(u, v) = Σ_λ (λ_ref/λ)² u_c(λ) kᵖ Σ_{n+m=p} Re(P̃ₙ P̃ₘ*)/(n! m!)
//! ```
//!
//! ([`IntegratedTable::compute`] with `Some(λ_ref)`; [`K_SQUARED_REFERENCE_NM`] = 555 nm,
//! the runtime's, for baked tables). Without it (`None`, and every table baked before the
//! weight existed) the table is Σ_λ u ρ and a picture drawn from it is tilted towards red
//! by (λ/λ_ref)² (×0.66 at 450 nm, ×1.37 at 650 nm against 555 nm). The weight is a
//! positive constant per wavelength, so everything below (the factorisation, the symmetry,
//! the blurred levels) holds unchanged. Only the mirror image's colour is not weighted: the
//! zeroth order's efficiency is the lobe's peak ρ(0, 0) times its integral
//! (σ_s k)²/π · π/(σ_s k)² = 1 at every wavelength, so [`IntegratedTable::specular_layers`]
//! keep Jₚ = Iₚ(0, 0) without the weight.
//!
//! Iₚ depends on (u, v) only: w and the wavelength sum are out of the texture coordinates.
//! Because n, m ≤ N on both sides, Σₚ wᵖ Iₚ is exactly the colour of the truncated terms
//! layout (`|Σ_{n≤N}|²`), not a second truncation. The channels are stored in the
//! colorimeter's output space (M · XYZ, linear; M = I for `xyz`): the sum is linear, so
//! colour = C · Σₚ wᵖ (M·Iₚ) is what `SpectralGrid` + `output_from_xyz` give from the
//! terms layout, and a shader needs no matrix.
//!
//! **Point symmetry: half the table.** A real height field has Tₙ\[−j\] = (−1)ⁿ conj Tₙ\[j\],
//! hence P̃ₙ(−q) = (−1)ⁿ conj P̃ₙ(q) and Iₚ(−u, −v) = (−1)ᵖ Iₚ(u, v). The table stores
//! u ≥ 0 only and a shader folds the other half over:
//!
//! ```text
//! u < 0:  Σₚ wᵖ Iₚ(u, v) = Σₚ (−w)ᵖ Iₚ(−u, −v)      (evaluate at (−u, −v) with w → −w)
//! ```
//!
//! The one exception is the unpaired Nyquist bin −M/2 of an even-sized DFT, which the
//! window reaches only within a few 1/σ_s of the Nyquist limit; the measured
//! reconstruction error below includes any trace of it (u < 0 is measured too).
//!
//! **Cancellation.** The terms wᵖ Iₚ grow like (2|kwh|)ᵖ/p! while their sum is the colour
//! of |P̃|² ≤ 1, so for tall structures the sum cancels catastrophically in the f32 a
//! shader stores and adds: with x = max |kwh| the rounding of the stored Iₚ is bounded by
//! about 2⁻²⁴ Σₚ (2x)ᵖ/p! ≈ 6·10⁻⁸ e^{2x} of the white. The bound is pessimistic;
//! [`IntegratedTable::storage_error`] measures it at texel centres: 1.0·10⁻⁷ of the white
//! for the CD-like surface (x = 2.78), 10⁻⁴ for a 0.5 µm blazed grating (x ≈ 8), 24 for a
//! 1 µm one (x ≈ 16). [`IntegratedTable::reconstruction_error`] measures the whole effect
//! (f32 storage, bilinear interpolation, f32 Horner sum) against the f64 terms-layout
//! colour.
//!
//! # Axes
//!
//! v spans [−u_max, u_max] and u the half [0, u_max] (u_max = 2 sin θ_max,
//! [`WarpedAxis`]), on warped axes that pack texels near the specular direction
//! u = v = 0, where the mirror lobe exp(−σ_s²k²(u² + v²)) is 1/(kσ_s) wide and where the
//! v-profile of a 1-D grating is as sharp at every u. The full axis has n texels (n even);
//! texel i has its centre at t_i = (2i + 1)/n − 1 and
//!
//! ```text
//! forward:  t = sign(u) (|u|/u_max)^{1/γ},   x = (t + 1) n/2 − ½   (texel coordinate: centre of i at x = i)
//! inverse:  u = u_max sign(t) |t|^γ
//! ```
//!
//! The stored u columns are texels n/2 … n − 1 of that axis: column c = i − n/2 holds
//! u = u_max ((2c + 1)/n)^γ, and a shader reads column coordinate x − n/2 (clamped to
//! [0, n/2 − 1]: for u → 0 it clamps onto column 0, whose centre is at u_max n^{−γ}).
//! The texel spacing is 2γ u_max |t|^{γ−1}/n: near the specular direction it shrinks like
//! |u|^{(γ−1)/γ}, at the edge it is γ times the uniform spacing.

use super::{DiffractionSurface, FresnelTerm, SpectralGrid, geometry_over_w2, k_per_um};
use crate::C64;
use crate::colour::Colorimeter;
use crate::elementary;
use crate::error::{Error, Result};
use ndarray::{Array2, Axis};
use rayon::prelude::*;

/// Most texels per axis of an integrated table.
pub const MAX_INTEGRATED_SAMPLES: usize = 4096;

/// The reference wavelength λ_ref of Stam's k² weight (λ_ref/λ)² in baked integrated tables,
/// nm (module docs): the wavelength of the runtime's light gain (σ_s k_ref)²/π
/// (`nacre_runtime::diffraction::LOBE_REFERENCE_NM` is this constant).
pub const K_SQUARED_REFERENCE_NM: f64 = 555.0;

/// Stam's k² relative to the reference, (k/k_ref)² = (λ_ref/λ)² (module docs).
pub fn k_squared_weight(reference_nm: f64, wavelength_nm: f64) -> f64 {
    let r = reference_nm / wavelength_nm;
    r * r
}

/// The weight (λ_ref/λ)² of `wavelength_nm` for an optional reference (1 without one).
fn weight_of(reference_nm: Option<f64>, wavelength_nm: f64) -> f64 {
    reference_nm.map_or(1.0, |r| k_squared_weight(r, wavelength_nm))
}

/// A warped texture axis over [−u_max, u_max] packing texels near 0 (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WarpedAxis {
    /// u_max = 2 sin θ_max: the largest |u| (or |v|) served.
    pub max_uv: f64,
    /// The warp exponent γ ≥ 1 (1: uniform).
    pub gamma: f64,
    /// Texels n over [−u_max, u_max]: even, at least 4.
    pub count: usize,
}

impl WarpedAxis {
    /// An axis of `count` texels over [−`max_uv`, `max_uv`] with exponent `gamma`.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for `max_uv` outside (0, 2], γ outside [1, 8] or a count
    /// that is odd or outside 4 … [`MAX_INTEGRATED_SAMPLES`].
    pub fn new(max_uv: f64, gamma: f64, count: usize) -> Result<Self> {
        if !(max_uv > 0.0 && max_uv <= 2.0) {
            return Err(Error::OutOfRange {
                what: "largest |u|, |v| of an integrated table",
                value: max_uv,
                expected: "a number in (0, 2]",
            });
        }
        if !(1.0..=8.0).contains(&gamma) {
            return Err(Error::OutOfRange {
                what: "integrated-table warp exponent γ",
                value: gamma,
                expected: "a number in [1, 8]",
            });
        }
        if !(4..=MAX_INTEGRATED_SAMPLES).contains(&count) || count % 2 == 1 {
            return Err(Error::OutOfRange {
                what: "integrated-table texels per axis",
                value: count as f64,
                expected: "an even number from 4 to 4096",
            });
        }
        Ok(WarpedAxis {
            max_uv,
            gamma,
            count,
        })
    }

    /// u at the centre of texel i (inverse mapping).
    pub fn texel_centre(&self, i: usize) -> f64 {
        let t = (2.0 * i as f64 + 1.0) / self.count as f64 - 1.0;
        self.max_uv * t.signum() * elementary::powf(t.abs(), self.gamma)
    }

    /// The continuous texel coordinate of u (forward mapping): texel i's centre is at i;
    /// clamped to [0, n − 1] (clamp-to-edge).
    pub fn coordinate(&self, u: f64) -> f64 {
        let a = (u.abs() / self.max_uv).min(1.0);
        let t = u.signum() * elementary::powf(a, 1.0 / self.gamma);
        ((t + 1.0) * 0.5 * self.count as f64 - 0.5).clamp(0.0, self.count as f64 - 1.0)
    }
}

/// An integrated table: I_{p,c}(u, v) for p = 0 … 2N, u ≥ 0 (n/2 columns) and v over the
/// whole axis (n rows), stored as f32 in the colorimeter's output space (module docs), with
/// the k² reference it was summed with and the zeroth order's layers Jₚ.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegratedTable {
    axis: WarpedAxis,
    order: usize,
    /// `values[(p * n + iv) * n/2 + c]`: layer p, row v, column c (u ≥ 0).
    values: Vec<[f32; 3]>,
    /// λ_ref of the (λ_ref/λ)² weight in `values`; `None`: summed without Stam's k².
    k_squared_reference_nm: Option<f64>,
    /// Jₚ, p = 0 … 2N: the mirror-lobe peak's layers without the k² weight.
    specular: Vec<[f32; 3]>,
}

impl IntegratedTable {
    /// Computes the table of `surface` for the wavelengths and weights of `grid`, stored in
    /// `colorimeter`'s output space, each wavelength weighted by Stam's k² relative to
    /// `k_squared_reference_nm` (λ_ref/λ)² (module docs: the BRDF is ρ (σ_s k)²/π and the
    /// renderer's gain takes k at λ_ref; `None` sums ρ u without it, as tables baked before
    /// issue 37's k² did). Also computes the zeroth order's layers
    /// Jₚ = Σ_λ u(λ) kᵖ Σ_{n+m=p} Re(P̃ₙ(0) P̃ₘ(0)*)/(n! m!), unweighted
    /// ([`Self::specular_layers`]). Rows of texels in parallel; each row is summed in a
    /// fixed order, so the values do not depend on the thread count.
    ///
    /// Per row (fixed v) and wavelength the window's y factor is applied once to every
    /// column of bins (R_n\[jₓ\] = Σ_{j_y} g_y Tₙ\[jₓ, j_y\]); each texel then needs only
    /// its x factor.
    pub fn compute(
        surface: &DiffractionSurface,
        grid: &SpectralGrid,
        colorimeter: &Colorimeter,
        axis: WarpedAxis,
        k_squared_reference_nm: Option<f64>,
    ) -> Self {
        let terms = surface.terms();
        let order = terms.order();
        let terms_per_bin = order + 1;
        let layers = 2 * order + 1;
        let (nx, ny) = terms.size();
        let n = axis.count;
        let half = n / 2;
        let inv_fact: Vec<f64> = (0..=order)
            .scan(1.0, |f, i| {
                if i > 0 {
                    *f /= i as f64;
                }
                Some(*f)
            })
            .collect();
        let matrix = colorimeter.matrix();
        let columns_u: Vec<f64> = (half..n).map(|i| axis.texel_centre(i)).collect();
        let rows: Vec<Vec<[f32; 3]>> = (0..n)
            .into_par_iter()
            .map(|iv| {
                let v = axis.texel_centre(iv);
                let mut acc = vec![[0.0f64; 3]; half * layers];
                // Σ_y over the rows of the terms: (sx, n) for one wavelength.
                let mut r = Array2::from_elem((nx, terms_per_bin), C64::new(0.0, 0.0));
                let mut pt = vec![C64::new(0.0, 0.0); terms_per_bin];
                let mut q = vec![0.0f64; layers];
                let mut k_pow = vec![0.0f64; layers];
                for (&wavelength, xyz_weight) in grid.wavelengths_nm().iter().zip(&grid.xyz_weights)
                {
                    let k = k_per_um(wavelength);
                    let k2 = weight_of(k_squared_reference_nm, wavelength);
                    let weight = xyz_weight.map(|x| x * k2);
                    r.fill(C64::new(0.0, 0.0));
                    for (jy, wy) in surface.axis_weights(k * v, false) {
                        let sy = (jy + (ny / 2) as i64) as usize;
                        r.zip_mut_with(&terms.data.index_axis(Axis(0), sy), |r, t| *r += t * wy);
                    }
                    let mut kp = 1.0;
                    for v in k_pow.iter_mut() {
                        *v = kp;
                        kp *= k;
                    }
                    for (c, &u) in columns_u.iter().enumerate() {
                        pt.fill(C64::new(0.0, 0.0));
                        for (jx, wx) in surface.axis_weights(k * u, true) {
                            let sx = (jx + (nx / 2) as i64) as usize;
                            for (p, b) in pt.iter_mut().zip(r.row(sx)) {
                                *p += b * wx;
                            }
                        }
                        // kᵖ Σ_{n+m=p} Re(P̃ₙ P̃ₘ*)/(n! m!), the (m, n) twin of n < m doubling it.
                        q.fill(0.0);
                        for a in 0..=order {
                            for b in a..=order {
                                let re = pt[a].re * pt[b].re + pt[a].im * pt[b].im;
                                let twin = if a == b { 1.0 } else { 2.0 };
                                q[a + b] += twin * re * inv_fact[a] * inv_fact[b];
                            }
                        }
                        let cell = &mut acc[c * layers..(c + 1) * layers];
                        for ((cell, q), kp) in cell.iter_mut().zip(&q).zip(&k_pow) {
                            let s = q * kp;
                            for ch in 0..3 {
                                cell[ch] += weight[ch] * s;
                            }
                        }
                    }
                }
                // Layer-major within the row, in the output space: out[p * half + c].
                let mut out = vec![[0.0f32; 3]; layers * half];
                for c in 0..half {
                    for p in 0..layers {
                        let xyz = acc[c * layers + p];
                        let rgb: [f64; 3] = std::array::from_fn(|i| {
                            matrix[i][0] * xyz[0] + matrix[i][1] * xyz[1] + matrix[i][2] * xyz[2]
                        });
                        out[p * half + c] = rgb.map(|v| v as f32);
                    }
                }
                out
            })
            .collect();
        let mut values = vec![[0.0f32; 3]; layers * n * half];
        for (iv, row) in rows.iter().enumerate() {
            for p in 0..layers {
                values[(p * n + iv) * half..(p * n + iv + 1) * half]
                    .copy_from_slice(&row[p * half..(p + 1) * half]);
            }
        }
        let specular = zeroth_order_layers(surface, grid, colorimeter);
        IntegratedTable {
            axis,
            order,
            values,
            k_squared_reference_nm,
            specular,
        }
    }

    /// A table from stored values (`values[(p * n + iv) * n/2 + c]`, p = 0 … 2N), e.g.
    /// read back from a baked file, summed without Stam's k² (as every table baked before
    /// issue 37's k²; [`Self::with_k_squared`] marks one baked with it). Its zeroth-order
    /// layers Jₚ are the layers read at u = v = 0 (bilinear, in f32 as the shader reads
    /// them), so [`Self::specular_sum`] is [`Self::sum_at`] at (0, 0, w) up to the rounding
    /// of the Horner sum: such a table renders as before.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] when the value count is not (2N + 1)·n·n/2.
    pub fn from_values(axis: WarpedAxis, order: usize, values: Vec<[f32; 3]>) -> Result<Self> {
        let expected = (2 * order + 1) * axis.count * (axis.count / 2);
        if values.len() != expected {
            return Err(Error::OutOfRange {
                what: "integrated-table values",
                value: values.len() as f64,
                expected: "(2N + 1) × n × n/2 texels",
            });
        }
        let mut table = IntegratedTable {
            axis,
            order,
            values,
            k_squared_reference_nm: None,
            specular: Vec::new(),
        };
        let at = table.lookup(0.0, 0.0, 0.0);
        table.specular = (0..table.layers())
            .map(|p| table.bilinear(p, &at))
            .collect();
        Ok(table)
    }

    /// This table marked as summed with Stam's k² relative to `reference_nm`, with the
    /// unweighted zeroth-order layers `specular` (Jₚ, p = 0 … 2N) a manifest records.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a reference that is not a finite wavelength in
    /// (0, 10⁶] nm, or `specular` not of 2N + 1 finite values.
    pub fn with_k_squared(mut self, reference_nm: f64, specular: Vec<[f32; 3]>) -> Result<Self> {
        if !(reference_nm > 0.0 && reference_nm <= 1e6) {
            return Err(Error::OutOfRange {
                what: "k² reference wavelength of an integrated table (nm)",
                value: reference_nm,
                expected: "a finite wavelength in (0, 1e6] nm",
            });
        }
        if specular.len() != self.layers() || !specular.iter().flatten().all(|x| x.is_finite()) {
            return Err(Error::OutOfRange {
                what: "zeroth-order layers of an integrated table",
                value: specular.len() as f64,
                expected: "2N + 1 finite colours",
            });
        }
        self.k_squared_reference_nm = Some(reference_nm);
        self.specular = specular;
        Ok(self)
    }

    /// λ_ref of the (λ_ref/λ)² weight the table was summed with; `None` for a table summed
    /// without Stam's k² (baked by a nacre before issue 37's k²): its colours are Σ_λ ρ u,
    /// tilted towards red by (λ/λ_ref)² against the terms technique (module docs).
    pub fn k_squared_reference_nm(&self) -> Option<f64> {
        self.k_squared_reference_nm
    }

    /// Jₚ, p = 0 … 2N: the layers of the mirror lobe's peak without the k² weight, so that
    /// F² Σₚ (−2 cos θ)ᵖ Jₚ is the colour of |P̃(0, 0)|², the zeroth order's efficiency
    /// (module docs).
    pub fn specular_layers(&self) -> &[[f32; 3]] {
        &self.specular
    }

    /// Σₚ wᵖ Jₚ by the f32 Horner sum (the shader's `diffraction_integrated_specular_colour`
    /// without F²): the colour of |P̃(0, 0)|² at w, unweighted.
    pub fn specular_sum(&self, w: f64) -> [f64; 3] {
        let w = w as f32;
        let mut acc = [0.0f32; 3];
        for j in self.specular.iter().rev() {
            for ch in 0..3 {
                acc[ch] = acc[ch] * w + j[ch];
            }
        }
        acc.map(f64::from)
    }

    /// The axis (v whole, u its half u ≥ 0).
    pub fn axis(&self) -> WarpedAxis {
        self.axis
    }

    /// The Taylor order N of the terms the table was built from.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Layers 2N + 1.
    pub fn layers(&self) -> usize {
        2 * self.order + 1
    }

    /// (columns, rows) = (n/2, n) of each layer.
    pub fn size(&self) -> (usize, usize) {
        (self.axis.count / 2, self.axis.count)
    }

    /// I_p at column c (u ≥ 0) and row iv, output space.
    pub fn texel(&self, p: usize, c: usize, iv: usize) -> [f32; 3] {
        let (w, h) = self.size();
        self.values[(p * h + iv) * w + c]
    }

    /// Every value, `[(p * n + iv) * n/2 + c]`.
    pub fn values(&self) -> &[[f32; 3]] {
        &self.values
    }

    /// Σₚ wᵖ Iₚ(u, v) as a shader computes it: the fold u < 0 → (−u, −v, −w), the texel
    /// coordinates of the forward mapping (clamped to the edge), bilinear weights, and
    /// the Horner sum (…(I_{2N} w + I_{2N−1}) w + …) w + I₀, all in f32.
    pub fn sum_at(&self, u: f64, v: f64, w: f64) -> [f64; 3] {
        let at = self.lookup(u, v, w);
        self.horner(&at).map(f64::from)
    }

    /// Where (u, v, w) reads the table: the fold, the clamped texel coordinates, the
    /// bilinear weights and the (folded) w in f32.
    fn lookup(&self, u: f64, v: f64, w: f64) -> Lookup {
        let (u, v, w) = if u < 0.0 { (-u, -v, -w) } else { (u, v, w) };
        let (cols, rows) = self.size();
        let split = |x: f64, n: usize| {
            let x = x.clamp(0.0, (n - 1) as f64);
            let i0 = (x.floor() as usize).min(n - 2);
            (i0, (x - i0 as f64) as f32)
        };
        let (x0, fx) = split(self.axis.coordinate(u) - cols as f64, cols);
        let (y0, fy) = split(self.axis.coordinate(v), rows);
        Lookup {
            x0,
            y0,
            fx,
            fy,
            w: w as f32,
        }
    }

    /// Layer p read bilinearly at `at` (f32, as in [`Self::horner`]).
    fn bilinear(&self, p: usize, at: &Lookup) -> [f32; 3] {
        let (x0, y0, fx, fy) = (at.x0, at.y0, at.fx, at.fy);
        let a = self.texel(p, x0, y0);
        let b = self.texel(p, x0 + 1, y0);
        let c = self.texel(p, x0, y0 + 1);
        let d = self.texel(p, x0 + 1, y0 + 1);
        std::array::from_fn(|ch| {
            let lo = a[ch] + fx * (b[ch] - a[ch]);
            let hi = c[ch] + fx * (d[ch] - c[ch]);
            lo + fy * (hi - lo)
        })
    }

    /// The f32 Horner sum of the bilinear reads at `at`.
    fn horner(&self, at: &Lookup) -> [f32; 3] {
        let (x0, y0, fx, fy, w) = (at.x0, at.y0, at.fx, at.fy, at.w);
        let mut acc = [0.0f32; 3];
        for p in (0..self.layers()).rev() {
            let a = self.texel(p, x0, y0);
            let b = self.texel(p, x0 + 1, y0);
            let c = self.texel(p, x0, y0 + 1);
            let d = self.texel(p, x0 + 1, y0 + 1);
            for ch in 0..3 {
                let lo = a[ch] + fx * (b[ch] - a[ch]);
                let hi = c[ch] + fx * (d[ch] - c[ch]);
                acc[ch] = acc[ch] * w + (lo + fy * (hi - lo));
            }
        }
        acc
    }

    /// The colour (output space) C(ω_i, ω_r) · Σₚ wᵖ Iₚ(u, v) with
    /// C = F²(θ_h) · G/w² (module docs); 0 when either direction is at or below the
    /// horizon. F² must not depend on the wavelength, which [`FresnelTerm`] guarantees.
    pub fn colour(&self, omega_i: [f64; 3], omega_r: [f64; 3], fresnel: FresnelTerm) -> [f64; 3] {
        let g = geometry_over_w2(omega_i, omega_r);
        if g == 0.0 {
            return [0.0; 3];
        }
        let [u, v, w] = std::array::from_fn(|i| -omega_i[i] - omega_r[i]);
        let cos_h =
            -(omega_i[0] * u + omega_i[1] * v + omega_i[2] * w) / (u * u + v * v + w * w).sqrt();
        let c = fresnel.reflectance(cos_h) * g;
        self.sum_at(u, v, w).map(|s| c * s)
    }

    /// The white the errors are measured in, per output channel: the colour of ρ ≡ 1 (a flat
    /// perfect mirror in its specular direction) as this table sums it, with its own
    /// (λ_ref/λ)² weight when it has a k² reference (Σ_λ (λ_ref/λ)² u(λ): the same units on
    /// both sides of the comparison), without it otherwise (the output space's white).
    pub fn white(&self, grid: &SpectralGrid, colorimeter: &Colorimeter) -> [f64; 3] {
        let ones: Vec<f64> = grid
            .wavelengths_nm()
            .iter()
            .map(|&l| weight_of(self.k_squared_reference_nm, l))
            .collect();
        colorimeter.output_from_xyz(grid.xyz(&ones))
    }

    /// Measures the table against the terms layout: for every (ω_i, ω_r) of `pairs`, the
    /// colour of [`IntegratedTable::colour`] against the exact colour of `surface`
    /// (f64 terms, ρ per wavelength weighted by the table's own (λ_ref/λ)² when it has a
    /// k² reference — like with like —, [`SpectralGrid::xyz`], `output_from_xyz`), both
    /// with F = 1. The metric is the largest |Δ| of any output channel divided by that
    /// channel's white ([`Self::white`]: the colour ρ ≡ 1 gives, a flat perfect mirror seen
    /// in its specular direction, with the table's k² weight), i.e. errors in units of the
    /// specular white. Pairs in parallel; the
    /// maximum is taken in pair order, so the result does not depend on the thread count.
    pub fn reconstruction_error(
        &self,
        surface: &DiffractionSurface,
        grid: &SpectralGrid,
        colorimeter: &Colorimeter,
        pairs: &[([f64; 3], [f64; 3])],
    ) -> ReconstructionError {
        let white = self.white(grid, colorimeter);
        let errors: Vec<(f64, usize, [f64; 3], [f64; 3])> = pairs
            .par_iter()
            .map(|&(wi, wr)| {
                let rho: Vec<f64> = grid
                    .wavelengths_nm()
                    .iter()
                    .map(|&l| {
                        weight_of(self.k_squared_reference_nm, l)
                            * surface.relative_reflectance(wi, wr, l, FresnelTerm::Unity)
                    })
                    .collect();
                let exact = colorimeter.output_from_xyz(grid.xyz(&rho));
                let fast = self.colour(wi, wr, FresnelTerm::Unity);
                let (mut worst, mut channel) = (0.0f64, 0);
                for c in 0..3 {
                    let e = (fast[c] - exact[c]).abs() / white[c].abs().max(1e-300);
                    if !(e <= worst) {
                        worst = e;
                        channel = c;
                    }
                }
                (worst, channel, exact, fast)
            })
            .collect();
        let mut report = ReconstructionError {
            max_error: 0.0,
            mean_error: 0.0,
            omega_i: [0.0, 0.0, 1.0],
            omega_r: [0.0, 0.0, 1.0],
            channel: 0,
            exact: [0.0; 3],
            integrated: [0.0; 3],
            pairs: pairs.len(),
        };
        let mut sum = 0.0;
        for (i, &(e, channel, exact, integrated)) in errors.iter().enumerate() {
            sum += e;
            if !(e <= report.max_error) {
                report = ReconstructionError {
                    max_error: e,
                    omega_i: pairs[i].0,
                    omega_r: pairs[i].1,
                    channel,
                    exact,
                    integrated,
                    ..report
                };
            }
        }
        report.mean_error = sum / pairs.len().max(1) as f64;
        report
    }
}

impl IntegratedTable {
    /// The error of f32 storage and the f32 Horner sum alone (no interpolation): at the
    /// centres of every `stride`-th column and row, |Σₚ wᵖ Iₚ − M Σ_λ u(λ)|P̃(λ)|²| (each
    /// wavelength weighted by the table's (λ_ref/λ)² when it has a k² reference) for
    /// w = −2 and w = `w_min` (the smallest |w| served, −2 cos θ_max), P̃ from `surface`'s
    /// f64 terms, in units of the specular white as in
    /// [`IntegratedTable::reconstruction_error`]. This isolates the catastrophic
    /// cancellation of the sum for tall structures (module docs). Texels in parallel, the
    /// maximum in a fixed order.
    pub fn storage_error(
        &self,
        surface: &DiffractionSurface,
        grid: &SpectralGrid,
        colorimeter: &Colorimeter,
        stride: usize,
        w_min: f64,
    ) -> f64 {
        let white = self.white(grid, colorimeter);
        let (cols, rows) = self.size();
        let stride = stride.max(1);
        let probes: Vec<(f64, f64, f64)> = (0..rows)
            .step_by(stride)
            .flat_map(|iv| {
                (0..cols)
                    .step_by(stride)
                    .flat_map(move |c| [-2.0, w_min].map(|w| (c, iv, w)))
            })
            .map(|(c, iv, w)| {
                (
                    self.axis.texel_centre(cols + c),
                    self.axis.texel_centre(iv),
                    w,
                )
            })
            .collect();
        let errors: Vec<f64> = probes
            .par_iter()
            .map(|&(u, v, w)| {
                let p2: Vec<f64> = grid
                    .wavelengths_nm()
                    .iter()
                    .map(|&l| {
                        weight_of(self.k_squared_reference_nm, l)
                            * surface.transform(l, u, v, w).norm_sqr()
                    })
                    .collect();
                let exact = colorimeter.output_from_xyz(grid.xyz(&p2));
                let fast = self.sum_at(u, v, w);
                (0..3)
                    .map(|c| (fast[c] - exact[c]).abs() / white[c].abs().max(1e-300))
                    .fold(0.0, |m: f64, e| if e <= m { m } else { e })
            })
            .collect();
        errors
            .into_iter()
            .fold(0.0, |m: f64, e| if e <= m { m } else { e })
    }
}

/// Jₚ = Σ_λ u(λ) kᵖ Σ_{n+m=p} Re(P̃ₙ(0) P̃ₘ(0)*)/(n! m!), p = 0 … 2N, in `colorimeter`'s
/// output space, f32: the table's layers at u = v = 0 without the k² weight. P̃ₙ(0) does not
/// depend on k (the window is centred on q = k(u, v) = 0), so it is computed once and the
/// wavelength sum is Σ_λ u(λ) kᵖ.
fn zeroth_order_layers(
    surface: &DiffractionSurface,
    grid: &SpectralGrid,
    colorimeter: &Colorimeter,
) -> Vec<[f32; 3]> {
    let order = surface.terms().order();
    let layers = 2 * order + 1;
    let Some(&first) = grid.wavelengths_nm().first() else {
        return vec![[0.0; 3]; layers];
    };
    let pt = surface.transform_terms(first, 0.0, 0.0);
    let mut fact = vec![1.0f64; order + 1];
    for i in 1..=order {
        fact[i] = fact[i - 1] * i as f64;
    }
    let mut q = vec![0.0f64; layers];
    for a in 0..=order {
        for b in a..=order {
            let re = pt[a].re * pt[b].re + pt[a].im * pt[b].im;
            let twin = if a == b { 1.0 } else { 2.0 };
            q[a + b] += twin * re / (fact[a] * fact[b]);
        }
    }
    let matrix = colorimeter.matrix();
    (0..layers)
        .map(|p| {
            let mut xyz = [0.0f64; 3];
            for (&wavelength, weight) in grid.wavelengths_nm().iter().zip(&grid.xyz_weights) {
                let s = q[p] * elementary::powi(k_per_um(wavelength), p as i32);
                for ch in 0..3 {
                    xyz[ch] += weight[ch] * s;
                }
            }
            std::array::from_fn(|i| {
                (matrix[i][0] * xyz[0] + matrix[i][1] * xyz[1] + matrix[i][2] * xyz[2]) as f32
            })
        })
        .collect()
}

/// Where a point (u, v, w) reads an integrated table (the same for every level).
#[derive(Clone, Copy, Debug)]
struct Lookup {
    x0: usize,
    y0: usize,
    fx: f32,
    fy: f32,
    w: f32,
}

/// Φ(z), the standard normal distribution, as ½ erfc(−z/√2).
fn normal_cdf(z: f64) -> f64 {
    0.5 * elementary::erfc(-z * std::f64::consts::FRAC_1_SQRT_2)
}

/// Weights below which the ends of a row of [`gaussian_weights`] are dropped (the row is
/// renormalised): at most 2·10⁻¹² of its mass, far below the f32 storage.
const WEIGHT_FLOOR: f64 = 1e-12;

/// The weights of the nodes `nodes` (ascending) in ∫ f(u) N(u − c; σ²) du, where f is
/// linear in u between neighbouring nodes and constant beyond the end nodes (the shader's
/// clamp to the edge), N the normal density: per segment [a, b] of length h, with
/// z = (u − c)/σ, P = Φ(z_b) − Φ(z_a) and M = ∫ₐᵇ (u − c) N du = σ (φ(z_a) − φ(z_b)),
/// node b gets ((c − a) P + M)/h and node a gets P minus that; the end nodes get the tails
/// Φ(z₀) and Φ(−z_last). Returned as (first node, weights), trimmed of ends below
/// [`WEIGHT_FLOOR`] and normalised to sum 1.
fn gaussian_weights(nodes: &[f64], c: f64, sigma: f64) -> (usize, Vec<f64>) {
    let m = nodes.len();
    let z = |u: f64| (u - c) / sigma;
    let pdf = |z: f64| elementary::exp(-0.5 * z * z) / (2.0 * std::f64::consts::PI).sqrt();
    let mut w = vec![0.0f64; m];
    w[0] += normal_cdf(z(nodes[0]));
    w[m - 1] += normal_cdf(-z(nodes[m - 1]));
    for j in 0..m - 1 {
        let (a, b) = (nodes[j], nodes[j + 1]);
        let (za, zb) = (z(a), z(b));
        if za > 40.0 || zb < -40.0 {
            continue;
        }
        // Both in the upper tail: the difference of the complements keeps its digits.
        let p = if za > 0.0 {
            normal_cdf(-za) - normal_cdf(-zb)
        } else {
            normal_cdf(zb) - normal_cdf(za)
        };
        let mean = sigma * (pdf(za) - pdf(zb));
        let to_b = ((c - a) * p + mean) / (b - a);
        w[j + 1] += to_b;
        w[j] += p - to_b;
    }
    let first = w.iter().position(|x| x.abs() > WEIGHT_FLOOR).unwrap_or(0);
    let last = w
        .iter()
        .rposition(|x| x.abs() > WEIGHT_FLOOR)
        .unwrap_or(m - 1)
        .max(first);
    let kept = &w[first..=last];
    let sum: f64 = kept.iter().sum();
    (first, kept.iter().map(|x| x / sum).collect())
}

impl IntegratedTable {
    /// The table blurred by an isotropic Gaussian of standard deviation `sigma_uv` per axis
    /// in (u, v) — in u and v, not in texel coordinates: the axes are warped —
    /// Iₚ^σ(u, v) = ∬ Iₚ(u′, v′) N(u′ − u; σ²) N(v′ − v; σ²) du′ dv′ at every texel centre,
    /// with Iₚ between the texel centres as the shader reads it (linear between
    /// neighbouring centres, taken linear in u rather than in the warped coordinate: they
    /// differ only within a texel, to second order) and clamped beyond the edge texels.
    /// The blur is separable: v first (every column), then u, where u′ < 0 is the folded
    /// half Iₚ(u′, v) = (−1)ᵖ Iₚ(−u′, −v) (rows r and n − 1 − r hold ±v): a v-blurred
    /// layer keeps the point symmetry, so the shader's fold holds for every level. Weights
    /// by [`gaussian_weights`] (exact for that piecewise-linear Iₚ); sums in f64, stored in
    /// f32. σ ≤ 0 or not finite returns the table itself. Layers in parallel, each summed in
    /// a fixed order: the values do not depend on the thread count.
    ///
    /// As Iₚ enters the colour linearly, Σₚ wᵖ Iₚ^σ is the colour's (u, v) blur at fixed w:
    /// the mean of the BRDF over a footprint of that spread (issue 37, item 3), and the
    /// two-scale model's facet average (item 4): a facet of slope s moves (u, v) by w s.
    pub fn blurred(&self, sigma_uv: f64) -> IntegratedTable {
        if !(sigma_uv > 0.0 && sigma_uv.is_finite()) {
            return self.clone();
        }
        let n = self.axis.count;
        let half = n / 2;
        let nodes: Vec<f64> = (0..n).map(|i| self.axis.texel_centre(i)).collect();
        let along_v: Vec<(usize, Vec<f64>)> = nodes
            .iter()
            .map(|&v| gaussian_weights(&nodes, v, sigma_uv))
            .collect();
        let along_u: Vec<(usize, Vec<f64>)> = nodes[half..]
            .iter()
            .map(|&u| gaussian_weights(&nodes, u, sigma_uv))
            .collect();
        let blocks: Vec<Vec<[f32; 3]>> = (0..self.layers())
            .into_par_iter()
            .map(|p| {
                // v first: j[r * half + c].
                let mut j = vec![[0.0f64; 3]; n * half];
                for (r, (first, weights)) in along_v.iter().enumerate() {
                    let out = &mut j[r * half..(r + 1) * half];
                    for (k, &wk) in weights.iter().enumerate() {
                        for (c, o) in out.iter_mut().enumerate() {
                            let t = self.texel(p, c, first + k);
                            for ch in 0..3 {
                                o[ch] += wk * f64::from(t[ch]);
                            }
                        }
                    }
                }
                // Then u over the whole axis: node i ≥ n/2 is column i − n/2; node i < n/2
                // is column n/2 − 1 − i of row n − 1 − r, times (−1)ᵖ.
                let sign = if p % 2 == 0 { 1.0 } else { -1.0 };
                let mut out = vec![[0.0f32; 3]; n * half];
                for r in 0..n {
                    for (c, (first, weights)) in along_u.iter().enumerate() {
                        let mut acc = [0.0f64; 3];
                        for (k, &wk) in weights.iter().enumerate() {
                            let i = first + k;
                            let (value, s) = if i >= half {
                                (j[r * half + i - half], wk)
                            } else {
                                (j[(n - 1 - r) * half + half - 1 - i], sign * wk)
                            };
                            for ch in 0..3 {
                                acc[ch] += s * value[ch];
                            }
                        }
                        out[r * half + c] = acc.map(|x| x as f32);
                    }
                }
                out
            })
            .collect();
        IntegratedTable {
            axis: self.axis,
            order: self.order,
            values: blocks.concat(),
            k_squared_reference_nm: self.k_squared_reference_nm,
            specular: self.specular.clone(),
        }
    }
}

/// Prefiltered levels most integrated tables get ([`IntegratedLevels::new`]): the table and
/// 9 blurs, σ from u_max/256 to u_max.
pub const INTEGRATED_FILTER_LEVELS: usize = 10;

/// An integrated table with prefiltered copies of its layers, for the lookup filtered over
/// a spread σ in (u, v) (issue 37, items 3 and 4): level 0 is the table, level ℓ ≥ 1 the
/// table [`IntegratedTable::blurred`] by σ_ℓ = σ₁ 2^{ℓ−1}, σ₁ = u_max / 2^{L−2} (L levels,
/// so the last is u_max: a blur as wide as the table). Every level has the table's axes and
/// size (a shader reads them with the same texel coordinates).
///
/// The filtered sum at a variance σ² between two levels' σ_ℓ² ≤ σ² ≤ σ_{ℓ+1}² (σ₀ = 0) is
///
/// ```text
/// S_σ = (1 − t) S_ℓ + t S_{ℓ+1},   t = (σ² − σ_ℓ²)/(σ_{ℓ+1}² − σ_ℓ²),
/// ```
///
/// interpolated in σ², so the kernel (a mixture of the two Gaussians, each of mass 1) keeps
/// the energy and has exactly the variance σ² per axis; above the last level t is clamped
/// to 1. The level pair is found by a loop over σ_ℓ² = σ₁² 4^{ℓ−1} in f32 (products by 4
/// are exact), the arithmetic the shader repeats.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegratedLevels {
    levels: Vec<IntegratedTable>,
    sigma_base: f64,
}

impl IntegratedLevels {
    /// `count` levels of `table` (level 0 the table itself; 1 = no filter).
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for `count` outside 1 … 16.
    pub fn new(table: &IntegratedTable, count: usize) -> Result<Self> {
        if !(1..=16).contains(&count) {
            return Err(Error::OutOfRange {
                what: "prefiltered levels of an integrated table",
                value: count as f64,
                expected: "1 to 16",
            });
        }
        let sigma_base = table.axis.max_uv / elementary::powi(2.0, count as i32 - 2);
        let mut levels = vec![table.clone()];
        let blurred: Vec<IntegratedTable> = (1..count)
            .map(|l| table.blurred(sigma_base * elementary::powi(2.0, l as i32 - 1)))
            .collect();
        levels.extend(blurred);
        Ok(IntegratedLevels { levels, sigma_base })
    }

    /// The levels, 0 (the table) first.
    pub fn levels(&self) -> &[IntegratedTable] {
        &self.levels
    }

    /// σ₁, the spread of level 1 in (u, v).
    pub fn sigma_base(&self) -> f64 {
        self.sigma_base
    }

    /// σ₁² as the shader takes it (f32).
    pub fn sigma_base_sq_f32(&self) -> f32 {
        (self.sigma_base * self.sigma_base) as f32
    }

    /// σ_ℓ of level ℓ (0 for level 0).
    pub fn sigma(&self, level: usize) -> f64 {
        if level == 0 {
            0.0
        } else {
            self.sigma_base * elementary::powi(2.0, level as i32 - 1)
        }
    }

    /// (ℓ, t) for the variance σ² (f32, as the shader): S = (1 − t) S_ℓ + t S_{ℓ+1}
    /// (type docs); (0, 0) for σ² ≤ 0, NaN or a single level.
    pub fn level_weights(sigma2: f32, sigma_base_sq: f32, count: usize) -> (usize, f32) {
        if !(sigma2 > 0.0) || count < 2 {
            return (0, 0.0);
        }
        let (mut l, mut lo, mut hi) = (0usize, 0.0f32, sigma_base_sq);
        while l + 2 < count && sigma2 > hi {
            l += 1;
            lo = hi;
            hi *= 4.0;
        }
        (l, ((sigma2 - lo) / (hi - lo)).min(1.0))
    }

    /// Σₚ wᵖ Iₚ filtered by the variance σ² per axis in (u, v) (type docs), in f32 as the
    /// shader: the Horner sums of levels ℓ and ℓ + 1 at the same texel coordinates, then
    /// S_ℓ + t (S_{ℓ+1} − S_ℓ); level ℓ alone when t = 0.
    pub fn sum_filtered(&self, u: f64, v: f64, w: f64, sigma2: f32) -> [f64; 3] {
        let (l, t) = Self::level_weights(sigma2, self.sigma_base_sq_f32(), self.levels.len());
        let at = self.levels[0].lookup(u, v, w);
        let lo = self.levels[l].horner(&at);
        if !(t > 0.0) {
            return lo.map(f64::from);
        }
        let hi = self.levels[l + 1].horner(&at);
        std::array::from_fn(|c| f64::from(lo[c] + t * (hi[c] - lo[c])))
    }

    /// The colour C(ω_i, ω_r) · S_σ (as [`IntegratedTable::colour`], the sum filtered) for
    /// a footprint of spread `sigma_uv` in (u, v) and microfacets of slope variance
    /// `slope_variance` σ_m² per axis: σ² = σ_uv² + w² σ_m² in f32 (the variances of
    /// independent spreads add; a facet of slope s moves (u, v) by w s). σ² = 0 is
    /// [`IntegratedTable::colour`] of level 0 exactly.
    pub fn colour_filtered(
        &self,
        omega_i: [f64; 3],
        omega_r: [f64; 3],
        fresnel: FresnelTerm,
        sigma_uv: f32,
        slope_variance: f32,
    ) -> [f64; 3] {
        let g = geometry_over_w2(omega_i, omega_r);
        if g == 0.0 {
            return [0.0; 3];
        }
        let [u, v, w] = std::array::from_fn(|i| -omega_i[i] - omega_r[i]);
        let cos_h =
            -(omega_i[0] * u + omega_i[1] * v + omega_i[2] * w) / (u * u + v * v + w * w).sqrt();
        let c = fresnel.reflectance(cos_h) * g;
        let wf = w as f32;
        let sigma2 = sigma_uv * sigma_uv + wf * wf * slope_variance;
        self.sum_filtered(u, v, w, sigma2).map(|s| c * s)
    }
}

/// The outcome of [`IntegratedTable::reconstruction_error`].
#[derive(Clone, Debug, PartialEq)]
pub struct ReconstructionError {
    /// The largest error, in units of the specular white (NaN when a value was not finite).
    pub max_error: f64,
    /// The mean of the per-pair errors.
    pub mean_error: f64,
    /// Light direction of the worst pair.
    pub omega_i: [f64; 3],
    /// View direction of the worst pair.
    pub omega_r: [f64; 3],
    /// Output channel (0, 1, 2) of the worst error.
    pub channel: usize,
    /// Terms-layout colour there.
    pub exact: [f64; 3],
    /// Integrated-layout colour there.
    pub integrated: [f64; 3],
    /// Pairs compared.
    pub pairs: usize,
}

/// The light/view pairs [`IntegratedTable::reconstruction_error`] is measured on for a
/// table serving polar angles up to `max_angle_deg`:
///
/// * lights at θ_i ∈ {0, ½, 1}·θ_max (the edge pulled in by 10⁻⁶°) and azimuths
///   φ_i ∈ {0°, 30°, 90°} (one light at the normal);
/// * for each light, views on a 25 × 25 grid of the projected disc of radius sin θ_max
///   (off-plane views included), the specular view and views 0.02°, 0.05°, 0.1°,
///   0.2°, 0.5° and 1° from it in four directions (the mirror lobe), and in-plane views
///   every 0.5° (across the grating lines and along them).
pub fn check_directions(max_angle_deg: f64) -> Vec<([f64; 3], [f64; 3])> {
    let theta_max = max_angle_deg - 1e-6;
    let radius = elementary::sin(theta_max.to_radians());
    let dir = |theta_deg: f64, phi_deg: f64| {
        let (st, ct) = elementary::sin_cos(theta_deg.to_radians());
        let (sp, cp) = elementary::sin_cos(phi_deg.to_radians());
        [st * cp, st * sp, ct]
    };
    let mut lights = vec![[0.0, 0.0, 1.0]];
    for frac in [0.5, 1.0] {
        for phi in [0.0, 30.0, 90.0] {
            let d = dir(frac * theta_max, phi);
            lights.push([-d[0], -d[1], d[2]]);
        }
    }
    let mut pairs = Vec::new();
    for wi in lights {
        let m = 25;
        for iy in 0..m {
            for ix in 0..m {
                let at = |i: usize| radius * (2.0 * i as f64 / (m - 1) as f64 - 1.0);
                let (x, y) = (at(ix), at(iy));
                let r2 = x * x + y * y;
                if r2 <= radius * radius {
                    pairs.push((wi, [x, y, (1.0 - r2).sqrt()]));
                }
            }
        }
        // The specular view and the lobe around it.
        let spec = [-wi[0], -wi[1], wi[2]];
        let theta_s = elementary::acos(spec[2]).to_degrees();
        let phi_s = if spec[0] == 0.0 && spec[1] == 0.0 {
            0.0
        } else {
            elementary::atan2(spec[1], spec[0]).to_degrees()
        };
        pairs.push((wi, spec));
        for off in [0.02, 0.05, 0.1, 0.2, 0.5, 1.0] {
            for (dt, dp) in [(off, 0.0), (-off, 0.0), (0.0, off), (0.0, -off)] {
                let t = theta_s + dt;
                // An azimuth step of `off` degrees of arc at θ_s.
                let p = phi_s + dp / elementary::sin(theta_s.to_radians()).max(1e-3);
                if t.abs() <= theta_max {
                    pairs.push((wi, dir(t, p)));
                }
            }
        }
        let steps = (2.0 * theta_max / 0.5).floor() as i64;
        for s in 0..=steps {
            let t = -theta_max + 0.5 * s as f64;
            pairs.push((wi, dir(t, 0.0)));
            pairs.push((wi, dir(t, 90.0)));
        }
    }
    pairs
}
