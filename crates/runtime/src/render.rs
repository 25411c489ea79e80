//! The headless scene renderer behind `nacre render`: analytic scenes (a film-coated sphere,
//! a soap bubble, an oil film on a plane) ray-cast in a fragment shader, shaded by the
//! thin-film microfacet material of `shaders/material.wgsl` with any technique, lit by a
//! directional light and an equirectangular HDR environment, tone-mapped and read back as
//! sRGB-encoded RGBA8 pixels.
//!
//! Bind groups (`shaders/README.md`): 0 = the view ([`ViewUniform`], the environment, its
//! GGX-prefiltered layers, the E₁ table and the `rough-film-lut` of the split-sum paths:
//! [`FilmEval`], [`crate::ibl`]), 1 = the technique's tables ([`TechniqueBinding`]), 2 = the material
//! ([`MaterialUniform`], the thickness map and its sampler). The pipeline's source is
//! `shaders::film_pipeline(technique.module(), &["material", "scene"])` (= `shaders::compose(technique,
//! &[MATERIAL, SCENE])`).
//!
//! CPU-side inputs:
//!
//! * the environment ([`EnvironmentMap`]): an OpenEXR equirectangular image (row 0 = the
//!   zenith, u = 0.5 looks down −z), or the default `tables/env/studio.exr`, which is
//!   [`procedural_environment`]`(256, 128)` written once in half floats (project-made, CC0;
//!   `tables/env/README.md`). Uploaded as `Rgba16Float` with a full mip chain of 2×2 box
//!   filters built here;
//! * the thickness map ([`ThicknessMap`]): an 8- or 16-bit greyscale PNG, or
//!   [`procedural_thickness_map`]. Uploaded as `Rg16Float` holding (g, g²) with a full mip
//!   chain, so that the shader can recover the thickness variance that filtering removed.
//!
//! ```no_run
//! use nacre_runtime::render::{SceneKind, SceneOptions, render_scene};
//! use nacre_runtime::{GpuContext, TableSet, Technique};
//! # fn main() -> nacre_runtime::Result<()> {
//! let ctx = GpuContext::new_headless()?;
//! let mut tables = TableSet::load(&ctx, "tables/baked/film-dielectric.json".as_ref())?;
//! tables.add(&ctx, "tables/baked/fourier-srgb.json".as_ref())?;
//! let mut options = SceneOptions::new(SceneKind::Sphere);
//! options.fit_to_tables(&tables)?;
//! let image = render_scene(&ctx, &tables, Technique::Fourier, &options)?;
//! image.write_png("sphere.png".as_ref())?;
//! # Ok(()) }
//! ```

use crate::bindings::{SpectralSetup, TechniqueBinding, TechniqueOptions};
use crate::context::BufferInitExt;
use crate::context::GpuContext;
pub use crate::environment::{
    DEFAULT_ENVIRONMENT_SIZE, EnvironmentMap, SUN_DIRECTION, default_environment_path,
    procedural_environment, procedural_environment_with,
};
use crate::error::{Error, Result};
pub use crate::image_io::{Level, MAX_DIMENSION};
use crate::image_io::{check_image_size, mip_chain};
use crate::readback::read_texture;
use crate::shaders::{self, Technique};
use crate::tables::TableSet;
use bytemuck::{Pod, Zeroable};
use half::f16;
use nacre_optics::{C64, Material};
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Size of the built-in thickness map, texels (square).
pub const DEFAULT_THICKNESS_MAP_SIZE: usize = 256;

/// The render target format: 8-bit RGBA holding sRGB-encoded values written by the shader
/// (`material_display`), not an `…Srgb` format: the bytes read back are the bytes of the PNG.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

// ─── Scene description ─────────────────────────────────────────────────────────────────────

/// Which analytic scene `shaders/scene.wgsl` ray-casts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneKind {
    /// A film-coated sphere (radius 1 at (0, 1, 0)) on a dielectric or metal base.
    Sphere,
    /// The same sphere as a soap bubble: a thin transparent shell, both walls reflecting and
    /// transmitting, the film draining towards the bottom.
    Bubble,
    /// The plane y = 0 to the horizon with the thickness map tiled across it (an oil slick).
    Plane,
}

impl SceneKind {
    /// Every scene.
    pub const ALL: [SceneKind; 3] = [SceneKind::Sphere, SceneKind::Bubble, SceneKind::Plane];

    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Sphere => "sphere",
            SceneKind::Bubble => "bubble",
            SceneKind::Plane => "plane",
        }
    }

    /// `ViewParams.scene` in `shaders/scene.wgsl`.
    fn id(self) -> u32 {
        match self {
            SceneKind::Sphere => 0,
            SceneKind::Bubble => 1,
            SceneKind::Plane => 2,
        }
    }
}

impl FromStr for SceneKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        SceneKind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::Invalid {
                context: format!("scene `{s}`"),
                message: "expected sphere, bubble or plane".into(),
            })
    }
}

/// How the film enters the lighting (`MaterialParams.film_eval` in `shaders/material.wgsl`,
/// whose header has the equations; `nacre render --film-eval`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FilmEval {
    /// The original nacre path: the light sees the film at its half vector v·h; the
    /// environment is the box-filtered mip chain at a roughness-dependent level times the film
    /// at n·v times Karis's fit of the GGX albedo, 1 − 0.55√α (no split-sum tables).
    #[default]
    Classic,
    /// The engines' common shortcut (Belcour & Barla 2017, §6, Fig. 16, bottom row): the film
    /// colour is evaluated once per pixel, at n·v, and used for every light and for the
    /// split-sum environment: L̃(r, α) R_f(n·v) E₁(n·v, α).
    NormalView,
    /// Film per light at its half vector (F(ω_o·h)), and for the environment the iridescent
    /// lobe's directional albedo E_f(n·v, α, d, n₂) from a `rough-film-lut` table times the
    /// film-weighted mean of the prefiltered environment over 32 visible normals of the lobe,
    /// each read at its own footprint (filtered importance sampling).
    Exact,
}

impl FilmEval {
    /// Every path.
    pub const ALL: [FilmEval; 3] = [FilmEval::Classic, FilmEval::NormalView, FilmEval::Exact];

    /// The name used on the command line (`classic`, `nv`, `exact`).
    pub fn name(self) -> &'static str {
        match self {
            FilmEval::Classic => "classic",
            FilmEval::NormalView => "nv",
            FilmEval::Exact => "exact",
        }
    }

    /// `MaterialParams.film_eval`.
    pub fn id(self) -> u32 {
        match self {
            FilmEval::Classic => 0,
            FilmEval::NormalView => 1,
            FilmEval::Exact => 2,
        }
    }

    /// Whether the path samples the GGX-prefiltered environment (the split sum).
    pub fn split_sum(self) -> bool {
        self != FilmEval::Classic
    }
}

impl FromStr for FilmEval {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        FilmEval::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::Invalid {
                context: format!("film evaluation `{s}`"),
                message: "expected classic, nv or exact".into(),
            })
    }
}

/// What a [`Renderer`] writes: display pixels or linear radiance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RenderOutput {
    /// Exposed, tone-mapped (PBR Neutral), sRGB-encoded RGBA8 ([`TARGET_FORMAT`]).
    #[default]
    Display,
    /// Linear scene radiance before exposure and tone mapping, `Rgba32Float`
    /// ([`LINEAR_TARGET_FORMAT`]; `scene_fs_linear`).
    Linear,
}

/// The render target format of [`RenderOutput::Linear`].
pub const LINEAR_TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position, world units.
    pub eye: [f32; 3],
    /// The point looked at, world units.
    pub target: [f32; 3],
    /// Up direction (need not be unit or orthogonal to the view direction).
    pub up: [f32; 3],
    /// Vertical field of view, degrees, in (0, 180).
    pub fov_y_deg: f32,
}

