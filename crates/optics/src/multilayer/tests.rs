//! Tests of the vectorised multilayer kernel against the scalar transfer-matrix reference.

use super::media::Slots;
use super::*;
use crate::stack::sweep_recurrence;
use num_complex::Complex64 as C64;

fn c(re: f64, im: f64) -> C64 {
    C64::new(re, im)
}

/// Test stacks: (name, thicknesses, indices per wavelength at `wl`).
type Case = (&'static str, Vec<f64>, fn(f64) -> Vec<C64>);

fn cases() -> Vec<Case> {
    vec![
        (
            // Five dispersive-like films on glass, a thin gold-like absorber at the bottom.
            "five films",
            vec![56.45, 99.75, 56.45, 120.0, 10.0],
            |wl| {
                let u = (wl - 380.0) / 400.0;
                let tio2 = c(2.9 - 0.5 * u, (0.05 - 0.1 * u).max(0.0));
                vec![
                    c(1.000_29, 0.0),
                    tio2,
                    c(1.39 - 0.01 * u, 0.0),
                    tio2,
                    c(1.47 - 0.01 * u, 0.0),
                    c(1.5 - 1.3 * u, 1.8 + 2.5 * u),
                    c(1.53 - 0.02 * u, 0.0),
                ]
            },
        ),
        (
            // Dense ambient: total internal reflection in the films and the substrate.
            "total internal reflection",
            vec![80.0, 40.0],
            |wl| {
                let u = (wl - 380.0) / 400.0;
                vec![
                    c(1.7 + 0.02 * u, 0.0),
                    c(1.38, 0.0),
                    c(2.0, 0.0),
                    c(1.0, 0.0),
                ]
            },
        ),
        (
            // Absorbing film on a metal.
            "absorbing film on metal",
            vec![150.0],
            |wl| {
                let u = (wl - 380.0) / 400.0;
                vec![c(1.0, 0.0), c(1.5, 0.05 * u), c(0.27 + 0.1 * u, 2.9 + u)]
            },
        ),
        ("bare interface", vec![], |_| vec![c(1.0, 0.0), c(1.5, 0.0)]),
        (
            "evanescent absorbing substrate, zero-thickness film",
            vec![0.0, 300.0],
            |_| vec![c(1.6, 0.0), c(2.2, 0.0), c(1.2, 0.0), c(1.0, 1e-3)],
        ),
        (
            // Thick absorber: the phasor decays to 0.
            "opaque film",
            vec![1e5, 20.0],
            |_| vec![c(1.33, 0.0), c(1.8, 0.5), c(1.4, 0.0), c(1.5, 0.0)],
        ),
        (
            // A periodic mirror whose media repeat everywhere: the ambient is the L
            // material, the substrate the H one, two adjacent films share a material,
            // and films of one material come in two thicknesses.
            "periodic mirror",
            vec![60.0, 100.0, 60.0, 100.0, 60.0, 30.0, 60.0, 150.0, 60.0],
            |wl| {
                let u = (wl - 380.0) / 400.0;
                let h = c(2.4 - 0.2 * u, (0.02 - 0.04 * u).max(0.0));
                let l = c(1.38 - 0.01 * u, 0.0);
                vec![l, h, l, h, l, h, h, l, l, h, h]
            },
        ),
        (
            // A negative-zero imaginary part must not pick the growing wave.
            "negative zero",
            vec![70.0],
            |_| vec![c(1.5, 0.0), c(1.0, -0.0), c(1.46, 0.0)],
        ),
    ]
}

const ANGLES_DEG: [f64; 9] = [0.0, 1e-9, 10.0, 30.0, 45.0, 60.0, 75.0, 89.0, 89.999];

fn wavelengths(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| 380.0 + 400.0 * k as f64 / n as f64)
        .collect()
}

fn run(media: &Media, sin_theta: f64, vector: bool) -> Vec<Power> {
    let mut out = vec![Power::default(); media.wavelengths()];
    stack_powers(media, sin_theta, &mut out, vector);
    out
}

fn bits(p: &[Power]) -> Vec<u64> {
    p.iter()
        .flat_map(|p| [p.R_s, p.R_p, p.T_s, p.T_p])
        .map(f64::to_bits)
        .collect()
}

