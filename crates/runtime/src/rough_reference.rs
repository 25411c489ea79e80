//! Monte Carlo reference images of a rough film-coated sphere (issue 6): the ground truth
//! that the split-sum paths of `shaders/material.wgsl` ([`FilmEval`]) are measured against.
//!
//! # What is computed
//!
//! The sphere of `shaders/scene.wgsl` (centre (0, 1, 0), radius 1) seen through the same
//! pinhole camera as the GPU render — one ray per pixel centre, (x + ½, y + ½), through
//! [`Camera::inverse_view_projection`] exactly as `scene_camera_ray` does — with a film of
//! constant thickness d and index n₂ on a dielectric base, its diffuse part black (so that the
//! specular lobe is what is compared). At each hit, with the local frame n = +z:
//!
//! ```text
//! L_o(ω_o) = ∫ f_r(ω_o, ω_i) L_env(ω_i) cos θ_i dω_i  +  f_r(ω_o, ω_l) E_l cos θ_l
//! f_r = D(h) G₂(ω_o, ω_i) C(F(ω_o·h)) / (4 cos θ_o cos θ_i)     (Belcour & Barla 2017, Eq. 1)
//! ```
//!
//! with C(F) the exact spectral colour of the film's Airy reflectance
//! ([`nacre_optics::microfacet::FilmTerm`]), the directional light evaluated in closed form
//! ([`nacre_optics::microfacet::radiance_directional`]) and the environment integral by
//! visible-normal sampling ([`nacre_optics::microfacet::sample_ggx_vndf`], Heitz 2018): each
//! sample's weight is C(F(ω_o·h)) G₂/G₁(ω_o) L_env(ω_i), ω_i = 2(ω_o·h)h − ω_o (0 below the
//! horizon). L_env is the environment's full-resolution level, bilinear, u repeating and v
//! clamped — what the GPU's sampler returns at level 0. Pixels whose ray misses the sphere
//! show L_env(ray) (not compared).
//!
//! # Noise
//!
//! Pixel p draws its `samples_per_pixel` samples from its own SplitMix64 stream keyed by
//! (seed, p): the image is deterministic and independent of the thread count. The standard
//! error of each pixel's mean (sample standard deviation / √N) is returned beside it;
//! [`ReferenceImage::mean_relative_error`] summarises it.

use crate::context::GpuContext;
use crate::environment::{EnvironmentMap, procedural_environment_with};
use crate::error::{Error, Result};
use crate::ibl::{env_direction_to_uv, sample_level_bilinear, tangent_frame};
use crate::image_io::{Level, RenderedImage};
use crate::render::{
    Camera, FilmEval, Light, RenderOutput, Renderer, SceneKind, SceneOptions, ThicknessMapping,
};
use crate::shaders::Technique;
use crate::tables::TableSet;
use nacre_format::table_io::{self, Precision, Table3};
use nacre_optics::colour::{Colorimeter, delta_e_2000, xyz_to_lab};
use nacre_optics::microfacet::{
    FilmTerm, SplitMix64, radiance_directional, sample_ggx_vndf, smith_g1, smith_g2,
};
use nacre_optics::{C64, Layer, Material, Stack};
use rayon::prelude::*;
use std::path::Path;

/// Centre of the analytic sphere (`SCENE_SPHERE_CENTRE` in `shaders/scene.wgsl`).
pub const SPHERE_CENTRE: [f64; 3] = [0.0, 1.0, 0.0];
/// Radius of the analytic sphere (`SCENE_SPHERE_RADIUS`).
pub const SPHERE_RADIUS: f64 = 1.0;

/// Everything the reference integrates (the GPU render must be set up identically).
pub struct ReferenceScene<'a> {
    /// Camera (the scene's: [`Camera::for_scene`]).
    pub camera: Camera,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The film's exact colour as a function of the microfacet incidence cosine.
    pub film: &'a FilmTerm,
    /// GGX roughness α.
    pub alpha: f64,
    /// The directional light.
    pub light: Light,
    /// The environment (linear RGB radiance).
    pub environment: &'a EnvironmentMap,
    /// Scale of the environment radiance.
    pub env_intensity: f64,
}

