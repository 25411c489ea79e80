//! Validation of the diffraction model against physics laws and closed forms: the grating
//! equation, Bessel-function order intensities of a sinusoidal grating (Jacobi–Anger),
//! Parseval, and the flat mirror.

use super::*;
use crate::colour::{Illuminant, Observer, OutputSpace, RgbSpace};

/// σ_s of the thesis' 65 µm coherence diameter.
const SIGMA_S_UM: f64 = DEFAULT_COHERENCE_DIAMETER_UM / 4.0;

/// Bessel function of the first kind J_m(x) by its power series
/// Σ_k (−1)^k (x/2)^{2k+|m|} / (k! (k+|m|)!), with J_{−m} = (−1)^m J_m. Accurate to ~1e-14
/// for |x| ≤ 10 (terms peak near (x/2)^{x}/Γ(x/2)² and the series is summed to 60 terms).
fn bessel_j(m: i32, x: f64) -> f64 {
    let ma = m.unsigned_abs() as i32;
    let half = 0.5 * x;
    let mut term = half.powi(ma) / (1..=ma).map(f64::from).product::<f64>();
    let mut sum = term;
    for k in 1..60 {
        term *= -half * half / (f64::from(k) * f64::from(k + ma));
        sum += term;
    }
    if m < 0 && ma % 2 == 1 { -sum } else { sum }
}

#[test]
fn bessel_series_matches_reference_values() {
    // Abramowitz & Stegun Table 9.1.
    assert!((bessel_j(0, 1.0) - 0.765_197_686_557_966_6).abs() < 1e-14);
    assert!((bessel_j(1, 1.0) - 0.440_050_585_744_933_5).abs() < 1e-14);
    assert!((bessel_j(2, 5.0) - 0.046_565_116_277_752_21).abs() < 1e-13);
    assert!((bessel_j(-1, 2.0) + 0.576_724_807_756_873_4).abs() < 1e-14);
}

/// A 1-D grating sampled with `per_period` samples per period over enough whole periods to
/// cover the coherence diameter.
fn grating(kind: &str, period_um: f64, height_um: f64) -> HeightField {
    let per_period = ((period_um / 0.04).ceil() as usize).max(16);
    let pitch = period_um / per_period as f64;
    let periods = (DEFAULT_COHERENCE_DIAMETER_UM / period_um).ceil() as usize;
    let nx = periods * per_period;
    match kind {
        "sine" => HeightField::sine_grating(period_um, height_um, pitch, nx).unwrap(),
        _ => HeightField::blazed_grating(period_um, height_um, pitch, nx).unwrap(),
    }
}

fn surface(field: &HeightField, wavelength_min_nm: f64, tolerance: f64) -> DiffractionSurface {
    let (order, _) = taylor_order_for(max_phase(field, wavelength_min_nm, 2.0), tolerance).unwrap();
    DiffractionSurface::new(TaylorTerms::compute(field, order), SIGMA_S_UM).unwrap()
}

/// Local maxima of ρ over view angles −89°…89° (step 0.02°) above `floor`, each refined by
/// the parabola through log ρ at the three samples around it (exact for a Gaussian lobe).
fn peaks(s: &DiffractionSurface, incidence_deg: f64, wavelength_nm: f64, floor: f64) -> Vec<f64> {
    let step = 0.02;
    let views: Vec<f64> = (0..=8900).map(|i| -89.0 + step * i as f64).collect();
    let rho: Vec<f64> = views
        .iter()
        .map(|&v| {
            let (wi, wr) = in_plane_directions(incidence_deg, v);
            s.relative_reflectance(wi, wr, wavelength_nm, FresnelTerm::Unity)
        })
        .collect();
    let mut out = Vec::new();
    for i in 1..views.len() - 1 {
        if rho[i] > floor && rho[i] >= rho[i - 1] && rho[i] > rho[i + 1] {
            let (a, b, c) = (rho[i - 1].ln(), rho[i].ln(), rho[i + 1].ln());
            let offset = 0.5 * (a - c) / (a - 2.0 * b + c);
            out.push(views[i] + offset * step);
        }
    }
    out
}

/// θ_m from sin θ_m = sin θ_i + mλ/d, degrees, when it is a propagating order.
fn order_angle_deg(incidence_deg: f64, m: i32, wavelength_nm: f64, period_um: f64) -> Option<f64> {
    let s = incidence_deg.to_radians().sin() + f64::from(m) * wavelength_nm * 1e-3 / period_um;
    (s.abs() < 0.97).then(|| s.asin().to_degrees())
}

