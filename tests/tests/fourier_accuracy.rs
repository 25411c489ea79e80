//! Accuracy of the Fourier-domain method (Belcour & Barla 2017 Eq. 10 with exact Fresnel)
//! against the exact spectral reference, at 2000 random points per case (angles 0–85°,
//! thickness 50 nm–10 µm, film index 1.2–2.4). Targets (issue: Fourier sensitivities):
//!
//! * dielectric base (index 1.0–2.5): `fourier` (= `fourier:auto`, the default) ΔE2000
//!   p95 ≤ 0.1, max ≤ 0.5 (reflectance and transmittance); `fourier:3` reported beside it;
//! * conductor base (n 0.2–2.0, κ 0.5–4): `fourier` p95 ≤ 0.3, max ≤ 1.0;
//!
//! (`fourier_default.rs` holds the default to the same targets at the worst cases: a grid,
//! free films, grazing angles);
//! * prefiltered, σ_d 5–200 nm: `fourier:3:σ` against the brute-force average of spectral
//!   colours over the Gaussian thickness distribution, p95 ≤ 0.5.

use nacre_bake::commands::color::{self, Method, Point, Quantity};
use nacre_format::Manifest;
use nacre_format::fourier::FourierTable;
use nacre_format::set::default_baked_dir;
use nacre_optics::colour::{
    Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace, delta_e_2000, xyz_to_lab,
};
use nacre_optics::fourier::Harmonics;
use nacre_optics::{C64, Layer, Material, SpectralRule, Stack};
use std::sync::Arc;

use nacre_tests::Rng;

const POINTS: usize = 2000;

/// The default-set `fourier-srgb` table (the `fourier:` methods sample it as a GPU would).
fn table() -> Arc<FourierTable> {
    let path = default_baked_dir().join("fourier-srgb.json");
    Arc::new(Manifest::read(&path).unwrap().load_fourier(&path).unwrap())
}

fn srgb() -> Colorimeter {
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
}

fn constant(n: C64) -> Material {
    Material::constant(format!("{n}"), n).unwrap()
}

fn film_stack(n_film: f64, d: f64, base: C64) -> Stack {
    Stack::new(
        constant(C64::new(1.0, 0.0)),
        vec![Layer {
            material: constant(C64::new(n_film, 0.0)),
            thickness_nm: d,
        }],
        constant(base),
    )
    .unwrap()
}

struct Stats {
    mean: f64,
    p95: f64,
    max: f64,
}

fn stats(c: &Colorimeter, a: &[[f64; 3]], b: &[[f64; 3]]) -> Stats {
    let lab = |rgb: [f64; 3]| xyz_to_lab(c.xyz_from_output(rgb), c.white_xyz());
    let mut de: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(x, y)| delta_e_2000(lab(*x), lab(*y)))
        .collect();
    de.sort_by(f64::total_cmp);
    Stats {
        mean: de.iter().sum::<f64>() / de.len() as f64,
        p95: de[((de.len() - 1) as f64 * 0.95).round() as usize],
        max: de[de.len() - 1],
    }
}

/// (stack, point) pairs: each point has its own base, so evaluate one at a time.
fn evaluate(cases: &[(Stack, Point)], method: &Method, c: &Colorimeter) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    cases
        .par_iter()
        .map(|(s, p)| {
            color::evaluate(
                s,
                std::slice::from_ref(p),
                method,
                c,
                Quantity::Reflectance,
                None,
            )
            .unwrap()[0]
        })
        .collect()
}

fn random_cases(seed: u64, base: impl Fn(&mut Rng) -> C64) -> Vec<(Stack, Point)> {
    let mut rng = Rng(seed);
    (0..POINTS)
        .map(|_| {
            let point = Point {
                angle_deg: rng.uniform(0.0, 85.0),
                thickness_nm: Some(rng.uniform(50.0, 10_000.0)),
                film_ior: Some(rng.uniform(1.2, 2.4)),
            };
            let b = base(&mut rng);
            (
                film_stack(point.film_ior.unwrap(), point.thickness_nm.unwrap(), b),
                point,
            )
        })
        .collect()
}

