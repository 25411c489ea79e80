//! `nacre export --layer …`: a multilayer stack prepared for the `film_stack` technique of an
//! engine library (`nacre_film_stack_colour` in `shaders/glsl/nacre.glsl` and
//! `shaders/hlsl/nacre.hlsl`, the Bevy plugin's stack): the JSON of
//! [`nacre_format::export::stack_json`] (nodes, per-node indices, uniform and the stack
//! table's texels) with what it was made from under `about`.

use crate::commands::color_request::{ColourSettings, colorimeter};
use crate::commands::stack_spec::StackSpec;
use crate::error::{Error, Result};
use nacre_format::Param;
use nacre_format::gpu_params::StackGpu;
use nacre_optics::few_wavelengths::StackEvaluation;
use serde_json::json;

/// What `nacre export` prepares a stack from.
#[derive(Clone, Copy, Debug)]
pub struct StackExport<'a> {
    /// The stack (ambient, 1 to 8 films top first, base).
    pub spec: &'a StackSpec,
    /// Each film's relative thickness r_j, nm (empty: 0 for every film).
    pub relative_nm: &'a [f64],
    /// Each film's thickness-map channel, 0 R, 1 G, 2 B (empty: R for every film).
    pub channels: &'a [usize],
    /// `None`: the rule ladder; `Some(N)`: a fixed rule of N nodes.
    pub samples: Option<usize>,
    /// Observer, illuminant and output space.
    pub colour: ColourSettings<'a>,
}

/// The stack JSON of `request` (schema in docs/engines/README.md).
///
/// Errors: a material that does not load or has no data at a node (naming its flag), a film
/// count outside 1 to 8, relative thicknesses or channels other than one per film, a
/// negative relative thickness, a top film off channel R, a rule outside 1 to 256 nodes,
/// unknown colour settings.
pub fn stack_export(request: &StackExport) -> Result<serde_json::Value> {
    let stack = request.spec.build()?;
    let films = stack.layers().len();
    let colorimeter = colorimeter(&request.colour)?;
    let one_per_film = |param: Param, given: usize| {
        Error::value(
            param,
            format!("{given} values"),
            format!("give one per film ({films}), top first, or none"),
        )
    };
    if !request.relative_nm.is_empty() && request.relative_nm.len() != films {
        return Err(one_per_film(Param::Relative, request.relative_nm.len()));
    }
    if !request.channels.is_empty() && request.channels.len() != films {
        return Err(one_per_film(Param::LayerChannel, request.channels.len()));
    }
    let relative = if request.relative_nm.is_empty() {
        vec![0.0; films]
    } else {
        request.relative_nm.to_vec()
    };
    let named = |param: Param| move |e| Error::optics_in(param, e);
    let mut eval = StackEvaluation::new(&colorimeter, &stack, &relative, request.samples)
        .map_err(|e| request.spec.attribute(&stack, e.into()))
        .map_err(|e| match e {
            Error::Optics(source @ nacre_optics::Error::OutOfRange { what, .. }) => {
                let param = if what.contains("relative") {
                    Param::Relative
                } else if what.contains("wavelengths") {
                    Param::Wavelengths
                } else {
                    Param::Layer
                };
                named(param)(source)
            }
            other => other,
        })?;
    if !request.channels.is_empty() {
        eval = eval
            .with_channels(request.channels)
            .map_err(named(Param::LayerChannel))?;
    }
    if let Some(j) = eval.slab() {
        return Err(Error::value(
            Param::Layer,
            format!("layer {j}"),
            "it is incoherent, and the engine libraries' stack technique sums coherent amplitudes only: export the stack without the slab".to_string(),
        ));
    }
    let gpu = StackGpu::new(&eval);
    let about = json!({
        "ambient": stack.ambient().name(),
        "films": stack.layers().iter().enumerate().map(|(j, l)| json!({
            "material": l.material.name(),
            "thickness_nm": l.thickness_nm,
            "relative_nm": relative[j],
            "channel": channel_name(eval.channels()[j]),
        })).collect::<Vec<_>>(),
        "base": stack.substrate().name(),
        "observer": request.colour.observer.unwrap_or("1931"),
        "illuminant": request.colour.illuminant.unwrap_or("d65"),
        "space": request.colour.space.unwrap_or("srgb"),
        "rule": match request.samples {
            Some(n) => json!(n),
            None => json!("ladder"),
        },
    });
    Ok(nacre_format::export::stack_json(&gpu, about))
}

/// A thickness-map channel's name as `--layer-channel` spells it.
fn channel_name(channel: usize) -> &'static str {
    ["r", "g", "b"][channel.min(2)]
}