impl Camera {
    /// The default camera of `scene`.
    pub fn for_scene(scene: SceneKind) -> Camera {
        match scene {
            SceneKind::Sphere | SceneKind::Bubble => Camera {
                eye: [0.0, 1.45, 3.9],
                target: [0.0, 1.0, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 36.0,
            },
            SceneKind::Plane => Camera {
                eye: [0.0, 1.1, 3.0],
                target: [0.0, 0.0, -2.5],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 55.0,
            },
        }
    }

    /// The inverse of projection × view for an image of aspect ratio `aspect` (width /
    /// height), as WGSL columns: clip space (x, y ∈ [−1, 1], z ∈ [0, 1] from near to far) →
    /// world.
    pub fn inverse_view_projection(&self, aspect: f64) -> Result<[[f32; 4]; 4]> {
        let bad = |message: String| Error::Invalid {
            context: "camera".into(),
            message,
        };
        let v = |a: [f32; 3]| a.map(f64::from);
        let (eye, target, up) = (v(self.eye), v(self.target), v(self.up));
        if !eye.iter().chain(&target).chain(&up).all(|x| x.is_finite()) {
            return Err(bad(format!("non-finite eye, target or up: {self:?}")));
        }
        let fov = f64::from(self.fov_y_deg);
        if !(fov > 0.0 && fov < 180.0) {
            return Err(bad(format!(
                "vertical field of view {fov} degrees (expected between 0 and 180)"
            )));
        }
        if !(aspect > 0.0 && aspect.is_finite()) {
            return Err(bad(format!("aspect ratio {aspect}")));
        }
        let forward = normalize(sub(target, eye)).ok_or_else(|| bad("eye equals target".into()))?;
        let right = normalize(cross(forward, up))
            .ok_or_else(|| bad("up is parallel to the view direction".into()))?;
        let true_up = cross(right, forward);
        // Camera to world: columns right, up, −forward (the camera looks down −z), eye.
        let c = [
            [right[0], true_up[0], -forward[0], eye[0]],
            [right[1], true_up[1], -forward[1], eye[1]],
            [right[2], true_up[2], -forward[2], eye[2]],
            [0.0, 0.0, 0.0, 1.0],
        ];
        // Inverse of the right-handed perspective projection with depth in [0, 1]:
        // P = [[f/a, 0, 0, 0], [0, f, 0, 0], [0, 0, A, B], [0, 0, −1, 0]],
        // A = far/(near − far), B = near·far/(near − far), f = 1/tan(fov/2).
        let (near, far) = (0.05, 1000.0);
        let f = 1.0 / (0.5 * fov.to_radians()).tan();
        let b = near * far / (near - far);
        let p_inv = [
            [aspect / f, 0.0, 0.0, 0.0],
            [0.0, 1.0 / f, 0.0, 0.0],
            [0.0, 0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0 / b, 1.0 / near],
        ];
        let mut m = [[0.0f64; 4]; 4];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = (0..4).map(|k| c[i][k] * p_inv[k][j]).sum();
            }
        }
        // WGSL matrices are column-major.
        Ok(std::array::from_fn(|col| {
            std::array::from_fn(|row| m[row][col] as f32)
        }))
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    (len > 1e-12 && len.is_finite()).then(|| a.map(|x| x / len))
}

/// A directional light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Direction from the scene towards the light (need not be unit).
    pub direction: [f32; 3],
    /// Linear RGB colour.
    pub colour: [f32; 3],
    /// Irradiance at normal incidence = colour × intensity.
    pub intensity: f32,
}

impl Default for Light {
    /// The sun of the default environment: [`SUN_DIRECTION`], warm white, intensity 3.
    fn default() -> Self {
        Light {
            direction: SUN_DIRECTION.map(|x| x as f32),
            colour: [1.0, 0.95, 0.88],
            intensity: 3.0,
        }
    }
}

/// How the greyscale thickness map value g ∈ [0, 1] becomes the film thickness d.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThicknessMapping {
    /// Spatially varying thickness, Sussenbach 2013 §4.2 (Eq. 4.3–4.4):
    /// d = d_avg + d_rel (2g − 1).
    Svt {
        /// Average thickness d_avg, nm.
        average_nm: f32,
        /// Relative thickness d_rel, nm (d spans d_avg ± d_rel).
        relative_nm: f32,
    },
    /// glTF `KHR_materials_iridescence`: d = mix(d_min, d_max, g).
    Gltf {
        /// Thickness at g = 0, nm.
        min_nm: f32,
        /// Thickness at g = 1, nm.
        max_nm: f32,
    },
}

impl ThicknessMapping {
    /// The largest thickness the mapping produces (before drainage), nm.
    pub fn max_nm(&self) -> f32 {
        match *self {
            ThicknessMapping::Svt {
                average_nm,
                relative_nm,
            } => average_nm + relative_nm.abs(),
            ThicknessMapping::Gltf { min_nm, max_nm } => min_nm.max(max_nm),
        }
    }
}

/// Whether the base under the film is a dielectric (with a Lambertian diffuse) or a metal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseKind {
    /// Dielectric: a Lambertian diffuse of albedo `base_colour` under the film, weighted by
    /// 1 − the film's reflectance.
    Dielectric,
    /// Metal: no diffuse; the film term already contains the metal's reflectance.
    Metal,
}

impl BaseKind {
    /// [`BaseKind::Metal`] when the material's extinction coefficient κ at 550 nm is at
    /// least 0.1, else [`BaseKind::Dielectric`].
    pub fn of(base: &Material) -> BaseKind {
        match base.index_at(550.0) {
            Ok(n) if n.im >= 0.1 => BaseKind::Metal,
            _ => BaseKind::Dielectric,
        }
    }
}

/// The film-coated material of a scene (`MaterialParams` in `shaders/material.wgsl`).
#[derive(Clone, Debug)]
pub struct MaterialOptions {
    /// Real film index n₂.
    pub film_ior: f32,
    /// Ambient index n₁ (a `film-lut` table bakes it: it must match the table's).
    pub ambient_ior: f32,
    /// How the thickness map becomes a thickness.
    pub thickness: ThicknessMapping,
    /// Sub-pixel standard deviation of the thickness, nm (film_fourier prefiltering).
    pub thickness_roughness_nm: f32,
    /// Extra thickness at the bottom of the object (0 at the top, linear in height), nm:
    /// a draining soap film.
    pub drain_nm: f32,
    /// Scale s of the triplanar thickness-map projection: one map tile spans 2/s units of the
    /// scene's map coordinate (the sphere's unit normal, the plane's world x and z).
    pub thickness_map_scale: f32,
    /// The base under the film: its index feeds `film_fourier` (at each channel's centroid
    /// wavelength) and `film_spectral` (at every wavelength); `film_lut` bakes it.
    pub base: Material,
    /// Dielectric (with diffuse) or metal.
    pub base_kind: BaseKind,
    /// Diffuse albedo of a dielectric base, linear RGB.
    pub base_colour: [f32; 3],
    /// GGX roughness α (= perceptual roughness²), in [0.001, 1].
    pub roughness_alpha: f32,
    /// A thin transparent shell (the bubble): transmits the film's transmittance.
    pub transmission: bool,
    /// Film weight w ∈ [0, 1], the coated fraction of the surface: every film term becomes
    /// mix(F_base, film, w), F_base the bare base's Fresnel reflectance (glTF
    /// `iridescenceFactor`, OpenPBR `thin_film_weight`; default 1: the film alone).
    pub film_weight: f32,
}

impl MaterialOptions {
    /// The default material of `scene`:
    ///
    /// * sphere: a film of index 1.9 (SVT 380 ± 220 nm) on a black glazed dielectric of index
    ///   1.5, α = 0.06;
    /// * bubble: a soap film of index 1.33 in air (SVT 170 ± 80 nm plus 700 nm of drainage
    ///   towards the bottom), a mirror (α = 0.001), transmitting;
    /// * plane: an oil film of index 1.47 (glTF mapping 100–700 nm) on water over a dark
    ///   bottom, α = 0.02, the map repeating every 3 units.
    pub fn for_scene(scene: SceneKind) -> MaterialOptions {
        let constant = |n: f64| {
            Material::constant(format!("{n}"), C64::new(n, 0.0))
                .expect("a positive real index is a valid material")
        };
        match scene {
            SceneKind::Sphere => MaterialOptions {
                film_ior: 1.9,
                ambient_ior: 1.0,
                thickness: ThicknessMapping::Svt {
                    average_nm: 380.0,
                    relative_nm: 220.0,
                },
                thickness_roughness_nm: 0.0,
                drain_nm: 0.0,
                thickness_map_scale: 1.5,
                base: constant(1.5),
                base_kind: BaseKind::Dielectric,
                base_colour: [0.02, 0.02, 0.025],
                roughness_alpha: 0.06,
                transmission: false,
                film_weight: 1.0,
            },
            SceneKind::Bubble => MaterialOptions {
                film_ior: 1.33,
                ambient_ior: 1.0,
                thickness: ThicknessMapping::Svt {
                    average_nm: 170.0,
                    relative_nm: 80.0,
                },
                thickness_roughness_nm: 0.0,
                drain_nm: 700.0,
                thickness_map_scale: 1.0,
                base: constant(1.0),
                base_kind: BaseKind::Dielectric,
                base_colour: [0.0; 3],
                roughness_alpha: 0.001,
                transmission: true,
                film_weight: 1.0,
            },
            SceneKind::Plane => MaterialOptions {
                film_ior: 1.47,
                ambient_ior: 1.0,
                thickness: ThicknessMapping::Gltf {
                    min_nm: 100.0,
                    max_nm: 700.0,
                },
                thickness_roughness_nm: 0.0,
                drain_nm: 0.0,
                thickness_map_scale: 2.0 / 3.0,
                base: constant(1.333),
                base_kind: BaseKind::Dielectric,
                base_colour: [0.015, 0.02, 0.025],
                roughness_alpha: 0.02,
                transmission: false,
                film_weight: 1.0,
            },
        }
    }

