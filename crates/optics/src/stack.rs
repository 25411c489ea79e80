//! Multilayer thin-film stacks: reflectance, transmittance and absorptance of an ambient
//! medium, 0..N films and a substrate, by the substrate-up recurrence of composite
//! amplitudes.
//!
//! # Symbols
//!
//! | symbol | code | meaning |
//! |---|---|---|
//! | j = 0 … N+1 | index into `indices` | medium: 0 ambient, 1 … N films (top first), N+1 substrate |
//! | d_j | `thickness_nm[j-1]` | physical thickness of film j, nm |
//! | δ_j = k₀ q_j d_j | `delta` | complex phase thickness of film j |
//! | r_{j,j+1}, t_{j,j+1} | `Prepared::interfaces[j]` | Fresnel amplitudes of interface j ([`crate::fresnel`]) |
//! | Γ_j, τ_j | `gamma`, `tau` | composite reflection / transmission amplitude of everything below interface j, seen from medium j |
//!
//! # Method
//!
//! Starting at the substrate, `Γ_N = r_{N,N+1}`, `τ_N = t_{N,N+1}`, and for j = N−1 … 0
//!
//! ```text
//!          r_{j,j+1} + Γ_{j+1} e^{2iδ_{j+1}}                 t_{j,j+1} τ_{j+1} e^{iδ_{j+1}}
//! Γ_j = ─────────────────────────────────────     τ_j = ─────────────────────────────────────
//!        1 + r_{j,j+1} Γ_{j+1} e^{2iδ_{j+1}}               1 + r_{j,j+1} Γ_{j+1} e^{2iδ_{j+1}}
//! ```
//!
//! (Heavens, *Optical Properties of Thin Solid Films*, 1955, §4; Born & Wolf §1.6.5 — the
//! Airy summation of the real-time thesis in `shared/seeds`, Sussenbach 2013 §3.1, applied
//! recursively; for one film it *is* the Airy formula of Belcour & Barla 2017, Eq. 2.)
//! The stack's amplitudes are r = Γ₀ and t = τ₀, identical to the transfer-matrix result of
//! Byrnes' `tmm` (phase reference at the top interface for r, at the substrate's interface
//! for t). Only `e^{+iδ}` with Im δ ≥ 0 appears, so thick, absorbing or evanescent layers
//! never overflow, unlike a transfer-matrix product.
//!
//! Powers: `R = |r|²`; `T` is the power that crosses into the substrate, with the
//! `Re(ñ cos θ)` factors of [`crate::fresnel`] (the `tmm` convention); unpolarised
//! `R = (R_s + R_p)/2`, `T = (T_s + T_p)/2`, and the absorptance `A = 1 − R − T` is the
//! power absorbed in the films (and, for an evanescent substrate, zero).
//!
//! # Sweeps
//!
//! [`Stack::sweep`] and [`Stack::sweep_thickness`] resolve the material indices once per
//! wavelength and run angles in parallel with rayon. Every value is computed by the same
//! code whatever the thread count, so results are bit-identical across thread counts.
//! [`Stack::sweep`] runs each angle's row through the vectorised multilayer kernel of
//! the `multilayer` module (wavelengths as SIMD lanes; the same recurrence with Γ and |τ|²
//! carried as fractions; IEEE basic operations only, so the same bits on every CPU and
//! vector width), or, for indices or phases outside that kernel's range, through the
//! scalar recurrence below, which computes interface coefficients once per (angle, distinct
//! set of indices). A sweep over a film's thickness folds the stack below it once per
//! (angle, wavelength); over the top film it runs the Airy closed form through the
//! vectorised kernel of the `simd` module.

pub(crate) use crate::airy::uniform_step;
use crate::airy::{AiryRow, airy_powers};
use crate::elementary;
use crate::error::{Error, Result};
use crate::fresnel::{Interface, normal_component, power_factor_p, power_factor_s};
use crate::material::Material;
use crate::power::PowerSlot;
pub use crate::power::{Power, wavenumber};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// One film of a stack.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// The film's material.
    pub material: Material,
    /// Physical thickness d, in nanometres (≥ 0).
    pub thickness_nm: f64,
}

/// Complex amplitude coefficients of a whole stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Amplitudes {
    /// Reflection amplitude, s polarisation.
    pub r_s: C64,
    /// Reflection amplitude, p polarisation.
    pub r_p: C64,
    /// Transmission amplitude into the substrate, s polarisation.
    pub t_s: C64,
    /// Transmission amplitude into the substrate, p polarisation.
    pub t_p: C64,
}