/// A reference image: radiance and its standard error per pixel.
#[derive(Clone, Debug)]
pub struct ReferenceImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Linear RGB radiance, row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// Standard error of each pixel's mean, per channel (0 where the ray misses).
    pub standard_error: Vec<[f32; 3]>,
    /// Whether the pixel's centre ray hits the sphere.
    pub hit: Vec<bool>,
    /// Samples per pixel N.
    pub samples_per_pixel: usize,
}

impl ReferenceImage {
    /// Mean over hit pixels of (standard error / radiance), averaged over channels with
    /// radiance above 10⁻⁴.
    pub fn mean_relative_error(&self) -> f64 {
        let mut sum = 0.0;
        let mut n = 0usize;
        for ((c, e), &h) in self.rgb.iter().zip(&self.standard_error).zip(&self.hit) {
            if !h {
                continue;
            }
            for k in 0..3 {
                if c[k] > 1e-4 {
                    sum += f64::from(e[k] / c[k]);
                    n += 1;
                }
            }
        }
        if n == 0 { 0.0 } else { sum / n as f64 }
    }
}

/// A camera ray: origin and unit direction.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin (the eye).
    pub origin: [f64; 3],
    /// Unit direction.
    pub dir: [f64; 3],
}

/// The camera rays of every pixel centre, as `scene_camera_ray` computes them from the same
/// f32 matrix.
pub fn camera_rays(camera: &Camera, width: u32, height: u32) -> Result<Vec<Ray>> {
    let m = camera.inverse_view_projection(f64::from(width) / f64::from(height))?;
    let apply = |v: [f64; 4]| -> [f64; 3] {
        let mut out = [0.0f64; 4];
        for (col, &x) in m.iter().zip(&v) {
            for r in 0..4 {
                out[r] += f64::from(col[r]) * x;
            }
        }
        let w = if out[3] != 0.0 { out[3] } else { 1.0 };
        [out[0] / w, out[1] / w, out[2] / w]
    };
    let origin = camera.eye.map(f64::from);
    let mut rays = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let ndc = [
                2.0 * (f64::from(x) + 0.5) / f64::from(width) - 1.0,
                1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(height),
            ];
            let a = apply([ndc[0], ndc[1], 0.0, 1.0]);
            let b = apply([ndc[0], ndc[1], 1.0, 1.0]);
            rays.push(Ray {
                origin,
                dir: normalize(sub(b, a)).unwrap_or([0.0, 0.0, -1.0]),
            });
        }
    }
    Ok(rays)
}

/// The outward unit normal where `ray` first hits the sphere, if it does.
pub fn hit_sphere(ray: &Ray) -> Option<[f64; 3]> {
    let oc = sub(ray.origin, SPHERE_CENTRE);
    let b = dot(oc, ray.dir);
    let c = dot(oc, oc) - SPHERE_RADIUS * SPHERE_RADIUS;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let (t_near, t_far) = (-b - root, -b + root);
    if t_far <= 0.0 {
        return None;
    }
    let t = if t_near > 0.0 { t_near } else { t_far };
    let p: [f64; 3] = std::array::from_fn(|k| ray.origin[k] + t * ray.dir[k]);
    normalize(sub(p, SPHERE_CENTRE))
}

/// The per-pixel integrator of a [`ReferenceScene`].
struct Integrator<'a> {
    scene: &'a ReferenceScene<'a>,
    level0: Level<4>,
    light_dir: [f64; 3],
    e_l: [f64; 3],
}