    /// Sets the film from OpenPBR's thin-film parameters (OpenPBR Surface 1.1, "Thin-film
    /// iridescence": `thin_film_weight` ∈ [0, 1], default 0; `thin_film_thickness` in µm,
    /// default 0.5; `thin_film_ior`, default 1.4 — the OpenPBR specification's parameter table
    /// and `open_pbr_surface.mtlx`; the glTF iridescence extension's default is 1.3):
    ///
    /// * film weight w = `thin_film_weight` (clamped to [0, 1]): OpenPBR's
    ///   mix(base, film-coated base, w), which nacre applies to the Fresnel term;
    /// * a constant thickness d = 1000 × `thin_film_thickness_um` nm (OpenPBR has no
    ///   thickness texture range: [`ThicknessMapping::Gltf`] with min = max = d);
    /// * film index n₂ = `thin_film_ior`.
    ///
    /// The base (OpenPBR's `specular_ior`, `base_metalness`, …) is left as it is.
    ///
    /// ```
    /// use nacre_runtime::render::{MaterialOptions, SceneKind, ThicknessMapping};
    /// let mut m = MaterialOptions::for_scene(SceneKind::Sphere);
    /// m.apply_openpbr(0.8, 0.5, 1.5).unwrap();
    /// assert_eq!(m.film_weight, 0.8);
    /// assert_eq!(m.thickness, ThicknessMapping::Gltf { min_nm: 500.0, max_nm: 500.0 });
    /// ```
    pub fn apply_openpbr(
        &mut self,
        thin_film_weight: f32,
        thin_film_thickness_um: f32,
        thin_film_ior: f32,
    ) -> Result<()> {
        let bad = |message: String| {
            Err(Error::Invalid {
                context: "OpenPBR thin film".into(),
                message,
            })
        };
        if !thin_film_weight.is_finite() {
            return bad(format!(
                "thin_film_weight {thin_film_weight} (expected 0 to 1)"
            ));
        }
        if !(thin_film_thickness_um.is_finite() && (0.0..=1000.0).contains(&thin_film_thickness_um))
        {
            return bad(format!(
                "thin_film_thickness {thin_film_thickness_um} µm (expected 0 to 1000)"
            ));
        }
        if !(thin_film_ior.is_finite() && thin_film_ior > 0.0) {
            return bad(format!(
                "thin_film_ior {thin_film_ior} (expected a positive number)"
            ));
        }
        let d_nm = thin_film_thickness_um * 1000.0;
        self.film_weight = thin_film_weight.clamp(0.0, 1.0);
        self.thickness = ThicknessMapping::Gltf {
            min_nm: d_nm,
            max_nm: d_nm,
        };
        self.film_ior = thin_film_ior;
        Ok(())
    }

    /// Replaces the base (and its kind, [`BaseKind::of`]).
    pub fn set_base(&mut self, base: Material) {
        self.base_kind = BaseKind::of(&base);
        self.base = base;
    }

    /// The largest thickness the material produces, nm.
    pub fn max_thickness_nm(&self) -> f32 {
        self.thickness.max_nm() + self.drain_nm.max(0.0)
    }

    /// Checks indices, thicknesses, roughness, weight and colour ranges.
    pub fn validate(&self) -> Result<()> {
        let bad = |message: String| {
            Err(Error::Invalid {
                context: "material".into(),
                message,
            })
        };
        let positive = [
            ("film index", self.film_ior),
            ("ambient index", self.ambient_ior),
        ];
        for (name, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return bad(format!("{name} {v} (expected a positive number)"));
            }
        }
        let (a, b) = match self.thickness {
            ThicknessMapping::Svt {
                average_nm,
                relative_nm,
            } => (average_nm, relative_nm),
            ThicknessMapping::Gltf { min_nm, max_nm } => (min_nm, max_nm),
        };
        let finite = [
            ("thickness", a),
            ("thickness", b),
            ("drainage", self.drain_nm),
            ("thickness roughness", self.thickness_roughness_nm),
            ("thickness map scale", self.thickness_map_scale),
        ];
        for (name, v) in finite {
            if !(v.is_finite() && v.abs() <= 1e6) {
                return bad(format!("{name} {v} (expected a finite number within ±1e6)"));
            }
        }
        if !(self.thickness_roughness_nm >= 0.0 && self.drain_nm >= 0.0) {
            return bad("thickness roughness and drainage must be non-negative".into());
        }
        if !(self.film_weight >= 0.0 && self.film_weight <= 1.0) {
            return bad(format!(
                "film weight {} (expected 0 to 1)",
                self.film_weight
            ));
        }
        if !(self.roughness_alpha >= 0.0 && self.roughness_alpha <= 1.0) {
            return bad(format!(
                "GGX roughness α {} (expected 0 to 1)",
                self.roughness_alpha
            ));
        }
        if !self.base_colour.iter().all(|c| (0.0..=1.0).contains(c)) {
            return bad(format!(
                "base colour {:?} (expected 0 to 1 per channel)",
                self.base_colour
            ));
        }
        Ok(())
    }
}

/// Everything a render needs besides the tables and the technique.
#[derive(Clone, Debug)]
pub struct SceneOptions {
    /// The scene.
    pub scene: SceneKind,
    /// Image width, pixels (1 to [`MAX_DIMENSION`]; default 800).
    pub width: u32,
    /// Image height, pixels (1 to [`MAX_DIMENSION`]; default 600).
    pub height: u32,
    /// The camera (default: [`Camera::for_scene`]).
    pub camera: Camera,
    /// An OpenEXR equirectangular environment, or `None` for the default
    /// ([`EnvironmentMap::default_map`]).
    pub environment: Option<PathBuf>,
    /// Scale of the environment's radiance (default 1).
    pub env_intensity: f32,
    /// A greyscale PNG thickness map, or `None` for [`procedural_thickness_map`].
    pub thickness_map: Option<PathBuf>,
    /// The material (default: [`MaterialOptions::for_scene`]).
    pub material: MaterialOptions,
    /// The directional light (default: [`Light::default`]).
    pub light: Light,
    /// Exposure, EV stops: radiance is scaled by 2^EV before tone mapping (default 0).
    pub exposure_ev: f32,
    /// Harmonics M of `film_fourier` (0 = automatic; default 3).
    pub harmonics: u32,
    /// Wavelengths N of `film_spectral` (default 30).
    pub spectral_samples: usize,
    /// How the film enters the lighting (default [`FilmEval::Classic`]).
    pub film_eval: FilmEval,
}

impl SceneOptions {
    /// The defaults of `scene` at 800 × 600.
    pub fn new(scene: SceneKind) -> SceneOptions {
        let technique = TechniqueOptions::default();
        SceneOptions {
            scene,
            width: 800,
            height: 600,
            camera: Camera::for_scene(scene),
            environment: None,
            env_intensity: 1.0,
            thickness_map: None,
            material: MaterialOptions::for_scene(scene),
            light: Light::default(),
            exposure_ev: 0.0,
            harmonics: technique.harmonics,
            spectral_samples: technique.spectral.samples,
            film_eval: FilmEval::Classic,
        }
    }

    /// Adapts the material to the loaded `film-lut` table, if any: the base becomes the
    /// table's (its manifest's `base` material), the ambient index the table's, and the
    /// film index is clamped into the table's index range, so that every technique renders
    /// the film the table describes.
    pub fn fit_to_tables(&mut self, tables: &TableSet) -> Result<()> {
        let Some(lut) = &tables.film_lut else {
            return Ok(());
        };
        let dir = lut.manifest_path.parent();
        let context = format!("{} (base)", lut.manifest_path.display());
        let base = nacre_format::materials::resolve(&lut.manifest.base, &context, dir)?;
        self.material.set_base(base);
        self.material.ambient_ior = lut.axes.ambient_index as f32;
        self.material.film_ior = self
            .material
            .film_ior
            .clamp(lut.axes.ior_min as f32, lut.axes.ior_max as f32);
        Ok(())
    }

    /// The group-1 options: harmonics, wavelengths and the material's base.
    pub fn technique_options(&self) -> TechniqueOptions {
        TechniqueOptions {
            harmonics: self.harmonics,
            spectral: SpectralSetup {
                samples: self.spectral_samples,
                base: self.material.base.clone(),
            },
        }
    }

