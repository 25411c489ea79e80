//! The live view: the runtime's scene renderer ([`nacre_runtime::render::Renderer`], the
//! renderer of `nacre render`) drawing the designed stack on a sphere, a bubble or a plane,
//! with an orbit camera.
//!
//! The renderer is compiled once per technique; a stack edit rebinds its group 1
//! ([`Renderer::rebind`]: the stack's buffers, a new base) and changes the material
//! uniform, so the picture follows a slider in the next frame without a shader
//! compilation. Frames are read back as sRGB RGBA8 ([`Renderer::render_with`]) and shown
//! as an egui texture: the same pixels `nacre render` writes to its PNG.

use crate::doc::StackDoc;
use nacre_format::set::resolve_table;
use nacre_optics::Stack;
use nacre_runtime::bindings::StackSetup;
use nacre_runtime::gltf_scene::GltfScene;
use nacre_runtime::mesh::{Orbit as MeshOrbit, ViewPoint};
use nacre_runtime::render::{
    DEFAULT_THICKNESS_MAP_SIZE, EnvironmentMap, RenderedImage, Renderer, SceneKind, SceneOptions,
    ThicknessMap, ThicknessMapping, procedural_thickness_map,
};
use nacre_runtime::{GpuContext, TableSet, Technique};
use std::path::{Path, PathBuf};

/// The tables the view loads: the sphere's film-lut (films of index 1.1–2.5 in air on a
/// dielectric base) and the sRGB Fourier table.
pub const TABLES: [&str; 2] = ["film-dielectric", "fourier-srgb"];

/// The wavelength where the lut, fourier and spectral techniques take a film's single real
/// index (they draw one film of real index; `film_stack` draws every film, dispersive and
/// absorbing), nm.
pub const INDEX_WAVELENGTH_NM: f64 = 550.0;

/// How the scene is lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lighting {
    /// `nacre render`'s default: the bundled studio environment and its sun.
    Studio,
    /// A uniform white sky of radiance 1 and no sun: a mirror-smooth film then shows its
    /// own reflectance colour (the sphere's centre: `nacre color` at 0°, tone-mapped).
    Uniform,
    /// An equirectangular environment file (OpenEXR, Radiance HDR, PNG or JPEG: what
    /// `nacre render --env` reads), [`ViewSettings::environment`], lighting the scene
    /// alone: the file holds its own sun, so the studio's is off.
    File,
}

impl Lighting {
    /// Every lighting, in menu order.
    pub const ALL: [Lighting; 3] = [Lighting::Studio, Lighting::Uniform, Lighting::File];

    /// The menu name.
    pub fn name(self) -> &'static str {
        match self {
            Lighting::Studio => "studio environment",
            Lighting::Uniform => "uniform white sky",
            Lighting::File => "environment file",
        }
    }
}

/// The orbit camera: angles about the scene's target, degrees, and the distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Rotation about the vertical axis, degrees (0: looking along −z).
    pub yaw_deg: f32,
    /// Elevation, degrees (−89 to 89).
    pub pitch_deg: f32,
    /// Distance from the target, scene units.
    pub distance: f32,
}

impl Orbit {
    /// The orbit through `scene`'s default camera.
    pub fn for_scene(scene: SceneKind) -> Orbit {
        let c = SceneOptions::new(scene).camera;
        let d: [f32; 3] = std::array::from_fn(|k| c.eye[k] - c.target[k]);
        let distance = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        Orbit {
            yaw_deg: d[0].atan2(d[2]).to_degrees(),
            pitch_deg: (d[1] / distance).asin().to_degrees(),
            distance,
        }
    }

    /// Turns the orbit by a drag of (dx, dy) points (0.4° per point), the elevation kept
    /// within ±89°.
    pub fn drag(&mut self, dx: f32, dy: f32) {
        self.yaw_deg = (self.yaw_deg - 0.4 * dx).rem_euclid(360.0);
        self.pitch_deg = (self.pitch_deg + 0.4 * dy).clamp(-89.0, 89.0);
    }

    /// The eye position for `target`.
    pub fn eye(&self, target: [f32; 3]) -> [f32; 3] {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        [
            target[0] + self.distance * pitch.cos() * yaw.sin(),
            target[1] + self.distance * pitch.sin(),
            target[2] + self.distance * pitch.cos() * yaw.cos(),
        ]
    }
}

