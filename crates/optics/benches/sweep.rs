//! Throughput of the stack solver (issue target: ≥ 2×10⁷ single-film (angle, wavelength,
//! thickness) evaluations per second per core, both polarisations, f64).
//!
//! Run: `cargo bench -p nacre-optics --bench sweep`. Figures are in BENCHMARKS.md.

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let angles = common::angles_deg();
    let wavelengths = common::wavelengths_5nm();
    let thicknesses = common::thicknesses_nm();
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();

    // Single lossless film (soap-like 1.33 on glass 1.5 in air): angle × wavelength × thickness.
    let film = common::soap_film();
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
    let metal = common::absorbing_film_on_metal();
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
    let wavelengths_1nm = common::wavelengths_1nm();
    let five = common::five_layer_dispersive();
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

    // The same with no repeated medium (the second TiO₂ replaced by silicon).
    let distinct = common::five_distinct_dispersive();
    let mut g = c.benchmark_group("five-distinct-dispersive");
    g.throughput(Throughput::Elements(
        (angles.len() * wavelengths_1nm.len()) as u64,
    ));
    g.sample_size(20);
    g.bench_function("90x401 one thread", |b| {
        one_thread
            .install(|| b.iter(|| black_box(distinct.sweep(&angles, &wavelengths_1nm).unwrap())))
    });
    g.finish();
}

criterion_group!(sweep, benches);
criterion_main!(sweep);
