//! The grids and stacks of the sweep benchmarks, shared by `benches/sweep.rs` (criterion,
//! wall clock) and `examples/sweep_cpu.rs` (per CPU-second), so that both measure the same
//! work.

use nacre_optics::{C64, Layer, Material, Stack};

/// Angles 0–89°, step 1°.
pub fn angles_deg() -> Vec<f64> {
    grid(0.0, 1.0, 90)
}

/// Wavelengths 380–780 nm, step 5 nm (the single-film sweeps).
pub fn wavelengths_5nm() -> Vec<f64> {
    grid(380.0, 5.0, 81)
}

/// Wavelengths 380–780 nm, step 1 nm (the five-layer sweep).
pub fn wavelengths_1nm() -> Vec<f64> {
    grid(380.0, 1.0, 401)
}

/// Film thicknesses 0–990 nm, step 10 nm.
pub fn thicknesses_nm() -> Vec<f64> {
    grid(0.0, 10.0, 100)
}

fn grid(start: f64, step: f64, count: usize) -> Vec<f64> {
    (0..count).map(|i| start + step * i as f64).collect()
}

fn constant(n: f64, k: f64) -> Material {
    Material::constant(format!("{n}"), C64::new(n, k)).unwrap()
}

fn dispersive(name: &str) -> Material {
    let text = std::fs::read_to_string(format!(
        "{}/../../tables/materials/{name}.yml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    Material::from_refractiveindex_yaml(name, name, &text).unwrap()
}

/// One film of constant index `film` on `base` in air (its thickness is swept).
fn single_film(film: C64, base: C64) -> Stack {
    Stack::new(
        constant(1.0, 0.0),
        vec![Layer {
            material: constant(film.re, film.im),
            thickness_nm: 0.0,
        }],
        constant(base.re, base.im),
    )
    .unwrap()
}

/// A lossless soap-like film: 1.33 on glass 1.5 in air.
pub fn soap_film() -> Stack {
    single_film(C64::new(1.33, 0.0), C64::new(1.5, 0.0))
}

/// An absorbing film 1.5 + 0.05i on a metal 0.27 + 2.9i.
pub fn absorbing_film_on_metal() -> Stack {
    single_film(C64::new(1.5, 0.05), C64::new(0.27, 2.9))
}

/// Five dispersive layers (refractiveindex.info data in `tables/materials/`): TiO₂ 56.45 nm,
/// MgF₂ 99.75, TiO₂ 56.45, fused silica 120, gold 10, on BK7 in air.
pub fn five_layer_dispersive() -> Stack {
    stack_of(&[
        ("tio2", 56.45),
        ("mgf2", 99.75),
        ("tio2", 56.45),
        ("fused-silica", 120.0),
        ("au", 10.0),
    ])
}

/// Films of bundled materials (name, thickness in nm), top first, on BK7 in air.
fn stack_of(films: &[(&str, f64)]) -> Stack {
    let layers = films
        .iter()
        .map(|&(m, d)| Layer {
            material: dispersive(m),
            thickness_nm: d,
        })
        .collect();
    Stack::new(dispersive("air"), layers, dispersive("bk7")).unwrap()
}

/// Five distinct dispersive layers: [`five_layer_dispersive`] with the second TiO₂ replaced by
/// 20 nm of silicon, so that no medium repeats (the kernel computes a repeated medium once).
pub fn five_distinct_dispersive() -> Stack {
    stack_of(&[
        ("tio2", 56.45),
        ("mgf2", 99.75),
        ("si", 20.0),
        ("fused-silica", 120.0),
        ("au", 10.0),
    ])
}