#[test]
fn peaks_follow_the_grating_equation() {
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for (kind, d, h) in [
        ("sine", 1.6, 0.06),
        ("sine", 0.74, 0.05),
        ("blazed", 2.5, 0.25),
        ("blazed", 1.6, 0.15),
    ] {
        let field = grating(kind, d, h);
        let s = surface(&field, 400.0, 1e-8);
        s.check_sampling(400.0, 2.0).unwrap();
        for incidence in [0.0, 20.0, 45.0] {
            for wavelength in [450.0, 550.0, 650.0] {
                let found = peaks(&s, incidence, wavelength, 1e-6);
                for m in [-2, -1, 1, 2] {
                    let Some(theory) = order_angle_deg(incidence, m, wavelength, d) else {
                        continue;
                    };
                    let nearest = found
                        .iter()
                        .map(|p| (p - theory).abs())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        nearest < 0.2,
                        "{kind} d={d} θi={incidence} λ={wavelength} m={m}: theory {theory:.4}°, peaks {found:?}"
                    );
                    worst = worst.max(nearest);
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 60, "{checked}");
    eprintln!("grating equation: {checked} orders, max peak-angle error {worst:.2e}°");
}

#[test]
fn period_is_recovered_from_peak_angles() {
    // The thesis' blazed 2.5 µm grating, first orders on both sides, 400–700 nm.
    let d = 2.5;
    let field = grating("blazed", d, 0.3);
    let s = surface(&field, 400.0, 1e-8);
    let incidence: f64 = 15.0;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for i in 0..=12 {
        let wavelength = 400.0 + 25.0 * f64::from(i);
        let found = peaks(&s, incidence, wavelength, 1e-6);
        for m in [-1, 1] {
            let theory = order_angle_deg(incidence, m, wavelength, d).unwrap();
            let p = found
                .iter()
                .copied()
                .min_by(|a, b| (a - theory).abs().total_cmp(&(b - theory).abs()))
                .unwrap();
            // sin θ_m − sin θ_i = (mλ) / d: slope 1/d through the origin.
            let x = f64::from(m) * wavelength * 1e-3;
            let y = p.to_radians().sin() - incidence.to_radians().sin();
            sxx += x * x;
            sxy += x * y;
        }
    }
    let recovered = sxx / sxy;
    let error = (recovered - d).abs() / d;
    eprintln!("recovered period {recovered:.6} µm, relative error {error:.2e}");
    assert!(error < 0.005, "{recovered}");
}

#[test]
fn sinusoidal_grating_orders_are_bessel_functions() {
    let d = 1.6;
    let mut worst: f64 = 0.0;
    for a in [0.02, 0.05, 0.1] {
        let field = grating("sine", d, a);
        let s = surface(&field, 400.0, 1e-9);
        for wavelength in [400.0, 550.0, 700.0] {
            for incidence in [0.0, 10.0, 30.0] {
                for m in -3..=3 {
                    let Some(theta_m) = order_angle_deg(incidence, m, wavelength, d) else {
                        continue;
                    };
                    let (wi, wr) = in_plane_directions(incidence, theta_m);
                    let [u, v, w] = [-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]];
                    let p2 = s.transform(wavelength, u, v, w).norm_sqr();
                    let j = bessel_j(m, k_per_um(wavelength) * w * a);
                    let err = (p2 - j * j).abs();
                    assert!(
                        err < 1e-3,
                        "a={a} λ={wavelength} θi={incidence} m={m}: {p2} vs {}",
                        j * j
                    );
                    worst = worst.max(err);
                }
            }
        }
    }
    eprintln!("sinusoidal grating: max | |P_m|² − J_m(kwa)² | = {worst:.2e}");
}

#[test]
fn taylor_sum_carries_unit_energy_up_to_the_bound() {
    // Parseval for the DFT: Σ_j |P_j|² = mean |Σ_n (ikwh)ⁿ/n!|², within 2ε + ε² of 1 where
    // ε is the remainder bound, for every order N.
    let field = HeightField::cd_tracks(128, 128, 0.125, CD_PIT_DEPTH_UM, 7).unwrap();
    let kw = -2.0 * k_per_um(380.0);
    let x_max = kw.abs() * field.max_abs_height_um();
    let (n_tol, _) = taylor_order_for(x_max, 1e-10).unwrap();
    let terms = TaylorTerms::compute(&field, n_tol);
    for order in [2, 4, 6, 8, n_tol] {
        let sub: Vec<Vec<C64>> = (0..=order).map(|n| terms.layer(n)).collect();
        let t = TaylorTerms::from_terms(128, 128, 0.125, &sub).unwrap();
        let energy: f64 = t.series(kw).iter().map(|p| p.norm_sqr()).sum();
        let eps = taylor_remainder_bound(x_max, order);
        assert!(
            (energy - 1.0).abs() <= 2.0 * eps + eps * eps + 1e-12,
            "N={order}: energy {energy}, bound {eps}"
        );
        if order == n_tol {
            eprintln!(
                "DFT Parseval at N={order}: |Σ|P_j|² − 1| = {:.2e}",
                (energy - 1.0).abs()
            );
            assert!((energy - 1.0).abs() < 1e-9);
        }
    }
}

#[test]
fn windowed_transform_carries_unit_energy() {
    // ∫|P̃(q)|² dq / ∫ exp(−σ²q²) dq = 1 for a unit-modulus phase screen: the flat mirror's
    // energy is spread over the orders, not created or lost by the window. 1-D surfaces
    // (ny = 1), so the y factor is the same for both and cancels.
    let mut worst: f64 = 0.0;
    let profiles = [
        grating("blazed", 2.5, 0.3),
        grating("sine", 0.74, 0.08),
        // A smooth random profile: the bins lie closer than the window's width here.
        {
            let nx = 1024;
            let pitch = 0.0625;
            let mut rng = SplitMix64::stream(3, 0);
            let waves: Vec<(f64, f64, f64)> = (0..12)
                .map(|_| {
                    let j = 1 + (rng.next_u64() % 40) as usize;
                    (j as f64, 0.02 * rng.next_f64(), 2.0 * PI * rng.next_f64())
                })
                .collect();
            let h = (0..nx)
                .map(|i| {
                    let x = i as f64 / nx as f64;
                    waves
                        .iter()
                        .map(|(j, a, p)| a * (2.0 * PI * j * x + p).sin())
                        .sum()
                })
                .collect();
            HeightField::new(nx, 1, pitch, h).unwrap()
        },
    ];
    for field in &profiles {
        let s = surface(field, 400.0, 1e-10);
        for (wavelength, w) in [(400.0, -2.0), (550.0, -1.7), (700.0, -1.2)] {
            let k = k_per_um(wavelength);
            let q_max = PI / field.pitch_um();
            let dq = 0.05 / SIGMA_S_UM;
            let steps = (2.0 * q_max / dq) as usize;
            let integral: f64 = (0..=steps)
                .map(|i| {
                    let q = -q_max + i as f64 * dq;
                    s.transform(wavelength, q / k, 0.0, w).norm_sqr() * dq
                })
                .sum();
            let flat = PI.sqrt() / SIGMA_S_UM;
            let ratio = integral / flat;
            worst = worst.max((ratio - 1.0).abs());
            assert!((ratio - 1.0).abs() < 1e-3, "λ={wavelength}: {ratio}");
        }
    }
    eprintln!("windowed Parseval: max |E − 1| = {worst:.2e}");
}

#[test]
fn flat_mirror_reflects_one_in_the_specular_direction() {
    let field = HeightField::new(256, 256, 0.25, vec![0.37; 256 * 256]).unwrap();
    assert_eq!(field.mean_removed_um(), 0.37);
    assert_eq!(field.max_abs_height_um(), 0.0);
    let s = DiffractionSurface::new(TaylorTerms::compute(&field, 3), 16.0).unwrap();
    for incidence in [0.0, 25.0, 60.0, -40.0] {
        for wavelength in [380.0, 550.0, 780.0] {
            let (wi, wr) = in_plane_directions(incidence, incidence);
            let rho = s.relative_reflectance(wi, wr, wavelength, FresnelTerm::Unity);
            assert!((rho - 1.0).abs() < 1e-12, "{incidence} {wavelength}: {rho}");
            // Three degrees off the specular direction the window has fallen away.
            let (wi, wr) = in_plane_directions(incidence, incidence + 3.0);
            let off = s.relative_reflectance(wi, wr, wavelength, FresnelTerm::Unity);
            assert!(off < 1e-3, "{incidence} {wavelength}: {off}");
        }
    }
    // With a Fresnel term the specular value is the bulk reflectance at θ_i.
    let glass = FresnelTerm::Index(C64::new(1.5, 0.0));
    let (wi, wr) = in_plane_directions(0.0, 0.0);
    let rho = s.relative_reflectance(wi, wr, 550.0, glass);
    assert!((rho - 0.04).abs() < 1e-12, "{rho}");
}

#[test]
fn taylor_bound_and_order() {
    assert_eq!(taylor_remainder_bound(1.0, 0), 1.0);
    assert!((taylor_remainder_bound(2.0, 2) - 8.0 / 6.0).abs() < 1e-15);
    let (n, b) = taylor_order_for(2.3, 1e-4).unwrap();
    assert!(b <= 1e-4 && taylor_remainder_bound(2.3, n - 1) > 1e-4);
    // The bound is a true bound of the phase-factor error.
    for x in [0.3, 1.0, 2.5, 6.0] {
        for order in 0..20 {
            let c = taylor_coefficients(x, order);
            let s: C64 = c
                .iter()
                .enumerate()
                .map(|(n, c)| c * C64::new(0.0, 1.0).powi(n as i32))
                .sum();
            let err = (C64::from_polar(1.0, x) - s).norm();
            assert!(err <= taylor_remainder_bound(x, order) * (1.0 + 1e-12) + 1e-15);
        }
    }
    assert!(matches!(
        taylor_order_for(200.0, 1e-6),
        Err(Error::TaylorOrder { .. })
    ));
    assert!(taylor_order_for(1.0, 0.0).is_err());
}

#[test]
fn dft_terms_match_direct_sums_and_are_dc_centred() {
    let field = HeightField::random_bumps(12, 10, 0.3, 0.5, 0.05, 0.4, 9).unwrap();
    let terms = TaylorTerms::compute(&field, 3);
    assert_eq!(terms.bin(0, 0, 0), Some(C64::new(1.0, 0.0)));
    assert!(terms.bin(1, 0, 0).unwrap().norm() < 1e-15); // mean removed
    let h = field.heights_um();
    for n in 0..=3usize {
        for (jx, jy) in [(1i64, 0i64), (-3, 2), (5, -5), (-6, 4)] {
            let mut direct = C64::new(0.0, 0.0);
            for y in 0..10 {
                for x in 0..12 {
                    let phase =
                        2.0 * PI * (jx as f64 * x as f64 / 12.0 + jy as f64 * y as f64 / 10.0);
                    direct +=
                        C64::new(0.0, h[y * 12 + x]).powi(n as i32) * C64::from_polar(1.0, phase);
                }
            }
            direct /= 120.0;
            let t = terms.bin(n, jx, jy).unwrap();
            assert!(
                (t - direct).norm() < 1e-15,
                "n={n} ({jx},{jy}): {t} vs {direct}"
            );
        }
    }
    assert_eq!(terms.bin(0, 6, 0), None);
    assert_eq!(terms.bin(0, 0, -6), None);
}

#[test]
fn generators_are_deterministic_and_shaped() {
    let a = HeightField::cd_tracks(256, 256, 0.125, CD_PIT_DEPTH_UM, 1).unwrap();
    let b = HeightField::cd_tracks(256, 256, 0.125, CD_PIT_DEPTH_UM, 1).unwrap();
    let c = HeightField::cd_tracks(256, 256, 0.125, CD_PIT_DEPTH_UM, 2).unwrap();
    assert_eq!(a, b);
    assert_ne!(a, c);
    // Pits go down by at most the depth; lands sit at the top.
    let max = a.heights_um().iter().fold(f64::MIN, |m, h| m.max(*h));
    let min = a.heights_um().iter().fold(f64::MAX, |m, h| m.min(*h));
    assert!((max - min - CD_PIT_DEPTH_UM).abs() < 1e-12, "{max} {min}");
    // The tracks are 1.6 µm apart: the x power spectrum peaks at j = L/1.6 = 20.
    let t = TaylorTerms::compute(&a, 1);
    let power = |j: i64| t.bin(1, j, 0).unwrap().norm_sqr();
    assert!((1..40).filter(|&j| j != 20).all(|j| power(j) < power(20)));
    let blazed = HeightField::blazed_grating(2.0, 0.2, 0.1, 40).unwrap();
    let h = blazed.heights_um();
    assert!((h[1] - h[0] - 0.01).abs() < 1e-12 && h[20] < h[19]);
    let sine = HeightField::sine_grating(1.0, 0.1, 0.05, 40).unwrap();
    assert!((sine.max_abs_height_um() - 0.1).abs() < 1e-12);
    assert!(HeightField::sine_grating(0.0, 0.1, 0.05, 40).is_err());
    assert!(HeightField::new(2, 2, 0.1, vec![0.0, f64::NAN, 0.0, 0.0]).is_err());
    assert!(HeightField::new(2, 2, 0.1, vec![0.0; 3]).is_err());
}

#[test]
fn sampling_checks_name_the_limits() {
    let field = HeightField::cd_tracks(256, 256, 0.125, CD_PIT_DEPTH_UM, 1).unwrap();
    let s = DiffractionSurface::new(TaylorTerms::compute(&field, 2), 8.0).unwrap();
    s.check_sampling(380.0, 1.5).unwrap();
    assert!(matches!(
        s.check_sampling(380.0, 2.0),
        Err(Error::NyquistExceeded { .. })
    ));
    let s = DiffractionSurface::new(TaylorTerms::compute(&field, 2), SIGMA_S_UM).unwrap();
    assert!(matches!(
        s.check_sampling(380.0, 1.0),
        Err(Error::PatchTooSmall { .. })
    ));
}

#[test]
fn white_spectrum_is_white() {
    let c = Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    );
    let wl: Vec<f64> = (0..=80).map(|i| 380.0 + 5.0 * f64::from(i)).collect();
    let grid = SpectralGrid::new(&c, &wl).unwrap();
    let xyz = grid.xyz(&vec![1.0; wl.len()]);
    let rgb = c.output_from_xyz(xyz);
    for v in rgb {
        assert!((v - 1.0).abs() < 1e-12, "{rgb:?}");
    }
    assert!(SpectralGrid::new(&c, &[300.0, 400.0]).is_err());
}

