//! Table kind `rough-film-lut`: the directional albedo of the iridescent GGX lobe,
//! pre-integrated over wavelength and over the microfacet distribution — the split-sum
//! "second factor" for rough thin-film surfaces (issue 6).
//!
//! # What the table holds
//!
//! For a view direction ω_o at cos θ_o = ω_o·n, GGX roughness α, and a film of thickness d
//! and real index n_f over the recipe's fixed layers and base, in the recipe's ambient:
//!
//! ```text
//! E_r(cos θ_o, α, d, n_f) = ∫ f_r(ω_o, ω_i) cos θ_i dω_i            (reflectance table)
//! E_t(cos θ_o, α, d, n_f) = ∫ f_t(ω_o, ω_t) |cos θ_t| dω_t          (transmittance table)
//! ```
//!
//! with f_r the GGX BRDF of Belcour & Barla 2017, Eq. 1 (height-correlated Smith G₂, the
//! film's spectral Airy reflectance R(ω_o·h; λ) in place of Fresnel) and f_t the energy it
//! transmits into a dielectric base, exactly as [`nacre_optics::microfacet`] defines them,
//! each as a colour of the recipe's colorimeter (RGB in the output space, a perfect
//! reflector = (1, 1, 1); XYZ with Y = 1 for `space = "xyz"`). Light that single scattering
//! masks is lost, so E_r + E_t ≤ 1 for a lossless stack (white-furnace test). The stored
//! values keep the law exactly, channel by channel: [`store_albedo_pair`] renormalises a
//! pair whose quadrature sum exceeds 1 and rounds a pair down instead of to the nearest
//! `f32` or half float where rounding to the nearest would push the sum above 1.
//!
//! # The bake is a matrix product (not Monte Carlo)
//!
//! f_r is linear in the film term, which depends on the microfacet only through
//! c = cos θ_d = ω_o·h. With microfacet normals drawn from the distribution of visible
//! normals D_ωo(h) (Heitz 2018) the albedo is (microfacet.rs, "Estimator")
//!
//! ```text
//! E_r = ∫ D_ωo(h) F_R(ω_o·h) G₂(ω_o, ω_i)/G₁(ω_o) χ⁺(ω_i·n) dh = ∫₀¹ K_r(c; cos θ_o, α) F_R(c) dc
//! E_t = ∫ D_ωo(h) F_T(ω_o·h) G₂(ω_o, ω_t)/G₁(ω_o) χ⁻(ω_t·n) dh = ∫₀¹ K_t(c; cos θ_o, α, η) F_T(c) dc
//! ```
//!
//! where F_R(c), F_T(c) are the colours of the film stack's unpolarised reflectance and
//! transmittance at incidence cosine c (the exact spectral integral of film-lut,
//! [`nacre_optics::SpectralRule`]), ω_i = 2(ω_o·h)h − ω_o, ω_t = refract(ω_o, h, η) with
//! η = n_base/n_ambient at 560 nm, and K_r, K_t are *kernels*: the distribution of c under
//! the visible normals, weighted by G₂/G₁. The kernels do not depend on the film, so the
//! bake computes them once per (cos θ_o, α) and the film colours once per (c, d, n_f):
//!
//! 1. **Kernels** ([`nacre_optics::microfacet::kernel`]). The visible-normal domain is
//!    Heitz's unit disk (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT
//!    7(4), 2018, Listing 1: the map (u₁, u₂) ∈ [0, 1]² → h of
//!    [`nacre_optics::microfacet::sample_ggx_vndf`] has constant density on the disk), so
//!    E = ∫∫ F(ω_o·h(u₁, u₂)) g(u₁, u₂) du₁ du₂ with g = G₂/G₁ (0 below the horizon). The
//!    integral is taken by a deterministic product rule: [`KERNEL_RADIAL_NODES`]-point
//!    Gauss–Legendre in v, u₁ = r² = 1 − (1 − v)² (nodes crowd the rim, where GGX's tail
//!    lives), and the [`KERNEL_AZIMUTH_NODES`]-point midpoint rule in
//!    u₂ = φ/2π (the trapezoid rule of a periodic function). Each node's weight is spread
//!    onto a uniform grid of [`KERNEL_COS_NODES`] cosines c_j = j/(N_c − 1) with the
//!    4-point (cubic) Lagrange weights of its c, so that Σ_j K_j F(c_j) = ∫ K F̃ with F̃ the
//!    cubic interpolant of F through the grid nodes.
//! 2. **Film colours**. For every film index n_k of the table and every c_j, one thickness
//!    sweep ([`Stack::colours_over_thickness`]) gives F_R and F_T on a uniform fine grid of
//!    thicknesses d_m = m δd over [0, [`THICKNESS_EXTENSION`] · d_max] with δd chosen so
//!    that the optical path advances by at most [`FINE_OPD_STEP_NM`] per node
//!    (2 δd n_max ≤ 24 nm), resolving the interference fringes. Where neither the ambient
//!    nor the base is dispersive and no fixed layers lie under the film (the default
//!    table), the same wavelength sums come from the film's Airy Fourier series instead
//!    ([`nacre_optics::film_series`], after Belcour & Barla 2017 §4):
//!    F_j = ½(c₀,s + c₀,p) Σₖ Wₖⱼ + Σ_pol Σ_{m=1}^{M} Re(c_m F_j(m D)), D = 2 d q_f, with
//!    F_j(μ) = Σₖ Wₖⱼ e^{2πiμ/λₖ} the rule's own transform (tabulated once per bake) and M
//!    per (c_j, n_k) such that the tail is below 10⁻¹³: the same numbers to ≈ 10⁻¹¹ at
//!    O(M) operations per thickness instead of one Airy evaluation per wavelength node.
//! 3. **Product**. Texel (x, y, n_k, α_a) at cos θ_o, Δ and d = Δ / (2 q(n_k, c_ref(cos θ_o,
//!    α_a))) holds Σ_j K[x, a, j] F̃(c_j, d, n_k), with F̃ cubic Lagrange interpolation in d on
//!    the fine grid. Thicknesses beyond the fine grid (texels outside the physical range that only
//!    grazing views of films nearly index-matched to the ambient reach) take its last node.
//!
//! Every sum runs in a fixed order and every parallel task writes its own texels, so the
//! output is byte-identical whatever the thread count (tested by the default-set test).
//!
//! ## Accuracy of the quadrature
//!
//! Cubic Lagrange interpolation of a fringe of phase step k h per node errs by at most
//! (k h)⁴ · 9/16 / 24: the fine thickness grid (24 nm of optical path per node, k h ≤ 0.4
//! rad at 380 nm) and the c grid (128 nodes: at most 2 d_max dc = 19 nm of path per node
//! inside the thickness range, |dΔ/dc| = 2 d c/q ≤ 2 d) keep it below 6·10⁻⁴ of the fringe
//! amplitude (a film reflects a few per cent: ≲ 3·10⁻⁵ absolute). With F ≡ 1 the
//! reflection kernel's mass is GGX's single-scattering albedo; it matches the Monte Carlo
//! reference of [`nacre_optics::microfacet`] at 2²² samples within its noise (nacre-optics
//! test `microfacet::kernel::tests::furnace_kernel_matches_monte_carlo`). The table's own
//! interpolation error dominates: the default `rough-film-dielectric` (16 × 256 × 12 α ×
//! 24 n) is off by ΔE2000 0.112 / 0.297 / 0.66 (mean / p95 / max) in reflection and 0.055 /
//! 0.119 / 0.30 in transmission against the Monte Carlo reference at 1000 random points
//! (`tests/tests/rough_lut_accuracy.rs` with `NACRE_ROUGH_POINTS=1000`); the film-index
//! axis is the one that matters most (at 160 points, 16 indices gave p95 0.51 and 24 give
//! 0.27; 24 view angles or 16 roughnesses with 16 indices instead did not lower it).
//!
use crate::error::{Error, Result};
use crate::kinds::{KindEntry, TableRecipe};
use crate::recipe::{
    OutputSettings, RawColour, RawOutput, RawStack, RecipeStack, line_of, parse_colour, table_name,
    toml_error,
};
use nacre_format::film_lut::MIN_COS_THETA;
use nacre_format::ktx2::film_lut_image;
use nacre_format::manifest::{AxisRecord, FileRecord, KindRecord, MAX_TEXELS, Manifest, TableKind};
use nacre_format::rough_film_lut::{RoughFilmLut, RoughLutAxes, validate_axes};
use nacre_format::stage::StagedTable;
use nacre_format::table_io::{Precision, Table3};
use nacre_optics::colour::Colorimeter;
use nacre_optics::elementary;
use nacre_optics::film_series::{
    RuleTransform, SingleFilm, non_dispersive_surround, series_extent,
};
use nacre_optics::microfacet::REFRACTION_WAVELENGTH_NM;
use nacre_optics::microfacet::kernel::{
    KERNEL_AZIMUTH_NODES, KERNEL_COS_NODES, KERNEL_RADIAL_NODES, Kernel, kernel_cos, kernels,
};
use nacre_optics::quadrature::cubic_stencil;
use nacre_optics::{C64, Layer, Material, SpectralRule, Stack};
use rayon::prelude::*;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Largest optical path advance between nodes of the fine thickness grid, nm.
pub const FINE_OPD_STEP_NM: f64 = 24.0;

