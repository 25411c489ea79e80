//! # nacre-runtime
//!
//! A small wgpu library that a host engine uses with its own device: it loads baked nacre
//! tables through their manifests ([`TableSet::load`]), uploads them as textures, and
//! provides the WGSL modules under `shaders/` ([`shaders`]) that sample them, plus a headless
//! renderer for `nacre render` and the GPU = CPU probe used by the tests. `diffraction`
//! tables load separately ([`diffraction::DiffractionTables::load`], either layout) for the
//! technique `diffraction` (Stam's diffraction BRDF from Taylor terms,
//! `shaders/diffraction.wgsl`, or from the wavelength-integrated tables of the fast path,
//! `shaders/diffraction_integrated.wgsl`).

pub mod bench;
pub mod bindings;
pub mod context;
pub mod diffraction;
pub mod environment;
pub mod error;
pub mod gltf_scene;
pub mod gpu;
pub mod ibl;
pub mod image_io;
pub mod mesh;
pub mod params;
pub mod probe;
pub mod render;
pub mod rough_reference;
pub mod scene;
pub mod shaders;
pub mod tables;
pub mod technique;
pub mod thickness_map;

pub use bindings::{TechniqueBinding, TechniqueOptions};
pub use context::{BufferInitExt, Fault, GpuContext};
/// Layout "integrated" of the `diffraction` technique ([`diffraction::integrated`]).
pub use diffraction::integrated as diffraction_integrated;
pub use error::{Error, Result};
/// The glTF test assets, metals and textures under their former paths.
pub use gltf_scene::{assets as gltf_assets, metal as gltf_metal, textures as gltf_textures};
pub use params::{FilmInput, FilmOutput};
pub use render::{RenderedImage, Renderer, SceneKind, SceneOptions, render_scene};
pub use scene::Scene;
pub use tables::TableSet;
pub use technique::Technique;