#[test]
fn simd_and_scalar_paths_are_bit_identical() {
    for (name, d, index) in cases() {
        for n in [0, 1, 2, 3, 5, 7, 9, 31, 65, 401] {
            let wl = wavelengths(n);
            let idx: Vec<Vec<C64>> = wl.iter().map(|&w| index(w)).collect();
            let media = Media::new(&idx, &wl, &d).unwrap();
            for angle in ANGLES_DEG {
                let sin_theta = angle.to_radians().sin();
                let v = run(&media, sin_theta, true);
                let s = run(&media, sin_theta, false);
                assert_eq!(bits(&v), bits(&s), "{name}, n = {n}, {angle}°");
                // Each element alone (other neighbours in its vector) gives its bits.
                for k in (0..n).step_by(7) {
                    let one = Media::new(&idx[k..k + 1], &wl[k..k + 1], &d).unwrap();
                    assert_eq!(bits(&run(&one, sin_theta, true)), bits(&v[k..k + 1]));
                }
            }
        }
    }
}

/// Skipping e^{−0} and the root's work for lossless lanes changes no bit.
#[test]
fn shortcuts_match_the_general_formula() {
    for (name, d, index) in cases() {
        let wl = wavelengths(67);
        let idx: Vec<Vec<C64>> = wl.iter().map(|&w| index(w)).collect();
        let media = Media::new(&idx, &wl, &d).unwrap();
        for angle in ANGLES_DEG {
            let sin_theta = angle.to_radians().sin();
            for vector in [true, false] {
                let mut general = vec![Power::default(); wl.len()];
                row_powers::<_, false>(&media, sin_theta, &mut general, None, vector);
                let fast = run(&media, sin_theta, vector);
                assert_eq!(bits(&fast), bits(&general), "{name}, {angle}°");
            }
        }
    }
}

/// Computing repeated media and films once changes no bit.
#[test]
fn repeats_are_computed_once_with_the_same_bits() {
    for (name, d, index) in cases() {
        for n in [1, 9, 67, 130] {
            let wl = wavelengths(n);
            let idx: Vec<Vec<C64>> = wl.iter().map(|&w| index(w)).collect();
            let shared = Media::new(&idx, &wl, &d).unwrap();
            // No sharing, and fewer slots than repeated items (the rest computed).
            let mut apart = Media::new(&idx, &wl, &d).unwrap();
            apart.media_slots = Slots::new(d.len() + 2, 2, 0, |_, _| false, |_| false);
            apart.film_slots = Slots::new(d.len(), 1, 0, |_, _| false, |_| false);
            let mut capped = Media::new(&idx, &wl, &d).unwrap();
            let column = |j: usize| {
                idx.iter()
                    .map(move |i| (i[j].re.to_bits(), i[j].im.to_bits()))
            };
            let same = |i: usize, j: usize| column(i).eq(column(j));
            capped.media_slots = Slots::new(d.len() + 2, 2, 1, same, |_| false);
            capped.film_slots = Slots::new(
                d.len(),
                1,
                1,
                |i, j| d[i] == d[j] && same(i + 1, j + 1),
                |_| false,
            );
            for angle in ANGLES_DEG {
                let sin_theta = angle.to_radians().sin();
                for vector in [true, false] {
                    let want = bits(&run(&apart, sin_theta, vector));
                    for media in [&shared, &capped] {
                        assert_eq!(
                            bits(&run(media, sin_theta, vector)),
                            want,
                            "{name}, n = {n}, {angle}°"
                        );
                    }
                }
            }
        }
    }
    // The mirror shares L (ambient, films 2, 4, 8, 9) and H (films 1, 3, 5, 6, 7, substrate);
    // its films H 60 nm (1, 3, 5, 7) and L 100 nm (2, 4).
    let (_, d, index) = cases()
        .into_iter()
        .find(|c| c.0 == "periodic mirror")
        .unwrap();
    let media = Media::new(&[index(500.0)], &[500.0], &d).unwrap();
    let slots = &media.media_slots;
    assert_eq!(slots.slot[0], slots.slot[2]);
    assert_eq!(slots.slot[1], slots.slot[10]);
    assert_eq!(slots.known.iter().filter(|&&k| k).count(), 9);
    assert_eq!(media.film_slots.known.iter().filter(|&&k| k).count(), 4);
}