/// The fine thickness grid covers [0, THICKNESS_EXTENSION · d_max]: texels near the top of
/// the Δ axis at grazing views of low-index films hold thicker films than d_max, and the
/// interpolation near the physical range's edge reads them.
pub const THICKNESS_EXTENSION: f64 = 1.5;

/// The tables as the half-float files store them: each (E_r, E_t) pair rounded by
/// [`store_albedo_pair`] (so that E_r + E_t ≤ 1 holds for the stored halves), E_r alone
/// rounded to the nearest half where nothing is transmitted. Values are `f32`s that are
/// exactly half floats.
pub fn rounded_to_half(lut: &RoughFilmLut) -> (Table3, Option<Table3>) {
    let Some(t) = &lut.transmittance else {
        let mut r = lut.reflectance.clone();
        for v in &mut r.data {
            *v = half::f16::from_f32(*v).to_f32();
        }
        return (r, None);
    };
    let (mut r_out, mut t_out) = (lut.reflectance.clone(), t.clone());
    for ((r, t), (r_in, t_in)) in r_out
        .data
        .iter_mut()
        .zip(t_out.data.iter_mut())
        .zip(lut.reflectance.data.iter().zip(&t.data))
    {
        (*r, *t) = store_albedo_pair(f64::from(*r_in), f64::from(*t_in), Precision::Half);
    }
    (r_out, Some(t_out))
}

