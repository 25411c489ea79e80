//! Exact derivatives of the stack's powers (`nacre_optics::jacobian`) against central
//! finite differences and against forward-mode dual numbers, over random stacks: absorbing
//! films and substrates, dispersive films, total internal reflection and grazing incidence;
//! and the energy law ∂R + ∂T = 0 of lossless stacks.

use nacre_optics::colour::{
    Colorimeter, Illuminant, Observer, OutputSpace, delta_e_2000, xyz_to_lab,
};
use nacre_optics::fresnel::{normal_component, power_factor_p, power_factor_s};
use nacre_optics::jacobian::{
    ColourJacobian, PointJacobian, Wrt, colour_jacobian, delta_e_2000_gradient,
    delta_e_2000_param_gradient, lab_jacobian, point_jacobian, sweep_jacobian,
};
use nacre_optics::{C64, Layer, Material, Power, Stack};
use proptest::prelude::*;

/// Largest relative error allowed: |exact − check| ≤ 10⁻⁷ · the largest |derivative| of
/// the same output over the parameters (the Jacobian row's scale, at least [`FLOOR`]; a
/// single derivative can cross zero).
const TOL: f64 = 1e-7;
/// The smallest row scale: where every derivative of an output vanishes (a film of the
/// ambient's index), the differences' rounding (~10⁻¹⁶) is compared with 10⁻⁶.
const FLOOR: f64 = 1e-6;
/// The finite differences' own rounding, times the step: powers (≤ 1) carry ~ε of rounding
/// and the stencils' coefficients sum to ≤ 11, so a difference quotient with step h is no
/// better than 16 ε/h (2 × 10⁻⁹ for the one-sided index step 2 × 10⁻⁶); where a row's
/// derivatives are all small (grazing incidence) that exceeds 10⁻⁷ of them. The dual
/// numbers have no such floor and are held to [`TOL`] alone.
const FD_NOISE_TIMES_STEP: f64 = 16.0 * f64::EPSILON;

fn medium(n: f64, k: f64) -> Material {
    Material::constant(format!("{n}+{k}i"), C64::new(n, k)).unwrap()
}

fn parts(p: &Power) -> [f64; 4] {
    [p.R_s, p.R_p, p.T_s, p.T_p]
}

/// A complex dual number: value and derivative by one real parameter.
#[derive(Clone, Copy)]
struct D(C64, C64);

