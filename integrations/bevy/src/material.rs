//! The film material: an extension of Bevy's `StandardMaterial` whose fragment shader puts
//! nacre's film colour in place of the specular lobe's Fresnel term (`film_material.wgsl`
//! has the equations).

use crate::shaders::FILM_MATERIAL_HANDLE;
use crate::tables::{
    DEFAULT_FILM_LUT, DEFAULT_FOURIER, FilmLutUniform, FourierUniform, NacreTable, NacreTableAxes,
};
use bevy::asset::{AssetEvent, Assets, Handle};
use bevy::ecs::message::MessageReader;
use bevy::image::Image;
use bevy::math::{UVec4, Vec3, Vec4};
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{
    ExtendedMaterial, MaterialExtension, MaterialExtensionKey, MaterialExtensionPipeline,
    StandardMaterial,
};
use bevy::prelude::{Asset, ResMut};
use bevy::reflect::Reflect;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::{
    AsBindGroup, AsBindGroupShaderType, RenderPipelineDescriptor, ShaderType,
    SpecializedMeshPipelineError,
};
use bevy::render::storage::ShaderBuffer;
use bevy::render::texture::GpuImage;
use bevy::shader::ShaderRef;
use nacre_format::gpu_params::{StackGpu, StackParams};

/// `StandardMaterial` with a nacre thin film on top.
pub type NacreMaterial = ExtendedMaterial<StandardMaterial, NacreFilm>;

/// Which of nacre's techniques colours the film. Part of the material's pipeline key: each
/// technique is its own pipeline, whose fragment shader compiles that technique only
/// (shader def `NACRE_FILM_LUT` or `NACRE_FILM_FOURIER`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Reflect)]
pub enum FilmTechnique {
    /// One trilinear lookup in a baked `film-lut` table (`film_lut.wgsl`): the table's ambient
    /// and base are baked in ([`NacreFilm::base_ior`] and `base_kappa` are ignored).
    #[default]
    Lut,
    /// The Fourier-series method (`film_fourier.wgsl`): any film index on any base, metals
    /// included, from [`NacreFilm::base_ior`] and [`NacreFilm::base_kappa`].
    Fourier,
    /// A multilayer stack (`film_stack.wgsl`): ambient, 1 to 8 films, base, absorbing and
    /// dispersive media, from [`NacreFilm::set_stack`] (a [`StackGpu`] prepared by
    /// nacre, e.g. read from `nacre export --layer …`'s JSON with [`NacreFilm::stack_from_json`]).
    /// The top film's thickness is the material's ([`NacreFilm::thickness`]); film j ≥ 2 is
    /// d_j + r_j (2c − 1), c its channel (R, G or B) of the thickness texture (1 without one).
    /// `film_ior`, `base_ior`, `base_kappa` and `ambient_ior` are ignored: the stack has them.
    Stack,
}

/// Mirror of `StackParams` (`shaders/film_stack.wgsl`, 288 bytes; [`StackParams`] with
/// Bevy's shader types).
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType, Reflect)]
pub struct StackUniform {
    /// Films F.
    pub films: u32,
    /// 1 when some index varies with wavelength.
    pub dispersive: u32,
    /// Rules in the ladder.
    pub rule_count: u32,
    /// 1: always rule 0.
    pub fixed_rule: u32,
    /// N at OPD 0.
    pub base_count: f32,
    /// Samples per nm of OPD.
    pub count_per_opd_nm: f32,
    /// The stack's finesse factor h.
    pub finesse: f32,
    /// Padding.
    pub _pad0: f32,
    /// First node of rule i (component i % 4 of element i / 4).
    pub rule_offset: [UVec4; 4],
    /// Nodes of rule i.
    pub rule_size: [UVec4; 4],
    /// Film j: (d_j⁰, r_j, k_j, c_j).
    pub layers: [Vec4; 8],
}