/// Amplitudes and powers at one angle and wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// Complex amplitude coefficients.
    pub amplitudes: Amplitudes,
    /// Power coefficients.
    pub power: Power,
}

/// `exp(i z)` for complex z, without the general complex `exp` when z is real (sin, cos
/// and exp from [`crate::elementary`]: the same bits on every machine).
#[inline]
fn exp_i(z: C64) -> C64 {
    let (s, c) = elementary::sin_cos(z.re);
    if z.im == 0.0 {
        C64::new(c, s)
    } else {
        let m = elementary::exp(-z.im);
        C64::new(m * c, m * s)
    }
}

/// Everything at one angle and one set of media indices that does not depend on
/// wavelength or thickness: normal components and interface coefficients.
#[derive(Clone, Debug)]
pub struct Prepared {
    indices: Vec<C64>,
    /// q_j = ñ_j cos θ_j for every medium.
    q: Vec<C64>,
    /// Interface j: from medium j into medium j + 1.
    interfaces: Vec<Interface>,
    factor_s: f64,
    factor_p: f64,
}

impl Prepared {
    /// Prepares media `indices` (ambient first, substrate last; at least two) for a
    /// tangential component `beta = n₀ sin θ₀`.
    pub fn new(indices: &[C64], beta: f64) -> Self {
        assert!(indices.len() >= 2, "a stack has an ambient and a substrate");
        let q: Vec<C64> = indices.iter().map(|&n| normal_component(n, beta)).collect();
        let interfaces = (0..indices.len() - 1)
            .map(|j| Interface::new(indices[j], q[j], indices[j + 1], q[j + 1]))
            .collect();
        let last = indices.len() - 1;
        Prepared {
            factor_s: power_factor_s(q[0], q[last]),
            factor_p: power_factor_p(indices[0], q[0], indices[last], q[last]),
            indices: indices.to_vec(),
            q,
            interfaces,
        }
    }

    /// The media indices this was prepared for.
    pub fn indices(&self) -> &[C64] {
        &self.indices
    }

    /// Number of films.
    fn films(&self) -> usize {
        self.indices.len() - 2
    }

    /// `e^{iδ_j}` for film j (1-based medium index) of thickness `thickness_nm`.
    #[inline]
    fn phase(&self, j: usize, k0: f64, thickness_nm: f64) -> C64 {
        exp_i(self.q[j] * (k0 * thickness_nm))
    }

    /// Composite amplitudes seen from medium `j` looking down, given those seen from
    /// medium `j + 1` (Γ_{j+1}, τ_{j+1}) and film j+1's phase `e = e^{iδ_{j+1}}`.
    #[inline]
    fn step(&self, j: usize, e: C64, gamma: [C64; 2], tau: [C64; 2]) -> ([C64; 2], [C64; 2]) {
        let i = &self.interfaces[j];
        let e2 = e * e;
        let mut out_g = [C64::new(0.0, 0.0); 2];
        let mut out_t = out_g;
        for (pol, (r, t)) in [(i.r_s, i.t_s), (i.r_p, i.t_p)].into_iter().enumerate() {
            let ge2 = gamma[pol] * e2;
            let den_inv = (1.0 + r * ge2).inv();
            out_g[pol] = (r + ge2) * den_inv;
            out_t[pol] = t * tau[pol] * e * den_inv;
        }
        (out_g, out_t)
    }

    /// Amplitudes at vacuum wavelength `wavelength_nm` for film thicknesses
    /// `thickness_nm` (one per film, top first).
    pub fn amplitudes(&self, wavelength_nm: f64, thickness_nm: &[f64]) -> Amplitudes {
        debug_assert_eq!(thickness_nm.len(), self.films());
        let k0 = wavenumber(wavelength_nm);
        let n = self.films();
        let bottom = &self.interfaces[n];
        let mut gamma = [bottom.r_s, bottom.r_p];
        let mut tau = [bottom.t_s, bottom.t_p];
        for j in (0..n).rev() {
            let e = self.phase(j + 1, k0, thickness_nm[j]);
            (gamma, tau) = self.step(j, e, gamma, tau);
        }
        Amplitudes {
            r_s: gamma[0],
            r_p: gamma[1],
            t_s: tau[0],
            t_p: tau[1],
        }
    }