fn srgb_grid(step_nm: f64) -> (Colorimeter, SpectralGrid) {
    let c = Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    );
    let count = ((780.0 - 380.0) / step_nm).round() as usize;
    let wl: Vec<f64> = (0..=count).map(|i| 380.0 + step_nm * i as f64).collect();
    let grid = SpectralGrid::new(&c, &wl).unwrap();
    (c, grid)
}

#[test]
fn warped_axis_round_trips_and_packs_texels_near_zero() {
    use super::integrated::WarpedAxis;
    let a = WarpedAxis::new(1.4, 3.0, 64).unwrap();
    for i in 0..64 {
        let u = a.texel_centre(i);
        assert!((a.coordinate(u) - i as f64).abs() < 1e-9, "{i}");
        // Point symmetric about the middle of the axis.
        assert!((u + a.texel_centre(63 - i)).abs() < 1e-15);
    }
    // The spacing grows away from u = 0; the ends clamp.
    let gap = |i: usize| a.texel_centre(i + 1) - a.texel_centre(i);
    assert!(gap(32) < 2e-4 && gap(62) > 0.1 && gap(32) < gap(40));
    assert_eq!(a.coordinate(5.0), 63.0);
    assert_eq!(a.coordinate(-5.0), 0.0);
    assert!(WarpedAxis::new(1.4, 3.0, 63).is_err());
    assert!(WarpedAxis::new(1.4, 0.5, 64).is_err());
    assert!(WarpedAxis::new(0.0, 3.0, 64).is_err());
    assert!(WarpedAxis::new(1.4, 3.0, 1 << 20).is_err());
}