#[test]
fn vectorised_sweep_matches_the_recurrence() {
    let mut worst: f64 = 0.0;
    for (name, d, index) in cases() {
        let wl = wavelengths(203);
        let idx: Vec<Vec<C64>> = wl.iter().map(|&w| index(w)).collect();
        let media = Media::new(&idx, &wl, &d).unwrap();
        let sines: Vec<f64> = ANGLES_DEG.iter().map(|a| a.to_radians().sin()).collect();
        let want = sweep_recurrence(&sines, &idx, &wl, &d);
        for (a, &sin_theta) in sines.iter().enumerate() {
            let got = run(&media, sin_theta, true);
            for (w, (g, e)) in got.iter().zip(&want[a * wl.len()..]).enumerate() {
                for (x, y) in [
                    (g.R_s, e.R_s),
                    (g.R_p, e.R_p),
                    (g.T_s, e.T_s),
                    (g.T_p, e.T_p),
                ] {
                    assert!(x.is_finite(), "{name}, {}°, {} nm", ANGLES_DEG[a], wl[w]);
                    worst = worst.max((x - y).abs());
                    assert!(
                        (x - y).abs() <= 1e-12,
                        "{name}, {}°, {} nm: {g:?} vs {e:?}",
                        ANGLES_DEG[a],
                        wl[w]
                    );
                }
            }
        }
    }
    println!("vectorised sweep: worst difference from the recurrence {worst:.3e}");
}

#[test]
fn lossless_stacks_conserve_energy() {
    for (name, d, index) in cases() {
        let wl = wavelengths(101);
        let idx: Vec<Vec<C64>> = wl.iter().map(|&w| index(w)).collect();
        if idx.iter().flatten().any(|n| n.im != 0.0) {
            continue;
        }
        let media = Media::new(&idx, &wl, &d).unwrap();
        for angle in ANGLES_DEG {
            for p in run(&media, angle.to_radians().sin(), true) {
                for (r, t) in [(p.R_s, p.T_s), (p.R_p, p.T_p)] {
                    assert!((r + t - 1.0).abs() < 1e-13, "{name}, {angle}°: {p:?}");
                }
            }
        }
    }
}

#[test]
fn out_of_range_indices_take_the_recurrence() {
    let d = [50.0];
    for bad in [
        c(1e7, 0.0),
        c(1e-7, 0.0),
        c(f64::NAN, 0.0),
        c(1.5, f64::INFINITY),
    ] {
        let idx = vec![vec![c(1.0, 0.0), bad, c(1.5, 0.0)]];
        assert!(Media::new(&idx, &[500.0], &d).is_none(), "{bad}");
    }
    let idx = vec![vec![c(1.0, 0.0), c(1.4, 0.0), c(1.5, 0.0)]];
    assert!(Media::new(&idx, &[500.0], &[1e300]).is_none());
    assert!(Media::new(&idx, &[1e-300], &d).is_none());
    assert!(Media::new(&idx, &[500.0], &d).is_some());
}

#[test]
fn largest_is_the_left_to_right_fold() {
    let fold = |v: &[f64]| {
        v.iter()
            .fold(0.0_f64, |m, &k| if k > m || k.is_nan() { k } else { m })
    };
    let cases: [&[f64]; 7] = [
        &[],
        &[0.5],
        &[0.1, 0.7, 0.3, 0.2, 0.9, 0.05, 0.4],
        &[-1.0, -2.0, -0.0],
        &[0.1, 0.2, f64::NAN, 0.3, 0.4, 0.5],
        &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, f64::NAN],
        &[f64::INFINITY, 1.0, 2.0, 3.0, 4.0],
    ];
    for v in cases {
        let (a, b) = (super::media::largest(v), fold(v));
        assert!(
            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
            "{v:?}"
        );
    }
}

