//! What a glTF frame reads, loaded and validated before a device exists ([`RenderInputs`]),
//! so that `nacre render --gltf` reads every input once and bad input fails before the GPU
//! starts.

use super::camera::{FittedCamera, ViewPoint, view_camera};
use super::lights::scene_lights;
use crate::context::GpuContext;
use crate::environment::EnvironmentMap;
use crate::error::Result;
use crate::gltf_scene::GltfScene;
use crate::render::SceneOptions;
use crate::tables::TableSet;
use nacre_format::manifest::Manifest;
use std::path::{Path, PathBuf};

/// A table's manifest, read (its files are checked and uploaded by [`TableFile::upload`]).
#[derive(Clone, Debug)]
pub struct TableFile {
    /// The manifest's path.
    pub path: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
}

impl TableFile {
    /// Reads the manifest at `path`.
    pub fn read(path: &Path) -> Result<TableFile> {
        Ok(TableFile {
            path: path.to_path_buf(),
            manifest: Manifest::read(path)?,
        })
    }

    /// Checks the table's files against the manifest and uploads them into `tables`
    /// ([`TableSet::add_read`]).
    pub fn upload(&self, ctx: &GpuContext, tables: &mut TableSet) -> Result<()> {
        tables.add_read(ctx, self.manifest.clone(), &self.path)
    }
}

/// The environment `options` names (`environment`), or the default studio map.
pub fn load_environment(options: &SceneOptions) -> Result<EnvironmentMap> {
    match &options.environment {
        Some(path) => EnvironmentMap::load(path),
        None => EnvironmentMap::default_map(),
    }
}

/// Everything a glTF frame reads but the tables' pixels: the scene (its geometry, textures
/// and per-material thickness maps, [`GltfScene::thickness_maps`], decoded on load), the
/// validated settings with the camera and the scene's lights applied, the environment and
/// the camera. Built without a device: the renderer ([`super::render`]) only uploads and
/// draws it.
pub struct RenderInputs<'s> {
    /// The scene.
    pub scene: &'s GltfScene,
    /// The settings as given, validated.
    pub options: SceneOptions,
    /// The settings the view uniform is built from: `options` with the camera's eye, target,
    /// up and field of view, and the scene's lights.
    pub view_options: SceneOptions,
    /// The environment that lights the scene (and that transmissive surfaces see where the
    /// scene shows nothing).
    pub environment: EnvironmentMap,
    /// The camera.
    pub camera: FittedCamera,
    /// What [`scene_lights`] had to leave out, if anything.
    pub light_note: Option<String>,
}

impl<'s> RenderInputs<'s> {
    /// Validates `options`, loads the environment it names and fits the camera `view` to
    /// `scene` ([`view_camera`]; `options`' own scene, camera, thickness map and material are
    /// not used: the materials come from the file).
    pub fn load(
        scene: &'s GltfScene,
        options: &SceneOptions,
        view: ViewPoint,
    ) -> Result<RenderInputs<'s>> {
        options.validate()?;
        let environment = load_environment(options)?;
        RenderInputs::with_environment(scene, options, view, environment)
    }

    /// [`RenderInputs::load`] with the environment already loaded ([`load_environment`]).
    pub fn with_environment(
        scene: &'s GltfScene,
        options: &SceneOptions,
        view: ViewPoint,
        environment: EnvironmentMap,
    ) -> Result<RenderInputs<'s>> {
        options.validate()?;
        let aspect = f64::from(options.width) / f64::from(options.height);
        let camera = view_camera(scene, view, aspect)?;
        let mut view_options = options.clone();
        view_options.camera.eye = camera.eye;
        view_options.camera.target = camera.target;
        view_options.camera.up = camera.up;
        view_options.camera.fov_y_deg = camera.fov_y_deg;
        let (light, punctual_lights, light_note) = scene_lights(scene);
        view_options.light = light;
        view_options.punctual_lights = punctual_lights;
        Ok(RenderInputs {
            scene,
            options: options.clone(),
            view_options,
            environment,
            camera,
            light_note,
        })
    }
}