/// A film on the Airy-series path: its series, harmonics M and the extent M D it reaches.
type Planned = (SingleFilm, usize, f64);

/// A film the series computes: its series and harmonics M.
type Series = (SingleFilm, usize);

/// Everything needed to bake one rough-film LUT.
pub struct RoughLutJob {
    /// Axes.
    pub axes: RoughLutAxes,
    /// Ambient (constant real index).
    pub ambient: Material,
    /// Fixed layers under the film, top first.
    pub under: Vec<Layer>,
    /// Base.
    pub base: Material,
    /// Colour conversion.
    pub colorimeter: Colorimeter,
    /// Whether to bake the transmitted albedo.
    pub transmittance: bool,
}

impl RoughLutJob {
    /// Nodes of the fine thickness grid and its step, nm.
    pub fn thickness_grid(&self) -> (usize, f64) {
        let a = &self.axes;
        let top = THICKNESS_EXTENSION * a.thickness_max_nm;
        let nodes = ((top * 2.0 * a.ior_max / FINE_OPD_STEP_NM).ceil() as usize + 1).max(4);
        (nodes, top / (nodes - 1) as f64)
    }

    /// Bakes the table (module docs); `progress` is called once per film index.
    pub fn bake(&self, progress: &(dyn Fn() + Sync)) -> Result<RoughFilmLut> {
        let a = &self.axes;
        let n_c = KERNEL_COS_NODES;
        let eta = if self.transmittance { a.base_eta } else { None };
        let pairs: Vec<(usize, usize)> = (0..a.cos_theta_count)
            .flat_map(|x| (0..a.alpha_count).map(move |al| (x, al)))
            .collect();
        let kernels: Vec<Kernel> = pairs
            .par_iter()
            .map(|&(x, al)| kernels(a.texel_cos_theta(x), a.texel_alpha(al), eta, n_c))
            .collect();
        let supports: Vec<(usize, usize)> = kernels.iter().map(Kernel::support).collect();
        let (d_nodes, d_step) = self.thickness_grid();
        let d_grid: Vec<f64> = (0..d_nodes).map(|m| m as f64 * d_step).collect();
        let under_opd = Stack::new(self.ambient.clone(), self.under.clone(), self.base.clone())?
            .max_opd_nm(None);
        let rule = SpectralRule::new(
            &self.colorimeter,
            2.0 * d_grid[d_nodes - 1] * a.ior_max + under_opd,
        );
        let depth = a.depth();
        let mut reflectance = Table3::new(a.cos_theta_count, a.opd_count, depth);
        let mut transmittance = self
            .transmittance
            .then(|| Table3::new(a.cos_theta_count, a.opd_count, depth));
        // Non-dispersive stacks: the film colours from the Airy series (module docs, step 2),
        // where its transform's extent pays off (film_series::series_extent).
        let plans: Option<Vec<Vec<Option<Planned>>>> =
            non_dispersive_surround(&self.ambient, &self.under, &self.base).map(
                |(n_ambient, base)| {
                    (0..a.ior_count)
                        .map(|k| {
                            (0..n_c)
                                .map(|j| {
                                    let c = kernel_cos(j, n_c).max(MIN_COS_THETA);
                                    let film = SingleFilm::new(
                                        n_ambient,
                                        a.texel_ior(k),
                                        base,
                                        c,
                                        self.transmittance,
                                    )?;
                                    let (m, mu) = film.plan(d_grid[d_nodes - 1])?;
                                    Some((film, m, mu))
                                })
                                .collect()
                        })
                        .collect()
                },
            );
        let extent = plans.as_ref().map(|plans| {
            let needs: Vec<(f64, usize)> = plans
                .iter()
                .flatten()
                .flatten()
                .map(|&(_, _, mu)| (mu, d_nodes))
                .collect();
            series_extent(&needs)
        });
        let films: Option<Vec<Vec<Option<Series>>>> = plans.map(|plans| {
            plans
                .into_iter()
                .map(|row| {
                    row.into_iter()
                        .map(|p| {
                            p.filter(|&(_, _, mu)| Some(mu) <= extent)
                                .map(|(f, m, _)| (f, m))
                        })
                        .collect()
                })
                .collect()
        });
        let transform = extent
            .map(|extent| RuleTransform::new(&rule, extent))
            .transpose()?;
        for k in 0..a.ior_count {
            let n = a.texel_ior(k);
            let film = Material::constant(format!("{n}"), C64::new(n, 0.0))?;
            let mut layers = vec![Layer {
                material: film,
                thickness_nm: 0.0,
            }];
            layers.extend(self.under.iter().cloned());
            let stack = Stack::new(self.ambient.clone(), layers, self.base.clone())?;
            // Film colours F_R, F_T at every (c_j, d_m).
            let colours: Vec<nacre_optics::FilmColours> = (0..n_c)
                .into_par_iter()
                .map(|j| {
                    if let (Some(films), Some(transform)) = (&films, &transform)
                        && let Some((film, m)) = &films[k][j]
                    {
                        return Ok(film.colours_over_thickness(transform, *m, &d_grid));
                    }
                    let c = kernel_cos(j, n_c).max(MIN_COS_THETA);
                    let angle_deg = elementary::acos(c).to_degrees();
                    Ok(stack.colours_over_thickness(1, angle_deg, &rule, &d_grid)?)
                })
                .collect::<Result<_>>()?;
            // F by thickness then cosine, (F_R, F_T) side by side, so that the sums over j
            // below read consecutive memory: film[m · n_c + j] = (F_R, F_T)(c_j, d_m).
            let film: Vec<[f64; 6]> = (0..d_nodes)
                .flat_map(|m| {
                    colours.iter().map(move |f| {
                        let (r, t) = (f.reflectance[m], f.transmittance[m]);
                        [r[0], r[1], r[2], t[0], t[1], t[2]]
                    })
                })
                .collect();
            // The product, one column x at a time: texel (x, y, k, a) =
            // Σ_s w_s G(m₀ + s), w the cubic weights of its thickness and
            // G(m) = Σ_j K[x, a, j] F(c_j, d_m) the kernel-weighted film colour at fine node
            // m, computed once per node that some texel of the column reads.
            let columns: Vec<Vec<[f64; 6]>> = (0..a.cos_theta_count)
                .into_par_iter()
                .map(|x| {
                    let mut out = vec![[0.0; 6]; a.opd_count * a.alpha_count];
                    let mut g: Vec<[f64; 6]> = Vec::new();
                    for al in 0..a.alpha_count {
                        let kern = &kernels[x * a.alpha_count + al];
                        let (lo, hi) = supports[x * a.alpha_count + al];
                        let stencils: Vec<(usize, [f64; 4])> = (0..a.opd_count)
                            .map(|y| {
                                let d = a.texel_thickness_nm(x, y, k, al);
                                cubic_stencil(d / d_step, d_nodes)
                            })
                            .collect();
                        let first = stencils.iter().map(|s| s.0).min().unwrap_or(0);
                        let last = stencils.iter().map(|s| s.0 + 4).max().unwrap_or(0);
                        g.clear();
                        g.extend((first..last).map(|m| {
                            let mut v = [0.0; 6];
                            let row = m * n_c;
                            let rows = kern.reflection[lo..hi]
                                .iter()
                                .zip(&kern.transmission[lo..hi])
                                .zip(&film[row + lo..row + hi]);
                            for ((&kr, &kt), f) in rows {
                                for c in 0..3 {
                                    v[c] += kr * f[c];
                                    v[3 + c] += kt * f[3 + c];
                                }
                            }
                            v
                        }));
                        for (y, (m0, w)) in stencils.iter().enumerate() {
                            let mut e = [0.0; 6];
                            for (s, ws) in w.iter().enumerate() {
                                let v = &g[m0 + s - first];
                                for c in 0..6 {
                                    e[c] += ws * v[c];
                                }
                            }
                            out[y * a.alpha_count + al] = e;
                        }
                    }
                    out
                })
                .collect();
            for (x, column) in columns.iter().enumerate() {
                for y in 0..a.opd_count {
                    for al in 0..a.alpha_count {
                        let e = column[y * a.alpha_count + al];
                        let z = al * a.ior_count + k;
                        if let Some(t) = transmittance.as_mut() {
                            let pairs: [(f32, f32); 3] = std::array::from_fn(|c| {
                                store_albedo_pair(e[c], e[3 + c], Precision::Float)
                            });
                            reflectance.set(x, y, z, pairs.map(|p| p.0));
                            t.set(x, y, z, pairs.map(|p| p.1));
                        } else {
                            reflectance.set(x, y, z, [e[0], e[1], e[2]].map(|v| v as f32));
                        }
                    }
                }
            }
            progress();
        }
        Ok(RoughFilmLut {
            axes: a.clone(),
            reflectance,
            transmittance,
        })
    }
}

