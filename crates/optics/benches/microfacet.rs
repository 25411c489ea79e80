//! Cost of the Monte Carlo reference of the rough iridescent lobe (issue 6, item 1): one
//! directional albedo E(ω_o) of a 1.33 | 800 nm film on glass at α = 0.3, and the exact
//! spectral film table it reads.
//!
//! Run: `cargo bench -p nacre-optics --bench microfacet`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
use nacre_optics::microfacet::{FilmTerm, directional_albedo_with};
use nacre_optics::{C64, Layer, Material, Stack};
use std::hint::black_box;

fn constant(n: f64) -> Material {
    Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap()
}

fn benches(c: &mut Criterion) {
    let colorimeter = Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    );
    let stack = Stack::new(
        constant(1.0),
        vec![Layer {
            material: constant(1.33),
            thickness_nm: 800.0,
        }],
        constant(1.5),
    )
    .unwrap();
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let film = FilmTerm::from_stack(&stack, &colorimeter).unwrap();
    let samples = 1 << 20;

    let mut g = c.benchmark_group("rough-film-mc");
    g.sample_size(10);
    g.bench_function("film table 4096 cells one thread", |b| {
        one_thread
            .install(|| b.iter(|| black_box(FilmTerm::from_stack(&stack, &colorimeter).unwrap())))
    });
    g.throughput(Throughput::Elements(samples as u64));
    g.bench_function("albedo 2^20 samples one thread", |b| {
        one_thread.install(|| {
            b.iter(|| black_box(directional_albedo_with(&film, 0.3, 0.6, samples, 1).unwrap()))
        })
    });
    g.bench_function("albedo 2^20 samples all threads", |b| {
        b.iter(|| black_box(directional_albedo_with(&film, 0.3, 0.6, samples, 1).unwrap()))
    });
    g.finish();
}

criterion_group!(microfacet, benches);
criterion_main!(microfacet);
