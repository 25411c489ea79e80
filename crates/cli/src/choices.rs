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

/// `nacre render --footprint-filter`: whether the diffraction scenes average the BRDF over
/// each pixel's footprint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OnOffArg {
    On,
    Off,
}

/// `nacre render --lighting`: which of an analytic scene's sources light it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LightingArg {
    Both,
    Light,
    Environment,
}

/// `nacre render --layer-channel`, `nacre export --layer-channel`: the thickness-map channel
/// a stack's film follows.
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

/// `nacre render --technique`: one choice per entry of the runtime's technique registry
/// (`nacre_runtime::technique::REGISTRY`), by its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TechniqueArg(pub nacre_runtime::Technique);

/// Every technique as a choice, in the registry's order.
const TECHNIQUE_ARGS: [TechniqueArg; nacre_runtime::Technique::ALL.len()] = {
    let all = nacre_runtime::Technique::ALL;
    let mut args = [TechniqueArg(all[0]); nacre_runtime::Technique::ALL.len()];
    let mut i = 0;
    while i < all.len() {
        args[i] = TechniqueArg(all[i]);
        i += 1;
    }
    args
};

impl ValueEnum for TechniqueArg {
    fn value_variants<'a>() -> &'a [Self] {
        &TECHNIQUE_ARGS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()))
    }
}

impl From<TechniqueArg> for nacre_runtime::Technique {
    fn from(t: TechniqueArg) -> Self {
        t.0
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
    DvdDisc,
    SnakeSkin,
    GratingPlane,
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
            SceneArg::DvdDisc => Scene::Diffraction(DiffractionScene::DvdDisc),
            SceneArg::SnakeSkin => Scene::Diffraction(DiffractionScene::SnakeSkin),
            SceneArg::GratingPlane => Scene::Diffraction(DiffractionScene::GratingPlane),
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

#[cfg(test)]
mod tests {
    use super::*;
    use nacre_runtime::technique::REGISTRY;

    /// `--technique` offers every technique of the registry by its name, and each names a
    /// CPU twin that `nacre color --method` accepts.
    #[test]
    fn techniques_come_from_the_registry() {
        let names: Vec<String> = TechniqueArg::value_variants()
            .iter()
            .map(|t| t.to_possible_value().unwrap().get_name().to_string())
            .collect();
        let registry: Vec<&str> = REGISTRY.iter().map(|e| e.name).collect();
        assert_eq!(names, registry);
        for (e, technique) in REGISTRY.iter().zip(nacre_runtime::Technique::ALL) {
            let t = TechniqueArg::from_str(e.name, false).unwrap();
            assert_eq!(nacre_runtime::Technique::from(t), technique);
            let twin = e
                .cpu_twin
                .replace('N', "30")
                .replace("PATH", "tables/baked/film-dielectric.json");
            assert!(
                nacre_bake::commands::color::Method::parse(&twin).is_ok(),
                "{}: CPU twin `{}`",
                e.name,
                e.cpu_twin
            );
        }
    }
}
