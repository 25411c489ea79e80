//! Physical laws of stacks with incoherent layers (`nacre_optics::incoherent`) as property
//! tests (proptest): the thickness average of the coherent result, layers that vanish,
//! energy conservation and reciprocity.

use nacre_optics::incoherent::Part;
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

/// A stack with the films `films` (n, κ, d, incoherent), top first.
fn stack(n0: f64, films: &[(f64, f64, f64, bool)], (ns, ks): (f64, f64)) -> Stack {
    let layers = films.iter().map(|&(n, k, d, _)| film(n, k, d)).collect();
    Stack::new(medium(n0, 0.0), layers, medium(ns, ks))
        .unwrap()
        .with_incoherent(films.iter().map(|f| f.3).collect())
        .unwrap()
}

fn one(stack: &Stack, angle: f64, wl: f64) -> Power {
    stack.sweep(&[angle], &[wl]).unwrap()[0]
}

fn close(a: &Power, b: &Power, tol: f64) -> bool {
    (a.R_s - b.R_s).abs() <= tol
        && (a.R_p - b.R_p).abs() <= tol
        && (a.T_s - b.T_s).abs() <= tol
        && (a.T_p - b.T_p).abs() <= tol
}

/// A coherent coating of up to three films, lossless or absorbing.
fn coating() -> impl Strategy<Value = Vec<(f64, f64, f64, bool)>> {
    prop::collection::vec(
        (
            1.3..2.5f64,
            prop_oneof![3 => Just(0.0), 1 => 0.0..0.5f64],
            0.0..300.0f64,
        )
            .prop_map(|(n, k, d)| (n, k, d, false)),
        0..3,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A lossless incoherent slab between two coherent coatings gives the average, over one
    /// period of the slab's phase (many fringes of its coherent spectrum), of the coherent
    /// stack: the incoherent sum is the phase average of the Airy sum (Born & Wolf §7.6.1),
    /// here with composite coatings on both faces.
    #[test]
    fn slab_is_the_thickness_average_of_the_coherent_stack(
        top in coating(),
        bottom in coating(),
        n_slab in 1.4..2.0f64,
        (ns, ks) in (1.0..2.0f64, prop_oneof![Just(0.0), 0.0..2.0f64]),
        angle in 0.0..80.0f64,
        wl in 400.0..750.0f64,
        d0 in 5000.0..50000.0f64,
    ) {
        const N: usize = 256;
        let mut films = top.clone();
        let slab = films.len() + 1;
        films.push((n_slab, 0.0, d0, true));
        films.extend(bottom);
        let incoherent = stack(1.0, &films, (ns, ks));
        let coherent = incoherent.clone().with_incoherent(vec![false; films.len()]).unwrap();
        let sin_in = angle.to_radians().sin() / n_slab;
        let period = wl / (2.0 * n_slab * (1.0 - sin_in * sin_in).sqrt());
        let ds: Vec<f64> = (0..N).map(|m| d0 + period * m as f64 / N as f64).collect();
        let sweep = coherent.sweep_thickness(slab, &[angle], &[wl], &ds).unwrap();
        let n = N as f64;
        let mean = Power {
            R_s: sweep.iter().map(|p| p.R_s).sum::<f64>() / n,
            R_p: sweep.iter().map(|p| p.R_p).sum::<f64>() / n,
            T_s: sweep.iter().map(|p| p.T_s).sum::<f64>() / n,
            T_p: sweep.iter().map(|p| p.T_p).sum::<f64>() / n,
        };
        let inc = one(&incoherent, angle, wl);
        prop_assert!(close(&inc, &mean, 1e-9), "{inc:?} vs {mean:?}");
    }

    /// A zero-thickness incoherent layer of the medium next to it (the ambient's material
    /// on top, or a slab's material beside that slab) changes nothing; and an incoherent
    /// slab split in two incoherent slabs of the same material is the same slab.
    #[test]
    fn zero_thickness_and_split_slabs_change_nothing(
        top in coating(),
        bottom in coating(),
        (n_slab, k_slab) in (1.4..2.0f64, prop_oneof![Just(0.0), 1e-7..1e-5f64]),
        ns in 1.0..2.0f64,
        angle in 0.0..85.0f64,
        wl in 400.0..750.0f64,
        d in 1000.0..3e6f64,
        split in 0.0..1.0f64,
    ) {
        let mut films = top.clone();
        films.push((n_slab, k_slab, d, true));
        films.extend(bottom.iter().copied());
        let base = one(&stack(1.0, &films, (ns, 0.0)), angle, wl);

        let mut with_ambient_layer = vec![(1.0, 0.0, 0.0, true)];
        with_ambient_layer.extend(films.iter().copied());
        let p = one(&stack(1.0, &with_ambient_layer, (ns, 0.0)), angle, wl);
        prop_assert!(close(&p, &base, 1e-13), "ambient-index layer: {p:?} vs {base:?}");

        let mut zero_beside = top.clone();
        zero_beside.push((n_slab, k_slab, d, true));
        zero_beside.push((n_slab, k_slab, 0.0, true));
        zero_beside.extend(bottom.iter().copied());
        let p = one(&stack(1.0, &zero_beside, (ns, 0.0)), angle, wl);
        prop_assert!(close(&p, &base, 1e-13), "zero slab: {p:?} vs {base:?}");

        let mut halves = top.clone();
        halves.push((n_slab, k_slab, d * split, true));
        halves.push((n_slab, k_slab, d * (1.0 - split), true));
        halves.extend(bottom.iter().copied());
        let p = one(&stack(1.0, &halves, (ns, 0.0)), angle, wl);
        prop_assert!(close(&p, &base, 1e-12), "split slab: {p:?} vs {base:?}");
    }

    /// Energy conservation: R + T + ΣA = 1 per polarisation, the absorptance of each group
    /// and slab taken from the power flows through it; A ≥ 0 in each part (to O(κ) next to
    /// an absorbing slab), and for a lossless stack every A vanishes.
    #[test]
    fn energy_is_conserved_part_by_part(
        top in coating(),
        middle in coating(),
        bottom in coating(),
        slabs in prop::collection::vec(
            (1.4..2.2f64, prop_oneof![Just(0.0), 1e-7..1e-5f64, 1e-3..1e-2f64], 500.0..3e6f64),
            1..3,
        ),
        (ns, ks) in (1.0..2.5f64, prop_oneof![Just(0.0), 0.0..3.0f64]),
        angle in 0.0..85.0f64,
        wl in 400.0..750.0f64,
    ) {
        let mut films = top.clone();
        for (i, &(n, k, d)) in slabs.iter().enumerate() {
            // Strongly absorbing slabs only thin enough to pass light.
            let d = if k > 1e-4 { d.min(5000.0) } else { d };
            films.push((n, k, d, true));
            films.extend(if i == 0 { middle.iter().copied() } else { bottom.iter().copied() });
        }
        let s = stack(1.0, &films, (ns, ks));
        let a = &s.sweep_absorbed(&[angle], &[wl]).unwrap()[0];
        prop_assert_eq!(a.parts_s.len(), s.parts().len());
        let p = a.power;
        prop_assert!(close(&p, &one(&s, angle, wl), 0.0));
        let lossless = films.iter().all(|f| f.1 == 0.0) && ks == 0.0;
        // Next to an absorbing slab, the powers of the convention of Byrnes Eq. 21–22 (and
        // `tmm`, matched to 1e-10 by the goldens) leave out the cross term of the slab's two
        // waves, of order κ: a group bounded by such a slab may show an absorptance of −O(κ).
        let kappa = films.iter().filter(|f| f.3).map(|f| f.1).fold(0.0, f64::max);
        let floor = -1e-12 - kappa;
        for (r, t, parts) in [(p.R_s, p.T_s, &a.parts_s), (p.R_p, p.T_p, &a.parts_p)] {
            let sum: f64 = parts.iter().sum();
            prop_assert!((r + t + sum - 1.0).abs() < 1e-12, "R {r} T {t} A {parts:?}");
            for &x in parts.iter() {
                prop_assert!(x >= floor, "{parts:?}");
                if lossless {
                    prop_assert!(x.abs() < 1e-12, "{parts:?}");
                }
            }
        }
    }

    /// Reciprocity: the transmittance from the ambient into the substrate equals that from
    /// the substrate back into the ambient at the conjugate angle (the same β), for every
    /// polarisation, absorbing coherent films included (Stokes; Born & Wolf §1.6.3).
    #[test]
    fn transmittance_is_reciprocal(
        top in coating(),
        bottom in coating(),
        (n_slab, k_slab) in (1.4..2.0f64, prop_oneof![Just(0.0), 1e-7..1e-5f64]),
        ns in 1.0..1.8f64,
        angle in 0.0..80.0f64,
        wl in 400.0..750.0f64,
        d in 1000.0..3e6f64,
    ) {
        let mut films = top.clone();
        films.push((n_slab, k_slab, d, true));
        films.extend(bottom);
        let forward = one(&stack(1.0, &films, (ns, 0.0)), angle, wl);
        let reversed: Vec<_> = films.iter().rev().copied().collect();
        let back_angle = (angle.to_radians().sin() / ns).asin().to_degrees();
        let back = one(&stack(ns, &reversed, (1.0, 0.0)), back_angle, wl);
        prop_assert!((forward.T_s - back.T_s).abs() < 1e-11, "{forward:?} vs {back:?}");
        prop_assert!((forward.T_p - back.T_p).abs() < 1e-11, "{forward:?} vs {back:?}");
    }
}

#[test]
fn parts_name_groups_and_slabs() {
    let s = stack(
        1.0,
        &[
            (1.38, 0.0, 100.0, false),
            (1.5, 0.0, 2e6, true),
            (2.3, 0.0, 50.0, false),
            (1.38, 0.0, 100.0, false),
        ],
        (1.0, 0.0),
    );
    assert_eq!(
        s.parts(),
        [
            Part::Coherent { first: 1, last: 1 },
            Part::Slab { layer: 2 },
            Part::Coherent { first: 3, last: 4 },
        ]
    );
    // Amplitudes and thickness sweeps need a coherent stack.
    assert!(s.evaluate(0.0, 550.0).is_err());
    assert!(s.sweep_thickness(1, &[0.0], &[550.0], &[1.0]).is_err());
}

#[test]
fn an_opaque_slab_is_refused() {
    let s = stack(1.0, &[(1.5, 0.01, 1e6, true)], (1.0, 0.0));
    let e = s.sweep(&[0.0], &[550.0]).unwrap_err();
    assert!(
        matches!(e, nacre_optics::Error::OpaqueSlab { layer: 1, .. }),
        "{e}"
    );
}

#[test]
fn a_thick_coherent_film_is_undersampled() {
    let wl: Vec<f64> = (0..=80).map(|i| 380.0 + 5.0 * i as f64).collect();
    let s = stack(
        1.0,
        &[(1.5, 0.0, 2e6, false), (1.38, 0.0, 100.0, false)],
        (1.0, 0.0),
    );
    let u = s.undersampled_films(&wl);
    assert_eq!(u.len(), 1);
    assert_eq!(u[0].layer, 1);
    assert!(u[0].to_string().contains(":incoherent"), "{}", u[0]);
    // Fine fringes: the mean period over the step is λ²/(2nd) to first order in step/λ.
    let linear = 380.0 * 380.0 / (2.0 * 1.5 * 2e6);
    assert!(
        (u[0].fringe_period_nm / linear - 1.0).abs() < 0.02,
        "{} against {linear}",
        u[0].fringe_period_nm
    );
    assert_eq!((u[0].wavelength_nm, u[0].step_nm), (380.0, 5.0));
    let s = s.with_incoherent(vec![true, false]).unwrap();
    assert!(s.undersampled_films(&wl).is_empty());
    // A 400 nm soap film passes Δm = 2·1.33·400·(1/2000 − 1/11000) = 0.43 fringes between
    // samples 9 µm apart: not undersampled, although the linearised period λ²/(2nd) = 3.8 µm
    // at 2 µm is below the step. Nor on the default grid.
    let soap = stack(1.0, &[(1.33, 0.0, 400.0, false)], (1.0, 0.0));
    assert!(
        soap.undersampled_films(&[2000.0, 11000.0, 20000.0])
            .is_empty()
    );
    assert!(soap.undersampled_films(&wl).is_empty());
    // On 100, 150, 200 nm it passes 3.5 fringes per step but is 10.6 orders thick there:
    // a thin film on a sparse grid, not a slab (UNDERSAMPLED_MIN_ORDER).
    assert!(soap.undersampled_films(&[100.0, 150.0, 200.0]).is_empty());
    // 20 µm of it on a 20 nm grid over 400–700 nm (`samples:16`): Δm = 6.3 at 400 nm.
    let thick = stack(1.0, &[(1.33, 0.0, 2e4, false)], (1.0, 0.0));
    let grid: Vec<f64> = (0..16).map(|k| 400.0 + 20.0 * k as f64).collect();
    let u = thick.undersampled_films(&grid);
    assert_eq!(u.len(), 1);
    assert_eq!(u[0].wavelength_nm, 400.0);
}
