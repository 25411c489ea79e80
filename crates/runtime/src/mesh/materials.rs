//! Which technique draws each glTF material: `film-lut` only where the loaded table baked
//! the material's base (see the module documentation of [`super`]), `glass` only for a
//! transmissive dielectric ([`glass_setup`]), `fourier` otherwise.

use crate::error::{Error, Result};
use crate::gltf_scene::{GltfScene, is_gold_like};
use crate::render::{BaseKind, MaterialOptions, check_film_lut};
use crate::shaders::Technique;
use crate::tables::TableSet;
use crate::technique::StackSetup;
use nacre_format::msg;
use nacre_format::param::{Msg, Piece};
use nacre_optics::colour::Colorimeter;
use nacre_optics::{C64, Layer, Material, Stack};
use std::sync::Arc;

/// Nanometres per world unit: glTF's unit of length is the metre (glTF 2.0 §3.4), and
/// `KHR_materials_volume`'s `thicknessFactor` is in the mesh's units.
pub const NM_PER_WORLD_UNIT: f64 = 1e9;

/// The coated pane `film_glass` draws for glTF material `gm` (technique `glass`), or why it
/// cannot. A transmissive (`KHR_materials_transmission` `transmissionFactor` > 0), wholly
/// dielectric (metallic 0 everywhere) material maps onto one stack:
///
/// | medium | from |
/// |---|---|
/// | ambient | air (n = 1) |
/// | film 1, coherent | `KHR_materials_iridescence`: `iridescenceIor`; its thickness the pixel's, d = mix(min, max, g) |
/// | film 2, the incoherent slab | `KHR_materials_ior` `ior` (κ = 0); thickness `KHR_materials_volume` `thicknessFactor` × 10⁹ nm (metres), 0 when thin-walled (no volume, or thicknessFactor 0) |
/// | base | air (n = 1) |
///
/// so that R and T are the whole pane's: the film and the front face coherent, the pane's
/// back face added in intensity (Byrnes, arXiv:1603.02720 §4). A clear slab's R and T do not
/// depend on its thickness (its single pass P = 1), so the volume's thickness moves the
/// refracted picture and the attenuation only: `attenuationColor` / `attenuationDistance`
/// stay the renderer's Beer–Lambert factor over the path inside (`shaders/mesh.wgsl`
/// `mesh_behind`), an RGB quantity that names no spectrum (the internal reflections, a
/// share R′R_B ≈ 0.2 % of the light, go unattenuated). A material without iridescence has
/// film weight 0: the uncoated pane (`SurfaceMaterial.bare_pane`).
///
/// Metallic 0 everywhere is judged by [`GltfScene::metallic_range`], the metallic texture's
/// texels included.
///
/// # Errors
/// The reason, for the renderer's fallback note: `material` is not in the scene, does not
/// transmit, has a metal lobe, or a value makes no stack.
pub fn glass_setup(scene: &GltfScene, material: usize) -> std::result::Result<StackSetup, Msg> {
    let Some(gm) = scene.materials.get(material) else {
        return Err(format!("material {material} is not in the scene").into());
    };
    if !(gm.transmission.is_finite() && gm.transmission > 0.0) {
        return Err("it does not transmit (KHR_materials_transmission): glass draws a pane".into());
    }
    let (_, metallic_max) = scene.metallic_range(material);
    if metallic_max > 0.0 {
        return Err(format!(
            "its metallic value reaches {metallic_max} (a factor or texture): a metal lobe has no pane"
        )
        .into());
    }
    let iri = gm.iridescence.unwrap_or_default();
    let thickness_nm = gm.volume.map_or(0.0, |v| {
        let t = f64::from(v.thickness) * NM_PER_WORLD_UNIT;
        if t.is_finite() && t > 0.0 { t } else { 0.0 }
    });
    let constant = |what: &str, n: f32| {
        Material::constant(format!("{n}"), C64::new(f64::from(n), 0.0))
            .map_err(|e| Msg::from(format!("{what} {n}: {e}")))
    };
    let air = constant("air", 1.0)?;
    let layers = vec![
        Layer {
            material: constant("iridescenceIor", iri.ior)?,
            thickness_nm: f64::from(iri.thickness_max_nm.max(0.0)),
        },
        Layer {
            material: constant("ior", gm.dielectric_ior())?,
            thickness_nm,
        },
    ];
    let stack = Stack::new(air.clone(), layers, air)
        .and_then(|s| s.with_incoherent(vec![false, true]))
        .map_err(|e| Msg::from(e.to_string()))?;
    Ok(StackSetup {
        stack,
        relative_nm: vec![0.0; 2],
        channels: Vec::new(),
        samples: None,
    })
}