    /// Checks sizes, exposure, intensities, the light and the material (not the files, not
    /// the tables): [`Renderer::render`] calls it first.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_DIMENSION).contains(&v) {
                return Err(Error::Invalid {
                    context: format!("image {name}"),
                    message: format!("{v} pixels (expected 1 to {MAX_DIMENSION})"),
                });
            }
        }
        for (name, v) in [
            ("exposure", self.exposure_ev),
            ("environment intensity", self.env_intensity),
            ("light intensity", self.light.intensity),
        ] {
            if !(v.is_finite() && v.abs() <= 1e4) {
                return Err(Error::Invalid {
                    context: name.into(),
                    message: format!("{v} (expected a finite number within ±1e4)"),
                });
            }
        }
        if self.env_intensity < 0.0 || self.light.intensity < 0.0 {
            return Err(Error::Invalid {
                context: "lighting".into(),
                message: "intensities must be non-negative".into(),
            });
        }
        if self.exposure_ev.abs() > 64.0 {
            return Err(Error::Invalid {
                context: "exposure".into(),
                message: format!("{} EV (expected −64 to 64)", self.exposure_ev),
            });
        }
        if !self
            .light
            .direction
            .iter()
            .chain(&self.light.colour)
            .all(|x| x.is_finite())
            || self.light.colour.iter().any(|&c| c < 0.0)
        {
            return Err(Error::Invalid {
                context: "light".into(),
                message: format!(
                    "{:?} (expected finite values, a non-negative colour)",
                    self.light
                ),
            });
        }
        self.material.validate()
    }
}

// ─── Uniforms (mirrors of shaders/material.wgsl) ───────────────────────────────────────────

/// Mirror of `ViewParams` (`shaders/material.wgsl`): 128 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ViewUniform {
    /// Clip → world, column-major.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Eye position.
    pub eye_position: [f32; 3],
    /// Linear exposure factor 2^EV.
    pub exposure: f32,
    /// Unit direction towards the light.
    pub light_direction: [f32; 3],
    /// Light intensity.
    pub light_intensity: f32,
    /// Light colour, linear RGB.
    pub light_colour: [f32; 3],
    /// Environment intensity.
    pub env_intensity: f32,
    /// Target size, pixels.
    pub resolution: [f32; 2],
    /// Scene id (0 sphere, 1 bubble, 2 plane).
    pub scene: u32,
    /// Last mip level of the environment texture.
    pub env_lod_max: f32,
}

/// Mirror of `MaterialParams` (`shaders/material.wgsl`): 96 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MaterialUniform {
    /// Film index.
    pub film_ior: f32,
    /// Ambient index.
    pub ambient_ior: f32,
    /// SVT d_avg or glTF d_min, nm.
    pub thickness_a_nm: f32,
    /// SVT d_rel or glTF d_max, nm.
    pub thickness_b_nm: f32,
    /// 0 SVT, 1 glTF.
    pub thickness_mode: u32,
    /// Thickness roughness, nm.
    pub thickness_roughness_nm: f32,
    /// Drainage, nm.
    pub thickness_drain_nm: f32,
    /// GGX α.
    pub roughness_alpha: f32,
    /// Base index per channel, real part.
    pub base_ior: [f32; 3],
    /// 0 dielectric, 1 metal.
    pub base_kind: u32,
    /// Base index per channel, κ.
    pub base_kappa: [f32; 3],
    /// 1: thin transparent shell.
    pub transmission: u32,
    /// Diffuse albedo.
    pub base_colour: [f32; 3],
    /// Triplanar projection scale (a tile spans 2/scale map units).
    pub thickness_map_scale: f32,
    /// Film weight w: F = mix(F_base, R_f, w).
    pub film_weight: f32,
    /// [`FilmEval::id`]: 0 classic, 1 film at n·v, 2 exact.
    pub film_eval: u32,
    /// Padding to 96 bytes.
    pub _pad: [f32; 2],
}

impl ViewUniform {
    /// The view uniform of `options` for an environment of `env_levels` mip levels.
    pub fn new(options: &SceneOptions, env_levels: usize) -> Result<ViewUniform> {
        let aspect = f64::from(options.width) / f64::from(options.height);
        let light =
            normalize(options.light.direction.map(f64::from)).ok_or_else(|| Error::Invalid {
                context: "light".into(),
                message: "zero direction".into(),
            })?;
        Ok(ViewUniform {
            inv_view_proj: options.camera.inverse_view_projection(aspect)?,
            eye_position: options.camera.eye,
            exposure: 2f32.powf(options.exposure_ev),
            light_direction: light.map(|x| x as f32),
            light_intensity: options.light.intensity,
            light_colour: options.light.colour,
            env_intensity: options.env_intensity,
            resolution: [options.width as f32, options.height as f32],
            scene: options.scene.id(),
            env_lod_max: env_levels.saturating_sub(1) as f32,
        })
    }
}

/// Wavelengths (nm) at which the base index is taken for `film_fourier` when no `fourier`
/// table gives the channels' centroids (red, green, blue).
const FALLBACK_CHANNEL_WAVELENGTHS_NM: [f64; 3] = [610.0, 550.0, 465.0];

impl MaterialUniform {
    /// The material uniform of `m`; the base index per channel is taken at the channel
    /// centroid wavelengths 1/ν̄_j of the `fourier` table in `tables`, if any.
    pub fn new(m: &MaterialOptions, tables: &TableSet) -> Result<MaterialUniform> {
        let wavelengths = match &tables.fourier {
            Some(f) => {
                let nu = f.axes.carrier_nu_per_nm;
                std::array::from_fn(|j| {
                    if nu[j] > 1e-6 && nu[j].is_finite() {
                        1.0 / nu[j]
                    } else {
                        FALLBACK_CHANNEL_WAVELENGTHS_NM[j]
                    }
                })
            }
            None => FALLBACK_CHANNEL_WAVELENGTHS_NM,
        };
        let mut base_ior = [0.0f32; 3];
        let mut base_kappa = [0.0f32; 3];
        for j in 0..3 {
            let n = m
                .base
                .index_at(wavelengths[j])
                .map_err(crate::Error::from)?;
            base_ior[j] = n.re as f32;
            base_kappa[j] = n.im as f32;
        }
        let (mode, a, b) = match m.thickness {
            ThicknessMapping::Svt {
                average_nm,
                relative_nm,
            } => (0, average_nm, relative_nm),
            ThicknessMapping::Gltf { min_nm, max_nm } => (1, min_nm, max_nm),
        };
        Ok(MaterialUniform {
            film_ior: m.film_ior,
            ambient_ior: m.ambient_ior,
            thickness_a_nm: a,
            thickness_b_nm: b,
            thickness_mode: mode,
            thickness_roughness_nm: m.thickness_roughness_nm,
            thickness_drain_nm: m.drain_nm,
            roughness_alpha: m.roughness_alpha,
            base_ior,
            base_kind: match m.base_kind {
                BaseKind::Dielectric => 0,
                BaseKind::Metal => 1,
            },
            base_kappa,
            transmission: u32::from(m.transmission),
            base_colour: m.base_colour,
            thickness_map_scale: m.thickness_map_scale,
            film_weight: m.film_weight,
            film_eval: FilmEval::Classic.id(),
            _pad: [0.0; 2],
        })
    }
}

// ─── Thickness maps ───────────────────────────────────────────────────────────────────────

/// A greyscale thickness map: values g ∈ [0, 1], row-major, top row first. Values are data,
/// not colours: a PNG's gamma or sRGB chunks are ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct ThicknessMap {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// `width × height` values in [0, 1].
    pub values: Vec<f32>,
}