/// Both sides in one pass: the forward powers are the one-sided kernel's bits, and the
/// backward ones (light from the last medium) those of the stack turned upside down with
/// the same β, to 10⁻¹² (10⁻⁹ at 89.999°), wherever the last medium carries a propagating
/// wave.
#[test]
fn both_sides_in_one_pass_match_the_reversed_stack() {
    let mut compared = 0;
    for (name, d, index) in cases() {
        for n in [1, 9, 67, 130] {
            let wl = wavelengths(n);
            let idx: Vec<Vec<C64>> = wl.iter().map(|&w| index(w)).collect();
            let count = d.len() + 2;
            let columns: Vec<Vec<C64>> = (0..count)
                .map(|j| idx.iter().map(|i| i[j]).collect())
                .collect();
            let beta: Vec<f64> = columns[0].iter().map(|c| c.re).collect();
            let media = Media::from_columns_beta(&columns, Some(beta.as_slice()), &wl, &d).unwrap();
            let reversed: Vec<Vec<C64>> = columns.iter().rev().cloned().collect();
            let rev_d: Vec<f64> = d.iter().rev().copied().collect();
            let upside_down =
                Media::from_columns_beta(&reversed, Some(beta.as_slice()), &wl, &rev_d).unwrap();
            for angle in ANGLES_DEG {
                let sin_theta = angle.to_radians().sin();
                // 10⁻³ degree from grazing the two ways round differ by rounding alone
                // (R′ + T′ = 1 within 10⁻¹⁰ both ways on the lossless periodic mirror).
                let tol = if angle > 89.9 { 1e-9 } else { 1e-12 };
                for vector in [true, false] {
                    let mut forward = vec![Power::default(); n];
                    let mut backward = vec![Power::default(); n];
                    stack_powers_both(&media, sin_theta, &mut forward, &mut backward, vector);
                    assert_eq!(bits(&forward), bits(&run(&media, sin_theta, vector)));
                    let want = run(&upside_down, sin_theta, vector);
                    for (w, (ours, want)) in backward.iter().zip(&want).enumerate() {
                        let last = columns[count - 1][w];
                        let b = beta[w] * sin_theta;
                        if !(last.im == 0.0 && last.re > b) {
                            continue;
                        }
                        compared += 1;
                        for (a, e) in [
                            (ours.R_s, want.R_s),
                            (ours.R_p, want.R_p),
                            (ours.T_s, want.T_s),
                            (ours.T_p, want.T_p),
                        ] {
                            assert!(
                                (a - e).abs() <= tol,
                                "{name}, n = {n}, {angle}°, w = {w}: {ours:?} vs {want:?}"
                            );
                        }
                    }
                }
            }
        }
    }
    assert!(compared > 1000, "{compared}");
}

/// A slab's single pass e^{−2 k₀ d Im q} on the kernel's lanes against the scalar root and
/// `elementary::exp`, to 10⁻¹⁴ relative: glass with a little absorption, an absorbing slab,
/// a lossless slab beyond its critical angle (P = 0) and below it (P = 1 exactly).
#[test]
fn slab_passes_match_the_scalar_formula() {
    let wl = wavelengths(67);
    let k0: Vec<f64> = wl.iter().map(|&w| crate::power::wavenumber(w)).collect();
    for (n0, slab, d) in [
        (1.0, c(1.52, 1e-8), 2e6),
        (1.0, c(1.6, 2e-6), 1e6),
        (1.7, c(1.0, 0.0), 5e5),
        (1.0, c(1.5, 0.0), 2e6),
    ] {
        let column = vec![slab; wl.len()];
        let n0_re = vec![n0; wl.len()];
        let arrays = SlabArrays::new(&column, &n0_re, &k0, d);
        for angle in ANGLES_DEG {
            let sin_theta = angle.to_radians().sin();
            let mut out = vec![f64::NAN; arrays.padded()];
            slab_passes(&arrays, sin_theta, &mut out);
            for (w, &p) in out.iter().take(wl.len()).enumerate() {
                let q = crate::fresnel::normal_component(slab, n0 * sin_theta);
                let want = crate::elementary::exp(-2.0 * k0[w] * d * q.im);
                assert!(
                    (p - want).abs() <= 1e-14 * want.max(1e-300) || (p < 1e-300 && want < 1e-300),
                    "{slab} at {angle}°, w = {w}: {p} vs {want}"
                );
            }
        }
    }
}