impl From<&StackParams> for StackUniform {
    fn from(p: &StackParams) -> Self {
        let quad = |v: &[u32; 16], i: usize| UVec4::from_slice(&v[4 * i..4 * i + 4]);
        StackUniform {
            films: p.films,
            dispersive: p.dispersive,
            rule_count: p.rule_count,
            fixed_rule: p.fixed_rule,
            base_count: p.base_count,
            count_per_opd_nm: p.count_per_opd_nm,
            finesse: p.finesse,
            _pad0: 0.0,
            rule_offset: std::array::from_fn(|i| quad(&p.rule_offset, i)),
            rule_size: std::array::from_fn(|i| quad(&p.rule_size, i)),
            layers: p.layers.map(Vec4::from_array),
        }
    }
}

/// How the thickness texture's green channel g maps to the film thickness d.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
pub enum FilmThickness {
    /// glTF `KHR_materials_iridescence`: d = mix(min_nm, max_nm, g); d = max_nm without a
    /// texture.
    Gltf {
        /// `iridescenceThicknessMinimum`, nm.
        min_nm: f32,
        /// `iridescenceThicknessMaximum`, nm.
        max_nm: f32,
    },
    /// nacre's SVT form: d = average_nm + relative_nm (2g − 1); d = average_nm + relative_nm
    /// without a texture (g = 1).
    Svt {
        /// d_avg, nm.
        average_nm: f32,
        /// d_rel, nm.
        relative_nm: f32,
    },
}

impl Default for FilmThickness {
    /// glTF's defaults: 100–400 nm.
    fn default() -> Self {
        FilmThickness::Gltf {
            min_nm: 100.0,
            max_nm: 400.0,
        }
    }
}

/// Mirror of `NacreFilmUniform` (`film_material.wgsl`, 64 bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub struct NacreFilmUniform {
    /// 0 film_lut, 1 film_fourier, 2 film_stack.
    pub technique: u32,
    /// 0 glTF, 1 SVT.
    pub thickness_mode: u32,
    /// Bit 0: thickness texture bound; bit 1: weight texture bound.
    pub flags: u32,
    /// Padding.
    pub _pad0: u32,
    /// Film index n₂.
    pub film_ior: f32,
    /// glTF d_min or SVT d_avg, nm.
    pub thickness_a_nm: f32,
    /// glTF d_max or SVT d_rel, nm.
    pub thickness_b_nm: f32,
    /// Film weight w.
    pub weight: f32,
    /// Base index, real part, per channel (fourier).
    pub base_ior: Vec3,
    /// Ambient index n₁ (fourier).
    pub ambient_ior: f32,
    /// Base index, imaginary part, per channel (fourier).
    pub base_kappa: Vec3,
    /// Padding.
    pub _pad1: f32,
}

