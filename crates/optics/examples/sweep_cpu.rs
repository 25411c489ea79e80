//! Single-film and five-layer sweep throughput per CPU-second (user + system time of this
//! process from `/proc/self/stat`, Linux only), so that the figure per core holds on a
//! machine shared with other jobs, where wall-clock benchmarks (criterion) measure the
//! share of a core the scheduler gave. Same grids as `benches/sweep.rs`; one thread.
//!
//! Run: `cargo run --release -p nacre-optics --example sweep_cpu [FILTER]`.

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

/// CPU seconds (user + system) this process has used.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
    let fields: Vec<&str> = stat[stat.rfind(')').unwrap() + 2..].split(' ').collect();
    let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
    ticks / 100.0
}

/// Evaluations per CPU-second of `f`, each call doing `n` evaluations, over ≥ 3 CPU seconds.
fn measure(name: &str, n: usize, mut f: impl FnMut()) {
    if let Some(filter) = std::env::args().nth(1)
        && !name.contains(&filter)
    {
        return;
    }
    f();
    let (start_cpu, start_wall) = (cpu_seconds(), std::time::Instant::now());
    let mut calls = 0;
    while cpu_seconds() - start_cpu < 3.0 {
        f();
        calls += 1;
    }
    let cpu = cpu_seconds() - start_cpu;
    let wall = start_wall.elapsed().as_secs_f64();
    println!(
        "{name}: {:.1} M evaluations per CPU-second ({calls} calls, {cpu:.2} s CPU, {wall:.2} s wall)",
        (calls * n) as f64 / cpu / 1e6
    );
}

fn main() {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .unwrap();
    let angles = grid(0.0, 1.0, 90);
    let wavelengths = grid(380.0, 5.0, 81);
    let thicknesses = grid(0.0, 10.0, 100);
    let n = angles.len() * wavelengths.len() * thicknesses.len();
    let film = |sub: Material, f: Material| {
        Stack::new(
            constant(1.0, 0.0),
            vec![Layer {
                material: f,
                thickness_nm: 0.0,
            }],
            sub,
        )
        .unwrap()
    };
    let soap = film(constant(1.5, 0.0), constant(1.33, 0.0));
    measure("single film 1.0 | 1.33 | 1.5, 90x81x100", n, || {
        black_box(
            soap.sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                .unwrap(),
        );
    });
    let metal = film(constant(0.27, 2.9), constant(1.5, 0.05));
    measure("absorbing film on metal, 90x81x100", n, || {
        black_box(
            metal
                .sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                .unwrap(),
        );
    });
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
    measure(
        "five-layer dispersive, 90x401",
        angles.len() * wavelengths_1nm.len(),
        || {
            black_box(five.sweep(&angles, &wavelengths_1nm).unwrap());
        },
    );
}