    /// Power coefficients from a stack's amplitudes.
    #[inline]
    pub fn power(&self, a: &Amplitudes) -> Power {
        Power {
            R_s: a.r_s.norm_sqr(),
            R_p: a.r_p.norm_sqr(),
            T_s: a.t_s.norm_sqr() * self.factor_s,
            T_p: a.t_p.norm_sqr() * self.factor_p,
        }
    }
}

/// A thickness sweep of one film at fixed angle and wavelength: the part of the stack
/// below the varying film is folded into (Γ, τ) once; each thickness then costs one
/// complex exponential and the recurrence through the films above it. For the top film
/// that is the Airy closed form, evaluated by the vectorised kernel of [`crate::simd`]
/// (the same bits on every CPU and vector width).
pub(crate) struct ThicknessSweep<'a> {
    prepared: &'a Prepared,
    k0: f64,
    /// 1-based medium index of the varying film.
    film: usize,
    /// Γ_film, τ_film: composite amplitudes below the varying film.
    gamma: [C64; 2],
    tau: [C64; 2],
    /// e^{iδ_j} of the fixed films above the varying one (index j − 1).
    above: Vec<C64>,
    /// Top-film constants: r₀₁, Γ₁, r₀₁Γ₁, |t₀₁τ₁|² × power factor and z = 2k₀q₁.
    airy: AiryRow,
}

impl<'a> ThicknessSweep<'a> {
    pub(crate) fn new(
        prepared: &'a Prepared,
        wavelength_nm: f64,
        thickness_nm: &[f64],
        film: usize,
    ) -> Self {
        let k0 = wavenumber(wavelength_nm);
        let n = prepared.films();
        let bottom = &prepared.interfaces[n];
        let mut gamma = [bottom.r_s, bottom.r_p];
        let mut tau = [bottom.t_s, bottom.t_p];
        for j in (film..n).rev() {
            let e = prepared.phase(j + 1, k0, thickness_nm[j]);
            (gamma, tau) = prepared.step(j, e, gamma, tau);
        }
        let above = (1..film)
            .map(|j| prepared.phase(j, k0, thickness_nm[j - 1]))
            .collect();
        let top = &prepared.interfaces[0];
        let r01 = [top.r_s, top.r_p];
        let factor = [prepared.factor_s, prepared.factor_p];
        let pair = |c: C64| [c.re, c.im];
        let z = prepared.q[1] * (2.0 * k0);
        ThicknessSweep {
            prepared,
            k0,
            film,
            gamma,
            tau,
            above,
            airy: AiryRow {
                r01: r01.map(pair),
                gamma: gamma.map(pair),
                r01_gamma: [pair(r01[0] * gamma[0]), pair(r01[1] * gamma[1])],
                t_norm: [
                    (top.t_s * tau[0]).norm_sqr() * factor[0],
                    (top.t_p * tau[1]).norm_sqr() * factor[1],
                ],
                z_re: z.re,
                z_im: z.im,
            },
        }
    }

    /// The top-film constants, when the varying film is the top one.
    pub(crate) fn airy_row(&self) -> Option<&AiryRow> {
        (self.film == 1).then_some(&self.airy)
    }

    /// Writes into `row[k]` the powers at thickness `thickness_nm[k]`; `uniform_step_nm`
    /// is [`uniform_step`] of `thickness_nm`.
    pub(crate) fn fill<T: PowerSlot>(
        &self,
        thickness_nm: &[f64],
        uniform_step_nm: Option<f64>,
        row: &mut [T],
    ) {
        if self.film == 1 {
            airy_powers(&self.airy, thickness_nm, uniform_step_nm, row, true);
        } else {
            for (slot, &d) in row.iter_mut().zip(thickness_nm) {
                slot.put(self.power(d));
            }
        }
    }

    /// Powers at thickness `d_nm` of a varying film below the top one.
    fn power(&self, d_nm: f64) -> Power {
        let p = self.prepared;
        let e = p.phase(self.film, self.k0, d_nm);
        let (mut gamma, mut tau) = p.step(self.film - 1, e, self.gamma, self.tau);
        for j in (0..self.film - 1).rev() {
            (gamma, tau) = p.step(j, self.above[j], gamma, tau);
        }
        p.power(&Amplitudes {
            r_s: gamma[0],
            r_p: gamma[1],
            t_s: tau[0],
            t_p: tau[1],
        })
    }
}

