//! Tests of the Monte Carlo reference: white furnace and film lobes against an independent
//! (θ_i, φ_i) quadrature, reciprocity, the smooth limit, determinism.

use super::*;
use crate::{C64, Layer, Material};
use proptest::prelude::*;

fn constant(n: f64) -> Material {
    Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap()
}

/// A film of index 1.33 and thickness `d_nm` on glass (1.5) in air.
fn soap_on_glass(d_nm: f64) -> Stack {
    Stack::new(
        constant(1.0),
        vec![Layer {
            material: constant(1.33),
            thickness_nm: d_nm,
        }],
        constant(1.5),
    )
    .unwrap()
}

/// Exact spectral (R, T) colours of `stack` at `cos_theta`, straight from the stack solver.
fn exact_colours(stack: &Stack, c: &Colorimeter, cos_theta: f64) -> ([f64; 3], [f64; 3]) {
    let rule = SpectralRule::new(c, stack.max_opd_nm(None));
    let angle = cos_theta.acos().to_degrees();
    let p = stack.sweep(&[angle], rule.wavelengths_nm()).unwrap();
    (
        rule.colour(p.iter().map(|p| p.R())),
        rule.colour(p.iter().map(|p| p.T())),
    )
}

/// E_r(ω_o) = ∫₀^{π/2} ∫₀^{2π} f_r cos θ_i sin θ_i dφ dθ by the midpoint rule on an
/// `n_theta` × `n_phi` grid over θ ∈ (0, π/2), φ ∈ (0, π), doubled by the mirror symmetry
/// φ → −φ of a view in the xz plane. Independent of the sampler: only the BRDF is used.
fn quadrature(
    film: &FilmTerm,
    alpha: f64,
    cos_theta_o: f64,
    n_theta: usize,
    n_phi: usize,
) -> [f64; 3] {
    let wo = [(1.0 - cos_theta_o * cos_theta_o).sqrt(), 0.0, cos_theta_o];
    let d_theta = 0.5 * PI / n_theta as f64;
    let d_phi = PI / n_phi as f64;
    let rows: Vec<[f64; 3]> = (0..n_theta)
        .into_par_iter()
        .map(|i| {
            let theta = (i as f64 + 0.5) * d_theta;
            let (s, c) = theta.sin_cos();
            let mut row = [0.0; 3];
            for j in 0..n_phi {
                let (sp, cp) = ((j as f64 + 0.5) * d_phi).sin_cos();
                let f = brdf(film, alpha, wo, [s * cp, s * sp, c]);
                for k in 0..3 {
                    row[k] += f[k] * c * s;
                }
            }
            row
        })
        .collect();
    let mut e = [0.0; 3];
    for r in &rows {
        for k in 0..3 {
            e[k] += r[k];
        }
    }
    e.map(|v| 2.0 * v * d_theta * d_phi)
}