/// M Σ_λ u(λ) |P̃(λ)|², the colour of the terms layout without C, in the output space.
fn exact_sum(
    s: &DiffractionSurface,
    c: &Colorimeter,
    grid: &SpectralGrid,
    u: f64,
    v: f64,
    w: f64,
) -> [f64; 3] {
    let p2: Vec<f64> = grid
        .wavelengths_nm()
        .iter()
        .map(|&l| s.transform(l, u, v, w).norm_sqr())
        .collect();
    c.output_from_xyz(grid.xyz(&p2))
}

#[test]
fn integrated_table_is_the_terms_colour_at_texel_centres_on_both_halves() {
    use super::integrated::{IntegratedTable, WarpedAxis};
    // A 2-D field (the y contraction matters) and a grating; the f32 table against the f64
    // sum, at texel centres (no interpolation), u ≥ 0 stored and u < 0 by the fold.
    let (c, grid) = srgb_grid(20.0);
    let fields = [
        (
            HeightField::random_bumps(64, 64, 0.125, 0.6, 0.06, 0.5, 4).unwrap(),
            2.0,
        ),
        (grating("sine", 1.6, 0.05), 4.0),
    ];
    for (field, sigma) in fields {
        let (order, _) = taylor_order_for(max_phase(&field, 380.0, 2.0), 1e-6).unwrap();
        let s = DiffractionSurface::new(TaylorTerms::compute(&field, order), sigma).unwrap();
        let axis = WarpedAxis::new(1.2, 3.0, 24).unwrap();
        let t = IntegratedTable::compute(&s, &grid, &c, axis, None);
        assert_eq!(t.layers(), 2 * order + 1);
        assert_eq!(t.size(), (12, 24));
        let mut worst: f64 = 0.0;
        for iu in [0, 3, 7, 12, 16, 20, 23] {
            for iv in [0, 5, 11, 12, 18, 23] {
                let (u, v) = (axis.texel_centre(iu), axis.texel_centre(iv));
                for w in [-2.0, -1.6] {
                    let exact = exact_sum(&s, &c, &grid, u, v, w);
                    let fast = t.sum_at(u, v, w);
                    for ch in 0..3 {
                        worst = worst.max((fast[ch] - exact[ch]).abs());
                    }
                }
            }
        }
        assert!(worst < 1e-5, "{worst}");
        // The specular direction u = v = 0 clamps onto column 0, whose centre lies at
        // u_max n^(−γ) = 8.7e-5: within 1e-4 of the lobe's top.
        let spec = t.sum_at(0.0, 0.0, -2.0);
        let exact = exact_sum(&s, &c, &grid, 0.0, 0.0, -2.0);
        for ch in 0..3 {
            assert!((spec[ch] - exact[ch]).abs() < 1e-4, "{spec:?} {exact:?}");
        }
    }
}