/// One channel of a texel's reflected and transmitted albedo (E_r, E_t), rounded to
/// `precision` so that the stored pair keeps the white-furnace law E_r + E_t ≤ 1 exactly
/// (the sum taken of the stored values; `Precision::Half` for the half-float files).
///
/// 1. Energy-conserving renormalisation: a pair whose sum exceeds 1 (only the quadrature's
///    own error could do that — the reflection and transmission kernels each carry at most
///    GGX's single-scattering mass ≤ 1 and F_R + F_T = 1 at every node — and the default
///    table's largest sum is 0.999997) is scaled by 1/(E_r + E_t), which keeps its split.
/// 2. Each value is rounded to the nearest representable one, as the file writers do
///    (`f16::from_f32`, round to nearest even). Two values rounded up may together exceed 1
///    by up to an ulp (2⁻¹¹ at 1 in half floats, more where a linear-RGB channel of a
///    saturated film colour is slightly negative and the other slightly above 1).
/// 3. Where they do, the transmitted value, then also the reflected one, is rounded down
///    instead (towards −∞: towards zero for the non-negative values that make up nearly
///    every texel): the rounded-down values are ≤ the exact ones, so their sum is ≤ 1.
///    Each stored value then errs by less than one ulp (≤ 4.9·10⁻⁴ in half floats below 1).
pub fn store_albedo_pair(reflected: f64, transmitted: f64, precision: Precision) -> (f32, f32) {
    let (mut r, mut t) = (reflected, transmitted);
    let sum = r + t;
    if sum > 1.0 {
        (r, t) = (r / sum, t / sum);
        if r + t > 1.0 {
            t = 1.0 - r;
        }
    }
    let round = |v: f64, down: bool| -> f32 {
        match (precision, down) {
            (Precision::Half, false) => half::f16::from_f64(v).to_f32(),
            (Precision::Half, true) => f16_round_down(v).to_f32(),
            (Precision::Float, false) => v as f32,
            (Precision::Float, true) => f32_round_down(v),
        }
    };
    let nearest = |v: f64| round(v, false);
    let down = |v: f64| round(v, true);
    let fits = |a: f32, b: f32| f64::from(a) + f64::from(b) <= 1.0;
    let (qr, qt) = (nearest(r), nearest(t));
    if fits(qr, qt) {
        return (qr, qt);
    }
    let qt = down(t);
    if fits(qr, qt) {
        return (qr, qt);
    }
    (down(r), qt)
}