impl ThicknessMap {
    /// Reads an 8- or 16-bit greyscale PNG (grey + alpha too: alpha ignored; 1-, 2- and 4-bit
    /// greyscale are expanded to 8 bits), g = value / (2^bits − 1).
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read; [`Error::Invalid`] when it is not a valid
    /// PNG, not greyscale, or a side is 0 or larger than [`MAX_DIMENSION`] (checked before the
    /// pixels are decoded).
    pub fn load_png(path: &Path) -> Result<ThicknessMap> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let invalid = |message: String| Error::Invalid {
            context: path.display().to_string(),
            message,
        };
        let decode = || -> Result<ThicknessMap> {
            let bad = |e: png::DecodingError| invalid(format!("not a valid PNG file: {e}"));
            let mut decoder = png::Decoder::new_with_limits(
                Cursor::new(&bytes[..]),
                png::Limits { bytes: 1 << 29 },
            );
            decoder.set_transformations(png::Transformations::EXPAND);
            let info = decoder.read_header_info().map_err(bad)?;
            let (width, height) = (info.width as usize, info.height as usize);
            check_image_size(path, "a thickness map", width, height)?;
            let mut reader = decoder.read_info().map_err(bad)?;
            let (colour, depth) = reader.output_color_type();
            let channels = match colour {
                png::ColorType::Grayscale => 1,
                png::ColorType::GrayscaleAlpha => 2,
                other => {
                    return Err(invalid(format!(
                        "a {other:?} PNG; a thickness map must be greyscale (8 or 16 bits)"
                    )));
                }
            };
            let bytes_per_sample = match depth {
                png::BitDepth::Eight => 1,
                png::BitDepth::Sixteen => 2,
                other => {
                    return Err(invalid(format!(
                        "{} bits per sample; expected 8 or 16",
                        other as u8
                    )));
                }
            };
            let size = reader
                .output_buffer_size()
                .ok_or_else(|| invalid("image too large".into()))?;
            let mut buf = vec![0u8; size];
            let frame = reader.next_frame(&mut buf).map_err(bad)?;
            reader.finish().map_err(bad)?;
            let stride = channels * bytes_per_sample;
            let mut values = Vec::with_capacity(width * height);
            for y in 0..height {
                let row = &buf[y * frame.line_size..];
                for x in 0..width {
                    let at = x * stride;
                    values.push(if bytes_per_sample == 2 {
                        f32::from(u16::from_be_bytes([row[at], row[at + 1]])) / 65535.0
                    } else {
                        f32::from(row[at]) / 255.0
                    });
                }
            }
            Ok(ThicknessMap {
                width,
                height,
                values,
            })
        };
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode))
            .unwrap_or_else(|_| Err(invalid("malformed PNG data (the decoder failed)".into())))
    }

    /// The mip chain of (g, g²) uploaded to the GPU.
    pub fn mip_chain(&self) -> Vec<Level<2>> {
        let texels = self
            .values
            .iter()
            .map(|&g| {
                let g = if g.is_finite() {
                    g.clamp(0.0, 1.0)
                } else {
                    0.5
                };
                [g, g * g]
            })
            .collect();
        mip_chain(self.width, self.height, texels)
    }
}

/// The built-in thickness map: `size` × `size` marbled swirls, tileable (every term is
/// periodic with period 1 in both coordinates), normalised to span [0, 1].
///
/// g(x, y) = ½ + ½ Σ_k a_k sin(2π(m_k u + n_k v) + φ_k) after three rounds of domain warping
/// (u, v) ← (u, v) + A sin(2π(integer frequencies) + phase).
pub fn procedural_thickness_map(size: usize) -> ThicknessMap {
    use std::f64::consts::TAU;
    let size = size.max(1);
    // Warps: amplitude; integer frequencies (x, y) and phase of the u displacement; of the v one.
    type Warp = (f64, [f64; 2], f64, [f64; 2], f64);
    let warps: [Warp; 3] = [
        (0.12, [1.0, 2.0], 0.3, [2.0, -1.0], 1.7),
        (0.07, [3.0, -2.0], 2.1, [-1.0, 3.0], 0.4),
        (0.035, [4.0, 5.0], 4.0, [5.0, -3.0], 2.9),
    ];
    let waves: [(f64, [f64; 2], f64); 4] = [
        (0.55, [2.0, 1.0], 0.0),
        (0.35, [-1.0, 3.0], 1.0),
        (0.2, [4.0, -2.0], 2.2),
        (0.1, [5.0, 6.0], 0.7),
    ];
    let mut raw = Vec::with_capacity(size * size);
    for j in 0..size {
        for i in 0..size {
            let (mut u, mut v) = (
                (i as f64 + 0.5) / size as f64,
                (j as f64 + 0.5) / size as f64,
            );
            for &(a, fu, pu, fv, pv) in &warps {
                let du = a * (TAU * (fu[0] * u + fu[1] * v) + pu).sin();
                let dv = a * (TAU * (fv[0] * u + fv[1] * v) + pv).sin();
                u += du;
                v += dv;
            }
            let g: f64 = waves
                .iter()
                .map(|&(a, f, p)| a * (TAU * (f[0] * u + f[1] * v) + p).sin())
                .sum();
            raw.push(g);
        }
    }
    let lo = raw.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = raw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = (hi - lo).max(1e-12);
    ThicknessMap {
        width: size,
        height: size,
        values: raw.iter().map(|&g| ((g - lo) / span) as f32).collect(),
    }
}

// ─── GPU ───────────────────────────────────────────────────────────────────────────────────

/// An image rendered by [`Renderer::render`].
#[derive(Clone, Debug)]
pub struct RenderedImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// RGBA8, sRGB-encoded, alpha 255, row-major, top row first.
    pub pixels: Vec<u8>,
    /// Wall-clock seconds from submitting the render pass to its completion (excludes
    /// pipeline creation, uploads and the readback; includes any shader compilation the driver
    /// defers to the first draw, as lavapipe does without a warm shader cache).
    pub gpu_seconds: f64,
}

impl RenderedImage {
    /// The image as an 8-bit RGB PNG with an sRGB chunk.
    pub fn encode_png(&self) -> Result<Vec<u8>> {
        let err = |e: png::EncodingError| Error::Invalid {
            context: "encoding the PNG".into(),
            message: e.to_string(),
        };
        let rgb: Vec<u8> = self
            .pixels
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            encoder.set_compression(png::Compression::Balanced);
            let mut writer = encoder.write_header().map_err(err)?;
            writer.write_image_data(&rgb).map_err(err)?;
            writer.finish().map_err(err)?;
        }
        Ok(bytes)
    }

    /// Writes [`RenderedImage::encode_png`] to `path` atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        let bytes = self.encode_png()?;
        Ok(nacre_format::atomic::write_atomic(path, |w| {
            w.write_all(&bytes)
        })?)
    }
}

/// A technique's scene pipeline: group-1 tables, group-0/2 layouts, the render pipeline.
pub struct Renderer {
    technique: Technique,
    output: RenderOutput,
    binding: TechniqueBinding,
    view_layout: wgpu::BindGroupLayout,
    material_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

pub(crate) fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub(crate) fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

pub(crate) fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// Group 0, the view and the environment (`shaders/material.wgsl`): 0 the view uniform,
/// 1 the environment's box mip chain, 2 its sampler (u repeats, v clamps), 3 the
/// GGX-prefiltered environment, 4 the F = 1 GGX albedo table E₁, 5 a clamp-to-edge sampler,
/// 6 the `rough-film-lut` reflectance (3-D), 7 its [`RoughLutUniform`].
pub fn view_group_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let mut prefiltered = texture_entry(3);
    prefiltered.ty = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: wgpu::TextureViewDimension::D2Array,
        multisampled: false,
    };
    let mut rough_lut = texture_entry(6);
    rough_lut.ty = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: wgpu::TextureViewDimension::D3,
        multisampled: false,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            uniform_entry(0),
            texture_entry(1),
            sampler_entry(2),
            prefiltered,
            texture_entry(4),
            sampler_entry(5),
            rough_lut,
            uniform_entry(7),
        ],
    })
}

/// Mirror of `RoughLutParams` (`shaders/rough_lut_mapping.wgsl`; the axes of
/// `nacre_format::rough_film_lut::RoughLutAxes`): 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RoughLutUniform {
    /// Texels along cos θ_o.
    pub cos_theta_count: u32,
    /// Texels along Δ.
    pub opd_count: u32,
    /// Texels along the film index per α block.
    pub ior_count: u32,
    /// α blocks.
    pub alpha_count: u32,
    /// d_max, nm.
    pub thickness_max_nm: f32,
    /// Smallest film index.
    pub ior_min: f32,
    /// Largest film index.
    pub ior_max: f32,
    /// Smallest α.
    pub alpha_min: f32,
    /// Largest α.
    pub alpha_max: f32,
    /// Ambient index n₀.
    pub ambient_index: f32,
    /// 1 when the table has a transmittance.
    pub has_transmittance: u32,
    /// Padding to 48 bytes.
    pub _pad0: u32,
}

impl RoughLutUniform {
    /// The uniform of a loaded table.
    pub fn new(lut: &crate::tables::RoughFilmLutTextures) -> RoughLutUniform {
        let a = &lut.axes;
        RoughLutUniform {
            cos_theta_count: a.cos_theta_count as u32,
            opd_count: a.opd_count as u32,
            ior_count: a.ior_count as u32,
            alpha_count: a.alpha_count as u32,
            thickness_max_nm: a.thickness_max_nm as f32,
            ior_min: a.ior_min as f32,
            ior_max: a.ior_max as f32,
            alpha_min: a.alpha_min as f32,
            alpha_max: a.alpha_max as f32,
            ambient_index: a.ambient_index as f32,
            has_transmittance: u32::from(lut.has_transmittance),
            _pad0: 0,
        }
    }
}