#[test]
fn film_table_matches_exact_spectral_colour() {
    let c = Colorimeter::srgb_d65();
    let mut rng = SplitMix64::stream(7, 0);
    let mut worst: f64 = 0.0;
    for d in [300.0, 800.0] {
        let stack = soap_on_glass(d);
        let film = FilmTerm::from_stack(&stack, &c).unwrap();
        assert_eq!(film.eta(), Some(1.5));
        let mut cosines: Vec<f64> = (0..200).map(|_| rng.next_f64()).collect();
        cosines.extend([1.0, 1e-3, 0.5]);
        for cos in cosines.into_iter().filter(|&x| x > 0.0) {
            let (r, t) = exact_colours(&stack, &c, cos);
            let (rt, tt) = (film.reflectance_colour(cos), film.transmittance_colour(cos));
            for k in 0..3 {
                worst = worst.max((r[k] - rt[k]).abs()).max((t[k] - tt[k]).abs());
            }
        }
    }
    eprintln!("film table vs exact spectral colour: worst |Δ| = {worst:.2e}");
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn white_furnace_matches_quadrature() {
    let c = Colorimeter::srgb_d65();
    let mirror = FilmTerm::perfect_mirror(&c);
    for alpha in [0.1, 0.3, 0.6, 1.0] {
        for cos_o in [1.0, 0.5, 0.2] {
            let e = directional_albedo_with(&mirror, alpha, cos_o, 1 << 20, 11).unwrap();
            let q = quadrature(&mirror, alpha, cos_o, 2000, 1000);
            let (m, s) = (e.reflection.colour, e.reflection.standard_error);
            eprintln!(
                "furnace α={alpha} cos θ_o={cos_o}: MC {:.6} ± {:.1e}, quadrature {:.6}, loss {:.4}",
                m[1],
                s[1],
                q[1],
                1.0 - q[1]
            );
            for k in 0..3 {
                assert!(q[k] <= 1.0 + 1e-9 && m[k] <= 1.0, "{m:?} {q:?}");
                assert!(
                    (m[k] - q[k]).abs() <= 3.0 * s[k] + 1e-6,
                    "α={alpha} cos={cos_o}: {m:?} ± {s:?} vs {q:?}"
                );
            }
            // Multiple-scattering energy is missing: the loss grows with roughness.
            assert_eq!(e.transmission.colour, [0.0; 3]);
        }
    }
}

#[test]
fn films_match_quadrature() {
    let c = Colorimeter::srgb_d65();
    for d in [300.0, 800.0] {
        let film = FilmTerm::from_stack(&soap_on_glass(d), &c).unwrap();
        for alpha in [0.2, 0.5] {
            for cos_o in [0.9, 0.4] {
                let e = directional_albedo_with(&film, alpha, cos_o, 1 << 20, 3).unwrap();
                let q = quadrature(&film, alpha, cos_o, 2000, 1000);
                let (m, s) = (e.reflection.colour, e.reflection.standard_error);
                eprintln!(
                    "d={d} α={alpha} cos θ_o={cos_o}: MC {m:.5?} ± {:.1e}, quadrature {q:.5?}",
                    s[1]
                );
                for k in 0..3 {
                    assert!(
                        (m[k] - q[k]).abs() <= 3.0 * s[k] + 1e-6,
                        "d={d} α={alpha} cos={cos_o}: {m:?} ± {s:?} vs {q:?}"
                    );
                }
            }
        }
    }
}

/// E_t(ω_o) = ∫ f_t |cos θ_t| dω_t, changed to an integral over the microfacet normal h
/// (θ_h, φ_h) with the refraction Jacobian |∂ω_t/∂h| = (ω_o·h + η ω_t·h)² / (η² |ω_t·h|)
/// (Walter et al. 2007, Eq. 17), midpoint rule as [`quadrature`]. In ω_t the integrand
/// jumps where h reaches the horizon (D(h) → α²/π, then 0), which the midpoint rule
/// resolves only to O(Δθ); over h it is continuous.
fn quadrature_transmission(
    film: &FilmTerm,
    alpha: f64,
    cos_theta_o: f64,
    n_theta: usize,
    n_phi: usize,
) -> [f64; 3] {
    let eta = film.eta().unwrap();
    let wo = [(1.0 - cos_theta_o * cos_theta_o).sqrt(), 0.0, cos_theta_o];
    let d_theta = 0.5 * PI / n_theta as f64;
    let d_phi = PI / n_phi as f64;
    let rows: Vec<[f64; 3]> = (0..n_theta)
        .into_par_iter()
        .map(|i| {
            let theta = (i as f64 + 0.5) * d_theta;
            let (s, c) = theta.sin_cos();
            let mut row = [0.0; 3];
            for j in 0..n_phi {
                let (sp, cp) = ((j as f64 + 0.5) * d_phi).sin_cos();
                let h = [s * cp, s * sp, c];
                let cos_o_h = dot(wo, h);
                if cos_o_h <= 0.0 {
                    continue;
                }
                let Some(wt) = refract(wo, h, cos_o_h, eta) else {
                    continue;
                };
                let cos_t_h = dot(wt, h);
                let jacobian = (cos_o_h + eta * cos_t_h).powi(2) / (eta * eta * cos_t_h.abs());
                let f = btdf(film, alpha, wo, wt);
                for k in 0..3 {
                    row[k] += f[k] * wt[2].abs() * jacobian * s;
                }
            }
            row
        })
        .collect();
    let mut e = [0.0; 3];
    for r in &rows {
        for k in 0..3 {
            e[k] += r[k];
        }
    }
    e.map(|v| 2.0 * v * d_theta * d_phi)
}

#[test]
fn transmission_matches_quadrature() {
    let c = Colorimeter::srgb_d65();
    for d in [0.0, 300.0] {
        let film = FilmTerm::from_stack(&soap_on_glass(d), &c).unwrap();
        for alpha in [0.3, 0.7] {
            for cos_o in [0.9, 0.4] {
                let e = directional_albedo_with(&film, alpha, cos_o, 1 << 20, 17).unwrap();
                let q = quadrature_transmission(&film, alpha, cos_o, 2000, 1000);
                let (m, s) = (e.transmission.colour, e.transmission.standard_error);
                eprintln!(
                    "T d={d} α={alpha} cos θ_o={cos_o}: MC {m:.5?} ± {:.1e}, quadrature {q:.5?}",
                    s[1]
                );
                for k in 0..3 {
                    assert!(
                        (m[k] - q[k]).abs() <= 3.0 * s[k] + 1e-6,
                        "d={d} α={alpha} cos={cos_o}: {m:?} ± {s:?} vs {q:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn smooth_limit_is_the_specular_film_colour() {
    let c = Colorimeter::srgb_d65();
    for d in [300.0, 800.0] {
        let stack = soap_on_glass(d);
        let film = FilmTerm::from_stack(&stack, &c).unwrap();
        for cos_o in [1.0, 0.7, 0.3] {
            let e = directional_albedo_with(&film, 1e-4, cos_o, 1 << 14, 5).unwrap();
            let (r, t) = exact_colours(&stack, &c, cos_o);
            for k in 0..3 {
                assert!(
                    (e.reflection.colour[k] - r[k]).abs() < 1e-5,
                    "{e:?} vs {r:?}"
                );
                assert!(
                    (e.transmission.colour[k] - t[k]).abs() < 1e-5,
                    "{e:?} vs {t:?}"
                );
            }
        }
    }
    // The convenience entry point agrees with the table it builds.
    let stack = soap_on_glass(300.0);
    let (colour, se) = directional_albedo(&stack, 1e-4, 0.8, &c, 1 << 12, 1).unwrap();
    let (r, _) = exact_colours(&stack, &c, 0.8);
    for k in 0..3 {
        assert!(
            (colour[k] - r[k]).abs() < 1e-5 && se[k] < 1e-6,
            "{colour:?} ± {se:?} vs {r:?}"
        );
    }
}

#[test]
fn lossless_reflection_plus_transmission_at_most_one() {
    let c = Colorimeter::srgb_d65();
    for d in [0.0, 300.0, 800.0] {
        let film = FilmTerm::from_stack(&soap_on_glass(d), &c).unwrap();
        for alpha in [0.05, 0.3, 1.0] {
            for cos_o in [1.0, 0.5, 0.1] {
                let e = directional_albedo_with(&film, alpha, cos_o, 1 << 16, 9).unwrap();
                for k in 0..3 {
                    let sum = e.reflection.colour[k] + e.transmission.colour[k];
                    assert!(
                        sum <= 1.0 + 1e-9 && sum > 0.0,
                        "d={d} α={alpha} cos={cos_o}: {e:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn deterministic_across_thread_counts() {
    let c = Colorimeter::srgb_d65();
    let film = FilmTerm::from_stack(&soap_on_glass(800.0), &c).unwrap();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| directional_albedo_with(&film, 0.4, 0.6, 100_003, 42).unwrap())
    };
    let (a, b) = (run(1), run(2));
    for k in 0..3 {
        assert_eq!(
            a.reflection.colour[k].to_bits(),
            b.reflection.colour[k].to_bits()
        );
        assert_eq!(
            a.reflection.standard_error[k].to_bits(),
            b.reflection.standard_error[k].to_bits()
        );
        assert_eq!(
            a.transmission.colour[k].to_bits(),
            b.transmission.colour[k].to_bits()
        );
    }
    assert_eq!(a, run(3));
}

#[test]
fn vndf_samples_are_unit_and_visible() {
    let mut rng = SplitMix64::stream(1, 2);
    for alpha in [1e-3, 0.2, 1.0, 2.0] {
        for cos_o in [1.0f64, 0.5, 1e-3] {
            let wo = [(1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o];
            for _ in 0..1000 {
                let h = sample_ggx_vndf(wo, alpha, rng.next_f64(), rng.next_f64());
                assert!((dot(h, h) - 1.0).abs() < 1e-12 && h[2] >= 0.0, "{h:?}");
                assert!(dot(wo, h) >= -1e-12, "{wo:?} {h:?}");
            }
        }
    }
}

fn direction(cos_theta: f64, phi: f64) -> [f64; 3] {
    let s = (1.0 - cos_theta * cos_theta).sqrt();
    [s * phi.cos(), s * phi.sin(), cos_theta]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Helmholtz reciprocity f_r(ω_o, ω_i) = f_r(ω_i, ω_o) (Eq. 1 is symmetric: h, ω·h and
    /// G₂ are).
    #[test]
    fn brdf_is_reciprocal(
        cos_o in 0.01f64..1.0, phi_o in 0.0f64..std::f64::consts::TAU,
        cos_i in 0.01f64..1.0, phi_i in 0.0f64..std::f64::consts::TAU,
        alpha in 0.01f64..1.5,
    ) {
        let film = FilmTerm::from_fn(64, None, |c| ([c, c * c, 1.0 - 0.5 * c], [0.0; 3]));
        let (wo, wi) = (direction(cos_o, phi_o), direction(cos_i, phi_i));
        let (a, b) = (brdf(&film, alpha, wo, wi), brdf(&film, alpha, wi, wo));
        for k in 0..3 {
            prop_assert!((a[k] - b[k]).abs() <= 1e-12 * a[k].abs().max(1e-300), "{a:?} vs {b:?}");
        }
    }
}