/// The largest `f32` not above `v` (finite `v`).
fn f32_round_down(v: f64) -> f32 {
    let q = v as f32;
    if f64::from(q) <= v {
        return q;
    }
    // q > v: step one ulp towards −∞.
    if q > 0.0 {
        f32::from_bits(q.to_bits() - 1)
    } else if q == 0.0 {
        -f32::from_bits(1)
    } else {
        f32::from_bits(q.to_bits() + 1)
    }
}

/// The largest `f16` not above `v` (|v| within the `f16` range).
fn f16_round_down(v: f64) -> half::f16 {
    let q = half::f16::from_f64(v);
    if q.to_f64() <= v {
        return q;
    }
    let bits = q.to_bits();
    if q > half::f16::ZERO {
        half::f16::from_bits(bits - 1)
    } else if q == half::f16::ZERO {
        half::f16::from_bits(0x8001)
    } else {
        half::f16::from_bits(bits + 1)
    }
}

// ---------------------------------------------------------------------------------------
// Recipes
// ---------------------------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRoughAxes {
    cos_theta_count: usize,
    thickness_nm: [f64; 2],
    opd_count: usize,
    film_ior: [f64; 2],
    film_ior_count: usize,
    alpha: [f64; 2],
    alpha_count: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRoughRecipe {
    #[allow(dead_code)] // checked before the full parse
    kind: Spanned<String>,
    description: Option<String>,
    colour: Option<RawColour>,
    stack: RawStack,
    axes: Spanned<RawRoughAxes>,
    output: Option<RawOutput>,
}