#[test]
fn integrated_table_with_k_squared_is_the_weighted_terms_colour() {
    use super::integrated::{IntegratedTable, K_SQUARED_REFERENCE_NM, WarpedAxis};
    // Issue 37: a table summed with Stam's k² holds Σ_λ (λ_ref/λ)² u |P̃|², the colour the
    // terms technique gives with its (λ_ref/λ)² weight, not Σ_λ u |P̃|²; the zeroth-order
    // layers stay unweighted (the mirror image's efficiency has no k²).
    let (c, grid) = srgb_grid(20.0);
    let field = grating("sine", 1.6, 0.05);
    let (order, _) = taylor_order_for(max_phase(&field, 380.0, 2.0), 1e-6).unwrap();
    let s = DiffractionSurface::new(TaylorTerms::compute(&field, order), 4.0).unwrap();
    let axis = WarpedAxis::new(1.2, 3.0, 24).unwrap();
    let reference = K_SQUARED_REFERENCE_NM;
    let t = IntegratedTable::compute(&s, &grid, &c, axis, Some(reference));
    let plain = IntegratedTable::compute(&s, &grid, &c, axis, None);
    assert_eq!(
        (t.k_squared_reference_nm(), plain.k_squared_reference_nm()),
        (Some(reference), None)
    );
    let weighted_sum = |u: f64, v: f64, w: f64| {
        let p2: Vec<f64> = grid
            .wavelengths_nm()
            .iter()
            .map(|&l| (reference / l).powi(2) * s.transform(l, u, v, w).norm_sqr())
            .collect();
        c.output_from_xyz(grid.xyz(&p2))
    };
    let (mut worst, mut tilt_blue, mut tilt_red) = (0.0f64, 0.0f64, 0.0f64);
    for iu in [12, 14, 16, 20, 23] {
        for iv in [0, 5, 11, 12, 18, 23] {
            let (u, v) = (axis.texel_centre(iu), axis.texel_centre(iv));
            for w in [-2.0, -1.6] {
                let want = weighted_sum(u, v, w);
                let got = t.sum_at(u, v, w);
                let old = plain.sum_at(u, v, w);
                for ch in 0..3 {
                    worst = worst.max((got[ch] - want[ch]).abs());
                }
                if old[2] > 1e-3 && old[0] > 1e-3 {
                    tilt_blue = tilt_blue.max(got[2] / old[2]);
                    tilt_red = tilt_red.max(old[0] / got[0]);
                }
            }
        }
    }
    eprintln!(
        "k² table vs weighted terms colour: {worst:.2e}; blue ×{tilt_blue:.3}, red ÷{tilt_red:.3} against the table without k²"
    );
    assert!(worst < 1e-5, "{worst}");
    // The weight is what separates them: blue gains, red loses (a table without it is off).
    assert!(tilt_blue > 1.1 && tilt_red > 1.05, "{tilt_blue} {tilt_red}");
    // The zeroth order's layers: the unweighted colour of |P̃(0, 0)|², the same with or
    // without k², and that of the unweighted table's peak.
    assert_eq!(t.specular_layers(), plain.specular_layers());
    for w in [-2.0, -1.5] {
        let exact = exact_sum(&s, &c, &grid, 0.0, 0.0, w);
        let (spec, peak) = (t.specular_sum(w), plain.sum_at(0.0, 0.0, w));
        for ch in 0..3 {
            assert!((spec[ch] - exact[ch]).abs() < 1e-5, "{spec:?} {exact:?}");
            assert!((spec[ch] - peak[ch]).abs() < 1e-4, "{spec:?} {peak:?}");
        }
    }
    // A table read back without the field (an older bake) takes its peak as its zeroth
    // order, and one marked with it keeps the recorded layers.
    let old = IntegratedTable::from_values(axis, order, plain.values().to_vec()).unwrap();
    assert_eq!(old.k_squared_reference_nm(), None);
    for w in [-2.0f64, -1.7] {
        assert_eq!(old.specular_sum(w), old.sum_at(0.0, 0.0, w));
    }
    let marked = IntegratedTable::from_values(axis, order, t.values().to_vec())
        .unwrap()
        .with_k_squared(reference, t.specular_layers().to_vec())
        .unwrap();
    assert_eq!(marked, t);
    for bad in [0.0, -555.0, f64::NAN, f64::INFINITY] {
        assert!(
            old.clone()
                .with_k_squared(bad, t.specular_layers().to_vec())
                .is_err()
        );
    }
    assert!(
        old.clone()
            .with_k_squared(555.0, vec![[0.0; 3]; 2])
            .is_err()
    );
}

