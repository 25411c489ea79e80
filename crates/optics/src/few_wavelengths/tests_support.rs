//! Shared helpers of the few-wavelength tests: colorimeter, materials, random stacks, ΔE2000.

use super::*;
use crate::colour::{Illuminant, Observer, OutputSpace, RgbSpace, delta_e_2000, xyz_to_lab};
use crate::{C64, Layer, Material, Stack};

pub fn colorimeter() -> Colorimeter {
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
}

/// A bundled material (tables/materials).
pub fn metal(name: &str) -> Material {
    let text = match name {
        "au" => include_str!("../../../../tables/materials/au.yml"),
        "ag" => include_str!("../../../../tables/materials/ag.yml"),
        "cr" => include_str!("../../../../tables/materials/cr.yml"),
        "mgf2" => include_str!("../../../../tables/materials/mgf2.yml"),
        "tio2" => include_str!("../../../../tables/materials/tio2.yml"),
        "bk7" => include_str!("../../../../tables/materials/bk7.yml"),
        _ => include_str!("../../../../tables/materials/al.yml"),
    };
    Material::from_refractiveindex_yaml(name, name, text).unwrap()
}

/// A deterministic generator (SplitMix64).
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// The issue's population: 2–6 films, dielectric (n 1.2–2.5) or metal (au, ag, cr, al,
/// 5–30 nm), total optical thickness ≤ 2 µm, on a dielectric, metal or air base, 0–85°.
pub fn random_stack(rng: &mut Rng) -> (Stack, f64) {
    let films = 2 + (rng.next() * 5.0) as usize;
    let budget = rng.range(0.0, 2000.0);
    let shares: Vec<f64> = (0..films).map(|_| rng.range(0.05, 1.0)).collect();
    let total: f64 = shares.iter().sum();
    let mut layers = Vec::new();
    for share in shares {
        if rng.next() < 0.25 {
            let name = ["au", "ag", "cr", "al"][(rng.next() * 4.0) as usize];
            layers.push(Layer {
                material: metal(name),
                thickness_nm: rng.range(5.0, 30.0),
            });
        } else {
            let n = rng.range(1.2, 2.5);
            layers.push(Layer {
                material: Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap(),
                thickness_nm: budget * share / total / n,
            });
        }
    }
    let base = match (rng.next() * 3.0) as usize {
        0 => {
            let n = rng.range(1.3, 2.5);
            Material::constant("base", C64::new(n, 0.0)).unwrap()
        }
        1 => metal(["au", "ag", "cr", "al"][(rng.next() * 4.0) as usize]),
        _ => Material::constant("air", C64::new(1.0, 0.0)).unwrap(),
    };
    let ambient = Material::constant("ambient", C64::new(1.0, 0.0)).unwrap();
    let angle = rng.range(0.0, 85.0);
    (Stack::new(ambient, layers, base).unwrap(), angle)
}

pub fn reflectance_colour(
    stack: &Stack,
    angle: f64,
    nodes: &[f64],
    weights: &[[f64; 3]],
) -> [f64; 3] {
    let mut c = [0.0; 3];
    for (&l, w) in nodes.iter().zip(weights) {
        let r = stack.evaluate(angle, l).unwrap().power.R();
        for k in 0..3 {
            c[k] += r * w[k];
        }
    }
    c
}

pub fn delta_e(colorimeter: &Colorimeter, a: [f64; 3], b: [f64; 3]) -> f64 {
    let white = colorimeter.white_xyz();
    let lab = |c| xyz_to_lab(colorimeter.xyz_from_output(c), white);
    delta_e_2000(lab(a), lab(b))
}