/// The textures of group 0 besides the view uniform: the environment's box mip chain, its
/// GGX-prefiltered levels ([`crate::ibl::PrefilteredEnvironment`]) and the E₁ table
/// ([`crate::ibl::ggx_albedo_table`]). The classic path reads neither of the last two: they
/// are 1 × 1 placeholders unless the path is a split-sum one, and the `rough-film-lut`
/// a 1 × 1 × 1 placeholder unless the path is [`FilmEval::Exact`].
pub(crate) struct EnvironmentTextures {
    /// Mip levels of the environment's box chain.
    pub env_levels: usize,
    env: wgpu::Texture,
    prefiltered: wgpu::Texture,
    ggx_albedo: wgpu::Texture,
    rough_lut: wgpu::TextureView,
    rough_lut_uniform: RoughLutUniform,
}

impl EnvironmentTextures {
    /// Uploads `environment` (and, for the split-sum paths, prefilters it and builds E₁).
    pub(crate) fn new(
        ctx: &GpuContext,
        environment: &EnvironmentMap,
        film_eval: FilmEval,
        tables: &TableSet,
    ) -> Result<EnvironmentTextures> {
        let split_sum = film_eval.split_sum();
        let (rough_lut, rough_lut_uniform) = match (&tables.rough_film_lut, film_eval) {
            (Some(lut), FilmEval::Exact) => (
                lut.reflectance.create_view(&Default::default()),
                RoughLutUniform::new(lut),
            ),
            _ => {
                let placeholder = ctx.checked("a rough-film-lut placeholder", || {
                    ctx.device.create_texture(&wgpu::TextureDescriptor {
                        label: Some("rough-film-lut (unused)"),
                        size: wgpu::Extent3d {
                            width: 1,
                            height: 1,
                            depth_or_array_layers: 1,
                        },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D3,
                        format: wgpu::TextureFormat::Rgba16Float,
                        usage: wgpu::TextureUsages::TEXTURE_BINDING,
                        view_formats: &[],
                    })
                })?;
                (
                    placeholder.create_view(&Default::default()),
                    RoughLutUniform::default(),
                )
            }
        };
        let env_mips = environment.mip_chain();
        let env = upload_mips(
            ctx,
            "environment",
            wgpu::TextureFormat::Rgba16Float,
            &env_mips,
        )?;
        let (prefiltered, ggx_albedo) = if split_sum {
            let p = crate::ibl::PrefilteredEnvironment::cached(environment);
            (
                upload_layers(ctx, "prefiltered environment", &p.levels)?,
                upload_mips(
                    ctx,
                    "GGX albedo",
                    wgpu::TextureFormat::Rg16Float,
                    std::slice::from_ref(crate::ibl::ggx_albedo_table()),
                )?,
            )
        } else {
            (
                upload_layers(
                    ctx,
                    "prefiltered environment (unused)",
                    &[(1, 1, vec![[0.0f32; 4]])],
                )?,
                upload_mips(
                    ctx,
                    "GGX albedo (unused)",
                    wgpu::TextureFormat::Rg16Float,
                    &[(1, 1, vec![[0.0f32; 2]])],
                )?,
            )
        };
        Ok(EnvironmentTextures {
            env,
            env_levels: env_mips.len(),
            prefiltered,
            ggx_albedo,
            rough_lut,
            rough_lut_uniform,
        })
    }

    /// The group-0 bind group for `layout` ([`view_group_layout`]) with the view uniform
    /// `uniform` (its bytes).
    pub(crate) fn bind_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        label: &str,
        uniform: &[u8],
    ) -> wgpu::BindGroup {
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: uniform,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let env_view = self.env.create_view(&Default::default());
        let prefiltered_view = self.prefiltered.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let albedo_view = self.ggx_albedo.create_view(&Default::default());
        let rough_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rough-film-lut axes"),
            contents: bytemuck::bytes_of(&self.rough_lut_uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let env_sampler = linear_sampler(device, label, false);
        let clamp_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("lut clamp"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&env_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&env_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&prefiltered_view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&albedo_view),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Sampler(&clamp_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&self.rough_lut),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: rough_buffer.as_entire_binding(),
                },
            ],
        })
    }
}

/// Group 2 (and the old group 0) shape: 0 uniform, 1 filterable 2-D texture, 2 sampler.
pub(crate) fn group_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[uniform_entry(0), texture_entry(1), sampler_entry(2)],
    })
}

/// Uploads a mip chain as a 2-D half-float texture of `format` (C channels of 2 bytes).
pub(crate) fn upload_mips<const C: usize>(
    ctx: &GpuContext,
    label: &str,
    format: wgpu::TextureFormat,
    levels: &[Level<C>],
) -> Result<wgpu::Texture> {
    let (width, height, _) = &levels[0];
    let limit = ctx.device.limits().max_texture_dimension_2d;
    for n in [*width, *height] {
        if n as u64 > u64::from(limit) {
            return Err(Error::Limit {
                what: label.to_string(),
                needed: n as u64,
                limit: u64::from(limit),
                adapter: ctx.info.name.clone(),
            });
        }
    }
    ctx.checked(&format!("uploading {label}"), || {
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: *width as u32,
                height: *height as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (k, (w, h, texels)) in levels.iter().enumerate() {
            let halves: Vec<u16> = texels
                .iter()
                .flat_map(|t| t.map(|v| f16::from_f32(v).to_bits()))
                .collect();
            ctx.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: k as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(&halves),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some((*w * C * 2) as u32),
                    rows_per_image: Some(*h as u32),
                },
                wgpu::Extent3d {
                    width: *w as u32,
                    height: *h as u32,
                    depth_or_array_layers: 1,
                },
            );
        }
        texture
    })
}

/// Uploads equal-sized RGBA levels as the layers of a 2-D array `Rgba16Float` texture (one
/// mip level).
pub(crate) fn upload_layers(
    ctx: &GpuContext,
    label: &str,
    layers: &[Level<4>],
) -> Result<wgpu::Texture> {
    let (width, height, _) = &layers[0];
    if layers
        .iter()
        .any(|l| (l.0, l.1) != (*width, *height) || l.2.len() != l.0 * l.1)
    {
        return Err(Error::Invalid {
            context: label.into(),
            message: "layers of differing sizes".into(),
        });
    }
    let limit = ctx.device.limits();
    if (*width.max(height) as u64) > u64::from(limit.max_texture_dimension_2d)
        || layers.len() as u64 > u64::from(limit.max_texture_array_layers)
    {
        return Err(Error::Limit {
            what: label.to_string(),
            needed: (*width.max(height)).max(layers.len()) as u64,
            limit: u64::from(
                limit
                    .max_texture_dimension_2d
                    .min(limit.max_texture_array_layers),
            ),
            adapter: ctx.info.name.clone(),
        });
    }
    ctx.checked(&format!("uploading {label}"), || {
        let size = wgpu::Extent3d {
            width: *width as u32,
            height: *height as u32,
            depth_or_array_layers: layers.len() as u32,
        };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let halves: Vec<u16> = layers
            .iter()
            .flat_map(|l| l.2.iter())
            .flat_map(|t| t.map(|v| f16::from_f32(v).to_bits()))
            .collect();
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&halves),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some((*width * 8) as u32),
                rows_per_image: Some(*height as u32),
            },
            size,
        );
        texture
    })
}

/// A bind group of the layout shared by the view and material groups: binding 0 a uniform
/// buffer holding `contents`, 1 `texture`'s default view, 2 a linear sampler
/// ([`linear_sampler`]; `repeat_v` repeats v instead of clamping).
pub(crate) fn uniform_texture_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    contents: &[u8],
    texture: &wgpu::Texture,
    repeat_v: bool,
) -> wgpu::BindGroup {
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let view = texture.create_view(&Default::default());
    let sampler = linear_sampler(device, label, repeat_v);
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
        ],
    })
}

pub(crate) fn linear_sampler(device: &wgpu::Device, label: &str, repeat_v: bool) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: if repeat_v {
            wgpu::AddressMode::Repeat
        } else {
            wgpu::AddressMode::ClampToEdge
        },
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

impl Renderer {
    /// Compiles the scene pipeline of `technique` (`shaders::film_pipeline(technique.module(),
    /// &["material", "scene"])`) and builds its group-1 tables from `tables` with `options`.
    pub fn new(
        ctx: &GpuContext,
        tables: &TableSet,
        technique: Technique,
        options: &TechniqueOptions,
    ) -> Result<Renderer> {
        Renderer::new_with_output(ctx, tables, technique, options, RenderOutput::Display)
    }

