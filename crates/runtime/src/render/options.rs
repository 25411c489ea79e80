//! What a scene render is asked for: the scene ([`SceneKind`]), how the film enters the
//! lighting ([`FilmEval`]), the camera, the light, the film-coated material
//! ([`MaterialOptions`], mirrored by [`MaterialUniform`]) and everything together
//! ([`SceneOptions`]).

use crate::bindings::{SpectralSetup, StackSetup, TechniqueOptions};
use crate::environment::SUN_DIRECTION;
use crate::error::{Error, Result};
use crate::image_io::MAX_DIMENSION;
use crate::tables::TableSet;
use bytemuck::{Pod, Zeroable};
use nacre_optics::{C64, Material};
use std::f32::consts::FRAC_PI_2;
use std::path::PathBuf;
use std::str::FromStr;

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
    pub(crate) fn id(self) -> u32 {
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
            .ok_or_else(|| Error::UnknownName {
                what: "scene",
                name: s.to_string(),
                expected: "sphere, bubble or plane".into(),
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
            .ok_or_else(|| Error::UnknownName {
                what: "film evaluation",
                name: s.to_string(),
                expected: "classic, nv or exact".into(),
            })
    }
}

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
        let bad = |problem: String| Error::Camera {
            name: None,
            problem,
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

pub(super) fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
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

/// The most [`PunctualLight`]s one render draws ([`SceneOptions::punctual_lights`];
/// `VIEW_MAX_LIGHTS` in `shaders/view.wgsl`).
pub const MAX_PUNCTUAL_LIGHTS: usize = 8;

/// Where a [`PunctualLight`] is and how its light falls off (KHR_lights_punctual).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PunctualKind {
    /// Infinitely far: the same direction and irradiance everywhere.
    Directional,
    /// At `position`, in every direction.
    Point,
    /// At `position`, a cone about `direction` with the specification's angular falloff
    /// t² (t = clamp((cos θ − cos θ_outer) / (cos θ_inner − cos θ_outer), 0, 1)).
    Spot {
        /// Inner cone angle, radians.
        inner_cone_rad: f32,
        /// Outer cone angle, radians.
        outer_cone_rad: f32,
    },
}

/// A `KHR_lights_punctual` light evaluated at every shading point, besides the scene's one
/// directional [`Light`]. For a point or spot light at distance r the irradiance at normal
/// incidence is colour × intensity × w(r) / r², with the specification's range window
/// w(r) = clamp(1 − (r / range)⁴, 0, 1)² (w = 1 without a range); a directional light's is
/// colour × intensity (KHR_lights_punctual, "Range Property" and "Inner and Outer Cone
/// Angles").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PunctualLight {
    /// Directional, point or spot.
    pub kind: PunctualKind,
    /// World position (unused by a directional light).
    pub position: [f32; 3],
    /// Direction the light shines along (need not be unit; unused by a point light).
    pub direction: [f32; 3],
    /// Linear RGB colour.
    pub colour: [f32; 3],
    /// Lux for a directional light, candela otherwise.
    pub intensity: f32,
    /// Distance beyond which a point or spot light gives nothing; `None`: unlimited.
    pub range: Option<f32>,
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
        let bad = |what: &str, value: f32, unit: &'static str, expected: &str| {
            Err(Error::OutOfRange {
                what: format!("OpenPBR thin film: {what}"),
                value: f64::from(value),
                unit,
                expected: expected.into(),
            })
        };
        if !thin_film_weight.is_finite() {
            return bad("thin_film_weight", thin_film_weight, "", "0 to 1");
        }
        if !(thin_film_thickness_um.is_finite() && (0.0..=1000.0).contains(&thin_film_thickness_um))
        {
            return bad(
                "thin_film_thickness",
                thin_film_thickness_um,
                " µm",
                "0 to 1000",
            );
        }
        if !(thin_film_ior.is_finite() && thin_film_ior > 0.0) {
            return bad("thin_film_ior", thin_film_ior, "", "a positive number");
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
        let bad = |what: &str, value: f32, expected: &str| {
            Err(Error::OutOfRange {
                what: format!("material: {what}"),
                value: f64::from(value),
                unit: "",
                expected: expected.into(),
            })
        };
        let positive = [
            ("film index", self.film_ior),
            ("ambient index", self.ambient_ior),
        ];
        for (name, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return bad(name, v, "a positive number");
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
                return bad(name, v, "a finite number within ±1e6");
            }
        }
        for (name, v) in [
            ("thickness roughness", self.thickness_roughness_nm),
            ("drainage", self.drain_nm),
        ] {
            if v < 0.0 {
                return bad(name, v, "a non-negative number");
            }
        }
        if !(self.film_weight >= 0.0 && self.film_weight <= 1.0) {
            return bad("film weight", self.film_weight, "0 to 1");
        }
        if !(self.roughness_alpha >= 0.0 && self.roughness_alpha <= 1.0) {
            return bad("GGX roughness α", self.roughness_alpha, "0 to 1");
        }
        if let Some(&c) = self.base_colour.iter().find(|c| !(0.0..=1.0).contains(*c)) {
            return bad("base colour channel", c, "0 to 1 per channel");
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
    /// ([`EnvironmentMap::default_map`](crate::environment::EnvironmentMap::default_map)).
    pub environment: Option<PathBuf>,
    /// Scale of the environment's radiance (default 1).
    pub env_intensity: f32,
    /// A greyscale PNG thickness map, or `None` for [`procedural_thickness_map`](crate::thickness_map::procedural_thickness_map).
    pub thickness_map: Option<PathBuf>,
    /// The material (default: [`MaterialOptions::for_scene`]).
    pub material: MaterialOptions,
    /// The directional light (default: [`Light::default`]).
    pub light: Light,
    /// Point, spot and directional lights drawn besides `light`, at most
    /// [`MAX_PUNCTUAL_LIGHTS`] (default none; the glTF renderer fills it from the file's
    /// `KHR_lights_punctual` lights).
    pub punctual_lights: Vec<PunctualLight>,
    /// Exposure, EV stops: radiance is scaled by 2^EV before tone mapping (default 0).
    pub exposure_ev: f32,
    /// Harmonics M of `film_fourier` (0 = automatic, the default).
    pub harmonics: u32,
    /// Wavelengths N of `film_spectral` (default 30).
    pub spectral_samples: usize,
    /// The stack of `film_stack` (default [`StackSetup::default`]): its top film takes the
    /// material's thickness, its other films vary with the thickness map (s = 2g − 1).
    pub stack: StackSetup,
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
            punctual_lights: Vec::new(),
            exposure_ev: 0.0,
            harmonics: technique.harmonics,
            spectral_samples: technique.spectral.samples,
            stack: technique.stack,
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
            stack: self.stack.clone(),
        }
    }

    /// Checks sizes, exposure, intensities, the light and the material (not the files, not
    /// the tables): [`Renderer::render`](super::Renderer::render) calls it first.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_DIMENSION).contains(&v) {
                return Err(Error::OutOfRange {
                    what: format!("image {name}"),
                    value: f64::from(v),
                    unit: " pixels",
                    expected: format!("1 to {MAX_DIMENSION}"),
                });
            }
        }
        for (name, v) in [
            ("exposure", self.exposure_ev),
            ("environment intensity", self.env_intensity),
            ("light intensity", self.light.intensity),
        ] {
            if !(v.is_finite() && v.abs() <= 1e4) {
                return Err(Error::OutOfRange {
                    what: name.into(),
                    value: f64::from(v),
                    unit: "",
                    expected: "a finite number within ±1e4".into(),
                });
            }
        }
        for (name, v) in [
            ("environment intensity", self.env_intensity),
            ("light intensity", self.light.intensity),
        ] {
            if v < 0.0 {
                return Err(Error::OutOfRange {
                    what: name.into(),
                    value: f64::from(v),
                    unit: "",
                    expected: "a non-negative number".into(),
                });
            }
        }
        if self.exposure_ev.abs() > 64.0 {
            return Err(Error::OutOfRange {
                what: "exposure".into(),
                value: f64::from(self.exposure_ev),
                unit: " EV",
                expected: "−64 to 64".into(),
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
            return Err(Error::Light {
                index: None,
                problem: format!(
                    "{:?} (expected finite values, a non-negative colour)",
                    self.light
                ),
            });
        }
        if self.punctual_lights.len() > MAX_PUNCTUAL_LIGHTS {
            return Err(Error::TooManyLights {
                count: self.punctual_lights.len(),
                max: MAX_PUNCTUAL_LIGHTS,
            });
        }
        for (k, light) in self.punctual_lights.iter().enumerate() {
            let finite = light
                .position
                .iter()
                .chain(&light.direction)
                .chain(&light.colour)
                .chain([&light.intensity])
                .all(|x| x.is_finite());
            let cone_ok = match light.kind {
                PunctualKind::Spot {
                    inner_cone_rad,
                    outer_cone_rad,
                } => (0.0..outer_cone_rad).contains(&inner_cone_rad) && outer_cone_rad <= FRAC_PI_2,
                _ => true,
            };
            let aimed = light.kind == PunctualKind::Point
                || normalize(light.direction.map(f64::from)).is_some();
            if !finite
                || light.colour.iter().any(|&c| c < 0.0)
                || light.intensity < 0.0
                || light.range.is_some_and(|r| !(r > 0.0 && r.is_finite()))
                || !cone_ok
                || !aimed
            {
                return Err(Error::Light {
                    index: Some(k),
                    problem: format!(
                        "{light:?} (expected finite values, a non-negative colour and intensity, a positive range, a direction, 0 ≤ inner < outer ≤ π/2)"
                    ),
                });
            }
        }
        self.material.validate()
    }
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

#[cfg(test)]
mod tests {
    use super::*;

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
    fn scene_names_parse() {
        for k in SceneKind::ALL {
            assert_eq!(k.name().parse::<SceneKind>().unwrap(), k);
        }
        assert!("cube".parse::<SceneKind>().is_err());
    }
}
