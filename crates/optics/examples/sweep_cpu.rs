//! Single-film and five-layer sweep throughput per CPU-second (user + system time of this
//! process from `/proc/self/stat`, Linux only), so that the figure per core holds on a
//! machine shared with other jobs, where wall-clock benchmarks (criterion) measure the
//! share of a core the scheduler gave. Same grids as `benches/sweep.rs`; one thread.
//!
//! Run: `cargo run --release -p nacre-optics --example sweep_cpu [FILTER]`.

#[path = "../benches/common/mod.rs"]
mod common;

use std::hint::black_box;

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
    let angles = common::angles_deg();
    let wavelengths = common::wavelengths_5nm();
    let thicknesses = common::thicknesses_nm();
    let n = angles.len() * wavelengths.len() * thicknesses.len();
    let soap = common::soap_film();
    measure("single film 1.0 | 1.33 | 1.5, 90x81x100", n, || {
        black_box(
            soap.sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                .unwrap(),
        );
    });
    let metal = common::absorbing_film_on_metal();
    measure("absorbing film on metal, 90x81x100", n, || {
        black_box(
            metal
                .sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                .unwrap(),
        );
    });
    let wavelengths_1nm = common::wavelengths_1nm();
    let five = common::five_layer_dispersive();
    measure(
        "five-layer dispersive, 90x401",
        angles.len() * wavelengths_1nm.len(),
        || {
            black_box(five.sweep(&angles, &wavelengths_1nm).unwrap());
        },
    );
    let distinct = common::five_distinct_dispersive();
    measure(
        "five distinct dispersive layers, 90x401",
        angles.len() * wavelengths_1nm.len(),
        || {
            black_box(distinct.sweep(&angles, &wavelengths_1nm).unwrap());
        },
    );
}