    /// [`Renderer::new`] writing `output`: display pixels (`scene_fs`, [`TARGET_FORMAT`]) or
    /// linear radiance (`scene_fs_linear`, [`LINEAR_TARGET_FORMAT`]; read it with
    /// [`Renderer::render_linear_with`]).
    pub fn new_with_output(
        ctx: &GpuContext,
        tables: &TableSet,
        technique: Technique,
        options: &TechniqueOptions,
        output: RenderOutput,
    ) -> Result<Renderer> {
        let (entry_point, format) = match output {
            RenderOutput::Display => ("scene_fs", TARGET_FORMAT),
            RenderOutput::Linear => ("scene_fs_linear", LINEAR_TARGET_FORMAT),
        };
        let colorimeter = tables.colorimeter()?;
        let binding = TechniqueBinding::new(ctx, tables, technique, options, &colorimeter)?;
        let device = &ctx.device;
        let source = shaders::film_pipeline(technique.module(), &["material", "scene"])?;
        let module = shaders::create_module(ctx, "scene", &source)?;
        let (view_layout, material_layout, pipeline) =
            ctx.checked("creating the scene pipeline", || {
                let view_layout = view_group_layout(device, "scene view");
                let material_layout = group_layout(device, "scene material");
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("scene"),
                    bind_group_layouts: &[
                        Some(&view_layout),
                        Some(&binding.layout),
                        Some(&material_layout),
                    ],
                    immediate_size: 0,
                });
                let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("scene"),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("scene_vs"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: Default::default(),
                    depth_stencil: None,
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some(entry_point),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                });
                (view_layout, material_layout, pipeline)
            })?;
        Ok(Renderer {
            technique,
            output,
            binding,
            view_layout,
            material_layout,
            pipeline,
        })
    }

    /// The technique.
    pub fn technique(&self) -> Technique {
        self.technique
    }

    /// Renders `options`, loading its environment and thickness map.
    pub fn render(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
    ) -> Result<RenderedImage> {
        options.validate()?;
        let environment = match &options.environment {
            Some(path) => EnvironmentMap::load(path)?,
            None => EnvironmentMap::default_map()?,
        };
        let thickness = match &options.thickness_map {
            Some(path) => ThicknessMap::load_png(path)?,
            None => procedural_thickness_map(DEFAULT_THICKNESS_MAP_SIZE),
        };
        self.render_with(ctx, tables, options, &environment, &thickness)
    }

    /// Renders `options` with an environment and a thickness map already in memory
    /// (`options.environment` and `options.thickness_map` are not read). Needs a renderer
    /// made for [`RenderOutput::Display`].
    pub fn render_with(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
        environment: &EnvironmentMap,
        thickness: &ThicknessMap,
    ) -> Result<RenderedImage> {
        if self.output != RenderOutput::Display {
            return Err(Error::Invalid {
                context: "render".into(),
                message: "this renderer writes linear radiance: use render_linear_with".into(),
            });
        }
        let (target, gpu_seconds) = self.draw(ctx, tables, options, environment, thickness)?;
        let mut pixels = read_texture(ctx, &target, 4)?;
        for p in pixels.chunks_exact_mut(4) {
            p[3] = 255;
        }
        Ok(RenderedImage {
            width: options.width,
            height: options.height,
            pixels,
            gpu_seconds,
        })
    }

    /// Renders the linear scene radiance of `options` (before exposure and tone mapping)
    /// with an environment and a thickness map in memory. Needs a renderer made for
    /// [`RenderOutput::Linear`].
    pub fn render_linear_with(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
        environment: &EnvironmentMap,
        thickness: &ThicknessMap,
    ) -> Result<LinearImage> {
        if self.output != RenderOutput::Linear {
            return Err(Error::Invalid {
                context: "render".into(),
                message: "this renderer writes display pixels: use render_with".into(),
            });
        }
        let (target, gpu_seconds) = self.draw(ctx, tables, options, environment, thickness)?;
        let bytes = read_texture(ctx, &target, 16)?;
        let floats: &[f32] = bytemuck::cast_slice(&bytes);
        Ok(LinearImage {
            width: options.width,
            height: options.height,
            rgb: floats.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect(),
            gpu_seconds,
        })
    }

    /// Draws `options` into a new target of the renderer's output format; returns it and the
    /// seconds from submission to completion.
    fn draw(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
        environment: &EnvironmentMap,
        thickness: &ThicknessMap,
    ) -> Result<(wgpu::Texture, f64)> {
        options.validate()?;
        for (what, w, h, n) in [
            (
                "environment",
                environment.width,
                environment.height,
                environment.rgb.len(),
            ),
            (
                "thickness map",
                thickness.width,
                thickness.height,
                thickness.values.len(),
            ),
        ] {
            check_image_size(Path::new(what), what, w, h)?;
            if n != w * h {
                return Err(Error::Invalid {
                    context: what.into(),
                    message: format!("{n} texels for {w}x{h}"),
                });
            }
        }
        if self.technique == Technique::Lut {
            check_film_lut(tables, &options.material)?;
        }
        check_film_eval(tables, options)?;
        let (width, height) = (options.width, options.height);
        let limit = ctx.device.limits().max_texture_dimension_2d;
        if width.max(height) > limit {
            return Err(Error::Limit {
                what: "render target".into(),
                needed: u64::from(width.max(height)),
                limit: u64::from(limit),
                adapter: ctx.info.name.clone(),
            });
        }
        let env = EnvironmentTextures::new(ctx, environment, options.film_eval, tables)?;
        let view_uniform = ViewUniform::new(options, env.env_levels)?;
        let mut material_uniform = MaterialUniform::new(&options.material, tables)?;
        material_uniform.film_eval = options.film_eval.id();
        let thickness_texture = upload_mips(
            ctx,
            "thickness map",
            wgpu::TextureFormat::Rg16Float,
            &thickness.mip_chain(),
        )?;
        let device = &ctx.device;
        let (target, submitted) = ctx.checked("rendering the scene", || {
            let group = |layout: &wgpu::BindGroupLayout,
                         label: &str,
                         contents: &[u8],
                         texture: &wgpu::Texture,
                         repeat_v: bool| {
                uniform_texture_group(device, layout, label, contents, texture, repeat_v)
            };
            let view_group = env.bind_group(
                device,
                &self.view_layout,
                "scene view",
                bytemuck::bytes_of(&view_uniform),
            );
            let material_group = group(
                &self.material_layout,
                "scene material",
                bytemuck::bytes_of(&material_uniform),
                &thickness_texture,
                true,
            );
            let target = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("scene target"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: match self.output {
                    RenderOutput::Display => TARGET_FORMAT,
                    RenderOutput::Linear => LINEAR_TARGET_FORMAT,
                },
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let target_view = target.create_view(&Default::default());
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("scene"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &target_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &view_group, &[]);
                pass.set_bind_group(1, &self.binding.bind_group, &[]);
                pass.set_bind_group(2, &material_group, &[]);
                pass.draw(0..3, 0..1);
            }
            // Let the uploads finish first, so that the time measured is the pass's.
            let _ = device.poll(wgpu::PollType::wait_indefinitely());
            let submitted = std::time::Instant::now();
            ctx.queue.submit([encoder.finish()]);
            (target, submitted)
        })?;
        ctx.wait("rendering the scene")?;
        Ok((target, submitted.elapsed().as_secs_f64()))
    }
}

/// Linear scene radiance read back from a [`RenderOutput::Linear`] render.
#[derive(Clone, Debug)]
pub struct LinearImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Linear RGB radiance (the tables' output space), row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// As [`RenderedImage::gpu_seconds`].
    pub gpu_seconds: f64,
}

/// Checks that the tables can render `options.film_eval`: the exact path needs a
/// `rough-film-lut` whose ambient matches and whose ranges hold the material.
pub(crate) fn check_film_eval(tables: &TableSet, options: &SceneOptions) -> Result<()> {
    if options.film_eval != FilmEval::Exact {
        return Ok(());
    }
    let Some(lut) = &tables.rough_film_lut else {
        return Err(Error::Invalid {
            context: "film evaluation `exact`".into(),
            message: "needs a `rough-film-lut` table in the table set (e.g. rough-film-dielectric)"
                .into(),
        });
    };
    let a = &lut.axes;
    let context = format!("rough-film-lut `{}`", lut.name);
    check_material_in_table(
        &context,
        &options.material,
        a.ambient_index,
        [a.ior_min, a.ior_max],
        a.thickness_max_nm,
    )
}

/// Checks that a table baked for `ambient_index`, film indices `film_ior` = [min, max] and
/// thicknesses up to `thickness_max_nm` holds `material` (its ambient, film index and
/// thickest point), naming the table (`context`) and the value out of range.
fn check_material_in_table(
    context: &str,
    material: &MaterialOptions,
    ambient_index: f64,
    [ior_min, ior_max]: [f64; 2],
    thickness_max_nm: f64,
) -> Result<()> {
    let tol = 1e-4;
    let invalid = |message: String| {
        Err(Error::Invalid {
            context: context.to_string(),
            message,
        })
    };
    if (f64::from(material.ambient_ior) - ambient_index).abs() > tol {
        return invalid(format!(
            "the table was baked for ambient index {ambient_index}, the material has {}",
            material.ambient_ior
        ));
    }
    let n = f64::from(material.film_ior);
    if n < ior_min - tol || n > ior_max + tol {
        return invalid(format!(
            "film index {n} lies outside the table's {ior_min}–{ior_max}"
        ));
    }
    let d = f64::from(material.max_thickness_nm());
    if d > thickness_max_nm * (1.0 + tol) {
        return invalid(format!(
            "the material reaches {d} nm, beyond the table's {thickness_max_nm} nm"
        ));
    }
    Ok(())
}