/// An ambient medium, 0..N films (top first) and a substrate. Every film is coherent
/// unless marked incoherent ([`Stack::with_incoherent`]: a thick slab whose reflections add
/// in intensity, [`crate::incoherent`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Stack {
    ambient: Material,
    layers: Vec<Layer>,
    substrate: Material,
    /// Per film: incoherent. Empty when every film is coherent.
    incoherent: Vec<bool>,
}

impl Stack {
    /// Builds a stack. Errors when a thickness is negative or not finite, or when a
    /// constant ambient absorbs (a dispersive ambient is checked per wavelength).
    pub fn new(ambient: Material, layers: Vec<Layer>, substrate: Material) -> Result<Self> {
        for (i, layer) in layers.iter().enumerate() {
            if !(layer.thickness_nm >= 0.0 && layer.thickness_nm.is_finite()) {
                return Err(Error::InvalidThickness {
                    layer: i + 1,
                    material: layer.material.name().to_string(),
                    thickness_nm: layer.thickness_nm,
                });
            }
        }
        if ambient.is_constant() {
            check_ambient(&ambient, 550.0)?;
        }
        Ok(Stack {
            ambient,
            layers,
            substrate,
            incoherent: Vec::new(),
        })
    }

    /// The stack with film j (1-based) incoherent where `incoherent[j − 1]` (one flag per
    /// film; all `false` is the coherent stack). Its powers come from the intensity
    /// recurrence of [`crate::incoherent`]; the operations that need amplitudes
    /// ([`Stack::evaluate`], [`Stack::sweep_thickness`]) refuse it with [`Error::IncoherentLayer`].
    pub fn with_incoherent(mut self, incoherent: Vec<bool>) -> Result<Self> {
        if incoherent.len() != self.layers.len() {
            return Err(Error::CoherenceCount {
                given: incoherent.len(),
                count: self.layers.len(),
            });
        }
        self.incoherent = if incoherent.iter().any(|&i| i) {
            incoherent
        } else {
            Vec::new()
        };
        Ok(self)
    }

    /// Whether film `layer` (1-based) is incoherent.
    pub fn is_incoherent(&self, layer: usize) -> bool {
        self.incoherent.get(layer.wrapping_sub(1)) == Some(&true)
    }

    /// Per film, top first: whether it is incoherent.
    pub fn incoherent_flags(&self) -> Vec<bool> {
        (1..=self.layers.len())
            .map(|j| self.is_incoherent(j))
            .collect()
    }

    /// Whether every film is coherent.
    pub fn is_coherent(&self) -> bool {
        self.incoherent.is_empty()
    }

    /// `Ok` for a fully coherent stack, else [`Error::IncoherentLayer`] naming `operation`
    /// and the first incoherent film.
    pub fn require_coherent(&self, operation: &'static str) -> Result<()> {
        match self.incoherent.iter().position(|&i| i) {
            None => Ok(()),
            Some(j) => Err(Error::IncoherentLayer {
                operation,
                layer: j + 1,
                material: self.layers[j].material.name().to_string(),
            }),
        }
    }