/// The film on top of a `StandardMaterial` (use as [`NacreMaterial`]'s extension).
///
/// The table fields are filled from [`NacreFilm::lut_table`] and [`NacreFilm::fourier_table`]
/// by the plugin whenever those tables load or change (hot reload); they are the default
/// set unless set otherwise.
#[derive(Asset, AsBindGroup, Reflect, Debug, Clone)]
#[uniform(106, NacreFilmUniform)]
#[bind_group_data(NacreFilmKey)]
pub struct NacreFilm {
    /// The film-lut table whose textures are bound (see the struct docs).
    pub lut_table: Handle<NacreTable>,
    /// The fourier table whose texture is bound.
    pub fourier_table: Handle<NacreTable>,
    /// Technique.
    pub technique: FilmTechnique,
    /// Film index n₂ (glTF `iridescenceIor`, default 1.3).
    pub film_ior: f32,
    /// Thickness range and form.
    pub thickness: FilmThickness,
    /// Thickness texture (its green channel is g).
    #[texture(107)]
    #[sampler(108)]
    pub thickness_texture: Option<Handle<Image>>,
    /// Film weight w ∈ [0, 1] (glTF `iridescenceFactor`).
    pub weight: f32,
    /// Weight texture (its red channel multiplies [`NacreFilm::weight`]).
    #[texture(109)]
    #[sampler(110)]
    pub weight_texture: Option<Handle<Image>>,
    /// Base index n per channel (fourier; glTF `KHR_materials_ior`, 1.5 by default).
    pub base_ior: Vec3,
    /// Base index κ per channel (fourier; 0 for dielectrics).
    pub base_kappa: Vec3,
    /// Ambient index n₁ (fourier; 1 = air).
    pub ambient_ior: f32,
    /// film-lut reflectance (from [`NacreFilm::lut_table`]).
    #[texture(100, dimension = "3d")]
    #[sampler(102)]
    pub lut_reflectance: Option<Handle<Image>>,
    /// film-lut transmittance (from [`NacreFilm::lut_table`]).
    #[texture(101, dimension = "3d")]
    pub lut_transmittance: Option<Handle<Image>>,
    /// film-lut axes (from [`NacreFilm::lut_table`]).
    #[uniform(103)]
    pub lut_axes: FilmLutUniform,
    /// fourier coefficients (from [`NacreFilm::fourier_table`]).
    #[texture(104, dimension = "2d_array", sample_type = "float", filterable = false)]
    pub fourier_coefficients: Option<Handle<Image>>,
    /// fourier axes (from [`NacreFilm::fourier_table`]).
    #[uniform(105)]
    pub fourier_axes: FourierUniform,
    /// The stack's nodes, `array<StackNode>` ([`NacreFilm::set_stack`]; by default
    /// [`DEFAULT_STACK_NODES`]).
    #[storage(111, read_only)]
    pub stack_nodes: Handle<ShaderBuffer>,
    /// Every medium's index at every node, `array<vec2<f32>>` ([`NacreFilm::set_stack`]).
    #[storage(112, read_only)]
    pub stack_indices: Handle<ShaderBuffer>,
    /// The stack's uniform ([`NacreFilm::set_stack`]).
    #[uniform(113)]
    pub stack_params: StackUniform,
}

/// The nodes of the default stack (the runtime's `StackSetup::default()`: 100 nm of n 1.38
/// over 60 nm of n 2.3 on glass n 1.5, the lower film varying by ±30 nm), built by
/// [`crate::NacrePlugin`].
pub const DEFAULT_STACK_NODES: Handle<ShaderBuffer> =
    bevy::asset::uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a21");
/// The indices of the default stack.
pub const DEFAULT_STACK_INDICES: Handle<ShaderBuffer> =
    bevy::asset::uuid_handle!("6f0e35a4-3c1e-4b47-9d0e-4c5b1d6b0a22");

/// The default stack's numbers ([`default_stack`]), prepared once.
pub static DEFAULT_STACK: std::sync::LazyLock<StackGpu> = std::sync::LazyLock::new(default_stack);

/// The default stack's numbers ([`DEFAULT_STACK_NODES`]): 1.38 @ 100 nm (r 0) over
/// 2.3 @ 60 nm (r 30 nm) in air on n 1.5, 1931/D65/sRGB, the rule ladder.
pub fn default_stack() -> StackGpu {
    use nacre_optics::few_wavelengths::StackEvaluation;
    use nacre_optics::{C64, Layer, Material, Stack};
    let constant = |n: f64| {
        Material::constant(format!("{n}"), C64::new(n, 0.0))
            .expect("a real index above zero is a valid material")
    };
    let layer = |n: f64, d: f64| Layer {
        material: constant(n),
        thickness_nm: d,
    };
    let stack = Stack::new(
        constant(1.0),
        vec![layer(1.38, 100.0), layer(2.3, 60.0)],
        constant(1.5),
    )
    .expect("finite thicknesses and a clear ambient");
    let colorimeter = nacre_optics::colour::Colorimeter::new(
        nacre_optics::colour::Observer::Cie1931_2Deg,
        nacre_optics::colour::Illuminant::D65,
        nacre_optics::colour::OutputSpace::Rgb(nacre_optics::colour::RgbSpace::Srgb),
    );
    let eval = StackEvaluation::new(&colorimeter, &stack, &[0.0, 30.0], None)
        .expect("two films, valid relative thicknesses, the ladder");
    StackGpu::new(&eval)
}

