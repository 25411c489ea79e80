//! Cost of the full thickness Jacobian (`nacre_optics::jacobian::sweep_jacobian`, the reverse
//! sweep) against the powers alone, per (angle, wavelength), at L = 1, 4 and 8
//! constant-index films: one angle × 1000 wavelengths, one thread. "value simd" is
//! `Stack::sweep` (the vectorised kernel), "value scalar" the scalar recurrence
//! (`Prepared`, the path the Jacobian's powers follow), "jacobian" the powers plus ∂R_s,
//! ∂R_p, ∂T_s, ∂T_p by every film's thickness.
//!
//! Run: `cargo bench -p nacre-optics --bench jacobian -- --warm-up-time 1 --measurement-time 3`.
//! Figures are in BENCHMARKS.md.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nacre_optics::jacobian::{Wrt, sweep_jacobian};
use nacre_optics::{C64, Layer, Material, Prepared, Stack};
use std::hint::black_box;

fn stack(films: usize) -> Stack {
    let m = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
    let layers = (0..films)
        .map(|j| Layer {
            material: m(if j % 2 == 0 { 2.3 } else { 1.46 }),
            thickness_nm: 60.0 + 17.0 * j as f64,
        })
        .collect();
    Stack::new(m(1.0), layers, m(1.52)).unwrap()
}

fn benches(c: &mut Criterion) {
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let wavelengths: Vec<f64> = (0..1000).map(|i| 380.0 + 0.4 * i as f64).collect();
    let angles = [30.0];
    let mut g = c.benchmark_group("jacobian");
    g.throughput(Throughput::Elements(wavelengths.len() as u64));
    g.sample_size(20);
    for films in [1, 4, 8] {
        let s = stack(films);
        g.bench_function(format!("L={films} value simd"), |b| {
            one_thread.install(|| b.iter(|| black_box(s.sweep(&angles, &wavelengths).unwrap())))
        });
        let indices = s.indices_at(550.0).unwrap();
        let thickness = s.thicknesses_nm();
        let beta = 30f64.to_radians().sin();
        g.bench_function(format!("L={films} value scalar"), |b| {
            b.iter(|| {
                let p = Prepared::new(&indices, beta);
                let mut acc = 0.0;
                for &wl in &wavelengths {
                    acc += p.power(&p.amplitudes(wl, &thickness)).R_s;
                }
                black_box(acc)
            })
        });
        g.bench_function(format!("L={films} jacobian"), |b| {
            one_thread.install(|| {
                b.iter(|| {
                    black_box(sweep_jacobian(&s, &angles, &wavelengths, Wrt::Thickness).unwrap())
                })
            })
        });
    }
    g.finish();
}

criterion_group!(group, benches);
criterion_main!(group);
