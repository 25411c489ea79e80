//! Physical laws of the stack solver as property tests (proptest).

use nacre_optics::{C64, Layer, Material, Power, Stack};
use proptest::prelude::*;

fn medium(n: f64, k: f64) -> Material {
    Material::constant(format!("{n}+{k}i"), C64::new(n, k)).unwrap()
}

fn film(n: f64, k: f64, d: f64) -> Layer {
    Layer {
        material: medium(n, k),
        thickness_nm: d,
    }
}

fn power(stack: &Stack, angle_deg: f64, wavelength_nm: f64) -> Power {
    stack.evaluate(angle_deg, wavelength_nm).unwrap().power
}

fn close(a: &Power, b: &Power, tol: f64) -> bool {
    (a.R_s - b.R_s).abs() <= tol
        && (a.R_p - b.R_p).abs() <= tol
        && (a.T_s - b.T_s).abs() <= tol
        && (a.T_p - b.T_p).abs() <= tol
}

/// (n, κ, thickness) of an arbitrary film, absorbing or not.
fn any_film() -> impl Strategy<Value = (f64, f64, f64)> {
    (
        1.0..3.0f64,
        prop_oneof![Just(0.0), 0.0..3.0f64],
        0.0..1000.0f64,
    )
}

fn any_substrate() -> impl Strategy<Value = (f64, f64)> {
    (0.1..4.0f64, prop_oneof![Just(0.0), 0.0..5.0f64])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Energy is bounded: 0 ≤ R, T, A ≤ 1 for every polarisation, absorbing or not,
    /// including total internal reflection (ambient index up to 2).
    #[test]
    fn powers_are_bounded(
        n0 in 1.0..2.0f64,
        films in prop::collection::vec(any_film(), 0..5),
        (ns, ks) in any_substrate(),
        angle in 0.0..89.9f64,
        wl in 380.0..780.0f64,
    ) {
        let layers = films.iter().map(|&(n, k, d)| film(n, k, d)).collect();
        let stack = Stack::new(medium(n0, 0.0), layers, medium(ns, ks)).unwrap();
        let p = power(&stack, angle, wl);
        for v in [p.R_s, p.R_p, p.T_s, p.T_p] {
            prop_assert!((-1e-12..=1.0 + 1e-12).contains(&v), "{p:?}");
        }
        for a in [1.0 - p.R_s - p.T_s, 1.0 - p.R_p - p.T_p] {
            prop_assert!((-1e-12..=1.0 + 1e-12).contains(&a), "{p:?}");
        }
    }

    /// Without absorption, R + T = 1 per polarisation (also beyond the critical angle).
    #[test]
    fn lossless_conserves_energy(
        n0 in 1.0..2.0f64,
        films in prop::collection::vec((1.0..3.0f64, 0.0..2000.0f64), 0..8),
        ns in 1.0..4.0f64,
        angle in 0.0..89.9f64,
        wl in 380.0..780.0f64,
    ) {
        let layers = films.iter().map(|&(n, d)| film(n, 0.0, d)).collect();
        let stack = Stack::new(medium(n0, 0.0), layers, medium(ns, 0.0)).unwrap();
        let p = power(&stack, angle, wl);
        prop_assert!((p.R_s + p.T_s - 1.0).abs() < 1e-12, "{p:?}");
        prop_assert!((p.R_p + p.T_p - 1.0).abs() < 1e-12, "{p:?}");
    }

    /// A film of zero thickness changes nothing.
    #[test]
    fn zero_thickness_film_is_no_film(
        above in prop::collection::vec(any_film(), 0..3),
        (n, k, _) in any_film(),
        (ns, ks) in any_substrate(),
        angle in 0.0..89.0f64,
        wl in 380.0..780.0f64,
    ) {
        let base: Vec<Layer> = above.iter().map(|&(n, k, d)| film(n, k, d)).collect();
        let mut with = base.clone();
        with.push(film(n, k, 0.0));
        let a = Stack::new(medium(1.0, 0.0), base, medium(ns, ks)).unwrap();
        let b = Stack::new(medium(1.0, 0.0), with, medium(ns, ks)).unwrap();
        prop_assert!(close(&power(&a, angle, wl), &power(&b, angle, wl), 1e-13));
    }

    /// A top film with the ambient's index is invisible, whatever its thickness.
    #[test]
    fn ambient_index_film_is_invisible(
        n0 in 1.0..2.0f64,
        d in 0.0..5000.0f64,
        below in prop::collection::vec(any_film(), 0..3),
        (ns, ks) in any_substrate(),
        angle in 0.0..89.0f64,
        wl in 380.0..780.0f64,
    ) {
        let base: Vec<Layer> = below.iter().map(|&(n, k, d)| film(n, k, d)).collect();
        let mut with = vec![film(n0, 0.0, d)];
        with.extend(base.iter().cloned());
        let a = Stack::new(medium(n0, 0.0), base, medium(ns, ks)).unwrap();
        let b = Stack::new(medium(n0, 0.0), with, medium(ns, ks)).unwrap();
        prop_assert!(close(&power(&a, angle, wl), &power(&b, angle, wl), 1e-12));
    }

    /// Averaged over one period of its phase, a lossless film's reflectance is the
    /// incoherent (intensity) sum R₀₁ + T₀₁ T₁₀ R₁₂ / (1 − R₁₀ R₁₂) (per polarisation).
    #[test]
    fn phase_average_is_incoherent_sum(
        n1 in 1.2..2.5f64,
        ns in 1.2..2.5f64,
        angle in 0.0..75.0f64,
        wl in 380.0..780.0f64,
        d0 in 5000.0..20000.0f64,
    ) {
        const N: usize = 128;
        let air = medium(1.0, 0.0);
        let bare_top = Stack::new(air.clone(), vec![], medium(n1, 0.0)).unwrap();
        let beta = angle.to_radians().sin();
        // Incidence angle inside the film, seen from medium n1, for the bottom interface.
        let angle_in_film = (beta / n1).asin().to_degrees();
        let bare_bottom = Stack::new(medium(n1, 0.0), vec![], medium(ns, 0.0)).unwrap();
        let top = power(&bare_top, angle, wl);
        let bottom = power(&bare_bottom, angle_in_film, wl);
        let incoherent = |r01: f64, r12: f64| r01 + (1.0 - r01).powi(2) * r12 / (1.0 - r01 * r12);
        // One period of e^{2iδ}: Δd = λ / (2 n₁ cos θ₁).
        let period = wl / (2.0 * n1 * angle_in_film.to_radians().cos());
        let thicknesses: Vec<f64> = (0..N).map(|m| d0 + period * m as f64 / N as f64).collect();
        let stack = Stack::new(air.clone(), vec![film(n1, 0.0, d0)], medium(ns, 0.0)).unwrap();
        let sweep = stack.sweep_thickness(1, &[angle], &[wl], &thicknesses).unwrap();
        let mean_s = sweep.iter().map(|p| p.R_s).sum::<f64>() / N as f64;
        let mean_p = sweep.iter().map(|p| p.R_p).sum::<f64>() / N as f64;
        prop_assert!((mean_s - incoherent(top.R_s, bottom.R_s)).abs() < 1e-9, "{mean_s}");
        prop_assert!((mean_p - incoherent(top.R_p, bottom.R_p)).abs() < 1e-9, "{mean_p}");
    }

    /// The thickness-sweep fast path (Airy closed form for one film, partial recurrence
    /// otherwise) equals the general recurrence to 1e-13.
    #[test]
    fn thickness_sweep_matches_general_recurrence(
        films in prop::collection::vec(any_film(), 1..4),
        which in 0usize..3,
        (ns, ks) in any_substrate(),
        n0 in 1.0..1.6f64,
        angle in 0.0..89.9f64,
        wl in 380.0..780.0f64,
        d in 0.0..3000.0f64,
    ) {
        let layer = which % films.len() + 1;
        let layers: Vec<Layer> = films.iter().map(|&(n, k, d)| film(n, k, d)).collect();
        let stack = Stack::new(medium(n0, 0.0), layers.clone(), medium(ns, ks)).unwrap();
        let fast = stack.sweep_thickness(layer, &[angle], &[wl], &[d]).unwrap()[0];
        let mut changed = layers;
        changed[layer - 1].thickness_nm = d;
        let general = Stack::new(medium(n0, 0.0), changed, medium(ns, ks)).unwrap();
        prop_assert!(close(&fast, &power(&general, angle, wl), 1e-13));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Uniform thickness grids (phasor stepping) agree with per-thickness evaluation to
    /// 1e-12 — the level of the phase's own rounding: at 3 µm the phase 2δ is ~100 rad,
    /// whose ulp (1.4e-14) near a resonance moves R by ~1e-13 in either method.
    #[test]
    fn uniform_thickness_grid_matches_pointwise(
        (n1, k1, _) in any_film(),
        (ns, ks) in any_substrate(),
        angle in 0.0..89.9f64,
        wl in 380.0..780.0f64,
        start in 0.0..500.0f64,
        step in 0.1..50.0f64,
    ) {
        let stack = Stack::new(medium(1.0, 0.0), vec![film(n1, k1, 0.0)], medium(ns, ks)).unwrap();
        let grid: Vec<f64> = (0..200).map(|i| start + step * f64::from(i)).collect();
        let swept = stack.sweep_thickness(1, &[angle], &[wl], &grid).unwrap();
        for (p, &d) in swept.iter().zip(&grid) {
            let one = stack.sweep_thickness(1, &[angle], &[wl], &[d]).unwrap()[0];
            prop_assert!(close(p, &one, 1e-12), "{d}: {p:?} vs {one:?}");
        }
    }
}

/// A quarter-wave film at normal incidence: R = ((n₀ n₂ − n₁²)/(n₀ n₂ + n₁²))² at λ = 4 n₁ d,
/// and that is an extremum of R(λ).
#[test]
fn quarter_wave_extremum() {
    let (n0, n1, n2) = (1.0, 1.38, 1.52);
    let wl = 550.0;
    let d = wl / (4.0 * n1);
    let stack = Stack::new(medium(n0, 0.0), vec![film(n1, 0.0, d)], medium(n2, 0.0)).unwrap();
    let r = power(&stack, 0.0, wl).R();
    let expected = ((n0 * n2 - n1 * n1) / (n0 * n2 + n1 * n1)).powi(2);
    assert!((r - expected).abs() < 1e-15, "{r} vs {expected}");
    assert!(power(&stack, 0.0, wl - 1.0).R() > r && power(&stack, 0.0, wl + 1.0).R() > r);
}

/// Parallel sweeps give bit-identical results whatever the thread count.
#[test]
fn sweeps_are_deterministic_across_thread_counts() {
    let stack = Stack::new(
        medium(1.0, 0.0),
        vec![film(1.33, 0.0, 400.0), film(0.27, 2.9, 20.0)],
        medium(1.5, 0.0),
    )
    .unwrap();
    let angles: Vec<f64> = (0..90).map(f64::from).collect();
    let wavelengths: Vec<f64> = (0..81).map(|i| 380.0 + 5.0 * f64::from(i)).collect();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| stack.sweep(&angles, &wavelengths).unwrap())
    };
    assert_eq!(run(1), run(3));
}

/// Absorptance is never negative: lossless stacks have R + T = 1 up to rounding, and
/// A = 1 − R − T is reported as 0 there, not −10⁻¹⁶ (issue 16 §5).
#[test]
fn absorptance_is_never_negative() {
    let stack = Stack::new(
        medium(1.0, 0.0),
        vec![film(1.33, 0.0, 400.0), film(2.3, 0.0, 87.0)],
        medium(1.52, 0.0),
    )
    .unwrap();
    let mut negative_before_clamp = 0;
    for a in 0..90 {
        for w in 380..=780 {
            let p = power(&stack, f64::from(a), f64::from(w));
            assert!(p.A() >= 0.0, "A = {} at {a}°, {w} nm", p.A());
            assert!(p.A() < 1e-12);
            if 1.0 - p.R() - p.T() < 0.0 {
                negative_before_clamp += 1;
            }
        }
    }
    // The clamp is not idle: rounding does go below zero on this sweep.
    assert!(negative_before_clamp > 0);
}