/// Everything the view draws besides the stack.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    /// The scene.
    pub scene: SceneKind,
    /// The technique.
    pub technique: Technique,
    /// The lighting.
    pub lighting: Lighting,
    /// The camera.
    pub orbit: Orbit,
    /// Exposure, EV.
    pub exposure_ev: f32,
    /// GGX roughness α of the film's surface (0.001 to 1).
    pub roughness_alpha: f32,
    /// The picture's size, pixels.
    pub size: [u32; 2],
    /// A glTF file drawn instead of `scene` ([`View::load_model`] loads it).
    pub model: Option<PathBuf>,
    /// With a model: the stack's film on every material (true) or on the materials that
    /// have `KHR_materials_iridescence` only (false, the default).
    pub film_on_all: bool,
    /// The environment file [`Lighting::File`] draws ([`View::load_environment`] loads it).
    pub environment: Option<PathBuf>,
    /// A thickness map file in place of the procedural one ([`View::load_thickness_map`]
    /// loads it): grey g ∈ [0, 1] maps film 1 to d ± r (d + r(2g − 1)), as `nacre render
    /// --thickness-map` does.
    pub thickness_map: Option<PathBuf>,
    /// With a colour thickness map and `stack`: the channel each film follows (0 R, 1 G,
    /// 2 B; film 1 always follows R; a film past the end follows R), the thesis's one map
    /// per layer (Sussenbach 2013 §4.2).
    pub film_channels: Vec<usize>,
    /// The key ([`crate::live_lut::key`]) of the stack's own film-lut table that `lut`
    /// draws with, once [`View::set_stack_lut`] has loaded it; `stack` draws the film
    /// meanwhile. None: `lut` draws with the bundled `film-dielectric` table.
    pub lut_key: Option<String>,
}

impl ViewSettings {
    /// The sphere with `film_stack` under the studio environment, `size` pixels.
    pub fn new(size: [u32; 2]) -> ViewSettings {
        ViewSettings {
            scene: SceneKind::Sphere,
            technique: Technique::Stack,
            lighting: Lighting::Studio,
            orbit: Orbit::for_scene(SceneKind::Sphere),
            exposure_ev: 0.0,
            roughness_alpha: 0.06,
            size,
            model: None,
            film_on_all: false,
            environment: None,
            thickness_map: None,
            film_channels: Vec::new(),
            lut_key: None,
        }
    }
}

/// A drawn frame and the notes about it (what the technique leaves out).
pub struct Frame {
    /// The picture.
    pub image: RenderedImage,
    /// What the technique draws differently from the stack (one film, one real index).
    pub notes: Vec<String>,
    /// Seconds the frame took (options, rebind, render and readback).
    pub seconds: f64,
}

/// The GPU side of the view.
pub struct View {
    ctx: GpuContext,
    tables: TableSet,
    /// Compiled renderers, the most recently used last (at most [`KEPT_RENDERERS`]), each
    /// with the stack its group 1 was built from.
    renderers: Vec<(Renderer, Option<Bound>)>,
    studio: EnvironmentMap,
    uniform: EnvironmentMap,
    thickness: ThicknessMap,
    /// The loaded glTF model.
    model: Option<GltfScene>,
    /// The model's compiled passes, kept between frames (an orbit or a film edit compiles
    /// nothing).
    mesh_cache: nacre_runtime::mesh::MeshCache,
    /// The loaded environment file.
    environment_file: Option<(PathBuf, EnvironmentMap)>,
    /// The loaded thickness map: as read, and its grey channel alone (for the techniques
    /// that draw one film).
    thickness_file: Option<(PathBuf, ThicknessMap, ThicknessMap)>,
    /// The bundled film-lut table's base material.
    bundled_base: Option<nacre_optics::Material>,
    /// The stack's own film-lut table ([`View::set_stack_lut`]) and its key.
    stack_lut: Option<(String, TableSet)>,
}

/// What a kept renderer's group 1 was built from: the stack, its films' thickness-map
/// channels, and the key of the stack's own film-lut table when it was built from that one.
type Bound = (StackDoc, Vec<usize>, Option<String>);

/// Which tables draw a frame, and with which technique.
struct Source<'a> {
    /// The technique drawn (`stack` in place of `lut` while the stack's table bakes).
    technique: Technique,
    /// The tables it reads.
    tables: &'a TableSet,
    /// The stack table's key, when those are the tables.
    key: Option<&'a str>,
}

