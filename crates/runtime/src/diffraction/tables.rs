//! A `diffraction` table in either layout ([`DiffractionTables`]): what the scenes and the
//! bench pass take.

use super::common::{DiffractionLayout, diffraction_record};
use super::integrated::DiffractionIntegrated;
use super::terms::DiffractionTable;
use crate::context::GpuContext;
use crate::error::Result;
use nacre_format::diffraction::DiffractionRecord;
use nacre_optics::diffraction::FresnelTerm;
use std::path::Path;

/// A `diffraction` table on the GPU in either layout, as [`DiffractionTables::load`] reads it
/// from its manifest: what the scenes ([`render_diffraction_scene`](super::scene::render_diffraction_scene)) and the bench pass
/// ([`ScenePass::bench`](super::scene::ScenePass::bench)) take.
pub enum DiffractionTables {
    /// Layout "terms": the Taylor terms, summed over wavelengths per pixel.
    Terms(Box<DiffractionTable>),
    /// Layout "integrated": the wavelength sum done at bake time (the fast path).
    Integrated(Box<DiffractionIntegrated>),
}

impl DiffractionTables {
    /// Reads the manifest at `manifest_path` and loads the table by its layout:
    /// [`DiffractionTable::load`] for "terms",
    /// [`DiffractionIntegrated::load`] for "integrated", whose uniform holds `fresnel` (the F²
    /// the scene consumers apply; the terms technique takes F² from
    /// [`DiffractionOptions::fresnel`](super::terms::DiffractionOptions::fresnel) instead, and ignores this argument).
    ///
    /// # Errors
    /// As the loaders; [`Error::Manifest`](crate::Error::Manifest) for a table of another kind or an unknown layout.
    pub fn load(
        ctx: &GpuContext,
        manifest_path: &Path,
        fresnel: FresnelTerm,
    ) -> Result<DiffractionTables> {
        let record = diffraction_record(manifest_path)?.1;
        Ok(match DiffractionLayout::of(&record, manifest_path)? {
            DiffractionLayout::Terms { .. } => {
                DiffractionTables::Terms(Box::new(DiffractionTable::load(ctx, manifest_path)?))
            }
            DiffractionLayout::Integrated { .. } => DiffractionTables::Integrated(Box::new(
                DiffractionIntegrated::load(ctx, manifest_path, fresnel)?,
            )),
        })
    }

    /// Table name.
    pub fn name(&self) -> &str {
        match self {
            DiffractionTables::Terms(t) => &t.name,
            DiffractionTables::Integrated(t) => &t.name,
        }
    }

    /// The manifest's `diffraction` record.
    pub fn record(&self) -> &DiffractionRecord {
        match self {
            DiffractionTables::Terms(t) => &t.record,
            DiffractionTables::Integrated(t) => &t.record,
        }
    }

    /// The layout.
    pub fn layout(&self) -> DiffractionLayout {
        match self {
            DiffractionTables::Terms(t) => t.layout,
            DiffractionTables::Integrated(t) => DiffractionLayout::Integrated {
                order: t.record.taylor_order,
            },
        }
    }
}

impl From<DiffractionTable> for DiffractionTables {
    fn from(table: DiffractionTable) -> Self {
        DiffractionTables::Terms(Box::new(table))
    }
}

impl From<DiffractionIntegrated> for DiffractionTables {
    fn from(table: DiffractionIntegrated) -> Self {
        DiffractionTables::Integrated(Box::new(table))
    }
}