/// Checks that a `film-lut` table can render `material`: the table exists, its ambient is
/// the material's, the film index and the thicknesses lie inside the table, and a
/// transmitting material has a table with a transmittance.
pub(crate) fn check_film_lut(tables: &TableSet, material: &MaterialOptions) -> Result<()> {
    let Some(lut) = &tables.film_lut else {
        return Err(Error::Invalid {
            context: "technique `lut`".into(),
            message: "needs a `film-lut` table in the table set".into(),
        });
    };
    let a = &lut.axes;
    let context = format!("film-lut `{}`", lut.name);
    check_material_in_table(
        &context,
        material,
        a.ambient_index,
        [a.ior_min, a.ior_max],
        a.thickness_max_nm,
    )?;
    if material.transmission && !lut.has_transmittance {
        return Err(Error::Invalid {
            context,
            message: "a transmitting material (the bubble) needs a table with a transmittance (e.g. soap-film)".into(),
        });
    }
    Ok(())
}

/// Renders `options` with `technique` from `tables`: [`Renderer::new`] with
/// [`SceneOptions::technique_options`], then [`Renderer::render`].
pub fn render_scene(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    options: &SceneOptions,
) -> Result<RenderedImage> {
    options.validate()?;
    let renderer = Renderer::new(ctx, tables, technique, &options.technique_options())?;
    renderer.render(ctx, tables, options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_sizes_match_the_wgsl_layouts() {
        assert_eq!(std::mem::size_of::<ViewUniform>(), 128);
        assert_eq!(std::mem::size_of::<MaterialUniform>(), 96);
        assert_eq!(std::mem::offset_of!(MaterialUniform, film_weight), 80);
        assert_eq!(std::mem::offset_of!(MaterialUniform, base_ior), 32);
        assert_eq!(std::mem::offset_of!(MaterialUniform, base_kappa), 48);
        assert_eq!(std::mem::offset_of!(MaterialUniform, base_colour), 64);
        assert_eq!(std::mem::offset_of!(ViewUniform, eye_position), 64);
        assert_eq!(std::mem::offset_of!(ViewUniform, resolution), 112);
    }

    #[test]
    fn camera_ray_through_the_centre_looks_at_the_target() {
        let cam = Camera::for_scene(SceneKind::Sphere);
        let m = cam.inverse_view_projection(4.0 / 3.0).unwrap();
        let apply = |v: [f32; 4]| -> [f64; 3] {
            let mut out = [0.0f64; 4];
            for (col, &x) in m.iter().zip(&v) {
                for r in 0..4 {
                    out[r] += f64::from(col[r]) * f64::from(x);
                }
            }
            [out[0] / out[3], out[1] / out[3], out[2] / out[3]]
        };
        let near = apply([0.0, 0.0, 0.0, 1.0]);
        let far = apply([0.0, 0.0, 1.0, 1.0]);
        let dir = normalize(sub(far, near)).unwrap();
        let expect = normalize(sub(cam.target.map(f64::from), cam.eye.map(f64::from))).unwrap();
        for k in 0..3 {
            assert!((dir[k] - expect[k]).abs() < 1e-4, "{dir:?} vs {expect:?}");
        }
        // The near point is the eye pushed 0.05 along the view direction.
        for k in 0..3 {
            assert!((near[k] - (f64::from(cam.eye[k]) + 0.05 * expect[k])).abs() < 1e-3);
        }
        // The top edge of the image is fov/2 above the centre.
        let top = normalize(sub(apply([0.0, 1.0, 1.0, 1.0]), near)).unwrap();
        let angle = (top[0] * dir[0] + top[1] * dir[1] + top[2] * dir[2])
            .acos()
            .to_degrees();
        assert!((angle - 18.0).abs() < 1e-3, "{angle}");
        let mut bad = cam;
        bad.target = bad.eye;
        assert!(bad.inverse_view_projection(1.0).is_err());
        bad = cam;
        bad.fov_y_deg = 180.0;
        assert!(bad.inverse_view_projection(1.0).is_err());
    }

    #[test]
    fn mip_chain_averages_and_ends_at_one_texel() {
        let texels: Vec<[f32; 1]> = (0..15).map(|i| [i as f32]).collect();
        let chain = mip_chain(5, 3, texels);
        let sizes: Vec<(usize, usize)> = chain.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(sizes, vec![(5, 3), (2, 1), (1, 1)]);
        // Level 1 texel 0 averages (0, 0), (1, 0), (0, 1), (1, 1) = 0, 1, 5, 6.
        assert_eq!(chain[1].2[0][0], 3.0);
    }

    #[test]
    fn procedural_images_are_finite_and_in_range() {
        let env = procedural_environment(64, 32);
        assert!(
            env.rgb
                .iter()
                .flatten()
                .all(|v| v.is_finite() && *v >= 0.0 && *v < 65504.0)
        );
        let map = procedural_thickness_map(64);
        assert!(map.values.iter().all(|v| (0.0..=1.0).contains(v)));
        // Tileable: the first and the last column differ as little as neighbours do.
        let step = |a: usize, b: usize| (map.values[a] - map.values[b]).abs();
        let wrap: f32 = (0..64)
            .map(|y| step(y * 64, y * 64 + 63))
            .fold(0.0, f32::max);
        let inner: f32 = (0..64)
            .map(|y| step(y * 64, y * 64 + 1))
            .fold(0.0, f32::max);
        assert!(wrap <= 2.0 * inner + 1e-3, "{wrap} vs {inner}");
    }

    #[test]
    fn openpbr_maps_weight_micrometres_and_ior() {
        let mut m = MaterialOptions::for_scene(SceneKind::Sphere);
        // OpenPBR's defaults: weight 0 (the base bare), thickness 0.5 µm, index 1.4.
        m.apply_openpbr(0.0, 0.5, 1.4).unwrap();
        assert_eq!(m.film_weight, 0.0);
        assert_eq!(m.film_ior, 1.4);
        assert_eq!(
            m.thickness,
            ThicknessMapping::Gltf {
                min_nm: 500.0,
                max_nm: 500.0
            }
        );
        assert_eq!(m.max_thickness_nm(), 500.0);
        m.apply_openpbr(1.7, 0.25, 1.33).unwrap();
        assert_eq!(m.film_weight, 1.0, "the weight is clamped to [0, 1]");
        assert_eq!(m.thickness.max_nm(), 250.0);
        assert!(m.validate().is_ok());
        for bad in [
            (f32::NAN, 0.5, 1.5),
            (0.5, -1.0, 1.5),
            (0.5, 0.5, 0.0),
            (0.5, f32::INFINITY, 1.5),
        ] {
            assert!(
                m.clone().apply_openpbr(bad.0, bad.1, bad.2).is_err(),
                "{bad:?}"
            );
        }
        // The uniform carries the weight at offset 80.
        let tables = TableSet::default();
        let u = MaterialUniform::new(&m, &tables).unwrap();
        assert_eq!(u.film_weight, 1.0);
    }

    #[test]
    fn film_eval_names_parse_and_uniform_layouts_hold() {
        for k in FilmEval::ALL {
            assert_eq!(k.name().parse::<FilmEval>().unwrap(), k);
        }
        assert!("fresnel".parse::<FilmEval>().is_err());
        assert!(!FilmEval::Classic.split_sum() && FilmEval::Exact.split_sum());
        assert_eq!(std::mem::offset_of!(MaterialUniform, film_eval), 84);
        assert_eq!(std::mem::size_of::<RoughLutUniform>(), 48);
        assert_eq!(std::mem::offset_of!(RoughLutUniform, has_transmittance), 40);
    }

    #[test]
    fn exact_path_needs_a_rough_table() {
        let mut o = SceneOptions::new(SceneKind::Sphere);
        o.film_eval = FilmEval::Exact;
        assert!(check_film_eval(&TableSet::default(), &o).is_err());
        o.film_eval = FilmEval::NormalView;
        assert!(check_film_eval(&TableSet::default(), &o).is_ok());
    }

    #[test]
    fn scene_names_parse() {
        for k in SceneKind::ALL {
            assert_eq!(k.name().parse::<SceneKind>().unwrap(), k);
        }
        assert!("cube".parse::<SceneKind>().is_err());
    }
}