#[test]
fn integrated_sine_grating_reconstructs_the_terms_colour_within_tolerance() {
    use super::integrated::{IntegratedTable, WarpedAxis, check_directions};
    let (c, grid) = srgb_grid(10.0);
    let field = HeightField::sine_grating(1.6, 0.05, 0.1, 160).unwrap();
    let (order, _) = taylor_order_for(max_phase(&field, 380.0, 2.0), 1e-4).unwrap();
    let s = DiffractionSurface::new(TaylorTerms::compute(&field, order), 4.0).unwrap();
    let max_angle: f64 = 30.0;
    let axis = WarpedAxis::new(2.0 * max_angle.to_radians().sin(), 3.0, 256).unwrap();
    let t = IntegratedTable::compute(&s, &grid, &c, axis, None);
    let pairs = check_directions(max_angle);
    assert!(pairs.len() > 2000 && pairs.iter().any(|(_, r)| r[1].abs() > 0.1));
    let e = t.reconstruction_error(&s, &grid, &c, &pairs);
    eprintln!(
        "sine grating, integrated 128 x 256 x {}: max error {:.2e} (mean {:.2e}) of the white",
        t.layers(),
        e.max_error,
        e.mean_error
    );
    assert!(e.max_error < 1e-2, "{e:?}");
    // Coarser tables err more: the metric sees interpolation.
    let coarse = IntegratedTable::compute(&s, &grid, &c, WarpedAxis { count: 16, ..axis }, None);
    let ec = coarse.reconstruction_error(&s, &grid, &c, &pairs);
    assert!(ec.max_error > 5.0 * e.max_error, "{ec:?}");
}

