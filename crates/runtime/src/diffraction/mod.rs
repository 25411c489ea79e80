//! The `diffraction` technique on the GPU: loading baked `diffraction` tables (layout
//! "terms"; either layout through [`DiffractionTables`]) through their manifests, the technique's bind group (`shaders/diffraction.wgsl`),
//! the GPU = CPU probe, and the ray-cast scenes of `nacre render --scene cd-disc |
//! snake-skin` (`shaders/diffraction_scene.wgsl`).
//!
//! # Upload
//!
//! A `diffraction` table's Taylor terms Tₙ (`nacre_bake::kinds::diffraction` says what every texel
//! holds) become one 2-D array texture, `Rgba32Float`, Mₓ × M_y texels, ⌈(N + 1)/2⌉ layers,
//! layer l = (Re T₂ₗ, Im T₂ₗ, Re T₂ₗ₊₁, Im T₂ₗ₊₁) — the layout of the table's KTX2 file. Full
//! float is not filterable everywhere, and the technique needs exact bins anyway: the shader
//! reads it with `textureLoad` only (integer texel coordinates, texel (s, t) = bin
//! (s − ⌊Mₓ/2⌋, t − ⌊M_y/2⌋)). The texels come from the EXR file, else the KTX2 file
//! ([`nacre_format::Manifest::load_diffraction`]); every file is checked against its
//! manifest's SHA-256 and the texture against the device's limits before upload.
//!
//! [`DiffractionTables::load`] dispatches on the manifest's `layout` ([`DiffractionLayout`]):
//! "terms" loads as a [`DiffractionTable`] (`terms.rs`), "integrated" (the fast path, the
//! wavelength sum done at bake time) as a [`DiffractionIntegrated`](integrated::DiffractionIntegrated); another layout is an
//! [`Error::Manifest`](crate::Error::Manifest) naming it. The scenes, the bench pass ([`ScenePass`]) and
//! [`render_diffraction_scene`] take either: an integrated table runs the same consumers
//! (`shaders/diffraction_scene.wgsl`) through the adapter
//! `shaders/diffraction_integrated_technique.wgsl`
//! ([`integrated::compose_scene`]) with its own bind group at group 1.
//!
//! # Spectral sum
//!
//! The terms technique sums ρ(λ) u(λ) over a regular wavelength grid uploaded with the table
//! ([`DiffractionOptions::wavelength_step_nm`]): by default the table's own grid (the one the
//! CPU evaluation uses, `nacre diffraction --color`); a coarser step trades accuracy for
//! speed (10 nm halves the cost of the 5 nm default set). Each grid gets its own CIE weights
//! ([`SpectralGrid`](nacre_optics::diffraction::SpectralGrid): the 1 nm weights interpolated, × step, rescaled so that ρ ≡ 1 is white),
//! times the table's output matrix M: u(λ) = M · xyz_weight(λ).
//!
//! # Coherence-window neighbourhood
//!
//! The window sum runs over R bins on each side of the nearest bin, per axis, with R the
//! smallest radius whose largest dropped weight exp(−(σ_s Δκ)² (R + ½)²/2) is at most
//! [`DiffractionOptions::window_tolerance`] (10⁻³ by default; at most [`MAX_RADIUS`]). The
//! `cd-tracks` table (σ_s Δκ = π/2) gets R = 2 (5 × 5 bins), dropping weights ≤ 4.5 · 10⁻⁴;
//! a one-row (1-D) grating has R = 0 along y.
//!
//! # Files
//!
//! * `common.rs`: what both layouts share (the common WGSL, [`DiffractionLayout`], the
//!   array upload, the probe dispatch);
//! * `terms.rs`: layout "terms" ([`DiffractionTable`], [`DiffractionBinding`], [`run_probe`]);
//! * [`integrated`]: layout "integrated" (also reachable as `nacre_runtime::diffraction_integrated`);
//! * `tables.rs`: either layout ([`DiffractionTables`]);
//! * [`lobes`]: the environment diffracted through a "terms" table's lobes (the integral of
//!   Stam's BRDF against the whole environment, [`EnvironmentLobes`]);
//! * `scene.rs`: the scenes and the scene pass ([`render_diffraction_scene`], [`ScenePass`]).

mod common;
pub mod integrated;
pub mod lobes;
mod scene;
mod scenes;
mod tables;
mod terms;

pub use common::{DIFFRACTION_COMMON, DiffractionLayout};
pub use lobes::EnvironmentLobes;
pub use scene::{
    DEFAULT_ENV_SAMPLES, DIFFRACTION_SCENE, DiffractionLightsUniform, DiffractionSceneOptions,
    LOBE_REFERENCE_NM, LobeData, MAX_ENV_SAMPLES, MAX_ROUGHNESS, ScenePass, environment_samples,
    llvmpipe_filter_radius, lobe_gain, render_diffraction_scene, render_diffraction_scene_in,
    rough_slope_variance,
};
pub use scenes::DiffractionScene;
pub use tables::DiffractionTables;
pub use terms::{
    DIFFRACTION, DiffractionBinding, DiffractionOptions, DiffractionTable, DiffractionUniform,
    LLVMPIPE_LOOP_LIMIT, MAX_FILTER_RADIUS, MAX_RADIUS, MAX_TAYLOR_ORDER, MAX_WAVELENGTHS,
    ProbeOutput, compose, composition, filter_radius, filtered_iterations, run_probe,
    spectrum_weights, wavelength_grid,
};
