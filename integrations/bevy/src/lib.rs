//! # bevy_nacre
//!
//! Exact thin-film iridescence from nacre's tables in Bevy, and
//! `KHR_materials_iridescence` for Bevy's glTF loader.
//!
//! * [`NacrePlugin`] registers nacre's WGSL modules with Bevy's shader system
//!   ([`shaders`]), the table asset and its loader ([`tables`]; the default set is built
//!   in), the film material [`NacreMaterial`] ([`material`]) and the glTF hook ([`gltf`]).
//! * [`NacreMaterial`] = `ExtendedMaterial<StandardMaterial, NacreFilm>`: Bevy's PBR
//!   lighting with nacre's film colour (`film_lut`, `film_fourier` or a multilayer
//!   `film_stack`, [`NacreFilm::set_stack`]) in place of the specular Fresnel term.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_nacre::{NacreFilm, NacreMaterial, NacrePlugin};
//!
//! fn setup(
//!     mut commands: Commands,
//!     mut meshes: ResMut<Assets<Mesh>>,
//!     mut materials: ResMut<Assets<NacreMaterial>>,
//! ) {
//!     commands.spawn((
//!         Mesh3d(meshes.add(Sphere::new(1.0))),
//!         MeshMaterial3d(materials.add(NacreMaterial {
//!             base: StandardMaterial { base_color: Color::BLACK, ..default() },
//!             extension: NacreFilm { film_ior: 1.8, weight: 1.0, ..default() },
//!         })),
//!     ));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, NacrePlugin))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```

pub mod gltf;
pub mod material;
pub mod shaders;
pub mod tables;

pub use material::{
    DEFAULT_STACK_INDICES, DEFAULT_STACK_NODES, FilmTechnique, FilmThickness, NacreFilm,
    NacreFilmKey, NacreMaterial, StackUniform,
};
pub use tables::{DEFAULT_FILM_LUT, DEFAULT_FOURIER, NacreTable, NacreTableLoader};

use bevy::app::{App, Plugin, PostUpdate};
use bevy::asset::{AssetApp, Assets};
use bevy::image::Image;
use bevy::pbr::MaterialPlugin;
use bevy::prelude::IntoScheduleConfigs;
use bevy::shader::Shader;

/// Adds nacre to a Bevy app: see the [crate docs](crate). Add it after `DefaultPlugins`
/// (it needs the asset, render, PBR and glTF plugins).
#[derive(Default)]
pub struct NacrePlugin;

impl Plugin for NacrePlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<NacreTable>()
            .register_asset_loader(NacreTableLoader)
            .add_plugins(MaterialPlugin::<NacreMaterial>::default())
            .add_systems(
                PostUpdate,
                material::bind_tables.before(bevy::asset::AssetEventSystems),
            );
        shaders::register(&mut app.world_mut().resource_mut::<Assets<Shader>>());
        add_default_tables(app);
        add_default_stack(app);
        if let Some(handlers) = app
            .world_mut()
            .get_resource_mut::<bevy::gltf::extensions::GltfExtensionHandlers>()
        {
            handlers
                .0
                .write_blocking()
                .push(Box::new(gltf::NacreGltfHandler::default()));
        }
    }
}

/// Uploads the default stack ([`material::default_stack`]) under [`DEFAULT_STACK_NODES`] and
/// [`DEFAULT_STACK_INDICES`], which every [`NacreFilm`] binds until given its own.
fn add_default_stack(app: &mut App) {
    let (nodes, indices) = material::stack_buffers(&material::DEFAULT_STACK);
    let mut buffers = app
        .world_mut()
        .resource_mut::<Assets<bevy::render::storage::ShaderBuffer>>();
    // UUID handles never fail to insert.
    let _ = buffers.insert(DEFAULT_STACK_NODES.id(), nodes);
    let _ = buffers.insert(DEFAULT_STACK_INDICES.id(), indices);
}

/// Builds the compiled-in default set into [`DEFAULT_FILM_LUT`] and [`DEFAULT_FOURIER`].
fn add_default_tables(app: &mut App) {
    use tables::default_set::*;
    let world = app.world_mut();
    let mut built = Vec::new();
    {
        let mut images = world.resource_mut::<Assets<Image>>();
        for (handle, name, text, files) in [
            (
                DEFAULT_FILM_LUT,
                "film-dielectric.json",
                FILM_LUT_MANIFEST,
                &FILM_LUT_FILES[..],
            ),
            (
                DEFAULT_FOURIER,
                "fourier-srgb.json",
                FOURIER_MANIFEST,
                &FOURIER_FILES[..],
            ),
        ] {
            let table = tables::table_from_memory(name, text, files, |image| images.add(image))
                .unwrap_or_else(|e| panic!("bevy_nacre: the built-in table {name}: {e}"));
            built.push((handle, table));
        }
    }
    let mut tables = world.resource_mut::<Assets<NacreTable>>();
    for (handle, table) in built {
        // A UUID handle never fails to insert.
        let _ = tables.insert(handle.id(), table);
    }
}