/// The storage buffers of `stack`'s nodes and indices.
pub fn stack_buffers(stack: &StackGpu) -> (ShaderBuffer, ShaderBuffer) {
    use bevy::asset::RenderAssetUsages;
    (
        ShaderBuffer::new(
            bytemuck::cast_slice(&stack.nodes),
            RenderAssetUsages::RENDER_WORLD,
        ),
        ShaderBuffer::new(
            bytemuck::cast_slice(&stack.indices),
            RenderAssetUsages::RENDER_WORLD,
        ),
    )
}

/// The film's part of the material's pipeline key (see [`FilmTechnique`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NacreFilmKey {
    /// The technique the pipeline's fragment shader compiles.
    pub technique: FilmTechnique,
}

impl NacreFilm {
    /// Draws `stack` ([`FilmTechnique::Stack`]): its buffers are added to `buffers`, its
    /// uniform set, and the thickness set to the top film's SVT form (d⁰, r) from the stack.
    pub fn set_stack(&mut self, stack: &StackGpu, buffers: &mut bevy::asset::Assets<ShaderBuffer>) {
        let (nodes, indices) = stack_buffers(stack);
        self.stack_nodes = buffers.add(nodes);
        self.stack_indices = buffers.add(indices);
        self.stack_params = StackUniform::from(&stack.params);
        self.technique = FilmTechnique::Stack;
        self.thickness = FilmThickness::Svt {
            average_nm: stack.params.layers[0][0],
            relative_nm: stack.params.layers[0][1],
        };
    }

    /// The stack of the JSON `nacre export --layer … --out stack.json` writes (schema in
    /// docs/engines/README.md), ready for [`NacreFilm::set_stack`].
    ///
    /// # Errors
    /// Text that is not JSON, or JSON that is not a valid stack (naming `origin` and the field).
    pub fn stack_from_json(text: &str, origin: &str) -> Result<StackGpu, nacre_format::Error> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| nacre_format::Error::Invalid {
                context: origin.to_string().into(),
                message: format!("not JSON: {e}").into(),
            })?;
        nacre_format::export::read_stack_json(&value, origin)
    }
}

impl From<&NacreFilm> for NacreFilmKey {
    fn from(film: &NacreFilm) -> Self {
        NacreFilmKey {
            technique: film.technique,
        }
    }
}

impl FilmTechnique {
    /// The shader def that selects this technique in `film_material.wgsl`.
    pub fn shader_def(self) -> &'static str {
        match self {
            FilmTechnique::Lut => "NACRE_FILM_LUT",
            FilmTechnique::Fourier => "NACRE_FILM_FOURIER",
            FilmTechnique::Stack => "NACRE_FILM_STACK",
        }
    }
}

impl Default for NacreFilm {
    /// glTF `KHR_materials_iridescence`'s defaults (index 1.3, 100–400 nm, weight 1) on the
    /// default table set, film-lut technique.
    fn default() -> Self {
        NacreFilm {
            lut_table: DEFAULT_FILM_LUT,
            fourier_table: DEFAULT_FOURIER,
            technique: FilmTechnique::Lut,
            film_ior: 1.3,
            thickness: FilmThickness::default(),
            thickness_texture: None,
            weight: 1.0,
            weight_texture: None,
            base_ior: Vec3::splat(1.5),
            base_kappa: Vec3::ZERO,
            ambient_ior: 1.0,
            lut_reflectance: None,
            lut_transmittance: None,
            lut_axes: FilmLutUniform::default(),
            fourier_coefficients: None,
            fourier_axes: FourierUniform::default(),
            stack_nodes: DEFAULT_STACK_NODES,
            stack_indices: DEFAULT_STACK_INDICES,
            stack_params: StackUniform::from(&DEFAULT_STACK.params),
        }
    }
}