/// A parsed `rough-film-lut` recipe.
///
/// ```toml
/// kind = "rough-film-lut"
/// description = "..."
/// [colour]                      # as for film-lut
/// [stack]                       # as for film-lut: ambient (constant), film label, base, under
/// ambient = "1.0"
/// base = "1.5"
/// [axes]
/// cos_theta_count = 16          # texels along cos θ_o (√ mapping)
/// thickness_nm = [0.0, 1200.0]  # film thickness range
/// opd_count = 256               # texels along the optical path difference (at c_ref)
/// film_ior = [1.0, 2.5]         # film index range (≥ ambient), √ mapping
/// film_ior_count = 24
/// alpha = [0.02, 1.0]           # GGX roughness range (0.001 ≤ min ≤ max ≤ 1), log mapping
/// alpha_count = 12
/// [output]                      # optional
/// precision = "half"            # OpenEXR: half | float
/// png = false                   # default false for this kind
/// transmittance = "auto"        # auto (when the base is transparent) | true | false
/// ```
pub struct RoughRecipe {
    /// Table name (file stem).
    pub name: String,
    /// Recipe file.
    pub path: PathBuf,
    /// Recipe text.
    pub text: String,
    /// Description.
    pub description: String,
    /// Ambient spec.
    pub ambient_spec: String,
    /// Film label.
    pub film_label: String,
    /// Base spec.
    pub base_spec: String,
    /// Fixed layers under the film (spec, thickness nm).
    pub under_specs: Vec<(String, f64)>,
    /// The job.
    pub job: RoughLutJob,
    /// OpenEXR precision.
    pub precision: Precision,
    /// Also write 16-bit PNGs (when every value is in [0, 1]).
    pub png: bool,
}

impl RoughRecipe {
    /// Parses recipe text; `path` names it in errors and anchors relative material paths.
    pub fn parse(path: &Path, text: String) -> Result<Self> {
        let raw: RawRoughRecipe = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        let at = |span: std::ops::Range<usize>| {
            format!("{}:{}", path.display(), line_of(&text, span.start))
        };
        let colorimeter = parse_colour(path, &text, raw.colour)?;
        let RecipeStack {
            ambient,
            ambient_index,
            base,
            under,
            under_specs,
            under_incoherent: _,
        } = RecipeStack::parse(path, &text, &raw.stack, "rough-film-lut")?;
        let output = OutputSettings::parse(path, raw.output, &under, &base, false)?;
        let transmittance = output.transmittance;
        let base_eta = if transmittance {
            let nb = base.index_at(REFRACTION_WAVELENGTH_NM)?;
            if nb.im != 0.0 || !(nb.re > 0.0) {
                return Err(Error::invalid(
                    at(raw.stack.base.span()),
                    format!(
                        "transmittance through a rough interface needs a non-absorbing base; `{}` has index {nb} at {REFRACTION_WAVELENGTH_NM} nm (set [output] transmittance = false)",
                        raw.stack.base.get_ref()
                    ),
                ));
            }
            Some(nb.re / ambient_index)
        } else {
            None
        };
        let ax = raw.axes.get_ref();
        let axes = RoughLutAxes {
            cos_theta_count: ax.cos_theta_count,
            opd_count: ax.opd_count,
            ior_count: ax.film_ior_count,
            alpha_count: ax.alpha_count,
            thickness_min_nm: ax.thickness_nm[0],
            thickness_max_nm: ax.thickness_nm[1],
            ior_min: ax.film_ior[0],
            ior_max: ax.film_ior[1],
            alpha_min: ax.alpha[0],
            alpha_max: ax.alpha[1],
            ambient_index,
            base_eta,
        };
        validate_axes(&axes, &at(raw.axes.span()), MAX_TEXELS)?;
        Ok(RoughRecipe {
            name: table_name(path)?,
            path: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            ambient_spec: raw.stack.ambient.get_ref().clone(),
            film_label: raw.stack.film.unwrap_or_else(|| "film".into()),
            base_spec: raw.stack.base.get_ref().clone(),
            under_specs,
            job: RoughLutJob {
                axes,
                ambient,
                under,
                base,
                colorimeter,
                transmittance,
            },
            precision: output.precision,
            png: output.png,
            text,
        })
    }

    /// Units of work for progress bars: one per film index.
    pub fn work(&self) -> u64 {
        self.job.axes.ior_count as u64
    }