#[test]
fn dielectric_base_fourier_default() {
    let c = srgb();
    let cases = random_cases(7, |r| C64::new(r.uniform(1.0, 2.5), 0.0));
    let exact = evaluate(&cases, &Method::Spectral, &c);
    let mut report = Vec::new();
    let t = table();
    for (name, method) in [
        (
            "fourier:1",
            Method::Fourier(Harmonics::Fixed(1), 0.0, Some(t.clone())),
        ),
        (
            "fourier:2",
            Method::Fourier(Harmonics::Fixed(2), 0.0, Some(t.clone())),
        ),
        (
            "fourier:3",
            Method::Fourier(Harmonics::Fixed(3), 0.0, Some(t.clone())),
        ),
        (
            "fourier-exact:3",
            Method::Fourier(Harmonics::Fixed(3), 0.0, None),
        ),
        (
            "fourier (auto)",
            Method::Fourier(Harmonics::Auto, 0.0, Some(t.clone())),
        ),
        ("gaussian", Method::GaussianFitBelcour2017),
    ] {
        let s = stats(&c, &exact, &evaluate(&cases, &method, &c));
        report.push(format!(
            "dielectric {name}: mean {:.4} p95 {:.4} max {:.4}",
            s.mean, s.p95, s.max
        ));
        if name == "fourier (auto)" {
            assert!(s.p95 <= 0.1 && s.max <= 0.5, "{}", report.join("\n"));
        }
    }
    // Transmittance into the dielectric base (Belcour & Barla's appendix), the default.
    let exact_t: Vec<[f64; 3]> = {
        use rayon::prelude::*;
        cases
            .par_iter()
            .map(|(s, p)| {
                color::evaluate(
                    s,
                    std::slice::from_ref(p),
                    &Method::Spectral,
                    &c,
                    Quantity::Transmittance,
                    None,
                )
                .unwrap()[0]
            })
            .collect()
    };
    let got_t: Vec<[f64; 3]> = {
        use rayon::prelude::*;
        let m = Method::Fourier(Harmonics::Auto, 0.0, Some(t.clone()));
        cases
            .par_iter()
            .map(|(s, p)| {
                color::evaluate(
                    s,
                    std::slice::from_ref(p),
                    &m,
                    &c,
                    Quantity::Transmittance,
                    None,
                )
                .unwrap()[0]
            })
            .collect()
    };
    let st = stats(&c, &exact_t, &got_t);
    report.push(format!(
        "dielectric transmittance fourier (auto): mean {:.4} p95 {:.4} max {:.4}",
        st.mean, st.p95, st.max
    ));
    eprintln!("{}", report.join("\n"));
    assert!(st.p95 <= 0.1 && st.max <= 0.5, "{}", report.join("\n"));
}

#[test]
fn conductor_base_fourier_default() {
    let c = srgb();
    let cases = random_cases(11, |r| C64::new(r.uniform(0.2, 2.0), r.uniform(0.5, 4.0)));
    let exact = evaluate(&cases, &Method::Spectral, &c);
    let mut report = Vec::new();
    let t = table();
    for (name, method) in [
        (
            "fourier:3",
            Method::Fourier(Harmonics::Fixed(3), 0.0, Some(t.clone())),
        ),
        (
            "fourier:auto",
            Method::Fourier(Harmonics::Auto, 0.0, Some(t.clone())),
        ),
        (
            "fourier-exact:auto",
            Method::Fourier(Harmonics::Auto, 0.0, None),
        ),
        ("gaussian", Method::GaussianFitBelcour2017),
    ] {
        let s = stats(&c, &exact, &evaluate(&cases, &method, &c));
        report.push(format!(
            "conductor {name}: mean {:.4} p95 {:.4} max {:.4}",
            s.mean, s.p95, s.max
        ));
        if name == "fourier:auto" {
            assert!(s.p95 <= 0.3 && s.max <= 1.0, "{}", report.join("\n"));
        }
    }
    // The harmonics fourier:auto needs.
    let mut m: Vec<usize> = cases
        .iter()
        .map(|(s, p)| {
            let film = nacre_optics::fourier::FilmOnBase {
                n_ambient: 1.0,
                n_film: p.film_ior.unwrap(),
                base: [s.substrate().index_at(550.0).unwrap(); 3],
            };
            film.fourier_colour(
                &c,
                p.angle_deg.to_radians().cos(),
                p.thickness_nm.unwrap(),
                Harmonics::Auto,
                0.0,
                false,
            )
            .unwrap()
            .harmonics
        })
        .collect();
    m.sort_unstable();
    report.push(format!(
        "conductor fourier:auto harmonics: median {} p95 {} max {}",
        m[m.len() / 2],
        m[(m.len() - 1) * 95 / 100],
        m[m.len() - 1]
    ));
    eprintln!("{}", report.join("\n"));
}