impl NacreFilm {
    /// Copies the textures and axes of the loaded tables into the bound fields; true when
    /// something changed.
    pub fn bind_tables(&mut self, tables: &Assets<NacreTable>) -> bool {
        let mut changed = false;
        if let Some(t) = tables.get(&self.lut_table)
            && let NacreTableAxes::FilmLut(axes) = t.axes
        {
            let r = Some(t.texture.clone());
            if self.lut_reflectance != r
                || self.lut_transmittance != t.transmittance
                || self.lut_axes != axes
            {
                self.lut_reflectance = r;
                self.lut_transmittance = t.transmittance.clone();
                self.lut_axes = axes;
                changed = true;
            }
        }
        if let Some(t) = tables.get(&self.fourier_table)
            && let NacreTableAxes::Fourier(axes) = t.axes
        {
            let c = Some(t.texture.clone());
            if self.fourier_coefficients != c || self.fourier_axes != axes {
                self.fourier_coefficients = c;
                self.fourier_axes = axes;
                changed = true;
            }
        }
        changed
    }
}

impl AsBindGroupShaderType<NacreFilmUniform> for NacreFilm {
    fn as_bind_group_shader_type(&self, _images: &RenderAssets<GpuImage>) -> NacreFilmUniform {
        let (thickness_mode, a, b) = match self.thickness {
            FilmThickness::Gltf { min_nm, max_nm } => (0, min_nm, max_nm),
            FilmThickness::Svt {
                average_nm,
                relative_nm,
            } => (1, average_nm, relative_nm),
        };
        NacreFilmUniform {
            technique: match self.technique {
                FilmTechnique::Lut => 0,
                FilmTechnique::Fourier => 1,
                FilmTechnique::Stack => 2,
            },
            thickness_mode,
            flags: u32::from(self.thickness_texture.is_some())
                | (u32::from(self.weight_texture.is_some()) << 1),
            _pad0: 0,
            film_ior: self.film_ior,
            thickness_a_nm: a,
            thickness_b_nm: b,
            weight: self.weight,
            base_ior: self.base_ior,
            ambient_ior: self.ambient_ior,
            base_kappa: self.base_kappa,
            _pad1: 0.0,
        }
    }
}

impl MaterialExtension for NacreFilm {
    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(FILM_MATERIAL_HANDLE)
    }

    /// One technique per pipeline: a technique chosen at run time through the uniform
    /// compiles both into every call site, and a SIMD rasteriser such as lavapipe executes
    /// both sides of a branch under masks, so each film evaluation would cost both.
    fn specialize(
        _pipeline: &MaterialExtensionPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        _layout: &MeshVertexBufferLayoutRef,
        key: MaterialExtensionKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        if let Some(fragment) = descriptor.fragment.as_mut() {
            let technique = key.bind_group_data.technique;
            fragment.shader_defs.push(technique.shader_def().into());
        }
        Ok(())
    }
}

/// Binds each material's tables when the material or one of the tables is added or changes.
pub(crate) fn bind_tables(
    mut table_events: MessageReader<AssetEvent<NacreTable>>,
    mut material_events: MessageReader<AssetEvent<NacreMaterial>>,
    tables: bevy::prelude::Res<Assets<NacreTable>>,
    mut materials: ResMut<Assets<NacreMaterial>>,
) {
    let tables_changed = table_events.read().any(|e| {
        matches!(
            e,
            AssetEvent::Added { .. }
                | AssetEvent::Modified { .. }
                | AssetEvent::LoadedWithDependencies { .. }
        )
    });
    let mut ids: Vec<_> = material_events
        .read()
        .filter_map(|e| match e {
            AssetEvent::Added { id } | AssetEvent::Modified { id } => Some(*id),
            _ => None,
        })
        .collect();
    if tables_changed {
        ids = materials.ids().collect();
    }
    for id in ids {
        let needs = materials
            .get(id)
            .is_some_and(|m| m.extension.clone().bind_tables(&tables));
        if needs && let Some(mut m) = materials.get_mut(id) {
            m.extension.bind_tables(&tables);
        }
    }
}