    /// The coherent films whose interference fringes are finer, in wavelength, than the
    /// sampling of `wavelengths_nm` (ascending) can follow: film j's fringes are the orders
    /// m of 2 Re ñ_j d_j = mλ at normal incidence (Born & Wolf §7.5.1; oblique incidence
    /// only widens them), so between neighbouring samples λ₁ < λ₂ the spectrum passes
    /// Δm = 2 Re ñ_j d_j (1/λ₁ − 1/λ₂) fringes (ñ_j at λ₁); more than one somewhere on the
    /// grid and the samples cannot follow them. Only films far beyond the interference
    /// colours are named: more than [`UNDERSAMPLED_MIN_ORDER`] orders thick there
    /// (m = 2 Re ñ d / λ₁), the thickness from which a slab is better treated as
    /// incoherent; a thin film on a deliberately sparse grid (a 400 nm film at 100, 150 and
    /// 200 nm: 10.6 orders) is not. The mean fringe period over that step,
    /// (λ₂ − λ₁)/Δm (≈ λ²/(2 Re ñ d) for fine fringes), is reported against the step. Such
    /// a film's spectrum aliases; a slab that thick should be marked incoherent. Films
    /// whose index is unknown somewhere on the grid are skipped (the sweep reports that).
    ///
    /// A constant-index film whose order at the shortest wavelength is at most
    /// [`UNDERSAMPLED_MIN_ORDER`] is passed over without a walk of the grid (the order only
    /// falls with λ), so the check costs one pass for the grid's minimum on thin stacks.
    pub fn undersampled_films(&self, wavelengths_nm: &[f64]) -> Vec<Undersampled> {
        let mut out = Vec::new();
        let shortest_nm = wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min);
        for (j, layer) in self.layers.iter().enumerate() {
            if self.is_incoherent(j + 1) || layer.thickness_nm == 0.0 {
                continue;
            }
            if layer.material.is_constant()
                && layer.material.index_at(shortest_nm).is_ok_and(|n| {
                    2.0 * n.re.abs() * layer.thickness_nm / shortest_nm <= UNDERSAMPLED_MIN_ORDER
                })
            {
                continue;
            }
            let mut worst: Option<(f64, f64, f64)> = None;
            for pair in wavelengths_nm.windows(2) {
                let (wl, step) = (pair[0], pair[1] - pair[0]);
                let Ok(n) = layer.material.index_at(wl) else {
                    continue;
                };
                let fringes = 2.0 * n.re.abs() * layer.thickness_nm * (1.0 / wl - 1.0 / pair[1]);
                let period = step / fringes;
                let order = 2.0 * n.re.abs() * layer.thickness_nm / wl;
                if fringes > 1.0
                    && order > UNDERSAMPLED_MIN_ORDER
                    && worst.is_none_or(|(p, s, _)| period / step < p / s)
                {
                    worst = Some((period, step, wl));
                }
            }
            if let Some((period, step, wl)) = worst {
                out.push(Undersampled {
                    layer: j + 1,
                    material: layer.material.name().to_string(),
                    thickness_nm: layer.thickness_nm,
                    wavelength_nm: wl,
                    fringe_period_nm: period,
                    step_nm: step,
                });
            }
        }
        out
    }

    /// The ambient (incidence) medium.
    pub fn ambient(&self) -> &Material {
        &self.ambient
    }

    /// The films, top first.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// The substrate.
    pub fn substrate(&self) -> &Material {
        &self.substrate
    }

    /// Film thicknesses in nm, top first.
    pub fn thicknesses_nm(&self) -> Vec<f64> {
        self.layers.iter().map(|l| l.thickness_nm).collect()
    }

    /// The media's complex indices at `wavelength_nm`: ambient, films (top first), substrate.
    pub fn indices_at(&self, wavelength_nm: f64) -> Result<Vec<C64>> {
        let mut out = Vec::with_capacity(self.layers.len() + 2);
        out.push(check_ambient(&self.ambient, wavelength_nm)?);
        for layer in &self.layers {
            out.push(layer.material.index_at(wavelength_nm)?);
        }
        out.push(self.substrate.index_at(wavelength_nm)?);
        Ok(out)
    }

    /// Amplitudes and powers at incidence `angle_deg` (in the ambient) and vacuum
    /// wavelength `wavelength_nm`.
    pub fn evaluate(&self, angle_deg: f64, wavelength_nm: f64) -> Result<Response> {
        self.require_coherent("complex amplitudes")?;
        let sin_theta = sin_of_angle(angle_deg)?;
        let indices = self.indices_at(wavelength_nm)?;
        let prepared = Prepared::new(&indices, indices[0].re * sin_theta);
        let amplitudes = prepared.amplitudes(wavelength_nm, &self.thicknesses_nm());
        Ok(Response {
            amplitudes,
            power: prepared.power(&amplitudes),
        })
    }

    /// [`Stack::sweep`] with, per (angle, wavelength) and polarisation, the power absorbed in
    /// each part of the stack: its coherent groups and incoherent slabs, top first
    /// ([`Stack::parts`]; a coherent stack is one group). R + T + ΣA = 1.
    pub fn sweep_absorbed(
        &self,
        angles_deg: &[f64],
        wavelengths_nm: &[f64],
    ) -> Result<Vec<crate::incoherent::Absorbed>> {
        let thickness = self.thicknesses_nm();
        let (sines, columns) = self.resolve_columns(angles_deg, wavelengths_nm)?;
        let incoherent = if self.is_coherent() {
            vec![false; self.layers.len()]
        } else {
            self.incoherent.clone()
        };
        crate::incoherent::sweep_absorbed(
            &crate::incoherent::Groups::new(&incoherent),
            &sines,
            &columns,
            wavelengths_nm,
            &thickness,
            &self.layer_names(),
            scalar_powers,
        )
    }

    /// The parts [`Stack::sweep_absorbed`] reports, top first.
    pub fn parts(&self) -> Vec<crate::incoherent::Part> {
        let incoherent = if self.is_coherent() {
            vec![false; self.layers.len()]
        } else {
            self.incoherent.clone()
        };
        crate::incoherent::Groups::new(&incoherent).parts()
    }

    fn layer_names(&self) -> Vec<String> {
        self.layers
            .iter()
            .map(|l| l.material.name().to_string())
            .collect()
    }

    /// Powers over every (angle, wavelength, thickness) triple with film `layer`
    /// (1-based, top film = 1) taking each of `thicknesses_nm` and the other films as
    /// given; element `(a * wavelengths.len() + w) * thicknesses.len() + d`.
    pub fn sweep_thickness(
        &self,
        layer: usize,
        angles_deg: &[f64],
        wavelengths_nm: &[f64],
        thicknesses_nm: &[f64],
    ) -> Result<Vec<Power>> {
        self.check_layer(layer, thicknesses_nm)?;
        self.require_coherent("a thickness sweep")?;
        let thickness = self.thicknesses_nm();
        let (sines, indices) = self.resolve(angles_deg, wavelengths_nm)?;
        let per_angle = wavelengths_nm.len() * thicknesses_nm.len();
        let step = uniform_step(thicknesses_nm);
        let total = sines.len() * per_angle;
        let mut out: Vec<Power> = Vec::with_capacity(total);
        if per_angle == 0 {
            out.resize(total, Power::default());
            return Ok(out);
        }
        // Every slot is written once, straight into the fresh allocation (no zeroing pass).
        out.spare_capacity_mut()[..total]
            .par_chunks_mut(per_angle)
            .zip(&sines)
            .for_each(|(block, &sin_theta)| {
                let mut cache: Option<Prepared> = None;
                let rows = block.chunks_mut(thicknesses_nm.len());
                for ((row, &wl), idx) in rows.zip(wavelengths_nm).zip(&indices) {
                    let prepared = reuse(&mut cache, idx, sin_theta);
                    let sweep = ThicknessSweep::new(prepared, wl, &thickness, layer);
                    sweep.fill(thicknesses_nm, step, row);
                }
            });
        // SAFETY: the blocks partition `spare_capacity_mut()[..total]` (per_angle > 0), their
        // rows partition each block (one row per wavelength, `thicknesses_nm.len()` each),
        // and `fill` writes every slot of its row, so the first `total` elements are
        // initialised.
        unsafe { out.set_len(total) };
        Ok(out)
    }

    /// Checks that film `layer` (1-based) exists and that every thickness is valid.
    pub(crate) fn check_layer(&self, layer: usize, thicknesses_nm: &[f64]) -> Result<()> {
        if layer == 0 || layer > self.layers.len() {
            return Err(Error::NoSuchLayer {
                layer,
                count: self.layers.len(),
            });
        }
        for &d in thicknesses_nm {
            if !(d >= 0.0 && d.is_finite()) {
                return Err(Error::InvalidThickness {
                    layer,
                    material: self.layers[layer - 1].material.name().to_string(),
                    thickness_nm: d,
                });
            }
        }
        Ok(())
    }

    /// The fringe finesse ρ of the stack at incidence `angle_deg` and `wavelength_nm`: the
    /// largest round-trip amplitude |Γ↑ⱼ| |Γ↓ⱼ| of any film j, either polarisation, where
    /// Γ↓ⱼ is the composite reflection amplitude of everything below film j seen from inside
    /// it and Γ↑ⱼ that of everything above it. A film's Airy sum is a geometric series in
    /// ρ e^{iφ} (Born & Wolf §7.6.1): its reflectance has Fourier harmonics in the film
    /// phase φ that decay as ρᵏ, and its fringes are lines of width ≈ 2(1 − ρ) rad.
    ///
    /// For one film ρ = |r₀₁| |r₁₂| exactly. Below and above a film of a multilayer the
    /// composite magnitudes are bounded by the lossless Möbius bound of the recurrence
    /// of the module docs, |Γⱼ| ≤ (|r_{j,j+1}| + |Γ_{j+1}|) / (1 + |r_{j,j+1}| |Γ_{j+1}|)
    /// (exact for real Fresnel coefficients, with the films' attenuation taken as 1), so ρ
    /// is an upper bound there. Clamped to [0, 1].
    ///
    /// With incoherent layers, the largest finesse of its coherent groups (each group between
    /// the incoherent media that bound it, [`crate::incoherent`]): the incoherent slabs have
    /// no fringes.
    pub fn fringe_finesse(&self, angle_deg: f64, wavelength_nm: f64) -> Result<f64> {
        let sin_theta = sin_of_angle(angle_deg)?;
        let indices = self.indices_at(wavelength_nm)?;
        let beta = indices[0].re * sin_theta;
        if self.is_coherent() {
            return Ok(fringe_finesse_of(&indices, beta));
        }
        let media = crate::incoherent::Groups::new(&self.incoherent).media;
        Ok(media
            .windows(2)
            .map(|g| fringe_finesse_of(&indices[g[0]..=g[1]], beta))
            .fold(0.0, f64::max))
    }

    /// [`Stack::resolve`] with the indices per medium (ambient, films top first, substrate),
    /// each over `wavelengths_nm`: the same values and the same first error.
    fn resolve_columns(
        &self,
        angles_deg: &[f64],
        wavelengths_nm: &[f64],
    ) -> Result<(Vec<f64>, Vec<Vec<C64>>)> {
        let media = std::iter::once(&self.ambient)
            .chain(self.layers.iter().map(|l| &l.material))
            .chain([&self.substrate]);
        let columns: Result<Vec<Vec<C64>>> = media.map(|m| m.indices_at(wavelengths_nm)).collect();
        match columns {
            Ok(columns) if columns[0].iter().all(|n| n.im == 0.0) => {
                let sines = angles_deg
                    .iter()
                    .map(|&a| sin_of_angle(a))
                    .collect::<Result<Vec<_>>>()?;
                Ok((sines, columns))
            }
            // An error: the one the per-wavelength order meets first.
            _ => {
                let (sines, indices) = self.resolve(angles_deg, wavelengths_nm)?;
                let columns = (0..self.layers.len() + 2)
                    .map(|j| indices.iter().map(|idx| idx[j]).collect())
                    .collect();
                Ok((sines, columns))
            }
        }
    }

    /// Validates angles and resolves indices once per wavelength.
    pub(crate) fn resolve(
        &self,
        angles_deg: &[f64],
        wavelengths_nm: &[f64],
    ) -> Result<(Vec<f64>, Vec<Vec<C64>>)> {
        let sines = angles_deg
            .iter()
            .map(|&a| sin_of_angle(a))
            .collect::<Result<Vec<_>>>()?;
        let indices = wavelengths_nm
            .iter()
            .map(|&wl| self.indices_at(wl))
            .collect::<Result<Vec<_>>>()?;
        Ok((sines, indices))
    }
}