/// The mean colour over thickness d ~ N(d0, σ²), by brute force: spectral colours on a
/// thickness grid of step ≤ min(5 nm, σ/4) over ±5σ, weighted by the Gaussian.
fn brute_force_average(
    c: &Colorimeter,
    stack: &Stack,
    angle_deg: f64,
    d0: f64,
    sigma: f64,
) -> [f64; 3] {
    let step = (sigma / 4.0).min(5.0);
    let n = (10.0 * sigma / step).ceil() as usize + 1;
    let grid: Vec<f64> = (0..n)
        .map(|k| d0 - 5.0 * sigma + 10.0 * sigma * k as f64 / (n - 1) as f64)
        .collect();
    let rule = SpectralRule::new(c, stack.max_opd_nm(Some((1, d0 + 5.0 * sigma))));
    let colours = stack
        .colours_over_thickness(1, angle_deg, &rule, &grid)
        .unwrap();
    let mut sum = [0.0; 3];
    let mut wsum = 0.0;
    for (d, col) in grid.iter().zip(&colours.reflectance) {
        let w = (-0.5 * ((d - d0) / sigma).powi(2)).exp();
        wsum += w;
        for k in 0..3 {
            sum[k] += w * col[k];
        }
    }
    sum.map(|v| v / wsum)
}

#[test]
fn prefiltered_fourier_3_matches_thickness_averaged_spectral() {
    use rayon::prelude::*;
    let c = srgb();
    let mut rng = Rng(23);
    let cases: Vec<(Stack, Point, f64)> = (0..POINTS)
        .map(|_| {
            let sigma = rng.uniform(5.0, 200.0);
            let point = Point {
                angle_deg: rng.uniform(0.0, 85.0),
                thickness_nm: Some(rng.uniform((5.0 * sigma).max(50.0), 10_000.0)),
                film_ior: Some(rng.uniform(1.2, 2.4)),
            };
            let base = C64::new(rng.uniform(1.0, 2.5), 0.0);
            (
                film_stack(point.film_ior.unwrap(), point.thickness_nm.unwrap(), base),
                point,
                sigma,
            )
        })
        .collect();
    let exact: Vec<[f64; 3]> = cases
        .par_iter()
        .map(|(s, p, sigma)| {
            brute_force_average(&c, s, p.angle_deg, p.thickness_nm.unwrap(), *sigma)
        })
        .collect();
    let t = table();
    let got: Vec<[f64; 3]> = cases
        .par_iter()
        .map(|(s, p, sigma)| {
            let m = Method::Fourier(Harmonics::Fixed(3), *sigma, Some(t.clone()));
            color::evaluate(
                s,
                std::slice::from_ref(p),
                &m,
                &c,
                Quantity::Reflectance,
                None,
            )
            .unwrap()[0]
        })
        .collect();
    let s = stats(&c, &exact, &got);
    let report = format!(
        "prefiltered fourier:3:σ (σ 5–200 nm): mean {:.4} p95 {:.4} max {:.4}",
        s.mean, s.p95, s.max
    );
    eprintln!("{report}");
    assert!(s.p95 <= 0.5, "{report}");
}
