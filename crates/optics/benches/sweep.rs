//! Throughput of the stack solver (issue target: ≥ 2×10⁷ single-film (angle, wavelength,
//! thickness) evaluations per second per core, both polarisations, f64).
//!
//! Run: `cargo bench -p nacre-optics --bench sweep`. Figures are in BENCHMARKS.md.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nacre_optics::{C64, Layer, Material, Stack};
use std::hint::black_box;

fn constant(n: f64, k: f64) -> Material {
    Material::constant(format!("{n}"), C64::new(n, k)).unwrap()
}

fn grid(start: f64, step: f64, count: usize) -> Vec<f64> {
    (0..count).map(|i| start + step * i as f64).collect()
}

fn dispersive(name: &str) -> Material {
    let text = std::fs::read_to_string(format!(
        "{}/../../tables/materials/{name}.yml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    Material::from_refractiveindex_yaml(name, name, &text).unwrap()
}

fn benches(c: &mut Criterion) {
    let angles = grid(0.0, 1.0, 90);
    let wavelengths = grid(380.0, 5.0, 81);
    let thicknesses = grid(0.0, 10.0, 100);
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();

    // Single lossless film (soap-like 1.33 on glass 1.5 in air): angle × wavelength × thickness.
    let film = Stack::new(
        constant(1.0, 0.0),
        vec![Layer {
            material: constant(1.33, 0.0),
            thickness_nm: 0.0,
        }],
        constant(1.5, 0.0),
    )
    .unwrap();
    let n = (angles.len() * wavelengths.len() * thicknesses.len()) as u64;
    let mut g = c.benchmark_group("single-film");
    g.throughput(Throughput::Elements(n));
    g.sample_size(20);
    g.bench_function("90x81x100 one thread", |b| {
        one_thread.install(|| {
            b.iter(|| {
                black_box(
                    film.sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                        .unwrap(),
                )
            })
        })
    });
    g.bench_function("90x81x100 all threads", |b| {
        b.iter(|| {
            black_box(
                film.sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                    .unwrap(),
            )
        })
    });
    // Absorbing film on a metal: the complex exponential path.
    let metal = Stack::new(
        constant(1.0, 0.0),
        vec![Layer {
            material: constant(1.5, 0.05),
            thickness_nm: 0.0,
        }],
        constant(0.27, 2.9),
    )
    .unwrap();
    g.bench_function("absorbing film on metal 90x81x100 one thread", |b| {
        one_thread.install(|| {
            b.iter(|| {
                black_box(
                    metal
                        .sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                        .unwrap(),
                )
            })
        })
    });
    g.finish();

    // Five dispersive layers on BK7 over angle × wavelength at 1 nm.
    let wavelengths_1nm = grid(380.0, 1.0, 401);
    let layers = [
        ("tio2", 56.45),
        ("mgf2", 99.75),
        ("tio2", 56.45),
        ("fused-silica", 120.0),
        ("au", 10.0),
    ]
    .iter()
    .map(|&(m, d)| Layer {
        material: dispersive(m),
        thickness_nm: d,
    })
    .collect();
    let five = Stack::new(dispersive("air"), layers, dispersive("bk7")).unwrap();
    let mut g = c.benchmark_group("five-layer-dispersive");
    g.throughput(Throughput::Elements(
        (angles.len() * wavelengths_1nm.len()) as u64,
    ));
    g.sample_size(20);
    g.bench_function("90x401 one thread", |b| {
        one_thread.install(|| b.iter(|| black_box(five.sweep(&angles, &wavelengths_1nm).unwrap())))
    });
    g.bench_function("90x401 all threads", |b| {
        b.iter(|| black_box(five.sweep(&angles, &wavelengths_1nm).unwrap()))
    });
    g.finish();
}

criterion_group!(sweep, benches);
criterion_main!(sweep);