/// The interference order m = 2 Re ñ d / λ above which [`Stack::undersampled_films`] names
/// a film: interference colours fade to white by the fifth to seventh order (the
/// Michel-Lévy chart; Born & Wolf §7.5.1 for the orders), so a film of more than 20 orders
/// shows none and its fine fringes only average, as an incoherent slab's do.
pub const UNDERSAMPLED_MIN_ORDER: f64 = 20.0;

/// A coherent film too thick for a wavelength sampling ([`Stack::undersampled_films`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Undersampled {
    /// 1-based layer number, top first.
    pub layer: usize,
    /// Its material's name.
    pub material: String,
    /// Its thickness, nm.
    pub thickness_nm: f64,
    /// The wavelength where the fringes are finest relative to the step, nm.
    pub wavelength_nm: f64,
    /// The fringe period there, nm.
    pub fringe_period_nm: f64,
    /// The sampling step there, nm.
    pub step_nm: f64,
}

impl std::fmt::Display for Undersampled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "layer {} (`{}`, {} nm) is coherent but its fringes are {:.3e} nm apart near {} nm, finer than the {} nm wavelength step: its spectrum aliases; a layer that thick adds its reflections in intensity, mark it `:incoherent` (`{}@{}nm:incoherent`)",
            self.layer,
            self.material,
            self.thickness_nm,
            self.fringe_period_nm,
            round6(self.wavelength_nm),
            round6(self.step_nm),
            self.material,
            self.thickness_nm,
        )
    }
}