#[test]
fn f32_storage_cancels_for_tall_structures_only() {
    use super::integrated::{IntegratedTable, WarpedAxis};
    // max |kwh| at 380 nm, |w| = 2: 2.6 for the 0.1 µm-deep-like blazed profile, 16.5 for 1 µm.
    let (c, grid) = srgb_grid(20.0);
    let mut errors = Vec::new();
    for height in [0.16, 1.0] {
        let field = HeightField::blazed_grating(2.5, height, 2.5 / 48.0, 48 * 7).unwrap();
        let x = max_phase(&field, 380.0, 2.0);
        let (order, _) = taylor_order_for(x, 1e-4).unwrap();
        let s = DiffractionSurface::new(TaylorTerms::compute(&field, order), 4.0).unwrap();
        let t =
            IntegratedTable::compute(&s, &grid, &c, WarpedAxis::new(1.0, 3.0, 16).unwrap(), None);
        let e = t.storage_error(&s, &grid, &c, 1, -1.7);
        eprintln!("blazed {height} µm: max |kwh| = {x:.2}, N = {order}, f32 storage error {e:.2e}");
        errors.push(e);
    }
    assert!(errors[0] < 1e-5, "{errors:?}");
    assert!(errors[1] > 1.0, "{errors:?}");
}

/// A table of order `order` whose layer p holds `f(p, u, v)` at the texel centres.
fn integrated_from_fn(
    axis: super::integrated::WarpedAxis,
    order: usize,
    f: impl Fn(usize, f64, f64) -> f64,
) -> super::integrated::IntegratedTable {
    let n = axis.count;
    let half = n / 2;
    let mut values = Vec::new();
    for p in 0..2 * order + 1 {
        for iv in 0..n {
            for c in 0..half {
                let x = f(p, axis.texel_centre(half + c), axis.texel_centre(iv)) as f32;
                values.push([x, 0.5 * x, -x]);
            }
        }
    }
    super::integrated::IntegratedTable::from_values(axis, order, values).unwrap()
}

/// A normalised 2-D Gaussian of variance s2 per axis centred at (u0, v0).
fn bump(u: f64, v: f64, u0: f64, v0: f64, s2: f64) -> f64 {
    let d2 = (u - u0) * (u - u0) + (v - v0) * (v - v0);
    (-0.5 * d2 / s2).exp() / (2.0 * std::f64::consts::PI * s2)
}