impl<'a> Integrator<'a> {
    fn new(scene: &'a ReferenceScene<'a>, samples_per_pixel: usize) -> Result<Self> {
        let out_of_range = |what: &str, value: f64, expected: &str| {
            Err(Error::OutOfRange {
                what: format!("Monte Carlo reference: {what}"),
                value,
                unit: "",
                expected: expected.into(),
            })
        };
        if !(scene.alpha > 0.0 && scene.alpha <= 1.0) {
            return out_of_range("GGX roughness α", scene.alpha, "0 < α ≤ 1");
        }
        if samples_per_pixel == 0 {
            return out_of_range("samples per pixel", 0.0, "at least 1");
        }
        if scene.width == 0 || scene.height == 0 {
            return out_of_range(
                "image pixels",
                (scene.width * scene.height) as f64,
                "at least 1",
            );
        }
        let env = scene.environment;
        if env.width == 0 || env.height == 0 || env.rgb.len() != env.width * env.height {
            return Err(Error::TexelCount {
                what: "Monte Carlo reference environment",
                texels: env.rgb.len(),
                width: env.width,
                height: env.height,
            });
        }
        let level0: Level<4> = (
            env.width,
            env.height,
            env.rgb
                .iter()
                .map(|c| {
                    let c = c.map(|x| x.clamp(0.0, 65504.0));
                    [c[0], c[1], c[2], 1.0]
                })
                .collect(),
        );
        let light_dir =
            normalize(scene.light.direction.map(f64::from)).ok_or_else(|| Error::Light {
                index: None,
                problem: "zero direction".into(),
            })?;
        let e_l = std::array::from_fn(|k| {
            f64::from(scene.light.colour[k]) * f64::from(scene.light.intensity)
        });
        Ok(Integrator {
            scene,
            level0,
            light_dir,
            e_l,
        })
    }

    fn env(&self, d: [f64; 3]) -> [f64; 3] {
        let (u, v) = env_direction_to_uv(d);
        sample_level_bilinear(&self.level0, u, v).map(|x| x * self.scene.env_intensity)
    }

    /// Radiance, its standard error and whether the ray hits, for pixel `p` along `ray`.
    fn pixel(&self, p: usize, ray: &Ray, samples: usize, seed: u64) -> ([f32; 3], [f32; 3], bool) {
        let alpha = self.scene.alpha;
        let Some(n) = hit_sphere(ray) else {
            return (self.env(ray.dir).map(|x| x as f32), [0.0; 3], false);
        };
        let (t, b) = tangent_frame(n);
        let to_local = |w: [f64; 3]| [dot(w, t), dot(w, b), dot(w, n)];
        let to_world = |w: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|k| w[0] * t[k] + w[1] * b[k] + w[2] * n[k])
        };
        let mut wo = to_local(ray.dir.map(|x| -x));
        wo[2] = wo[2].max(1e-4);
        let wo = normalize(wo).unwrap_or([0.0, 0.0, 1.0]);
        let g1 = smith_g1(wo, alpha);
        let mut rng = SplitMix64::stream(seed, p as u64);
        let mut sum = [0.0f64; 3];
        let mut sum2 = [0.0f64; 3];
        for _ in 0..samples {
            let h = sample_ggx_vndf(wo, alpha, rng.next_f64(), rng.next_f64());
            let cos_d = dot(wo, h);
            let wi: [f64; 3] = std::array::from_fn(|k| 2.0 * cos_d * h[k] - wo[k]);
            if wi[2] <= 0.0 || cos_d <= 0.0 {
                continue;
            }
            let w = smith_g2(wo, wi, alpha) / g1;
            let f = self.scene.film.reflectance_colour(cos_d);
            let l = self.env(to_world(wi));
            for k in 0..3 {
                let x = f[k] * w * l[k];
                sum[k] += x;
                sum2[k] += x * x;
            }
        }
        let count = samples as f64;
        let direct =
            radiance_directional(self.scene.film, alpha, wo, to_local(self.light_dir), 1.0);
        let mut colour = [0.0f32; 3];
        let mut error = [0.0f32; 3];
        for k in 0..3 {
            let mean = sum[k] / count;
            let var = (sum2[k] / count - mean * mean).max(0.0) * count / (count - 1.0).max(1.0);
            colour[k] = (mean + direct[k] * self.e_l[k]) as f32;
            error[k] = (var / count).sqrt() as f32;
        }
        (colour, error, true)
    }
}

