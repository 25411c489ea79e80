//! The WGSL modules under `shaders/` and their composition.
//!
//! WGSL has no `import`: a pipeline's source is the concatenation, in this order, of
//! [`COMMON`], [`LUT_MAPPING`], one technique module ([`Technique::source`]) and one
//! consumer module (probe, material + scene, or the plain baseline). See `shaders/README.md`
//! for the bind-group contract each module follows.

/// Constants, complex arithmetic, Fresnel at an interface, NaN guards, `FilmInput`/`FilmOutput`.
pub const COMMON: &str = include_str!("../../../shaders/common.wgsl");
/// The film-lut coordinate mappings (mirror of `nacre_format::film_lut::FilmLutAxes`).
pub const LUT_MAPPING: &str = include_str!("../../../shaders/lut_mapping.wgsl");
/// Technique: trilinear lookup in a baked `film-lut` table.
pub const FILM_LUT: &str = include_str!("../../../shaders/film_lut.wgsl");
/// Technique: Belcour & Barla 2017 Eq. 10 with a baked `fourier` table.
pub const FILM_FOURIER: &str = include_str!("../../../shaders/film_fourier.wgsl");
/// Technique: brute-force loop over N wavelengths.
pub const FILM_SPECTRAL: &str = include_str!("../../../shaders/film_spectral.wgsl");

/// Baseline "technique" without a film (Schlick Fresnel) for `nacre bench-gpu`.
pub const PLAIN: &str = include_str!("../../../shaders/plain.wgsl");
/// Consumer: the full-screen GGX pass of `nacre bench-gpu`.
pub const BENCH: &str = include_str!("../../../shaders/bench.wgsl");
/// Consumer: the GPU = CPU probe pass.
pub const PROBE: &str = include_str!("../../../shaders/probe.wgsl");
/// The rough-film-lut coordinate mappings and two-fetch lookup (mirror of
/// `nacre_bake::kinds::rough_film_lut`; no bindings of its own).
pub const ROUGH_LUT_MAPPING: &str = include_str!("../../../shaders/rough_lut_mapping.wgsl");
/// Consumer: the thin-film microfacet material (GGX + film, environment, light, tone
/// mapping; groups 0 and 2), preceded by [`ROUGH_LUT_MAPPING`] (its exact split-sum path
/// samples a `rough-film-lut`). Compose it before [`SCENE`] or [`MESH`].
pub const MATERIAL: &str = concat!(
    include_str!("../../../shaders/rough_lut_mapping.wgsl"),
    "\n",
    include_str!("../../../shaders/material.wgsl")
);
/// Consumer: the ray-cast analytic scenes of `nacre render` (sphere, bubble, plane).
pub const SCENE: &str = include_str!("../../../shaders/scene.wgsl");
/// Consumer: rasterised triangle meshes (glTF scenes of `nacre render --gltf`; group 3 holds
/// the view-projection). Compose it after [`MATERIAL`].
pub const MESH: &str = include_str!("../../../shaders/mesh.wgsl");

/// How the film colour is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Technique {
    /// `film_lut.wgsl`.
    Lut,
    /// `film_fourier.wgsl`.
    Fourier,
    /// `film_spectral.wgsl`.
    Spectral,
}

impl Technique {
    /// Every technique.
    pub const ALL: [Technique; 3] = [Technique::Lut, Technique::Fourier, Technique::Spectral];

    /// The technique module's WGSL source.
    pub fn source(self) -> &'static str {
        match self {
            Technique::Lut => FILM_LUT,
            Technique::Fourier => FILM_FOURIER,
            Technique::Spectral => FILM_SPECTRAL,
        }
    }

    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Lut => "lut",
            Technique::Fourier => "fourier",
            Technique::Spectral => "spectral",
        }
    }
}

/// The full source of a pipeline: common + mapping + `technique` + `consumer`.
pub fn compose(technique: Technique, consumer: &[&str]) -> String {
    compose_source(technique.source(), consumer)
}

/// [`compose`] with any module that defines `film_colour` (e.g. [`PLAIN`]).
pub fn compose_source(technique_source: &str, consumer: &[&str]) -> String {
    let mut s = String::with_capacity(64 * 1024);
    for part in [COMMON, LUT_MAPPING, technique_source]
        .into_iter()
        .chain(consumer.iter().copied())
    {
        s.push_str(part);
        s.push('\n');
    }
    s
}