    /// Bakes and writes the table into `out_dir`; returns the manifest path.
    pub fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        let lut = self.job.bake(progress)?;
        // Every file goes to a staging folder first; `commit` moves them into `out_dir`,
        // the manifest last (nacre_format::stage::StagedTable).
        let stage = nacre_format::stage::StagedTable::new(out_dir)?;
        let a = &lut.axes;
        let c = &self.job.colorimeter;
        let channels: Vec<String> = c
            .space()
            .channel_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        let (d_nodes, d_step) = self.job.thickness_grid();
        let mut manifest = Manifest {
            colour_convention: format!(
                "linear {} (channels {:?}); reflectance: directional albedo E_r = integral of f_r cos(theta_i) over the hemisphere of the GGX microfacet BRDF with height-correlated Smith G2 and the film's unpolarised spectral reflectance in place of Fresnel (Belcour & Barla 2017 Eq. 1), as the colour of R(lambda) x illuminant x CMF over 360-830 nm normalised so that a perfect reflector has Y = 1 (RGB (1,1,1)); transmittance: energy E_t transmitted into the base through the rough film-coated interface (refraction at eta = {}); single scattering: E_r + E_t <= 1 for a lossless stack. Baked by kernel quadrature (no Monte Carlo): {} c nodes (cubic), {}x{} visible-normal nodes (Gauss-Legendre x midpoint), fine thickness grid {} nodes of {:.6} nm (cubic)",
                c.space(),
                channels,
                a.base_eta.map_or("none".to_string(), |e| e.to_string()),
                KERNEL_COS_NODES,
                KERNEL_RADIAL_NODES,
                KERNEL_AZIMUTH_NODES,
                d_nodes,
                d_step
            ),
            ambient: self.ambient_spec.clone(),
            film: self.film_label.clone(),
            under: self.under_specs.clone(),
            base: self.base_spec.clone(),
            axes: axis_records(a),
            texel_centres: "texel i of an axis with count n holds t = i / (n - 1); a sampler reaches t at u = (t * (n - 1) + 0.5) / n; clamp to edge. The film_ior coordinate of alpha block a is w = (a * count(film_ior) + t_ior * (count(film_ior) - 1) + 0.5) / (count(alpha) * count(film_ior)), which stays inside the block".into(),
            atlas: "per quantity one 3-D texture: width = count(cos_theta_o), height = count(opd_nm), depth = count(alpha) * count(film_ior) in alpha-major blocks, slice z = i_alpha * count(film_ior) + i_ior. EXR: an atlas of width = count(cos_theta_o), height = count(opd_nm) * depth, slice z at rows [z * count(opd_nm), (z + 1) * count(opd_nm)), row j of the slice is opd_nm index j, top row first; KTX2: the same texels as a 3-D RGBA16F texture, alpha 1".into(),
            reconstruction: "cos_o = dot(N, V); q(n) = sqrt(n^2 - n0^2 (1 - cos_o^2)); c_ref(alpha) = clamp(cos_o + (2 alpha - alpha^2) (0.7 - 0.8 cos_o), 0, 1); t = (sqrt(cos_o), t_y, sqrt((n_f - ior_min) / (ior_max - ior_min)), ln(alpha / alpha_min) / ln(alpha_max / alpha_min)), each clamped to [0, 1]; s = t_alpha (count(alpha) - 1), a0 = min(floor(s), count(alpha) - 2), f = s - a0; alpha_a = alpha_min (alpha_max / alpha_min)^(a / (count(alpha) - 1)) is block a's roughness and t_y(a) = 2 d q(n_f, c_ref(alpha_a)) / opd_max; E = mix(trilinear(block a0), trilinear(block a0 + 1), f) with trilinear(block a) = linear sample at (u(t_x), u(t_y(a)), (a count(ior) + t_ior (count(ior) - 1) + 0.5) / depth); environment specular = prefiltered_env(R, alpha) * E_reflectance, transmitted energy = E_transmittance (shaders/rough_lut_mapping.wgsl)".into(),
            files: Vec::new(),
            ..Manifest::for_recipe(
                KindRecord::RoughFilmLut(a.clone()),
                &self.name,
                &self.description,
                &self.path,
                &self.text,
                c,
            )
        };
        let embedded = manifest.embedded_json();
        let mut files = Vec::new();
        let mut stale = Vec::new();
        // The half-float files (the KTX2 textures always, the EXR atlases at
        // `precision = "half"`) hold the pairs rounded by `store_albedo_pair`.
        let (half_r, half_t) = rounded_to_half(&lut);
        for (quantity, table, halves) in [
            ("reflectance", Some(&lut.reflectance), Some(&half_r)),
            ("transmittance", lut.transmittance.as_ref(), half_t.as_ref()),
        ] {
            let (Some(table), Some(halves)) = (table, halves) else {
                continue;
            };
            let exr = match self.precision {
                Precision::Half => halves,
                Precision::Float => table,
            };
            files
                .extend(self.write_quantity(&stage, quantity, exr, halves, &embedded, &mut stale)?);
        }
        manifest.files = files;
        Ok(stage.commit_manifest(&manifest, &stale)?)
    }
}

