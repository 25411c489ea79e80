//! The probe points and CPU colours shared by the GPU = CPU tests (gpu_probe.rs for the WGSL
//! techniques, engine_shaders_gpu.rs for the GLSL and HLSL libraries): the same inputs
//! and the same references for both.
#![allow(dead_code)]

use nacre_bake::commands::color::{self, Method, Point, Quantity};
use nacre_format::set::default_baked_dir;
use nacre_optics::{C64, Material};
use nacre_runtime::FilmInput;

/// Deterministic uniform numbers in [0, 1).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub fn input(cos_theta: f64, d: f64, n: f64, sigma: f64, ambient: f64, base: C64) -> FilmInput {
    FilmInput {
        cos_theta_i: cos_theta as f32,
        thickness_nm: d as f32,
        film_ior: n as f32,
        sigma_thickness_nm: sigma as f32,
        ambient_ior: ambient as f32,
        base_ior: [base.re as f32; 3],
        base_kappa: [base.im as f32; 3],
        ..Default::default()
    }
}

pub fn manifest(name: &str) -> std::path::PathBuf {
    default_baked_dir().join(format!("{name}.json"))
}

pub fn max_diff(a: &[[f64; 3]], b: &[[f32; 3]]) -> (f64, usize) {
    let mut worst = (0.0f64, 0usize);
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for c in 0..3 {
            let d = (x[c] - f64::from(y[c])).abs();
            if d.is_nan() || d > worst.0 {
                worst = (d, i);
            }
        }
    }
    worst
}

/// CPU colours of `method` for one film (ambient 1.0) on `base` at the given points.
pub fn cpu_colours(
    method: &Method,
    base: &Material,
    points: &[(f64, f64, f64)],
    quantity: Quantity,
    colorimeter: &nacre_optics::colour::Colorimeter,
) -> Vec<[f64; 3]> {
    let ambient = Material::constant("1.0", C64::new(1.0, 0.0)).unwrap();
    let film = Material::constant("1.5", C64::new(1.5, 0.0)).unwrap();
    let stack = color::film_stack(ambient, film, 100.0, vec![], base.clone()).unwrap();
    let pts: Vec<Point> = points
        .iter()
        .map(|&(c, d, n)| Point {
            angle_deg: c.clamp(0.0, 1.0).acos().to_degrees(),
            thickness_nm: Some(d),
            film_ior: Some(n),
        })
        .collect();
    color::evaluate(&stack, &pts, method, colorimeter, quantity, None).unwrap()
}

pub fn random_points(seed: u64, count: usize, d_max: f64) -> Vec<(f64, f64, f64)> {
    let mut rng = Lcg(seed);
    (0..count)
        .map(|_| {
            let angle = rng.next() * 85.0;
            (
                angle.to_radians().cos(),
                rng.next() * d_max,
                1.2 + rng.next() * 1.2,
            )
        })
        .collect()
}

/// The stacks of the `film_stack` probes (`gpu_probe.rs` for the WGSL technique,
/// `engine_shaders_gpu.rs` for the GLSL and HLSL libraries): 1 to 8 films, dielectric,
/// absorbing metal films (10 nm silver, chromium) and bases, dispersive materials, an ambient
/// denser than its films (total internal reflection, evanescent films), the rule ladder
/// (`None`) and a fixed rule of 16 nodes.
pub fn stack_cases() -> Vec<(&'static str, nacre_optics::Stack, Option<usize>)> {
    use nacre_format::materials;
    use nacre_optics::{Layer, Stack};
    let constant = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
    let bundled = |name: &str| materials::resolve(name, "test", None).unwrap();
    let layer = |material: Material, thickness_nm: f64| Layer {
        material,
        thickness_nm,
    };
    vec![
        (
            "one film on gold",
            Stack::new(
                constant(1.0),
                vec![layer(constant(1.45), 300.0)],
                bundled("au"),
            )
            .unwrap(),
            None,
        ),
        (
            "metal-dielectric-metal",
            Stack::new(
                constant(1.0),
                vec![layer(bundled("ag"), 10.0), layer(constant(1.38), 150.0)],
                bundled("ag"),
            )
            .unwrap(),
            None,
        ),
        (
            "dispersive four films on silicon",
            Stack::new(
                bundled("air"),
                vec![
                    layer(bundled("mgf2"), 90.0),
                    layer(bundled("tio2"), 50.0),
                    layer(bundled("cr"), 8.0),
                    layer(bundled("water"), 200.0),
                ],
                bundled("si"),
            )
            .unwrap(),
            None,
        ),
        (
            "eight films, fixed 16 nodes",
            Stack::new(
                constant(1.0),
                (0..8)
                    .map(|j| {
                        layer(
                            constant(if j % 2 == 0 { 1.38 } else { 2.3 }),
                            40.0 + 10.0 * j as f64,
                        )
                    })
                    .collect(),
                constant(1.52),
            )
            .unwrap(),
            Some(16),
        ),
        (
            "dense ambient, total internal reflection",
            Stack::new(
                constant(1.6),
                vec![layer(constant(1.0), 120.0), layer(constant(1.33), 200.0)],
                constant(1.2),
            )
            .unwrap(),
            None,
        ),
    ]
}
