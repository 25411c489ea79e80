//! Every scene the renderer draws, by kind, and the default-set tables each one reads.
//!
//! The kinds share group 0 of their pipelines (`shaders/view.wgsl`: the view uniform
//! [`crate::render::ViewUniform`] and the environment's textures) and the display output
//! (`shaders/output.wgsl`: tone mapping and sRGB encoding); they differ in their geometry
//! and in what group 1 holds:
//!
//! | kind | geometry | group 1 | entry |
//! |---|---|---|---|
//! | [`Scene::Film`] | analytic, ray-cast (`scene.wgsl`) or a glTF mesh (`mesh.wgsl`) | a film technique | [`crate::render::render_scene`], [`crate::mesh::render_gltf`] |
//! | [`Scene::RoughRow`] | three rows of analytic spheres | a film technique | [`crate::rough_reference::render_rough_row`] |
//! | [`Scene::Diffraction`] | analytic, ray-cast (`diffraction_scene.wgsl`) | the `diffraction` technique | [`crate::diffraction::render_diffraction_scene`] |

use crate::diffraction::DiffractionScene;
use crate::error::{Error, Result};
use crate::render::{FilmEval, SceneKind};
use std::str::FromStr;

/// A scene of the renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scene {
    /// A thin-film scene: a coated sphere, a soap bubble or an oil film on a plane.
    Film(SceneKind),
    /// The rough-film comparison: the engines' shortcut, the exact path and a Monte Carlo
    /// reference, side by side over roughness.
    RoughRow,
    /// A diffraction scene: a CD-like or DVD-like disc, a snake's skin or a flat grating.
    Diffraction(DiffractionScene),
}

impl Scene {
    /// Every scene, in the order `nacre render --help` lists them.
    pub const ALL: [Scene; 8] = [
        Scene::Film(SceneKind::Sphere),
        Scene::Film(SceneKind::Bubble),
        Scene::Film(SceneKind::Plane),
        Scene::RoughRow,
        Scene::Diffraction(DiffractionScene::CdDisc),
        Scene::Diffraction(DiffractionScene::DvdDisc),
        Scene::Diffraction(DiffractionScene::SnakeSkin),
        Scene::Diffraction(DiffractionScene::GratingPlane),
    ];

    /// The scene's name (`nacre render --scene`, file names).
    pub fn name(self) -> &'static str {
        match self {
            Scene::Film(kind) => kind.name(),
            Scene::RoughRow => "rough-row",
            Scene::Diffraction(scene) => scene.name(),
        }
    }

    /// The default-set tables the scene reads when none are named: the film-lut baked for
    /// the scene's stack (`film-dielectric` for the sphere and for glTF meshes, `soap-film`
    /// for the bubble, `oil-slick` for the plane) and `fourier-srgb`, plus
    /// `rough-film-dielectric` for [`FilmEval::Exact`]; the rough row's three; a diffraction
    /// scene's one ([`DiffractionScene::default_table`]). `gltf`: the film scene draws a
    /// glTF file's meshes instead of its analytic geometry.
    pub fn default_tables(self, film_eval: FilmEval, gltf: bool) -> Vec<&'static str> {
        match self {
            Scene::Film(kind) => {
                let lut = match kind {
                    _ if gltf => "film-dielectric",
                    SceneKind::Sphere => "film-dielectric",
                    SceneKind::Bubble => "soap-film",
                    SceneKind::Plane => "oil-slick",
                };
                let mut names = vec![lut, "fourier-srgb"];
                if film_eval == FilmEval::Exact {
                    names.push("rough-film-dielectric");
                }
                names
            }
            Scene::RoughRow => vec!["film-dielectric", "fourier-srgb", "rough-film-dielectric"],
            Scene::Diffraction(scene) => vec![scene.default_table()],
        }
    }
}

impl FromStr for Scene {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Scene::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::UnknownName {
                what: "scene",
                name: s.to_string(),
                expected: format!("one of {}", Scene::ALL.map(Scene::name).join(", ")),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_default_tables_are_in_the_default_set() {
        for scene in Scene::ALL {
            assert_eq!(scene.name().parse::<Scene>().unwrap(), scene);
            for eval in [FilmEval::Classic, FilmEval::NormalView, FilmEval::Exact] {
                for gltf in [false, true] {
                    for name in scene.default_tables(eval, gltf) {
                        let path = nacre_format::set::resolve_table(name);
                        assert!(path.is_file(), "{} reads {name}: no {path:?}", scene.name());
                    }
                }
            }
        }
        assert!("teapot".parse::<Scene>().is_err());
        assert_eq!(
            Scene::Film(SceneKind::Sphere).default_tables(FilmEval::Exact, false),
            ["film-dielectric", "fourier-srgb", "rough-film-dielectric"]
        );
        assert_eq!(
            Scene::Film(SceneKind::Bubble).default_tables(FilmEval::Classic, true),
            ["film-dielectric", "fourier-srgb"]
        );
    }
}