/// Renders the reference (see the module doc), parallel over pixels.
///
/// # Errors
/// [`Error::Invalid`] for a roughness outside (0, 1], zero samples, an empty image or
/// environment, or a bad camera or light.
pub fn render_reference(
    scene: &ReferenceScene,
    samples_per_pixel: usize,
    seed: u64,
) -> Result<ReferenceImage> {
    let integrator = Integrator::new(scene, samples_per_pixel)?;
    let rays = camera_rays(&scene.camera, scene.width, scene.height)?;
    let pixels: Vec<([f32; 3], [f32; 3], bool)> = rays
        .par_iter()
        .enumerate()
        .map(|(p, ray)| integrator.pixel(p, ray, samples_per_pixel, seed))
        .collect();
    Ok(ReferenceImage {
        width: scene.width,
        height: scene.height,
        rgb: pixels.iter().map(|p| p.0).collect(),
        standard_error: pixels.iter().map(|p| p.1).collect(),
        hit: pixels.iter().map(|p| p.2).collect(),
        samples_per_pixel,
    })
}

/// The radiance of the listed pixels (row-major indices) of [`render_reference`]'s image,
/// bit-identical to it: each pixel draws from its own stream.
///
/// # Errors
/// As [`render_reference`], and for a pixel index outside the image.
pub fn render_reference_pixels(
    scene: &ReferenceScene,
    pixels: &[usize],
    samples_per_pixel: usize,
    seed: u64,
) -> Result<Vec<[f32; 3]>> {
    let integrator = Integrator::new(scene, samples_per_pixel)?;
    let rays = camera_rays(&scene.camera, scene.width, scene.height)?;
    pixels
        .par_iter()
        .map(|&p| {
            let ray = rays.get(p).ok_or_else(|| Error::Invalid {
                context: "Monte Carlo reference".into(),
                message: format!("pixel {p} outside a {} pixel image", rays.len()),
            })?;
            Ok(integrator.pixel(p, ray, samples_per_pixel, seed).0)
        })
        .collect()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let len = dot(a, a).sqrt();
    (len > 1e-12 && len.is_finite()).then(|| a.map(|x| x / len))
}

// ─── The comparison case of issue 6 ────────────────────────────────────────────────────────

/// The roughnesses of the reference images under `tests/golden/rough/`.
pub const COMPARISON_ALPHAS: [f64; 3] = [0.1, 0.3, 0.6];

/// Width and height of the reference images, pixels.
pub const COMPARISON_SIZE: u32 = 96;

/// Film index n₂ of the comparison sphere.
pub const COMPARISON_FILM_IOR: f32 = 1.8;

/// Film thickness d of the comparison sphere, nm (constant over the sphere).
pub const COMPARISON_THICKNESS_NM: f32 = 420.0;

/// Index of the dielectric base (the `rough-film-dielectric` and `film-dielectric` tables').
pub const COMPARISON_BASE_IOR: f64 = 1.5;

/// Samples per pixel of the committed reference images.
pub const COMPARISON_SAMPLES: usize = 32768;

/// Seed of the committed reference images.
pub const COMPARISON_SEED: u64 = 6;

/// The environment of the comparisons: the default studio ([`procedural_environment_with`]
/// at 256 × 128, rounded to half floats like `tables/env/studio.exr`) without its sun, whose
/// light the directional light alone carries — as engines light a scene with an analytic sun
/// and a sky probe. (With the sun also in the environment, a compact source of radiance 60
/// that a split sum spreads with the lobe-averaged film colour, the exact path's mean ΔE2000
/// is larger: see the README's figures.)
pub fn comparison_environment() -> EnvironmentMap {
    let (w, h) = crate::render::DEFAULT_ENVIRONMENT_SIZE;
    let mut env = procedural_environment_with(w, h, false);
    for t in &mut env.rgb {
        *t = t.map(|v| half::f16::from_f32(v).to_f32());
    }
    env
}