/// The view's errors: the runtime's, or a stack the technique cannot draw.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// From the runtime (GPU, tables, settings).
    #[error(transparent)]
    Runtime(#[from] nacre_runtime::Error),
    /// From loading a table manifest.
    #[error(transparent)]
    Format(#[from] nacre_format::Error),
    /// A model is chosen but none is loaded.
    #[error("no glTF model is loaded: open one")]
    NoModel,
    /// [`Lighting::File`] without an environment file loaded.
    #[error("no environment file is loaded: open one")]
    NoEnvironment,
    /// A material without an index at [`INDEX_WAVELENGTH_NM`].
    #[error("{what}: {source}")]
    Index {
        /// The layer.
        what: String,
        /// Why.
        source: nacre_optics::Error,
    },
}

impl View {
    /// A view on `ctx` (the window's device, or a headless one), loading [`TABLES`].
    pub fn new(ctx: GpuContext) -> Result<View, ViewError> {
        let mut tables = TableSet::default();
        for name in TABLES {
            tables.add(&ctx, &resolve_table(name))?;
        }
        let bundled_base = tables
            .film_lut
            .as_ref()
            .map(|lut| {
                nacre_format::materials::resolve(
                    &lut.manifest.base,
                    format!("{} (base)", lut.manifest_path.display()),
                    lut.manifest_path.parent(),
                )
            })
            .transpose()?;
        Ok(View {
            ctx,
            tables,
            renderers: Vec::new(),
            studio: EnvironmentMap::default_map()?,
            uniform: EnvironmentMap {
                width: 64,
                height: 32,
                rgb: vec![[1.0; 3]; 64 * 32],
            },
            thickness: procedural_thickness_map(DEFAULT_THICKNESS_MAP_SIZE),
            model: None,
            mesh_cache: Default::default(),
            environment_file: None,
            thickness_file: None,
            bundled_base,
            stack_lut: None,
        })
    }

    /// Reads the environment file at `path` ([`EnvironmentMap::load`], the reader of
    /// `nacre render --env`) as the one [`Lighting::File`] draws when
    /// [`ViewSettings::environment`] names it. A file that does not load changes nothing.
    pub fn load_environment(&mut self, path: &Path) -> Result<(), ViewError> {
        let map = EnvironmentMap::load(path)?;
        self.environment_file = Some((path.to_path_buf(), map));
        Ok(())
    }

    /// The loaded environment file's path, if any.
    pub fn environment_path(&self) -> Option<&Path> {
        self.environment_file.as_ref().map(|(p, _)| p.as_path())
    }

    /// Reads the thickness map at `path` ([`ThicknessMap::load`], the reader of `nacre
    /// render --thickness-map`: PNG or JPEG, grey or colour) as the one the scenes draw
    /// when [`ViewSettings::thickness_map`] names it; returns whether it is a colour map
    /// (channels G and B for the lower films). A file that does not load changes nothing.
    pub fn load_thickness_map(&mut self, path: &Path) -> Result<bool, ViewError> {
        let map = ThicknessMap::load(path)?;
        let grey = ThicknessMap {
            green_blue: None,
            ..map.clone()
        };
        let colour = map.green_blue.is_some();
        self.thickness_file = Some((path.to_path_buf(), map, grey));
        Ok(colour)
    }

    /// The loaded thickness map's path, if any.
    pub fn thickness_map_path(&self) -> Option<&Path> {
        self.thickness_file.as_ref().map(|(p, _, _)| p.as_path())
    }

    /// The environment `settings` light the scene with.
    fn environment(&self, settings: &ViewSettings) -> Result<&EnvironmentMap, ViewError> {
        match settings.lighting {
            Lighting::Studio => Ok(&self.studio),
            Lighting::Uniform => Ok(&self.uniform),
            Lighting::File => self
                .environment_file
                .as_ref()
                .filter(|(p, _)| settings.environment.as_deref() == Some(p.as_path()))
                .map(|(_, m)| m)
                .ok_or(ViewError::NoEnvironment),
        }
    }

    /// The thickness map `settings` draw with `technique`: the loaded file (its grey
    /// channel alone unless `technique` is `stack`, which gives the lower films G and B),
    /// or the procedural one.
    fn thickness(&self, settings: &ViewSettings, technique: Technique) -> &ThicknessMap {
        match &self.thickness_file {
            Some((path, map, grey))
                if settings.thickness_map.as_deref() == Some(path.as_path()) =>
            {
                if technique == Technique::Stack {
                    map
                } else {
                    grey
                }
            }
            _ => &self.thickness,
        }
    }

    /// Whether the bundled `film-dielectric` table holds `doc`'s film exactly: the same
    /// ambient index, no film under the top one, the same base (its index at every 5 nm
    /// from 380 to 780 nm), and the film's index and thickness range inside the table's
    /// axes. `lut` then needs no table of the stack's own.
    pub fn bundled_lut_holds(&self, doc: &StackDoc, stack: &Stack) -> bool {
        let Some(lut) = &self.tables.film_lut else {
            return false;
        };
        let a = &lut.axes;
        let (Some(layer), [top]) = (stack.layers().first(), doc.films.as_slice()) else {
            return false;
        };
        let same = |x: &nacre_optics::Material, y: &nacre_optics::Material| {
            (0..=80).all(|k| {
                let nm = 380.0 + 5.0 * f64::from(k);
                matches!((x.index_at(nm), y.index_at(nm)), (Ok(p), Ok(q)) if (p - q).norm() <= 1e-9 * q.norm())
            })
        };
        let index = |m: &nacre_optics::Material| m.index_at(INDEX_WAVELENGTH_NM).ok();
        let in_axes = index(&layer.material)
            .is_some_and(|n| n.im == 0.0 && (a.ior_min..=a.ior_max).contains(&n.re));
        index(stack.ambient())
            .is_some_and(|n| n.im == 0.0 && (n.re - a.ambient_index).abs() <= 1e-9)
            && self
                .bundled_base
                .as_ref()
                .is_some_and(|base| same(stack.substrate(), base))
            && in_axes
            && top.thickness_nm + top.relative_nm.abs() <= a.thickness_max_nm
    }

    /// Loads the stack's own film-lut table (a manifest [`crate::live_lut`] baked) under
    /// `key`: `lut` draws with it while [`ViewSettings::lut_key`] is `key`.
    pub fn set_stack_lut(&mut self, key: String, manifest: &Path) -> Result<(), ViewError> {
        let tables = TableSet::load(&self.ctx, manifest)?;
        self.stack_lut = Some((key, tables));
        // Renderers built from the previous table rebind on their next frame.
        Ok(())
    }

    /// The key of the loaded stack table, if any.
    pub fn stack_lut_key(&self) -> Option<&str> {
        self.stack_lut.as_ref().map(|(k, _)| k.as_str())
    }

    /// The technique and tables that draw `settings` (see [`ViewSettings::lut_key`]).
    fn source(&self, settings: &ViewSettings) -> Source<'_> {
        let bundled = Source {
            technique: settings.technique,
            tables: &self.tables,
            key: None,
        };
        if settings.technique != Technique::Lut {
            return bundled;
        }
        match (&settings.lut_key, &self.stack_lut) {
            (None, _) => bundled,
            (Some(want), Some((key, tables))) if want == key => Source {
                technique: Technique::Lut,
                tables,
                key: Some(key),
            },
            (Some(_), _) => Source {
                technique: Technique::Stack,
                tables: &self.tables,
                key: None,
            },
        }
    }

    /// The device description (adapter, backend).
    pub fn describe(&self) -> String {
        self.ctx.describe()
    }

    /// The scene options that draw `doc` (built as `stack`) with `settings`, and the notes on
    /// what the technique leaves out.
    pub fn options(
        &self,
        settings: &ViewSettings,
        doc: &StackDoc,
        stack: &Stack,
    ) -> Result<(SceneOptions, Vec<String>), ViewError> {
        let mut o = SceneOptions::new(settings.scene);
        [o.width, o.height] = settings.size;
        o.camera.eye = settings.orbit.eye(o.camera.target);
        o.exposure_ev = settings.exposure_ev;
        o.material.roughness_alpha = settings.roughness_alpha;
        match settings.lighting {
            Lighting::Uniform => {
                o.light.intensity = 0.0;
                o.material.base_colour = [0.0; 3];
            }
            Lighting::File => o.light.intensity = 0.0,
            Lighting::Studio => {}
        }
        let mut notes = Vec::new();
        let source = self.source(settings);
        let index = |m: &nacre_optics::Material, what: &str| {
            m.index_at(INDEX_WAVELENGTH_NM)
                .map_err(|source| ViewError::Index {
                    what: what.to_string(),
                    source,
                })
        };
        o.material.ambient_ior = index(stack.ambient(), "ambient")?.re as f32;
        o.material.set_base(stack.substrate().clone());
        o.material.drain_nm = 0.0;
        let top = stack.layers().first();
        let (thickness_nm, relative_nm) = doc
            .films
            .first()
            .map_or((0.0, 0.0), |f| (f.thickness_nm, f.relative_nm));
        o.material.thickness = ThicknessMapping::Svt {
            average_nm: thickness_nm as f32,
            relative_nm: relative_nm as f32,
        };
        match top {
            Some(layer) => {
                let n = index(&layer.material, "film 1")?;
                o.material.film_ior = n.re as f32;
                if settings.technique != Technique::Stack {
                    if stack.layers().len() > 1 {
                        notes.push(format!(
                            "{} draws the top film only; `stack` draws all {}",
                            settings.technique.name(),
                            stack.layers().len()
                        ));
                    }
                    if n.im != 0.0 || layer.material.index_at(450.0).ok() != Some(n) {
                        notes.push(format!(
                            "{} draws film 1 with the constant real index {:.3} (its index at {INDEX_WAVELENGTH_NM} nm)",
                            settings.technique.name(),
                            n.re
                        ));
                    }
                }
            }
            None => {
                // A bare interface: a film of zero thickness.
                o.material.film_ior = o.material.ambient_ior.max(1.0);
            }
        }
        let colour_map = self
            .thickness(settings, Technique::Stack)
            .green_blue
            .is_some();
        o.stack = StackSetup {
            stack: stack.clone(),
            relative_nm: doc.relative_nm(),
            channels: if colour_map && source.technique == Technique::Stack {
                (0..doc.films.len())
                    .map(|k| settings.film_channels.get(k).copied().unwrap_or(0).min(2))
                    .collect()
            } else {
                Vec::new()
            },
            samples: None,
        };
        let follows_gb = settings
            .film_channels
            .iter()
            .take(doc.films.len())
            .skip(1)
            .any(|&c| c != 0);
        if colour_map && follows_gb && source.technique != Technique::Stack {
            notes.push(format!(
                "{} draws the thickness map's R channel only; `stack` gives the lower films G and B",
                source.technique.name()
            ));
        }
        match (settings.technique, source.technique, source.key) {
            (Technique::Lut, Technique::Lut, Some(_)) => {
                // The stack's own table: its ambient and base are the stack's, the films
                // under the top one are in its texels.
                if let Some(lut) = &source.tables.film_lut {
                    let a = &lut.axes;
                    o.material.film_ior = o
                        .material
                        .film_ior
                        .clamp(a.ior_min as f32, a.ior_max as f32);
                }
                notes.push(format!(
                    "lut draws this stack's own film-lut table (baked in the background: film 1 varies, {} film(s) under it and the base are in the table)",
                    doc.films.len().saturating_sub(1)
                ));
            }
            (Technique::Lut, Technique::Lut, None) => {
                let holds = self.bundled_lut_holds(doc, stack);
                o.fit_to_tables(&self.tables)?;
                if !holds {
                    notes.push(
                        "lut draws the film-dielectric table's ambient and base (n 1.5, black glaze)"
                            .into(),
                    );
                }
            }
            (Technique::Lut, _, _) => notes.push(
                "the lut table of this stack is baking: `stack` draws it exactly meanwhile".into(),
            ),
            _ => {}
        }
        if settings.technique == Technique::Stack && stack.layers().is_empty() {
            notes.push("a bare interface: the base alone".into());
        }
        Ok((o, notes))
    }

    /// Loads the glTF file at `path` (the runtime's loader, [`GltfScene::load`]) as the
    /// model the view draws when [`ViewSettings::model`] names it.
    pub fn load_model(&mut self, path: &Path) -> Result<(), ViewError> {
        self.model = Some(GltfScene::load(path)?);
        self.mesh_cache = Default::default();
        Ok(())
    }

    /// The loaded model's path, if any.
    pub fn model_path(&self) -> Option<&Path> {
        self.model.as_ref().map(|m| m.path.as_path())
    }

    /// Draws the loaded model with `settings` and the stack's top film on its materials
    /// ([`film_on_model`]), through the runtime's glTF renderer
    /// ([`nacre_runtime::mesh::render`], that of `nacre render --gltf`), the orbit camera
    /// fitted to the model's bounds at the view's yaw and pitch.
    fn render_model(
        &mut self,
        settings: &ViewSettings,
        doc: &StackDoc,
        stack: &Stack,
    ) -> Result<Frame, ViewError> {
        let start = std::time::Instant::now();
        let Some(model) = &self.model else {
            return Err(ViewError::NoModel);
        };
        let mut notes = Vec::new();
        let (scene, filmed) = film_on_model(model, doc, stack, settings.film_on_all)?;
        let whose = if settings.film_on_all {
            "every material"
        } else {
            "the iridescent ones"
        };
        match stack.layers().first() {
            Some(layer) => notes.push(format!(
                "film 1 (index {:.3} at {INDEX_WAVELENGTH_NM} nm, {} nm) on {filmed} of {} materials ({whose}); each material keeps its own base and the ambient is air",
                index_of(&layer.material, "film 1")?.re,
                format_range(doc),
                model.materials.len(),
            )),
            None => notes.push("a bare interface: no film on the model".into()),
        }
        if stack.layers().len() > 1 {
            notes.push(format!(
                "a glTF material holds one film: films 2 to {} are not drawn",
                stack.layers().len()
            ));
        }
        let technique = if settings.technique == Technique::Stack {
            notes.push(
                "the glTF renderer draws one film per material: `stack` is drawn with spectral"
                    .into(),
            );
            Technique::Spectral
        } else {
            settings.technique
        };
        let mut o = SceneOptions::new(SceneKind::Sphere);
        [o.width, o.height] = settings.size;
        o.exposure_ev = settings.exposure_ev;
        if settings.lighting != Lighting::Studio {
            o.light.intensity = 0.0;
        }
        let environment = self.environment(settings)?.clone();
        if settings.thickness_map.is_some() {
            notes.push(
                "a glTF material takes its thickness from its own iridescence texture: the thickness map is not drawn"
                    .into(),
            );
        }
        let view = ViewPoint::Orbit(MeshOrbit {
            yaw_deg: f64::from(settings.orbit.yaw_deg),
            pitch_deg: f64::from(settings.orbit.pitch_deg),
            distance: None,
        });
        let inputs =
            nacre_runtime::mesh::RenderInputs::with_environment(&scene, &o, view, environment)?;
        let out = nacre_runtime::mesh::render_cached(
            &self.ctx,
            &self.tables,
            technique,
            &inputs,
            &mut self.mesh_cache,
        )?;
        notes.extend(out.notes.iter().map(|n| n.to_string()));
        Ok(Frame {
            image: out.image,
            notes,
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// Draws `doc` with `settings`: compiles the technique's pipeline when none is kept for
    /// it, rebinds its group 1 when the stack changed, renders and reads the picture back.
    pub fn render(
        &mut self,
        settings: &ViewSettings,
        doc: &StackDoc,
        stack: &Stack,
    ) -> Result<Frame, ViewError> {
        if settings.model.is_some() {
            return self.render_model(settings, doc, stack);
        }
        let start = std::time::Instant::now();
        let (options, notes) = self.options(settings, doc, stack)?;
        let technique_options = options.technique_options();
        // Checked before the renderers are taken out (an early return would lose them).
        self.environment(settings)?;
        // Taken out while the tables are borrowed; put back below, the latest last. A
        // renderer whose build or rebind fails is dropped: the next frame builds it anew.
        let mut renderers = std::mem::take(&mut self.renderers);
        let source = self.source(settings);
        let (technique, tables) = (source.technique, source.tables);
        let want: Bound = (
            doc.clone(),
            technique_options.stack.channels.clone(),
            source.key.map(str::to_string),
        );
        let environment = self.environment(settings).unwrap_or(&self.studio);
        let thickness = self.thickness(settings, technique);
        let kept = renderers
            .iter()
            .position(|(r, _)| r.technique() == technique);
        let drawn = (|| -> Result<_, ViewError> {
            let (mut renderer, mut bound) = match kept {
                Some(k) => renderers.remove(k),
                None => (
                    Renderer::new(&self.ctx, tables, technique, &technique_options)?,
                    Some(want.clone()),
                ),
            };
            if bound.as_ref() != Some(&want) {
                renderer.rebind(&self.ctx, tables, &technique_options)?;
                bound = Some(want);
            }
            let image = renderer.render_with(&self.ctx, tables, &options, environment, thickness);
            Ok((renderer, bound, image))
        })();
        let image = drawn.map(|(renderer, bound, image)| {
            renderers.push((renderer, bound));
            if renderers.len() > KEPT_RENDERERS {
                renderers.remove(0);
            }
            image
        });
        self.renderers = renderers;
        Ok(Frame {
            image: image??,
            notes,
            seconds: start.elapsed().as_secs_f64(),
        })
    }
}

/// A material's index at [`INDEX_WAVELENGTH_NM`], its error naming `what`.
fn index_of(m: &nacre_optics::Material, what: &str) -> Result<nacre_optics::C64, ViewError> {
    m.index_at(INDEX_WAVELENGTH_NM)
        .map_err(|source| ViewError::Index {
            what: what.to_string(),
            source,
        })
}

/// The top film's thickness as drawn on a model: `d` or `d − r to d + r`, nm.
fn format_range(doc: &StackDoc) -> String {
    match doc.films.first() {
        Some(f) if f.relative_nm > 0.0 => format!(
            "{} to {}",
            (f.thickness_nm - f.relative_nm).max(0.0),
            f.thickness_nm + f.relative_nm
        ),
        Some(f) => format!("{}", f.thickness_nm),
        None => "0".into(),
    }
}

/// `model` with the stack's top film on its materials: on those with
/// `KHR_materials_iridescence` (`all` false) or on every one (`all` true, a factor of 1
/// where a material had none). The film's index is its real index at
/// [`INDEX_WAVELENGTH_NM`] (`iridescenceIor`); its thickness spans `d − r` to `d + r`
/// (`iridescenceThicknessMinimum`/`Maximum`: a thickness texture, where the material has
/// one, varies it between them; without one the extension draws the maximum, so both
/// are d when r = 0). A bare interface (no film) sets the factors to 0. Returns the scene
/// and how many materials carry the film.
pub fn film_on_model(
    model: &GltfScene,
    doc: &StackDoc,
    stack: &Stack,
    all: bool,
) -> Result<(GltfScene, usize), ViewError> {
    let mut scene = model.clone();
    let film = match (stack.layers().first(), doc.films.first()) {
        (Some(layer), Some(f)) => Some((index_of(&layer.material, "film 1")?.re, f)),
        _ => None,
    };
    let mut filmed = 0;
    for m in &mut scene.materials {
        if m.iridescence.is_none() && all {
            m.iridescence = Some(nacre_runtime::gltf_scene::Iridescence {
                factor: 1.0,
                ..Default::default()
            });
        }
        let Some(i) = &mut m.iridescence else {
            continue;
        };
        match film {
            Some((n, f)) => {
                i.ior = n as f32;
                i.thickness_min_nm = (f.thickness_nm - f.relative_nm).max(0.0) as f32;
                i.thickness_max_nm = (f.thickness_nm + f.relative_nm) as f32;
                if i.factor > 0.0 {
                    filmed += 1;
                }
            }
            None => i.factor = 0.0,
        }
    }
    Ok((scene, filmed))
}

/// How many compiled renderers the view keeps (the chosen technique and the comparison's
/// reference, [`crate::compare::REFERENCE`], and one more to switch back without a compile).
pub const KEPT_RENDERERS: usize = 3;

/// The pixel the view shows where a film of reflectance colour `rgb` (linear, the output
/// space of `nacre color`) faces the camera under [`Lighting::Uniform`] (radiance 1, no
/// sun, black base; exposure 0): the classic environment term L · R_f(n·v) · E_GGX(α),
/// E_GGX(α) = 1 − 0.55 √α (Karis 2014, `shaders/material.wgsl`), then Khronos PBR Neutral
/// tone mapping and the sRGB transfer function (`shaders/output.wgsl`), as 8-bit values.
pub fn uniform_sky_pixel(rgb: [f64; 3], roughness_alpha: f64) -> [u8; 3] {
    let scale = (1.0 - 0.55 * roughness_alpha.sqrt()).clamp(0.0, 1.0);
    nacre_runtime::rough_reference::display_colour(rgb.map(|v| v.max(0.0) * scale))
}
