//! Cost of an incoherent slab (issue 31 target: an incoherent slab between two coherent
//! coatings costs at most about twice the coherent stack alone per (angle, wavelength)).
//!
//! The pane: air | MgF₂ 99 nm, TiO₂ 60 nm | BK7 2 mm | TiO₂ 60 nm, MgF₂ 99 nm | air, bundled
//! dispersive materials, 90 angles × 401 wavelengths (380–780 nm at 1 nm), one thread:
//!
//! * `coherent pane`: the same five layers all coherent (the vectorised kernel, one pass);
//! * `incoherent pane`: the slab incoherent (one kernel pass over the top coating giving
//!   both sides, one over the bottom coating, the slab's single pass and the intensity
//!   recurrence, row by row);
//! * `coatings alone`: the four coating films on BK7 (the coherent stack without the slab).
//!
//! Run: `cargo bench -p nacre-optics --bench incoherent -- --warm-up-time 1 --measurement-time 5`.
//! Figures are in BENCHMARKS.md.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nacre_optics::{Layer, Material, Stack};
use std::hint::black_box;

fn material(name: &str) -> Material {
    let text = std::fs::read_to_string(format!(
        "{}/../../tables/materials/{name}.yml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    Material::from_refractiveindex_yaml(name, name, &text).unwrap()
}

fn stack(films: &[(&str, f64, bool)], substrate: &str) -> Stack {
    let layers = films
        .iter()
        .map(|&(m, d, _)| Layer {
            material: material(m),
            thickness_nm: d,
        })
        .collect();
    Stack::new(material("air"), layers, material(substrate))
        .unwrap()
        .with_incoherent(films.iter().map(|f| f.2).collect())
        .unwrap()
}

fn benches(c: &mut Criterion) {
    let angles: Vec<f64> = (0..90).map(f64::from).collect();
    let wavelengths: Vec<f64> = (0..=400).map(|i| 380.0 + f64::from(i)).collect();
    let pane = |slab_incoherent: bool| {
        stack(
            &[
                ("mgf2", 99.0, false),
                ("tio2", 60.0, false),
                ("bk7", 2e6, slab_incoherent),
                ("tio2", 60.0, false),
                ("mgf2", 99.0, false),
            ],
            "air",
        )
    };
    let coherent = pane(false);
    let incoherent = pane(true);
    let coatings = stack(
        &[
            ("mgf2", 99.0, false),
            ("tio2", 60.0, false),
            ("tio2", 60.0, false),
            ("mgf2", 99.0, false),
        ],
        "bk7",
    );
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut g = c.benchmark_group("incoherent");
    g.throughput(Throughput::Elements(
        (angles.len() * wavelengths.len()) as u64,
    ));
    g.sample_size(20);
    for (name, s) in [
        ("coherent pane", &coherent),
        ("incoherent pane", &incoherent),
        ("coatings alone", &coatings),
    ] {
        g.bench_function(format!("{name} 90x401 one thread"), |b| {
            one_thread.install(|| b.iter(|| black_box(s.sweep(&angles, &wavelengths).unwrap())))
        });
    }
    g.finish();
}

criterion_group!(incoherent_benches, benches);
criterion_main!(incoherent_benches);
