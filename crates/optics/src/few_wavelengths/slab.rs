//! One incoherent slab in a real-time stack: thin-walled coated glass (a film on the front
//! face, a pane millimetres thick, optionally a coating on the back), the CPU twin of the
//! GPU technique `film_glass` (`shaders/film_glass.wgsl`) at one node.
//!
//! The media are those of the stack, 0 the ambient, 1 … F the films, F + 1 the base, and
//! medium s (1 ≤ s ≤ F) the slab. The coherent group above it (media 0 … s) and the group
//! below it (media s … F + 1) are evaluated with the exact amplitude recurrence
//! ([`crate::Prepared`]); the slab adds their powers in intensity, per polarisation, by the
//! recurrence of [`crate::incoherent`] with one slab (Byrnes, arXiv:1603.02720 §4; Katsidis &
//! Siapkas 2002, Eq. 13–16):
//!
//! ```text
//!              T_A T′_A P² R_B                T_A P T_B
//! R = R_A + ─────────────────────,   T = ─────────────────────,   P = exp(−4π d Im(ñ_s cos θ_s) / λ)
//!            1 − R′_A P² R_B             1 − R′_A P² R_B
//! ```
//!
//! R_A, T_A the upper group's powers from the ambient, R′_A, T′_A the same from inside the
//! slab (the group reversed), R_B, T_B the lower group's from inside the slab, P the slab's
//! single pass at its internal (complex) angle, d its thickness. A slab that passes less than
//! [`crate::incoherent::OPAQUE_PASS`] counts as opaque (P = 0: R = R_A, T = 0), as the GPU's
//! f32 exponential does.

use crate::incoherent::OPAQUE_PASS;
use crate::{C64, Power, Prepared, elementary, fresnel::normal_component, power::wavenumber};

/// Unpolarised (R, T) at one wavelength of the stack whose media have indices `indices`
/// (ambient first) and whose films have thicknesses `thickness_nm` (top first; the slab's
/// entry its own thickness), film `slab` (1-based medium index) incoherent; tangential
/// component `beta` = n₀ sin θ₀.
pub(crate) fn slab_power(
    indices: &[C64],
    beta: f64,
    wavelength_nm: f64,
    thickness_nm: &[f64],
    slab: usize,
) -> (f64, f64) {
    let above = Prepared::new(&indices[..=slab], beta);
    let forward = above.power(&above.amplitudes(wavelength_nm, &thickness_nm[..slab - 1]));
    let reversed: Vec<C64> = indices[..=slab].iter().rev().copied().collect();
    let films_reversed: Vec<f64> = thickness_nm[..slab - 1].iter().rev().copied().collect();
    let back = Prepared::new(&reversed, beta);
    let backward = back.power(&back.amplitudes(wavelength_nm, &films_reversed));
    let below = Prepared::new(&indices[slab..], beta);
    let lower = below.power(&below.amplitudes(wavelength_nm, &thickness_nm[slab..]));
    let q = normal_component(indices[slab], beta);
    let pass = elementary::exp(-2.0 * wavenumber(wavelength_nm) * thickness_nm[slab - 1] * q.im);
    let pass = if pass < OPAQUE_PASS || !pass.is_finite() {
        0.0
    } else {
        pass
    };
    let combine = |(ra, ta, rb, tb, r_below, t_below): (f64, f64, f64, f64, f64, f64)| {
        let a = pass * pass * r_below;
        let den = 1.0 - rb * a;
        (ra + ta * tb * a / den, ta * pass * t_below / den)
    };
    let (r_s, t_s) = combine(unpack(&forward, &backward, &lower, 0));
    let (r_p, t_p) = combine(unpack(&forward, &backward, &lower, 1));
    (0.5 * (r_s + r_p), 0.5 * (t_s + t_p))
}

/// (R_A, T_A, R′_A, T′_A, R_B, T_B) of polarisation `pol` (0 s, 1 p).
fn unpack(a: &Power, b: &Power, lower: &Power, pol: usize) -> (f64, f64, f64, f64, f64, f64) {
    if pol == 0 {
        (a.R_s, a.T_s, b.R_s, b.T_s, lower.R_s, lower.T_s)
    } else {
        (a.R_p, a.T_p, b.R_p, b.T_p, lower.R_p, lower.T_p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Layer, Material, Stack};

    fn constant(n: f64, k: f64) -> Material {
        Material::constant(format!("{n}+{k}i"), C64::new(n, k)).unwrap()
    }

    /// The one-slab recurrence equals the general incoherent core ([`Stack::sweep`], tested
    /// against Byrnes' `inc_tmm`) to rounding: front and back coatings, an absorbing slab,
    /// the slab first, last or alone, 0–85°.
    #[test]
    fn one_slab_matches_the_incoherent_core() {
        let films = |spec: &[(f64, f64, f64)]| -> Vec<Layer> {
            spec.iter()
                .map(|&(n, k, d)| Layer {
                    material: constant(n, k),
                    thickness_nm: d,
                })
                .collect()
        };
        let cases: Vec<(Vec<Layer>, usize, Material)> = vec![
            (
                films(&[(1.38, 0.0, 99.6), (1.52, 2e-7, 2e6), (1.38, 0.0, 99.6)]),
                2,
                constant(1.0, 0.0),
            ),
            (
                films(&[
                    (2.1, 0.0, 60.0),
                    (1.46, 0.0, 90.0),
                    (1.6, 1e-6, 1.5e6),
                    (0.2, 3.0, 12.0),
                ]),
                3,
                constant(1.0, 0.0),
            ),
            (films(&[(1.5, 1e-7, 3e6)]), 1, constant(1.33, 0.0)),
            (
                films(&[(1.5, 0.0, 2e6), (2.3, 0.0, 70.0)]),
                1,
                constant(1.0, 0.0),
            ),
        ];
        for (layers, s, substrate) in cases {
            let flags: Vec<bool> = (1..=layers.len()).map(|j| j == s).collect();
            let d: Vec<f64> = layers.iter().map(|l| l.thickness_nm).collect();
            let stack = Stack::new(constant(1.0, 0.0), layers, substrate)
                .unwrap()
                .with_incoherent(flags)
                .unwrap();
            for angle in [0.0, 30.0, 60.0, 85.0] {
                for wl in [410.0, 550.0, 690.0] {
                    let core = stack.sweep(&[angle], &[wl]).unwrap()[0];
                    let idx = stack.indices_at(wl).unwrap();
                    let beta = idx[0].re * elementary::sin(f64::to_radians(angle));
                    let (r, t) = slab_power(&idx, beta, wl, &d, s);
                    assert!((r - core.R()).abs() < 1e-12, "R {r} vs {}", core.R());
                    assert!((t - core.T()).abs() < 1e-12, "T {t} vs {}", core.T());
                }
            }
        }
    }
}