/// The GPU scene that the reference reproduces: the sphere of [`SceneKind::Sphere`] at
/// `size` × `size` with its camera, the default light (the environment is the caller's:
/// [`comparison_environment`]), a film of
/// [`COMPARISON_FILM_IOR`] and constant [`COMPARISON_THICKNESS_NM`] (glTF mapping with
/// min = max) on a dielectric of [`COMPARISON_BASE_IOR`] in air with a black diffuse, GGX
/// roughness `alpha`, drawn with `film_eval`.
pub fn comparison_options(alpha: f32, film_eval: FilmEval, size: u32) -> SceneOptions {
    let mut o = SceneOptions::new(SceneKind::Sphere);
    o.width = size;
    o.height = size;
    o.film_eval = film_eval;
    let m = &mut o.material;
    m.film_ior = COMPARISON_FILM_IOR;
    m.ambient_ior = 1.0;
    m.thickness = ThicknessMapping::Gltf {
        min_nm: COMPARISON_THICKNESS_NM,
        max_nm: COMPARISON_THICKNESS_NM,
    };
    m.thickness_roughness_nm = 0.0;
    m.drain_nm = 0.0;
    m.set_base(
        Material::constant(
            format!("{COMPARISON_BASE_IOR}"),
            C64::new(COMPARISON_BASE_IOR, 0.0),
        )
        .expect("a positive real index is a valid material"),
    );
    m.base_colour = [0.0; 3];
    m.roughness_alpha = alpha;
    m.transmission = false;
    m.film_weight = 1.0;
    o
}

/// The exact spectral film term of `options`' material (ambient | film of constant
/// thickness | base), for the reference. Errors for a material with a thickness map range
/// (the reference needs one thickness: [`ThicknessMapping::Gltf`] with min = max).
pub fn film_term_of(options: &SceneOptions, colorimeter: &Colorimeter) -> Result<FilmTerm> {
    let m = &options.material;
    let d = match m.thickness {
        ThicknessMapping::Gltf { min_nm, max_nm } if min_nm == max_nm && m.drain_nm == 0.0 => {
            f64::from(min_nm)
        }
        _ => {
            return Err(Error::Invalid {
                context: "Monte Carlo reference".into(),
                message:
                    "needs a constant film thickness (glTF mapping with min = max, no drainage)"
                        .into(),
            });
        }
    };
    let constant = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0));
    let stack = Stack::new(
        constant(f64::from(m.ambient_ior)).map_err(crate::Error::from)?,
        vec![Layer {
            material: constant(f64::from(m.film_ior)).map_err(crate::Error::from)?,
            thickness_nm: d,
        }],
        m.base.clone(),
    )
    .map_err(crate::Error::from)?;
    FilmTerm::from_stack(&stack, colorimeter).map_err(crate::Error::from)
}

/// The reference of `options` (built by [`comparison_options`] or alike) with `samples`
/// per pixel: the film term, the default or given environment, the light and camera of
/// `options`.
pub fn render_reference_of(
    options: &SceneOptions,
    environment: &EnvironmentMap,
    colorimeter: &Colorimeter,
    samples: usize,
    seed: u64,
) -> Result<ReferenceImage> {
    let film = film_term_of(options, colorimeter)?;
    render_reference(
        &ReferenceScene {
            camera: options.camera,
            width: options.width,
            height: options.height,
            film: &film,
            alpha: f64::from(options.material.roughness_alpha),
            light: options.light,
            environment,
            env_intensity: f64::from(options.env_intensity),
        },
        samples,
        seed,
    )
}