impl D {
    fn c(v: C64) -> D {
        D(v, C64::new(0.0, 0.0))
    }
    fn add(self, o: D) -> D {
        D(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: D) -> D {
        D(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: D) -> D {
        D(self.0 * o.0, self.1 * o.0 + self.0 * o.1)
    }
    fn div(self, o: D) -> D {
        let v = self.0 / o.0;
        D(v, (self.1 - v * o.1) / o.0)
    }
    fn scale(self, s: C64) -> D {
        D(self.0 * s, self.1 * s)
    }
    /// e^{iz}.
    fn exp_i(self) -> D {
        let e = (C64::new(0.0, 1.0) * self.0).exp();
        D(e, e * C64::new(0.0, 1.0) * self.1)
    }
}

/// Parameter of a dual-number evaluation: film j's thickness, Re ñ_j or Im ñ_j.
#[derive(Clone, Copy, PartialEq)]
enum Param {
    Thickness(usize),
    Re(usize),
    Im(usize),
}

/// The powers' derivatives by `param` through the recurrence in complex dual numbers
/// (forward mode, written independently of the library's adjoint sweep).
fn dual_derivative(
    indices: &[C64],
    thickness_nm: &[f64],
    sin_theta: f64,
    wavelength_nm: f64,
    param: Param,
) -> [f64; 4] {
    let n_films = thickness_nm.len();
    let beta = indices[0].re * sin_theta;
    let k0 = 2.0 * std::f64::consts::PI / wavelength_nm;
    let idx: Vec<D> = indices
        .iter()
        .enumerate()
        .map(|(j, &n)| match param {
            Param::Re(f) if f + 1 == j => D(n, C64::new(1.0, 0.0)),
            Param::Im(f) if f + 1 == j => D(n, C64::new(0.0, 1.0)),
            _ => D::c(n),
        })
        .collect();
    let q: Vec<D> = idx
        .iter()
        .map(|n| {
            let v = normal_component(n.0, beta);
            // q² = ñ² − β²: 2q q' = 2ñ ñ'.
            D(v, n.0 * n.1 / v)
        })
        .collect();
    let d: Vec<D> = thickness_nm
        .iter()
        .enumerate()
        .map(|(j, &t)| {
            let dt = if param == Param::Thickness(j) {
                1.0
            } else {
                0.0
            };
            D(C64::new(t, 0.0), C64::new(dt, 0.0))
        })
        .collect();
    let two = D::c(C64::new(2.0, 0.0));
    let one = D::c(C64::new(1.0, 0.0));
    let mut out = [0.0; 4];
    for pol in 0..2 {
        let coeffs = |j: usize| {
            let (ni, nj, qi, qj) = (idx[j], idx[j + 1], q[j], q[j + 1]);
            if pol == 0 {
                let s = qi.add(qj);
                (qi.sub(qj).div(s), two.mul(qi).div(s))
            } else {
                let a = nj.mul(nj).mul(qi);
                let b = ni.mul(ni).mul(qj);
                let s = a.add(b);
                (a.sub(b).div(s), two.mul(ni).mul(nj).mul(qi).div(s))
            }
        };
        let (mut gamma, mut tau) = coeffs(n_films);
        for j in (0..n_films).rev() {
            let (r, t) = coeffs(j);
            let e = q[j + 1].mul(d[j]).scale(C64::new(k0, 0.0)).exp_i();
            let g = gamma.mul(e).mul(e);
            let den = one.add(r.mul(g));
            gamma = r.add(g).div(den);
            tau = t.mul(tau).mul(e).div(den);
        }
        let last = indices.len() - 1;
        let factor = if pol == 0 {
            power_factor_s(q[0].0, q[last].0)
        } else {
            power_factor_p(indices[0], q[0].0, indices[last], q[last].0)
        };
        out[pol] = 2.0 * (gamma.0.conj() * gamma.1).re;
        out[2 + pol] = 2.0 * (tau.0.conj() * tau.1).re * factor;
    }
    out
}

/// The powers by the library's scalar recurrence (`Stack::evaluate`) at the given indices.
fn powers_at(
    indices: &[C64],
    thickness_nm: &[f64],
    angle_deg: f64,
    wavelength_nm: f64,
) -> [f64; 4] {
    let layers = thickness_nm
        .iter()
        .zip(&indices[1..])
        .map(|(&d, &n)| Layer {
            material: Material::constant("f", n).unwrap(),
            thickness_nm: d,
        })
        .collect();
    let stack = Stack::new(
        Material::constant("a", indices[0]).unwrap(),
        layers,
        Material::constant("s", indices[indices.len() - 1]).unwrap(),
    )
    .unwrap();
    parts(&stack.evaluate(angle_deg, wavelength_nm).unwrap().power)
}

/// Fourth-order central difference of the powers by `param` with step h (one-sided near
/// κ = 0).
fn central(
    indices: &[C64],
    thickness_nm: &[f64],
    angle_deg: f64,
    wavelength_nm: f64,
    param: Param,
    h: f64,
) -> [f64; 4] {
    let shifted = |step: f64| {
        let mut idx = indices.to_vec();
        let mut d = thickness_nm.to_vec();
        match param {
            Param::Thickness(j) => d[j] += step,
            Param::Re(j) => idx[j + 1].re += step,
            Param::Im(j) => idx[j + 1].im += step,
        }
        powers_at(&idx, &d, angle_deg, wavelength_nm)
    };
    if let Param::Im(j) = param
        && indices[j + 1].im < 4.0 * h
    {
        // κ ≥ 0 only: the one-sided fourth-order difference
        // (−25f₀ + 48f₁ − 36f₂ + 16f₃ − 3f₄)/(12h).
        // A fifth of the central step: one-sided stencils reach 4h, and the error constant is
        // larger.
        let h = h / 5.0;
        let f: Vec<[f64; 4]> = (0..5).map(|i| shifted(i as f64 * h)).collect();
        return std::array::from_fn(|k| {
            (-25.0 * f[0][k] + 48.0 * f[1][k] - 36.0 * f[2][k] + 16.0 * f[3][k] - 3.0 * f[4][k])
                / (12.0 * h)
        });
    }
    // The fourth-order central difference (8(f₁ − f₋₁) − (f₂ − f₋₂))/(12h).
    let f: Vec<[f64; 4]> = [-2.0, -1.0, 1.0, 2.0]
        .iter()
        .map(|&i| shifted(i * h))
        .collect();
    std::array::from_fn(|k| (8.0 * (f[2][k] - f[1][k]) - (f[3][k] - f[0][k])) / (12.0 * h))
}

/// Compares `exact` (per parameter) with `check` (per parameter) output by output, relative
/// to the largest |derivative| of each output, after forgiving `noise[p]` of absolute
/// difference for parameter p; returns the worst relative error.
fn worst_error(exact: &[[f64; 4]], check: &[[f64; 4]], noise: &[f64]) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..4 {
        let scale = exact.iter().map(|e| e[k].abs()).fold(FLOOR, f64::max);
        for ((e, c), noise) in exact.iter().zip(check).zip(noise) {
            worst = worst.max(((e[k] - c[k]).abs() - noise).max(0.0) / scale);
        }
    }
    worst
}

/// Every parameter of a point Jacobian, in the order thickness, Re ñ, Im ñ per film.
fn params(films: usize) -> Vec<Param> {
    (0..films)
        .flat_map(|j| [Param::Thickness(j), Param::Re(j), Param::Im(j)])
        .collect()
}

fn exact_of(j: &PointJacobian, p: Param) -> [f64; 4] {
    match p {
        Param::Thickness(f) => parts(&j.d_thickness[f]),
        Param::Re(f) => parts(&j.d_index_re[f]),
        Param::Im(f) => parts(&j.d_index_im[f]),
    }
}

/// A random case: (n₀, films (n, κ, d), substrate (n, κ), angle, wavelength).
type Case = (f64, Vec<(f64, f64, f64)>, (f64, f64), f64, f64);

fn check_case((n0, films, (ns, ks), angle, wl): Case) -> Result<(f64, f64), TestCaseError> {
    let mut indices = vec![C64::new(n0, 0.0)];
    indices.extend(films.iter().map(|&(n, k, _)| C64::new(n, k)));
    indices.push(C64::new(ns, ks));
    let d: Vec<f64> = films.iter().map(|f| f.2).collect();
    let sin_theta = nacre_optics::elementary::sin(angle.to_radians());
    let jac = point_jacobian(&indices, &d, sin_theta, wl, Wrt::ThicknessAndIndex);
    // The powers are those of the scalar recurrence.
    prop_assert_eq!(parts(&jac.power), powers_at(&indices, &d, angle, wl));
    let ps = params(d.len());
    let exact: Vec<[f64; 4]> = ps.iter().map(|&p| exact_of(&jac, p)).collect();
    let dual: Vec<[f64; 4]> = ps
        .iter()
        .map(|&p| dual_derivative(&indices, &d, sin_theta, wl, p))
        .collect();
    let steps: Vec<f64> = ps
        .iter()
        .map(|&p| match p {
            Param::Thickness(_) => 1e-2,
            // The one-sided stencil near κ = 0 takes a fifth of the step (`central`).
            Param::Im(j) if indices[j + 1].im < 4e-5 => 2e-6,
            _ => 1e-5,
        })
        .collect();
    let fd: Vec<[f64; 4]> = ps
        .iter()
        .map(|&p| {
            let h = if matches!(p, Param::Thickness(_)) {
                1e-2
            } else {
                1e-5
            };
            central(&indices, &d, angle, wl, p, h)
        })
        .collect();
    let noise: Vec<f64> = steps.iter().map(|h| FD_NOISE_TIMES_STEP / h).collect();
    let (e_dual, e_fd) = (
        worst_error(&exact, &dual, &vec![0.0; ps.len()]),
        worst_error(&exact, &fd, &noise),
    );
    prop_assert!(
        e_dual <= TOL,
        "dual numbers: relative error {e_dual:e}\n{exact:?}\n{dual:?}"
    );
    prop_assert!(
        e_fd <= TOL,
        "finite differences: relative error {e_fd:e}\n{exact:?}\n{fd:?}"
    );
    // Reported: the raw worst error, nothing forgiven.
    Ok((e_dual, worst_error(&exact, &fd, &vec![0.0; ps.len()])))
}

fn any_film() -> impl Strategy<Value = (f64, f64, f64)> {
    (
        1.0..3.0f64,
        prop_oneof![Just(0.0), 0.0..2.0f64],
        1.0..800.0f64,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Absorbing or lossless films and substrates, normal to grazing incidence, and total
    /// internal reflection (ambient index up to 2 over a substrate of index down to 1).
    #[test]
    fn derivatives_match_dual_numbers_and_finite_differences(
        n0 in 1.0..2.0f64,
        films in prop::collection::vec(any_film(), 1..6),
        sub in (1.0..4.0f64, prop_oneof![Just(0.0), 0.0..4.0f64]),
        angle in prop_oneof![0.0..80.0f64, 80.0..89.9f64],
        wl in 380.0..780.0f64,
    ) {
        check_case((n0, films, sub, angle, wl))?;
    }

    /// Lossless stacks conserve energy, so ∂R + ∂T = 0 per polarisation for every
    /// thickness and every real index (also beyond the critical angle).
    #[test]
    fn lossless_derivatives_conserve_energy(
        n0 in 1.0..2.0f64,
        films in prop::collection::vec((1.0..3.0f64, 0.0..2000.0f64), 1..8),
        ns in 1.0..4.0f64,
        angle in 0.0..89.9f64,
        wl in 380.0..780.0f64,
    ) {
        let mut indices = vec![C64::new(n0, 0.0)];
        indices.extend(films.iter().map(|&(n, _)| C64::new(n, 0.0)));
        indices.push(C64::new(ns, 0.0));
        let d: Vec<f64> = films.iter().map(|f| f.1).collect();
        let sin_theta = nacre_optics::elementary::sin(angle.to_radians());
        let jac = point_jacobian(&indices, &d, sin_theta, wl, Wrt::ThicknessAndIndex);
        for p in jac.d_thickness.iter().chain(&jac.d_index_re) {
            let scale = 1.0 + p.R_s.abs().max(p.R_p.abs());
            prop_assert!((p.R_s + p.T_s).abs() <= 1e-10 * scale, "{p:?}");
            prop_assert!((p.R_p + p.T_p).abs() <= 1e-10 * scale, "{p:?}");
        }
    }
}

/// Fixed regimes, with the worst errors printed: total internal reflection with an
/// evanescent substrate, grazing incidence on a metal, and an 8-film absorbing stack.
#[test]
fn named_regimes_match() {
    let cases: Vec<Case> = vec![
        (
            1.5,
            vec![(1.38, 0.0, 120.0), (2.3, 0.0, 60.0)],
            (1.0, 0.0),
            60.0,
            550.0,
        ),
        (1.0, vec![(1.46, 0.0, 300.0)], (0.2, 3.4), 89.5, 500.0),
        (
            1.0,
            (0..8)
                .map(|j| {
                    (
                        1.4 + 0.1 * j as f64,
                        0.05 * j as f64,
                        50.0 + 37.0 * j as f64,
                    )
                })
                .collect(),
            (3.9, 0.02),
            35.0,
            620.0,
        ),
    ];
    for case in cases {
        let (dual, fd) = check_case(case).unwrap();
        println!("worst relative error: dual numbers {dual:.2e}, central differences {fd:.2e}");
    }
}

/// The sweep runs the point Jacobian at every element (angle-major), with a dispersive
/// film, and its powers are those of `Stack::sweep` to 10⁻¹²; the same bits whatever the
/// thread count.
#[test]
fn sweep_matches_points_with_dispersion() {
    let csv = "wavelength_nm,n,k\n300,2.6,0.3\n500,2.4,0.05\n700,2.3,0.0\n900,2.25,0.0\n";
    let tio2 = Material::from_nk_csv("tio2", "tio2.csv", csv).unwrap();
    let stack = Stack::new(
        medium(1.0, 0.0),
        vec![
            Layer {
                material: tio2.clone(),
                thickness_nm: 110.0,
            },
            Layer {
                material: medium(1.46, 0.0),
                thickness_nm: 180.0,
            },
            Layer {
                material: tio2,
                thickness_nm: 70.0,
            },
        ],
        medium(1.52, 0.0),
    )
    .unwrap();
    let angles = [0.0, 30.0, 70.0];
    let wavelengths: Vec<f64> = (0..300).map(|i| 400.0 + i as f64 * 1.3).collect();
    let sweep = sweep_jacobian(&stack, &angles, &wavelengths, Wrt::ThicknessAndIndex).unwrap();
    let values = stack.sweep(&angles, &wavelengths).unwrap();
    let films = 3;
    for (a, &angle) in angles.iter().enumerate() {
        let sin_theta = nacre_optics::elementary::sin(angle.to_radians());
        for (w, &wl) in wavelengths.iter().enumerate() {
            let e = a * wavelengths.len() + w;
            let point = point_jacobian(
                &stack.indices_at(wl).unwrap(),
                &stack.thicknesses_nm(),
                sin_theta,
                wl,
                Wrt::ThicknessAndIndex,
            );
            assert_eq!(sweep.power[e], point.power);
            assert_eq!(
                &sweep.d_thickness[e * films..(e + 1) * films],
                &point.d_thickness[..]
            );
            assert_eq!(
                &sweep.d_index_re[e * films..(e + 1) * films],
                &point.d_index_re[..]
            );
            assert_eq!(
                &sweep.d_index_im[e * films..(e + 1) * films],
                &point.d_index_im[..]
            );
            let (x, y) = (parts(&sweep.power[e]), parts(&values[e]));
            for k in 0..4 {
                assert!((x[k] - y[k]).abs() < 1e-12, "{x:?} {y:?}");
            }
        }
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    // Thicknesses alone take the vectorised kernel: the same bits on one thread as on
    // many, within 10⁻¹² of the scalar sweep's derivatives (no evanescent film here).
    let thickness = sweep_jacobian(&stack, &angles, &wavelengths, Wrt::Thickness).unwrap();
    let serial =
        one.install(|| sweep_jacobian(&stack, &angles, &wavelengths, Wrt::Thickness).unwrap());
    assert_eq!(serial, thickness);
    assert!(serial.d_index_re.is_empty());
    let worst = kernel_error(&thickness, &sweep.d_thickness);
    assert!(worst <= 1e-12, "kernel against scalar: {worst:e}");
}

/// The smallest row scale of [`kernel_error`], per nm: the size of a thickness derivative
/// where it does not vanish (R and T swing by O(1) over a fringe of 2π/(2 k₀ n) nm, so their
/// slopes reach ~2 k₀ n ≈ 0.03–0.1 per nm over 380–780 nm). Where every derivative of an
/// output vanishes (R = 1 under total internal reflection into a lossless stack, or R = 1 −
/// 10⁻⁹ under frustrated total internal reflection through deep evanescent films) both
/// sweeps return rounding noise: the forward R itself is good only to ~10⁻¹¹ there (central
/// differences with steps of 10⁻² and 5 × 10⁻³ nm disagree at 10⁻⁹ per nm), and the two
/// sweeps' derivatives, 5 × 10⁻⁸ per nm each, differ by 2 × 10⁻⁹. Measured against this
/// floor, such rows are held to what the arithmetic can give, not to a relative error of a
/// quantity that is itself noise.
const KERNEL_FLOOR: f64 = 0.1;

/// The largest difference between the kernel's thickness derivatives and `scalar`'s (same
/// layout), relative to the largest |derivative| of the same output and element over the
/// films (at least [`KERNEL_FLOOR`]).
fn kernel_error(kernel: &nacre_optics::jacobian::SweepJacobian, scalar: &[Power]) -> f64 {
    let films = kernel.films.max(1);
    let mut worst: f64 = 0.0;
    for (k_row, s_row) in kernel.d_thickness.chunks(films).zip(scalar.chunks(films)) {
        for c in 0..4 {
            let scale = s_row
                .iter()
                .map(|p| parts(p)[c].abs())
                .fold(KERNEL_FLOOR, f64::max);
            for (a, b) in k_row.iter().zip(s_row) {
                worst = worst.max((parts(a)[c] - parts(b)[c]).abs() / scale);
            }
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The vectorised thickness Jacobian (`Wrt::Thickness`) against the scalar reverse sweep
    /// (`point_jacobian`, itself checked against dual numbers and finite differences above)
    /// over random stacks: absorbing films and substrates, up to 9 films, normal to grazing
    /// incidence, total internal reflection; its powers are `Stack::sweep`'s, bit for bit,
    /// and its bits do not depend on the thread count. Over 300 000 random cases (this
    /// strategy, [`kernel_error`] with the floor above) the worst difference was 3 × 10⁻⁸
    /// and fewer than 1 in 10⁵ exceeded 10⁻⁹: every one frustrated total internal reflection
    /// through lossless films 4–18 evanescent decay lengths deep, where the forward R is
    /// 1 − 10⁻⁹ and both sweeps round (see [`KERNEL_FLOOR`]); the next worst were below 10⁻⁹.
    /// Held to 10⁻⁹: a wrong term in the kernel is an O(1) difference. (An earlier floor of
    /// 10⁻³ per nm held such rows to 10⁻¹⁴ per nm absolute, and CI drew one at 2 × 10⁻¹⁰.)
    #[test]
    fn kernel_jacobian_matches_the_scalar_one(
        n0 in 1.0..2.0f64,
        films in prop::collection::vec(any_film(), 0..10),
        sub in (1.0..4.0f64, prop_oneof![Just(0.0), 0.0..4.0f64]),
        angles in prop::collection::vec(prop_oneof![0.0..80.0f64, 80.0..89.9f64], 1..3),
        count in 1..40usize,
    ) {
        let layers = films
            .iter()
            .map(|&(n, k, d)| Layer { material: medium(n, k), thickness_nm: d })
            .collect();
        let stack = Stack::new(medium(n0, 0.0), layers, medium(sub.0, sub.1)).unwrap();
        let wavelengths: Vec<f64> = (0..count).map(|i| 380.0 + 400.0 * i as f64 / count as f64).collect();
        let kernel = sweep_jacobian(&stack, &angles, &wavelengths, Wrt::Thickness).unwrap();
        let scalar =
            sweep_jacobian(&stack, &angles, &wavelengths, Wrt::ThicknessAndIndex).unwrap();
        prop_assert_eq!(&kernel.power, &stack.sweep(&angles, &wavelengths).unwrap());
        let worst = kernel_error(&kernel, &scalar.d_thickness);
        prop_assert!(worst <= 1e-9, "kernel against scalar: {:e}", worst);
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let serial =
            one.install(|| sweep_jacobian(&stack, &angles, &wavelengths, Wrt::Thickness).unwrap());
        prop_assert_eq!(serial, kernel);
    }
}

/// Incoherent layers are refused by name.
#[test]
fn incoherent_stacks_are_refused() {
    let stack = Stack::new(
        medium(1.0, 0.0),
        vec![Layer {
            material: medium(1.5, 0.0),
            thickness_nm: 1e6,
        }],
        medium(1.0, 0.0),
    )
    .unwrap()
    .with_incoherent(vec![true])
    .unwrap();
    let e = sweep_jacobian(&stack, &[0.0], &[500.0], Wrt::Thickness).unwrap_err();
    assert!(e.to_string().contains("derivatives"), "{e}");
}

/// XYZ, CIELAB and ΔE2000 derivatives through the 1 nm spectral sum against central
/// differences of the whole chain (stack → spectrum → colour), by thickness.
#[test]
fn colour_derivatives_match_finite_differences() {
    let colorimeter = Colorimeter::new(Observer::Cie1931_2Deg, Illuminant::D65, OutputSpace::Xyz);
    let wavelengths: Vec<f64> = (0..471).map(|i| 360.0 + i as f64).collect();
    let stack_of = |d: &[f64]| {
        Stack::new(
            medium(1.0, 0.0),
            vec![
                Layer {
                    material: medium(2.3, 0.0),
                    thickness_nm: d[0],
                },
                Layer {
                    material: medium(1.38, 0.0),
                    thickness_nm: d[1],
                },
            ],
            medium(1.2, 2.5),
        )
        .unwrap()
    };
    let d0 = [140.0, 95.0];
    let lab_of = |d: &[f64]| {
        let p = stack_of(d).sweep(&[20.0], &wavelengths).unwrap();
        let xyz = colorimeter.xyz_of({
            let mut k = 0;
            move |_| {
                k += 1;
                p[k - 1].R()
            }
        });
        xyz_to_lab(xyz, colorimeter.white_xyz())
    };
    let jac = sweep_jacobian(&stack_of(&d0), &[20.0], &wavelengths, Wrt::Thickness).unwrap();
    let values: Vec<f64> = jac.power.iter().map(|p| p.R()).collect();
    let derivs: Vec<f64> = jac.d_thickness.iter().map(|p| p.R()).collect();
    let xyz = colour_jacobian(colorimeter.xyz_weights_1nm(), &values, &derivs, 2);
    let lab: ColourJacobian = lab_jacobian(&xyz, colorimeter.white_xyz());
    let target = [55.0, 20.0, -30.0];
    let (de, grad) = delta_e_2000_param_gradient(target, &lab);
    assert!((de - delta_e_2000(target, lab_of(&d0))).abs() < 1e-9);
    let h = 1e-3;
    for p in 0..2 {
        let (mut up, mut down) = (d0, d0);
        up[p] += h;
        down[p] -= h;
        let (lu, ld) = (lab_of(&up), lab_of(&down));
        for c in 0..3 {
            let fd = (lu[c] - ld[c]) / (2.0 * h);
            let scale = lab.d[p].iter().fold(1e-9f64, |m, v| m.max(v.abs()));
            assert!(
                (lab.d[p][c] - fd).abs() <= 1e-7 * scale,
                "dLab/dd{p}[{c}] {} vs {fd}",
                lab.d[p][c]
            );
        }
        let fd = (delta_e_2000(target, lu) - delta_e_2000(target, ld)) / (2.0 * h);
        assert!(
            (grad[p] - fd).abs() <= 1e-7 * grad[p].abs().max(1e-9),
            "dΔE/dd{p} {} vs {fd}",
            grad[p]
        );
    }
}

/// The ΔE2000 gradient against central differences in L*, a*, b* over Sharma's pairs'
/// neighbourhood and random colours.
#[test]
fn delta_e_gradient_matches_finite_differences() {
    let mut worst: f64 = 0.0;
    let mut x = 0.123_456_f64;
    let mut next = || {
        x = (x * 9_301.0 + 0.497_3).fract();
        x
    };
    for _ in 0..2000 {
        let a = [
            100.0 * next(),
            200.0 * next() - 100.0,
            200.0 * next() - 100.0,
        ];
        let b = [
            100.0 * next(),
            200.0 * next() - 100.0,
            200.0 * next() - 100.0,
        ];
        let (v, g) = delta_e_2000_gradient(a, b);
        assert_eq!(v, delta_e_2000(a, b));
        let h = 1e-5;
        for c in 0..3 {
            let (mut up, mut down) = (b, b);
            up[c] += h;
            down[c] -= h;
            let fd = (delta_e_2000(a, up) - delta_e_2000(a, down)) / (2.0 * h);
            let scale = g.iter().fold(1e-3f64, |m, v| m.max(v.abs()));
            worst = worst.max((g[c] - fd).abs() / scale);
        }
    }
    println!("ΔE2000 gradient: worst relative difference from central differences {worst:.2e}");
    assert!(worst <= 1e-7, "{worst:e}");
}