impl RoughRecipe {
    /// Writes one quantity's files — `NAME.QUANTITY.exr` (atlas, from `table`), `.png` when
    /// asked for and every value is in [0, 1], and `.ktx2` (3-D `RGBA16F`, alpha 1, from
    /// `halves`, values that are already half floats) — each atomically, and returns their
    /// records; a PNG not written goes to `stale`, for the commit to remove an earlier
    /// bake's.
    fn write_quantity(
        &self,
        stage: &StagedTable,
        quantity: &str,
        table: &Table3,
        halves: &Table3,
        embedded_manifest: &str,
        stale: &mut Vec<String>,
    ) -> Result<Vec<FileRecord>> {
        let mut files = Vec::new();
        let exr = format!("{}.{quantity}.exr", self.name);
        files.push(stage.write_exr(&exr, quantity, table, self.precision)?);
        let png = format!("{}.{quantity}.png", self.name);
        if self.png
            && let Some(record) = stage.write_png16(&png, quantity, table)?
        {
            files.push(record);
        } else {
            // A stale PNG from an earlier bake would contradict the manifest.
            stale.push(png);
        }
        let ktx2 = format!("{}.{quantity}.ktx2", self.name);
        let image = film_lut_image(&stage.path().join(&ktx2), halves, embedded_manifest)?;
        files.push(stage.write_ktx2(&ktx2, quantity, &image)?);
        Ok(files)
    }
}

fn axis_records(a: &RoughLutAxes) -> Vec<AxisRecord> {
    vec![
        AxisRecord {
            name: "cos_theta_o".into(),
            unit: "1".into(),
            count: a.cos_theta_count,
            min: 0.0,
            max: 1.0,
            mapping: "square".into(),
            forward: "t = sqrt(cos_theta_o)".into(),
            inverse: "cos_theta_o = t * t".into(),
        },
        AxisRecord {
            name: "opd_nm".into(),
            unit: "nm".into(),
            count: a.opd_count,
            min: 0.0,
            max: a.opd_max_nm(),
            mapping: "linear in the optical path difference at the reference microfacet cosine c_ref = cos_theta_o + (2 alpha - alpha^2) (0.7 - 0.8 cos_theta_o) (clamped to [0, 1]); alpha is the alpha block's own roughness".into(),
            forward: format!(
                "t = 2 * thickness_nm * sqrt(film_ior^2 - {}^2 * (1 - c_ref^2)) / {}",
                a.ambient_index,
                a.opd_max_nm()
            ),
            inverse: format!(
                "opd_nm = t * {}; thickness_nm = opd_nm / (2 sqrt(film_ior^2 - {}^2 (1 - c_ref^2)))",
                a.opd_max_nm(),
                a.ambient_index
            ),
        },
        AxisRecord {
            name: "film_ior".into(),
            unit: "1".into(),
            count: a.ior_count,
            min: a.ior_min,
            max: a.ior_max,
            mapping: "square root".into(),
            forward: format!(
                "t = sqrt((film_ior - {lo}) / ({hi} - {lo}))",
                lo = a.ior_min,
                hi = a.ior_max
            ),
            inverse: format!(
                "film_ior = {lo} + t^2 ({hi} - {lo})",
                lo = a.ior_min,
                hi = a.ior_max
            ),
        },
        AxisRecord {
            name: "alpha".into(),
            unit: "1".into(),
            count: a.alpha_count,
            min: a.alpha_min,
            max: a.alpha_max,
            mapping: "logarithmic; alpha-major blocks of the depth axis, mixed by the shader"
                .into(),
            forward: format!(
                "t = ln(alpha / {lo}) / ln({hi} / {lo})",
                lo = a.alpha_min,
                hi = a.alpha_max
            ),
            inverse: format!(
                "alpha = {lo} * ({hi} / {lo})^t",
                lo = a.alpha_min,
                hi = a.alpha_max
            ),
        },
    ]
}

/// The registry entry of `rough-film-lut` ([`crate::kinds::REGISTRY`]).
pub const ENTRY: KindEntry = KindEntry {
    kind: TableKind::ROUGH_FILM_LUT,
    parse: |path, text| Ok(Box::new(RoughRecipe::parse(path, text)?)),
    start_rank: 0,
};

impl TableRecipe for RoughRecipe {
    fn kind(&self) -> TableKind {
        TableKind::ROUGH_FILM_LUT
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn work(&self) -> u64 {
        RoughRecipe::work(self)
    }

    fn bake(&self, out_dir: &Path, progress: &(dyn Fn() + Sync)) -> Result<PathBuf> {
        RoughRecipe::bake(self, out_dir, progress)
    }
}

#[cfg(test)]
mod tests;