/// `v` rounded to 6 decimals for a message (a grid step of `380:780:5` is 5, not
/// 5.000000000000057).
fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

/// [`Stack::sweep`] by the scalar recurrence of [`Prepared`] (one per angle and distinct set
/// of indices): the reference the vectorised kernel is tested against, and the path for
/// indices outside its range. `sines[a]` = sin θ₀, `indices[w]` the media at wavelength w.
pub(crate) fn sweep_recurrence(
    sines: &[f64],
    indices: &[Vec<C64>],
    wavelengths_nm: &[f64],
    thickness_nm: &[f64],
) -> Vec<Power> {
    let mut out = vec![Power::default(); sines.len() * wavelengths_nm.len()];
    if wavelengths_nm.is_empty() {
        return out;
    }
    out.par_chunks_mut(wavelengths_nm.len())
        .zip(sines)
        .for_each(|(row, &sin_theta)| {
            let mut cache: Option<Prepared> = None;
            for ((slot, &wl), idx) in row.iter_mut().zip(wavelengths_nm).zip(indices) {
                let prepared = reuse(&mut cache, idx, sin_theta);
                *slot = prepared.power(&prepared.amplitudes(wl, thickness_nm));
            }
        });
    out
}

/// [`Stack::fringe_finesse`] for media `indices` (ambient first) and tangential component
/// `beta`.
pub(crate) fn fringe_finesse_of(indices: &[C64], beta: f64) -> f64 {
    let films = indices.len() - 2;
    if films == 0 {
        return 0.0;
    }
    let q: Vec<C64> = indices.iter().map(|&n| normal_component(n, beta)).collect();
    // |r| of interface j (medium j into j + 1), per polarisation; |r_ji| = |r_ij|.
    let interfaces: Vec<Interface> = (0..=films)
        .map(|j| Interface::new(indices[j], q[j], indices[j + 1], q[j + 1]))
        .collect();
    let mobius = |a: f64, b: f64| ((a + b) / (1.0 + a * b)).min(1.0);
    let mut rho: f64 = 0.0;
    for magnitude in [
        |i: &Interface| elementary::norm(i.r_s),
        |i: &Interface| elementary::norm(i.r_p),
    ] {
        let r: Vec<f64> = interfaces.iter().map(magnitude).collect();
        // down[j - 1]: everything below film j, seen from inside it.
        let mut down = vec![0.0; films];
        down[films - 1] = r[films].min(1.0);
        for j in (1..films).rev() {
            down[j - 1] = mobius(r[j], down[j]);
        }
        let mut up = r[0].min(1.0);
        for j in 1..=films {
            if j > 1 {
                up = mobius(r[j - 1], up);
            }
            rho = rho.max(up * down[j - 1]);
        }
    }
    if rho.is_nan() {
        1.0
    } else {
        rho.clamp(0.0, 1.0)
    }
}

