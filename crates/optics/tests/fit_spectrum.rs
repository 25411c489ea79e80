//! The global spectrum fit on synthetic spectra: random 1–4 film dielectric stacks on glass
//! or silicon (10–2000 nm per film), 400–800 nm every 1 nm, Gaussian noise σ = 0.002, fitted
//! from bounds of 10–2000 nm alone. Success: every thickness within max(1 nm, 0.5 %) of the
//! truth. The CI test runs a small fixed-seed set; `--ignored` runs the statistical set of
//! issue 33 (200 cases, `NACRE_FIT_CASES` to change) and prints the success rate and the
//! time per fit.

use nacre_optics::fit::{Free, FreeKind, Measurement, Settings, Template, fit_spectrum};
use nacre_optics::{C64, Layer, Material, Stack};
use std::time::Instant;

/// splitmix64: a small deterministic generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// Film indices (MgF₂, SiO₂, Al₂O₃, Si₃N₄, Ta₂O₅, TiO₂, at about 550 nm).
const FILMS: [f64; 6] = [1.38, 1.46, 1.65, 2.02, 2.13, 2.4];

fn constant(n: C64) -> Material {
    Material::constant(format!("{n}"), n).unwrap()
}

struct Case {
    template: Template,
    truth: Vec<f64>,
    points: Vec<Measurement>,
}

fn case(rng: &mut Rng, max_films: u64) -> Case {
    let films = 1 + (rng.next() % max_films) as usize;
    let substrate = if rng.next().is_multiple_of(2) {
        C64::new(1.52, 0.0)
    } else {
        C64::new(3.95, 0.03)
    };
    // Neighbouring films differ (two of the same index would be one film).
    let mut last = usize::MAX;
    let mut layers = Vec::new();
    let mut truth = Vec::new();
    for _ in 0..films {
        let mut m = (rng.next() % FILMS.len() as u64) as usize;
        while m == last {
            m = (rng.next() % FILMS.len() as u64) as usize;
        }
        last = m;
        let d = 10.0 + 1990.0 * rng.uniform();
        truth.push(d);
        layers.push(Layer {
            material: constant(C64::new(FILMS[m], 0.0)),
            thickness_nm: d,
        });
    }
    let stack = Stack::new(constant(C64::new(1.0, 0.0)), layers, constant(substrate)).unwrap();
    let mut points = Vec::new();
    for w in 400..=800 {
        let wl = w as f64;
        let p = stack.evaluate(0.0, wl).unwrap().power;
        let r = 0.5 * (p.R_s + p.R_p) + 0.002 * rng.gauss();
        points.push(Measurement {
            angle_deg: 0.0,
            wavelength_nm: wl,
            value: r,
            sigma: None,
        });
    }
    let free = (1..=films)
        .map(|layer| Free {
            layer,
            kind: FreeKind::ThicknessNm,
            lo: 10.0,
            hi: 2000.0,
        })
        .collect();
    Case {
        template: Template::new(stack, free).unwrap(),
        truth,
        points,
    }
}

/// Per film count: fits, successes, seconds in all.
type Tally = [(usize, usize, f64); 4];

/// Fits `count` cases from `seed`; returns the failures (as text) and the tally by film
/// count.
fn run(seed: u64, count: usize, max_films: u64) -> (Vec<String>, Tally) {
    let mut rng = Rng(seed);
    let mut failures = Vec::new();
    let mut time = [(0usize, 0usize, 0.0f64); 4];
    for i in 0..count {
        let c = case(&mut rng, max_films);
        let t0 = Instant::now();
        let fit = fit_spectrum(&c.template, &c.points, &Settings::default()).unwrap();
        let dt = t0.elapsed().as_secs_f64();
        let films = c.truth.len();
        time[films - 1].0 += 1;
        time[films - 1].2 += dt;
        let ok = fit
            .x
            .iter()
            .zip(&c.truth)
            .all(|(x, t)| (x - t).abs() <= (0.005 * t).max(1.0));
        if ok {
            time[films - 1].1 += 1;
        } else {
            failures.push(format!(
                "case {i}: truth {:?} fit {:?} rms {:.4} starts {} fringes {:?}",
                c.truth, fit.x, fit.rms, fit.starts, fit.fringes
            ));
        }
    }
    (failures, time)
}

#[test]
fn synthetic_spectra_fit_from_the_bounds_alone() {
    // 1–3 films keep this within seconds in CI; the ignored test below runs 1–4.
    let (failures, time) = run(33, 12, 3);
    for f in &failures {
        eprintln!("{f}");
    }
    eprintln!("(fits, successes, seconds) by film count: {time:?}");
    assert!(failures.is_empty(), "{} of 12 failed", failures.len());
}

#[test]
#[ignore = "the statistical run of issue 33 (minutes): cargo test -p nacre-optics --test fit_spectrum -- --ignored --nocapture"]
fn synthetic_success_rate() {
    let count: usize = std::env::var("NACRE_FIT_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let (failures, time) = run(2026, count, 4);
    for f in &failures {
        println!("{f}");
    }
    let rate = 1.0 - failures.len() as f64 / count as f64;
    println!("success {:.1} % of {count}", 100.0 * rate);
    for (films, (n, ok, t)) in time.iter().enumerate() {
        println!(
            "{} films: {ok} of {n} fits succeed ({:.1} %), {:.3} s per fit",
            films + 1,
            100.0 * *ok as f64 / *n as f64,
            t / *n as f64
        );
    }
    assert!(rate >= 0.95, "success rate {rate}");
}