/// Mean CIEDE2000 between two linear images over the pixels where `mask` is true: each
/// colour is taken to XYZ by `colorimeter` (its output space → XYZ) and to CIELAB with the
/// colorimeter's white (Y = 1, the radiance of a white diffuser under irradiance π) — linear
/// radiance, before any exposure or tone mapping. Returns 0 for an empty mask.
pub fn mean_delta_e_2000(
    a: &[[f32; 3]],
    b: &[[f32; 3]],
    mask: &[bool],
    colorimeter: &Colorimeter,
) -> f64 {
    let white = colorimeter.white_xyz();
    let lab = |c: [f32; 3]| {
        xyz_to_lab(
            colorimeter.xyz_from_output(c.map(|x| f64::from(x.max(0.0)))),
            white,
        )
    };
    let mut sum = 0.0;
    let mut n = 0usize;
    for ((x, y), &m) in a.iter().zip(b).zip(mask) {
        if m {
            sum += delta_e_2000(lab(*x), lab(*y));
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// Writes linear RGB pixels as a float OpenEXR file (atomically).
pub fn write_linear_exr(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<()> {
    let table = Table3 {
        nx: width as usize,
        ny: height as usize,
        nz: 1,
        data: rgb.iter().flatten().copied().collect(),
    };
    Ok(table_io::write_exr(path, &table, Precision::Float)?)
}

/// Reads an OpenEXR image written by [`write_linear_exr`] (or any RGB EXR).
pub fn read_linear_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 3]>)> {
    let env = EnvironmentMap::load(path)?;
    Ok((env.width as u32, env.height as u32, env.rgb))
}

// ─── The rough-sphere row (`nacre render --scene rough-row`) ──────────────────────────────

/// Settings of [`render_rough_row`].
#[derive(Clone, Debug)]
pub struct RoughRowOptions {
    /// GGX roughness of each column (default 0.05, 0.1, 0.2, 0.35, 0.55, 0.8).
    pub alphas: Vec<f32>,
    /// Width and height of each sphere's tile, pixels (default 128).
    pub tile: u32,
    /// Monte Carlo samples per pixel of the reference row (default 1024).
    pub samples_per_pixel: usize,
    /// Exposure, EV stops, applied to every row before tone mapping (default 0).
    pub exposure_ev: f32,
    /// An OpenEXR environment, or `None` for [`comparison_environment`] (the default studio
    /// without its sun: the directional light is the sun).
    pub environment: Option<std::path::PathBuf>,
}

impl Default for RoughRowOptions {
    fn default() -> Self {
        RoughRowOptions {
            alphas: vec![0.05, 0.1, 0.2, 0.35, 0.55, 0.8],
            tile: 128,
            samples_per_pixel: 1024,
            exposure_ev: 0.0,
            environment: None,
        }
    }
}

/// What [`render_rough_row`] made.
pub struct RoughRow {
    /// Three rows of spheres, one column per α: the film-at-n·v shortcut, the exact path,
    /// the Monte Carlo reference (tone-mapped like `nacre render`'s scenes).
    pub image: RenderedImage,
    /// Mean ΔE2000 against the reference over each sphere's pixels: (α, shortcut, exact).
    pub delta_e: Vec<(f32, f64, f64)>,
    /// Seconds of GPU render passes (both paths, every column).
    pub gpu_seconds: f64,
    /// Seconds spent on the Monte Carlo reference.
    pub reference_seconds: f64,
}

/// Renders the comparison sphere ([`comparison_options`]) at each α of `options` by the
/// film-at-n·v shortcut and the exact path on the GPU (linear radiance) and by the Monte Carlo
/// reference on the CPU, and lays them out as three rows (shortcut, exact, reference), each
/// tile exposed, tone-mapped (Khronos PBR Neutral) and sRGB-encoded on the CPU exactly as
/// `material_display` does on the GPU.
///
/// # Errors
/// As [`Renderer::new_with_output`] and [`render_reference`]; [`Error::Invalid`] for no α,
/// an α outside (0, 1] or a tile outside 8–1024 pixels.
pub fn render_rough_row(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    options: &RoughRowOptions,
) -> Result<RoughRow> {
    if options.alphas.is_empty()
        || options.alphas.iter().any(|a| !(*a > 0.0 && *a <= 1.0))
        || !(8..=1024).contains(&options.tile)
    {
        let (what, value, unit, expected) =
            match options.alphas.iter().find(|a| !(**a > 0.0 && **a <= 1.0)) {
                Some(&a) => ("roughness α", f64::from(a), "", "0 < α ≤ 1"),
                None if options.alphas.is_empty() => ("roughnesses", 0.0, "", "at least one"),
                None => (
                    "tile",
                    options.tile as f64,
                    " pixels",
                    "8 to 1024 pixels a side",
                ),
            };
        return Err(Error::OutOfRange {
            what: format!("rough-sphere row: {what}"),
            value,
            unit,
            expected: expected.into(),
        });
    }
    let environment = match &options.environment {
        Some(path) => EnvironmentMap::load(path)?,
        None => comparison_environment(),
    };
    let colorimeter = tables.colorimeter()?;
    let thickness = crate::render::procedural_thickness_map(16);
    let first = comparison_options(options.alphas[0], FilmEval::Exact, options.tile);
    let renderer = Renderer::new_with_output(
        ctx,
        tables,
        technique,
        &first.technique_options(),
        RenderOutput::Linear,
    )?;
    let tile = options.tile as usize;
    let columns = options.alphas.len();
    let (width, height) = (tile * columns, tile * 3);
    let mut pixels = vec![0u8; width * height * 4];
    let exposure = 2f64.powf(f64::from(options.exposure_ev));
    let mut delta_e = Vec::with_capacity(columns);
    let (mut gpu_seconds, mut reference_seconds) = (0.0, 0.0);
    for (col, &alpha) in options.alphas.iter().enumerate() {
        let mut rows: Vec<Vec<[f32; 3]>> = Vec::with_capacity(3);
        for eval in [FilmEval::NormalView, FilmEval::Exact] {
            let o = comparison_options(alpha, eval, options.tile);
            let image = renderer.render_linear_with(ctx, tables, &o, &environment, &thickness)?;
            gpu_seconds += image.gpu_seconds;
            rows.push(image.rgb);
        }
        let o = comparison_options(alpha, FilmEval::Exact, options.tile);
        let start = std::time::Instant::now();
        let reference = render_reference_of(
            &o,
            &environment,
            &colorimeter,
            options.samples_per_pixel,
            COMPARISON_SEED,
        )?;
        reference_seconds += start.elapsed().as_secs_f64();
        delta_e.push((
            alpha,
            mean_delta_e_2000(&rows[0], &reference.rgb, &reference.hit, &colorimeter),
            mean_delta_e_2000(&rows[1], &reference.rgb, &reference.hit, &colorimeter),
        ));
        rows.push(reference.rgb);
        for (row, rgb) in rows.iter().enumerate() {
            for y in 0..tile {
                for x in 0..tile {
                    let c = rgb[y * tile + x].map(|v| f64::from(v) * exposure);
                    let encoded = display_colour(c);
                    let at = ((row * tile + y) * width + col * tile + x) * 4;
                    pixels[at..at + 3].copy_from_slice(&encoded);
                    pixels[at + 3] = 255;
                }
            }
        }
    }
    Ok(RoughRow {
        image: RenderedImage {
            width: width as u32,
            height: height as u32,
            pixels,
            gpu_seconds,
        },
        delta_e,
        gpu_seconds,
        reference_seconds,
    })
}

/// Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral) then the sRGB transfer
/// function, on exposed linear radiance: the CPU twin of `material_display`
/// (`shaders/material.wgsl`). Non-finite or negative channels count as 0.
pub fn display_colour(c: [f64; 3]) -> [u8; 3] {
    let mut c = c.map(|x| {
        if x.is_finite() {
            x.clamp(0.0, 65504.0)
        } else {
            0.0
        }
    });
    let start_compression = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = c[0].min(c[1]).min(c[2]);
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    c = c.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak >= start_compression {
        let d = 1.0 - start_compression;
        let new_peak = 1.0 - d * d / (peak + d - start_compression);
        c = c.map(|v| v * new_peak / peak);
        let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
        c = c.map(|v| v + (new_peak - v) * g);
    }
    c.map(|v| {
        let v = v.clamp(0.0, 1.0);
        let e = if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0 + 0.5).floor().clamp(0.0, 255.0) as u8
    })
}