/// The powers of the stack of media `indices` (first to last) at tangential component `beta`,
/// `wavelength_nm` and film thicknesses `thickness_nm`, by the scalar recurrence of
/// [`Prepared`] (a coherent group of [`crate::incoherent`] outside the vectorised kernel's
/// ranges).
pub(crate) fn scalar_powers(
    indices: &[C64],
    beta: f64,
    wavelength_nm: f64,
    thickness_nm: &[f64],
) -> Power {
    let prepared = Prepared::new(indices, beta);
    prepared.power(&prepared.amplitudes(wavelength_nm, thickness_nm))
}

/// Returns a `Prepared` for `indices`, reusing the cached one when the indices have not
/// changed (non-dispersive media across wavelengths).
fn reuse<'c>(cache: &'c mut Option<Prepared>, indices: &[C64], sin_theta: f64) -> &'c Prepared {
    if cache.as_ref().is_none_or(|p| p.indices() != indices) {
        *cache = Some(Prepared::new(indices, indices[0].re * sin_theta));
    }
    cache.as_ref().expect("just filled")
}

pub(crate) fn sin_of_angle(angle_deg: f64) -> Result<f64> {
    if !(angle_deg.abs() < 90.0) {
        return Err(Error::InvalidAngle { angle_deg });
    }
    Ok(elementary::sin(angle_deg.to_radians()))
}

fn check_ambient(ambient: &Material, wavelength_nm: f64) -> Result<C64> {
    let n = ambient.index_at(wavelength_nm)?;
    if n.im != 0.0 {
        return Err(Error::AbsorbingAmbient {
            material: ambient.name().to_string(),
            wavelength_nm,
            kappa: n.im,
        });
    }
    Ok(n)
}