/// Whether the loaded `film-lut` table can draw `material` (see the module documentation);
/// a gold-like metal gets the table's base. `Err` holds the reason it cannot.
fn lut_material(
    tables: &TableSet,
    material: &MaterialOptions,
    base_colour: [f32; 3],
) -> std::result::Result<MaterialOptions, Msg> {
    let Some(lut) = &tables.film_lut else {
        return Err("no film-lut table is loaded".into());
    };
    // Errors are kept whole, so that a front end names their parameters its own way.
    let quoted = |e: Error| Msg::from_pieces(vec![Piece::Nested(Arc::new(e))]);
    let context = format!("{} (base)", lut.manifest_path.display());
    let table_base =
        nacre_format::materials::resolve(&lut.manifest.base, &context, lut.manifest_path.parent())
            .map_err(|e| quoted(e.into()))?;
    let table_kind = BaseKind::of(&table_base);
    let mut m = material.clone();
    match (material.base_kind, table_kind) {
        (BaseKind::Dielectric, BaseKind::Dielectric) => {
            let a = material
                .base
                .index_at(550.0)
                .map_err(|e| quoted(e.into()))?;
            let b = table_base.index_at(550.0).map_err(|e| quoted(e.into()))?;
            if (a - b).norm() > 1e-3 {
                return Err(format!(
                    "base index {} differs from the table `{}`'s {}",
                    a.re, lut.name, b.re
                )
                .into());
            }
        }
        (BaseKind::Metal, BaseKind::Metal) if is_gold_like(base_colour) => {
            m.base = table_base;
        }
        (BaseKind::Metal, _) => {
            return Err(format!(
                "a metal base needs a table baked on that metal (film-gold for a gold-coloured base), not `{}`",
                lut.name
            )
            .into());
        }
        _ => return Err(format!("the base differs from the table `{}`'s", lut.name).into()),
    }
    check_film_lut(tables, &m).map_err(quoted)?;
    Ok(m)
}

/// How the mesh renderer draws a scene's materials.
pub(super) struct Choice {
    /// Per material of the file (used or not): nacre's options and the technique.
    pub drawn: Vec<(MaterialOptions, Technique)>,
    /// Per material of the file: the pane of those drawn with `glass` ([`glass_setup`]).
    pub glass: Vec<Option<StackSetup>>,
    /// The used materials' notes (ignored extensions, approximations), in the file's order.
    pub notes: Vec<Msg>,
    /// One line summing up the used materials drawn with `fourier` instead of `technique`.
    pub fallback_note: Option<Msg>,
}

/// The options and technique of every material of `scene` drawn with `technique`; `used`
/// (sorted) lists the materials a primitive refers to, the only ones noted. With `lut`, a
/// material the loaded `film-lut` table cannot draw ([`lut_material`]), and with `spectral`
/// one that mixes a dielectric and a metal lobe, and with `glass` one that is no transmissive
/// dielectric ([`glass_setup`]), falls back to `fourier`.
pub(super) fn choose(
    scene: &GltfScene,
    tables: &TableSet,
    technique: Technique,
    colorimeter: &Colorimeter,
    used: &[usize],
) -> Result<Choice> {
    let mut notes = Vec::new();
    let mut drawn = Vec::with_capacity(scene.materials.len());
    let mut glass = Vec::with_capacity(scene.materials.len());
    // Technique fallbacks, summarised in one line: (material, reason).
    let mut fallbacks: Vec<(String, Msg)> = Vec::new();
    for (i, gm) in scene.materials.iter().enumerate() {
        let (mut m, material_notes) = gm.material_options(colorimeter)?;
        if used.contains(&i) {
            notes.extend(material_notes.into_iter().map(Msg::from));
            for name in super::textures::coat_slots(gm).dropped {
                notes.push(Msg::from(format!(
                    "{}: {name} not read (the material's textures fill every slot); its factor is used",
                    gm.name
                )));
            }
        }
        let (lo, hi) = scene.metallic_range(i);
        let one_lobe = hi <= 0.0 || lo >= 1.0;
        let mut t = technique;
        let mut pane = None;
        if technique == Technique::Glass {
            match glass_setup(scene, i) {
                Ok(setup) => pane = Some(setup),
                Err(why) => {
                    if used.contains(&i) {
                        fallbacks.push((gm.name.clone(), why));
                    }
                    t = Technique::Fourier;
                }
            }
        } else if technique == Technique::Lut {
            let colour = [gm.base_colour[0], gm.base_colour[1], gm.base_colour[2]];
            let result = if one_lobe {
                lut_material(tables, &m, colour)
            } else {
                Err(Msg::from(
                    "its metallic value varies (a partial factor or a texture): the table bakes one base",
                ))
            };
            match result {
                Ok(lm) => m = lm,
                Err(why) => {
                    if used.contains(&i) {
                        fallbacks.push((gm.name.clone(), why));
                    }
                    t = Technique::Fourier;
                }
            }
        } else if technique == Technique::Spectral && !one_lobe {
            if used.contains(&i) {
                fallbacks.push((
                    gm.name.clone(),
                    Msg::from(
                        "it mixes a dielectric and a metal lobe; spectral holds one base per pass",
                    ),
                ));
            }
            t = Technique::Fourier;
        }
        if t == Technique::Lut {
            // The table's ambient (checked above) must be the material's.
            m.ambient_ior = tables
                .film_lut
                .as_ref()
                .map_or(1.0, |l| l.axes.ambient_index as f32);
        }
        drawn.push((m, t));
        glass.push(pane);
    }
    let fallback_note = fallbacks.first().map(|(name, why)| {
        msg![
            format!(
                "drawn with fourier instead of {}: {} of {} materials (e.g. `{name}`: ",
                technique.name(),
                fallbacks.len(),
                used.len()
            ),
            why.clone(),
            ")"
        ]
    });

    Ok(Choice {
        drawn,
        glass,
        notes,
        fallback_note,
    })
}
