//! The command line's fixed choices as typed values, parsed once by clap, and their
//! library values. Variants carry no doc comments: clap would list them in `--help` as a
//! long table instead of today's `[possible values: …]`.

use clap::ValueEnum;
use nacre_bake::commands::color::Quantity;

/// `--quantity`: r (reflectance) or t (transmittance).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QuantityArg {
    R,
    T,
}

impl From<QuantityArg> for Quantity {
    fn from(q: QuantityArg) -> Self {
        match q {
            QuantityArg::R => Quantity::Reflectance,
            QuantityArg::T => Quantity::Transmittance,
        }
    }
}

/// `nacre render --layer-channel`: the thickness-map channel a stack's film follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ChannelArg {
    R,
    G,
    B,
}

impl ChannelArg {
    /// The channel's index (0 R or grey, 1 G, 2 B).
    pub fn index(self) -> usize {
        match self {
            ChannelArg::R => 0,
            ChannelArg::G => 1,
            ChannelArg::B => 2,
        }
    }
}

/// `nacre render --technique`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TechniqueArg {
    Lut,
    Fourier,
    Spectral,
    Stack,
}

impl From<TechniqueArg> for nacre_runtime::Technique {
    fn from(t: TechniqueArg) -> Self {
        match t {
            TechniqueArg::Lut => nacre_runtime::Technique::Lut,
            TechniqueArg::Fourier => nacre_runtime::Technique::Fourier,
            TechniqueArg::Spectral => nacre_runtime::Technique::Spectral,
            TechniqueArg::Stack => nacre_runtime::Technique::Stack,
        }
    }
}

/// `nacre render --scene`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SceneArg {
    Sphere,
    Bubble,
    Plane,
    RoughRow,
    CdDisc,
    SnakeSkin,
}

impl From<SceneArg> for nacre_runtime::Scene {
    fn from(s: SceneArg) -> Self {
        use nacre_runtime::Scene;
        use nacre_runtime::diffraction::DiffractionScene;
        use nacre_runtime::render::SceneKind;
        match s {
            SceneArg::Sphere => Scene::Film(SceneKind::Sphere),
            SceneArg::Bubble => Scene::Film(SceneKind::Bubble),
            SceneArg::Plane => Scene::Film(SceneKind::Plane),
            SceneArg::RoughRow => Scene::RoughRow,
            SceneArg::CdDisc => Scene::Diffraction(DiffractionScene::CdDisc),
            SceneArg::SnakeSkin => Scene::Diffraction(DiffractionScene::SnakeSkin),
        }
    }
}

/// `nacre render --film-eval`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FilmEvalArg {
    Classic,
    Nv,
    Exact,
}

impl From<FilmEvalArg> for nacre_runtime::render::FilmEval {
    fn from(f: FilmEvalArg) -> Self {
        use nacre_runtime::render::FilmEval;
        match f {
            FilmEvalArg::Classic => FilmEval::Classic,
            FilmEvalArg::Nv => FilmEval::NormalView,
            FilmEvalArg::Exact => FilmEval::Exact,
        }
    }
}