#[test]
fn integrated_blur_is_a_gaussian_in_uv_on_both_halves_and_warped_axes() {
    use super::integrated::WarpedAxis;
    // Layer 0: a bump at (0.3, 0.1) and its point twin at (−0.3, −0.1) (even p); layer 1:
    // a bump at (0.02, 0.2) minus its twin at (−0.02, −0.2) (odd p: Iₚ(−u, −v) = −Iₚ(u, v)),
    // whose blur reaches across u = 0 into the folded half. A Gaussian of variance s0²
    // blurred by σ² is the Gaussian of variance s0² + σ² with the same mass.
    let (s0, sigma) = (0.05f64, 0.04f64);
    let even = |u: f64, v: f64, s2: f64| bump(u, v, 0.3, 0.1, s2) + bump(u, v, -0.3, -0.1, s2);
    let odd = |u: f64, v: f64, s2: f64| bump(u, v, 0.02, 0.2, s2) - bump(u, v, -0.02, -0.2, s2);
    let layer = |p: usize, u: f64, v: f64, s2: f64| match p {
        0 => even(u, v, s2),
        1 => odd(u, v, s2),
        _ => 0.0,
    };
    for gamma in [1.0, 2.0] {
        let axis = WarpedAxis::new(1.0, gamma, 256).unwrap();
        let table = integrated_from_fn(axis, 1, |p, u, v| layer(p, u, v, s0 * s0));
        let blurred = table.blurred(sigma);
        let s2 = s0 * s0 + sigma * sigma;
        let peak = bump(0.0, 0.0, 0.0, 0.0, s2);
        let mut worst: f64 = 0.0;
        for c in (0..128).step_by(3) {
            for iv in (0..256).step_by(5) {
                let (u, v) = (axis.texel_centre(128 + c), axis.texel_centre(iv));
                for p in 0..2 {
                    let want = layer(p, u, v, s2);
                    let got = f64::from(blurred.texel(p, c, iv)[0]);
                    worst = worst.max((got - want).abs() / peak);
                }
            }
        }
        eprintln!("γ = {gamma}: blurred bumps within {worst:.2e} of the peak");
        assert!(worst < 0.01, "γ = {gamma}: {worst}");
        // σ = 0 is the table itself.
        assert_eq!(table.blurred(0.0), table);
    }
}

#[test]
fn integrated_levels_interpolate_in_sigma_squared_and_start_at_the_table() {
    use super::integrated::{IntegratedLevels, WarpedAxis};
    let axis = WarpedAxis::new(1.0, 3.0, 256).unwrap();
    let s0 = 0.03f64;
    let table = integrated_from_fn(axis, 0, |_, u, v| {
        bump(u, v, 0.4, 0.0, s0 * s0) + bump(u, v, -0.4, 0.0, s0 * s0)
    });
    let levels = IntegratedLevels::new(&table, 6).unwrap();
    assert_eq!(levels.levels().len(), 6);
    assert_eq!(levels.sigma(5), 1.0);
    assert_eq!(levels.sigma(1), 1.0 / 16.0);
    // σ² = 0 reads the table exactly.
    for (u, v, w) in [(0.4, 0.0, -2.0), (0.1, -0.3, -1.5), (-0.4, 0.02, -1.8)] {
        assert_eq!(levels.sum_filtered(u, v, w, 0.0), table.sum_at(u, v, w));
    }
    // (ℓ, t): level pairs bracket σ², t linear in σ² and clamped above the last level.
    let b = levels.sigma_base_sq_f32();
    assert_eq!(IntegratedLevels::level_weights(0.5 * b, b, 6), (0, 0.5));
    assert_eq!(IntegratedLevels::level_weights(b, b, 6), (0, 1.0));
    assert_eq!(IntegratedLevels::level_weights(2.5 * b, b, 6), (1, 0.5));
    assert_eq!(IntegratedLevels::level_weights(1e3, b, 6), (4, 1.0));
    assert_eq!(IntegratedLevels::level_weights(f32::NAN, b, 6), (0, 0.0));
    assert_eq!(IntegratedLevels::level_weights(1.0, b, 1), (0, 0.0));
    // Continuous across a level boundary, and the peak falls as the spread grows, with the
    // mass of a Gaussian of variance s0² + σ² (the peak ∝ 1/(s0² + σ²)).
    let at = |s2: f32| levels.sum_filtered(0.4, 0.0, -2.0, s2)[0];
    let edge = 4.0 * b;
    assert!((at(edge * (1.0 - 1e-6)) - at(edge * (1.0 + 1e-6))).abs() < 1e-3 * at(edge));
    for s2 in [b, 4.0 * b, 16.0 * b] {
        let want = bump(0.0, 0.0, 0.0, 0.0, s0 * s0 + f64::from(s2));
        assert!(
            (at(s2) / want - 1.0).abs() < 0.02,
            "σ² {s2}: {} vs {want}",
            at(s2)
        );
    }
}
