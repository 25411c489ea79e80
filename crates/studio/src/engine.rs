//! The engine export: what a game engine needs to draw the studio's stack.
//!
//! * The closest glTF film: `nacre fit gltf`'s own fit ([`fit_gltf`]: the
//!   `KHR_materials_iridescence` material whose glTF reference colour comes closest in
//!   CIEDE2000 to the stack's exact colour over 0–85°), as a glTF material object
//!   ([`material_json`]) and its errors.
//! * The stack for the engine libraries' `film_stack` (`nacre_film_stack_colour` of the GLSL
//!   and HLSL libraries, `loadNacreStack` of `@nacre/three`, `NacreFilm::stack_from_json` of
//!   `bevy_nacre`): `nacre export`'s stack JSON ([`stack_export`], schema
//!   `nacre-film-stack` v1, docs/engines/README.md).
//! * A Bevy and a three.js snippet that load both.
//!
//! The fit runs on its own thread ([`EngineJob`]); the files are written atomically.

use crate::doc::StackDoc;
use nacre_bake::commands::color_request::ColourSettings;
use nacre_bake::commands::export_stack::{StackExport, stack_export};
use nacre_bake::commands::fit_gltf::{GltfFitReport, describe, fit_gltf, material_json};
use nacre_format::atomic::write_atomic;
use nacre_optics::fit::gltf::{GltfBase, GltfFilm};
use std::path::{Path, PathBuf};
use std::thread::JoinHandle;

/// Everything the engine export shows and writes.
#[derive(Clone, Debug)]
pub struct EngineExport {
    /// The stack it was made from.
    pub doc: StackDoc,
    /// The closest glTF film and its errors (and the naive mapping's).
    pub gltf: GltfFitReport,
    /// The glTF material object of the fitted film.
    pub material: serde_json::Value,
    /// The stack JSON (`nacre-film-stack` v1).
    pub stack: serde_json::Value,
    /// The Bevy snippet (Rust).
    pub bevy: String,
    /// The three.js snippet (JavaScript).
    pub three: String,
}

/// The thickness range the glTF fit spans: d ± r of the top film when it varies.
fn top_range(doc: &StackDoc) -> Option<(f64, f64)> {
    let top = doc.films.first()?;
    (top.relative_nm > 0.0).then(|| {
        (
            (top.thickness_nm - top.relative_nm).max(0.0),
            top.thickness_nm + top.relative_nm,
        )
    })
}

impl EngineExport {
    /// Fits and prepares the export of `doc` (which must build); `name` names the files
    /// the snippets load.
    pub fn new(doc: &StackDoc, name: &str) -> Result<EngineExport, String> {
        let stack = doc.build().map_err(|e| e.to_string())?;
        let gltf = fit_gltf(&stack, top_range(doc)).map_err(|e| e.to_string())?;
        let material = material_json(&gltf.fit.film, name);
        let spec = doc.spec();
        let relative = doc.relative_nm();
        let stack_json = stack_export(&StackExport {
            spec: &spec,
            relative_nm: &relative,
            channels: &[],
            samples: None,
            colour: ColourSettings {
                observer: None,
                illuminant: None,
                space: None,
            },
        })
        .map_err(|e| e.to_string())?;
        let written = nacre_bake::commands::fit_gltf::rounded(&gltf.fit.film);
        Ok(EngineExport {
            doc: doc.clone(),
            bevy: bevy_snippet(doc, &written, &gltf, name),
            three: three_snippet(doc, &written, &gltf, name),
            gltf,
            material,
            stack: stack_json,
        })
    }

    /// One line: the fitted film and its ΔE2000 against the stack, beside the naive
    /// mapping's.
    pub fn summary(&self) -> String {
        format!(
            "closest glTF film: {}; ΔE2000 against the stack over 0–85°: mean {:.2}, max {:.2} (naive mapping: mean {:.2}, max {:.2})",
            describe(&self.gltf.fit.film),
            self.gltf.fit.errors.mean,
            self.gltf.fit.errors.max,
            self.gltf.naive_errors.mean,
            self.gltf.naive_errors.max
        )
    }

    /// The files [`EngineExport::write`] writes into `folder`: `NAME.material.json` (the
    /// glTF material), `NAME.stack.json`, `NAME.bevy.rs`, `NAME.three.js`.
    pub fn files(folder: &Path, name: &str) -> [PathBuf; 4] {
        ["material.json", "stack.json", "bevy.rs", "three.js"]
            .map(|ext| folder.join(format!("{name}.{ext}")))
    }

    /// Writes the four files into `folder` (created if missing), each atomically.
    pub fn write(&self, folder: &Path, name: &str) -> Result<[PathBuf; 4], String> {
        if name.is_empty() || name.contains(['/', '\\']) || name.starts_with('.') {
            return Err(format!(
                "`{name}` is not a file name (no folders, not empty, not starting with .)"
            ));
        }
        std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
        let files = Self::files(folder, name);
        let json = |v: &serde_json::Value| {
            let mut t = serde_json::to_string_pretty(v).expect("JSON values serialise");
            t.push('\n');
            t
        };
        let texts = [
            json(&self.material),
            json(&self.stack),
            self.bevy.clone(),
            self.three.clone(),
        ];
        for (path, text) in files.iter().zip(texts) {
            write_atomic(path, |w| w.write_all(text.as_bytes()))
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        Ok(files)
    }
}

/// The top film's thickness, nm.
fn top_nm(doc: &StackDoc) -> f64 {
    doc.films.first().map_or(0.0, |f| f.thickness_nm)
}

fn bevy_snippet(doc: &StackDoc, film: &GltfFilm, fit: &GltfFitReport, name: &str) -> String {
    let gltf_like = match film.base {
        GltfBase::Dielectric { ior } => format!(
            "let gltf_like = materials.add(NacreMaterial {{
    base: StandardMaterial {{ base_color: Color::BLACK, perceptual_roughness: 0.2, ..default() }},
    extension: NacreFilm {{
        film_ior: {n},
        thickness: FilmThickness::Gltf {{ min_nm: {min}, max_nm: {max} }},
        weight: {w},
        base_ior: Vec3::splat({ior}),
        ..default()
    }},
}});",
            n = film.iridescence_ior,
            min = film.thickness_min_nm,
            max = film.thickness_max_nm,
            w = film.factor,
        ),
        GltfBase::Metal { base_colour: c } => format!(
            "// A metal base (baseColorFactor {c:?}): put {name}.material.json into a glTF file's
// `materials`; NacrePlugin's glTF hook gives it a NacreMaterial with the metal's index."
        ),
    };
    format!(
        "// {name}: the nacre studio's stack in Bevy (bevy_nacre). In a system with
// `mut materials: ResMut<Assets<NacreMaterial>>, mut buffers: ResMut<Assets<ShaderBuffer>>`.
use bevy::prelude::*;
use bevy_nacre::{{FilmTechnique, FilmThickness, NacreFilm, NacreMaterial}};

// The whole stack ({films} film(s), top {d} nm), drawn by film_stack:
let stack = NacreFilm::stack_from_json(include_str!(\"{name}.stack.json\"), \"{name}.stack.json\")
    .expect(\"a nacre-film-stack v1 file\");
let mut film = NacreFilm {{ technique: FilmTechnique::Stack, ..default() }};
film.set_stack(&stack, &mut buffers);
let stacked = materials.add(NacreMaterial {{
    base: StandardMaterial {{ base_color: Color::BLACK, perceptual_roughness: 0.2, ..default() }},
    extension: film,
}});

// Or the closest glTF film (KHR_materials_iridescence), ΔE2000 mean {mean:.2}, max {max:.2}
// against the stack over 0–85°:
{gltf_like}
",
        films = doc.films.len(),
        d = top_nm(doc),
        mean = fit.fit.errors.mean,
        max = fit.fit.errors.max,
    )
}

fn three_snippet(doc: &StackDoc, film: &GltfFilm, fit: &GltfFitReport, name: &str) -> String {
    let base = match film.base {
        GltfBase::Dielectric { ior } => format!("color: 0x000000, metalness: 0, ior: {ior},"),
        GltfBase::Metal { base_colour: c } => format!(
            "color: new THREE.Color().setRGB({}, {}, {}, THREE.LinearSRGBColorSpace), metalness: 1,",
            c[0], c[1], c[2]
        ),
    };
    let range = doc
        .films
        .first()
        .filter(|f| f.relative_nm > 0.0)
        .map(|f| {
            format!(
                "\n// the top film varies as d ± r with a thickness map's green channel:\nstacked.filmThicknessRangeNm = [{}, {}];",
                (f.thickness_nm - f.relative_nm).max(0.0),
                f.thickness_nm + f.relative_nm
            )
        })
        .unwrap_or_default();
    format!(
        "// {name}: the nacre studio's stack in three.js (@nacre/three).
import * as THREE from 'three';
import {{ NacreFilmMaterial, loadNacreStack }} from '@nacre/three';

// The whole stack ({films} film(s)), drawn by film_stack:
const stacked = new NacreFilmMaterial({{
  stack: await loadNacreStack('/{name}.stack.json'),
  filmThicknessNm: {d},
  color: 0x000000, roughness: 0.2,
}});{range}

// Or the closest glTF film on three's own material, ΔE2000 mean {mean:.2}, max {max:.2}
// against the stack over 0–85°:
const gltfLike = new THREE.MeshPhysicalMaterial({{
  {base} roughness: 0.2,
  iridescence: {w}, iridescenceIOR: {n},
  iridescenceThicknessRange: [{min}, {max_nm}],
}});
",
        films = doc.films.len(),
        d = top_nm(doc),
        mean = fit.fit.errors.mean,
        max = fit.fit.errors.max,
        w = film.factor,
        n = film.iridescence_ior,
        min = film.thickness_min_nm,
        max_nm = film.thickness_max_nm,
    )
}

/// An engine export being prepared on its own thread.
pub struct EngineJob {
    handle: Option<JoinHandle<Result<EngineExport, String>>>,
}

impl EngineJob {
    /// Starts preparing the export of `doc`.
    pub fn start(doc: StackDoc, name: String) -> EngineJob {
        EngineJob {
            handle: Some(std::thread::spawn(move || EngineExport::new(&doc, &name))),
        }
    }

    /// The export once ready (taken once).
    pub fn poll(&mut self) -> Option<Result<EngineExport, String>> {
        if !self.handle.as_ref()?.is_finished() {
            return None;
        }
        let handle = self.handle.take()?;
        Some(
            handle
                .join()
                .unwrap_or_else(|_| Err("the engine export's thread panicked".into())),
        )
    }
}
