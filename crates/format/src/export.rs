//! Raw 3-D textures for game engines (`nacre export`): one quantity of a `film-lut` or
//! `rough-film-lut` table as the bytes a 3-D texture upload takes, and a JSON sidecar that
//! says how to read them and how to sample them.
//!
//! Layout of the `.raw` file (docs/engines/ show the upload per engine):
//!
//! * texel format RGBA, four IEEE 754 binary16 ("half") values per texel, little-endian,
//!   8 bytes per texel; R, G, B the table's colour (rounded to nearest half), A = 1;
//! * texel order x fastest, then y, then z: byte offset of texel (x, y, z) =
//!   8 · ((z · height + y) · width + x) — slice z is the table's z-th slice, its first row
//!   is y = 0. This is the order of OpenGL/WebGL `texImage3D` (three.js `Data3DTexture`),
//!   Unity `Texture3D.SetPixelData` and a D3D/Vulkan 3-D upload with tightly packed rows;
//! * axes: film-lut x = cos θ, y = Δ, z = film index n; rough-film-lut x = cos θ_o, y = Δ,
//!   z = i_α · count(n_f) + i_n (α-major blocks). Texel i of an axis of `count` texels holds
//!   t = i / (count − 1) and is sampled at u = (t (count − 1) + 0.5) / count (texel
//!   centres), with linear filtering and clamp-to-edge addressing, as the WGSL, GLSL and
//!   HLSL lookups do.
//!
//! The sidecar (`.json` beside the `.raw`) holds `width`, `height`, `depth`, `format`
//! (`"rgba16f-le"`), `texel_order`, the table's kind, name, quantity and axes record as the
//! manifest stores them, the mappings as text, and `shader_params`: the fields of the
//! libraries' parameter struct (`NacreFilmLutParams` / `NacreRoughLutParams`), from the one
//! field list of [`crate::gpu_params`].
//!
//! A multilayer stack (`film_stack`) reads no table but its own prepared numbers:
//! [`stack_json`] lays out a [`StackGpu`] as the JSON an engine uploads (`nacre export
//! --layer …`; schema `nacre-film-stack` version [`STACK_JSON_VERSION`], documented in
//! docs/engines/README.md) and [`read_stack_json`] reads it back.

use crate::TableKind;
use crate::atomic::write_files_atomic;
use crate::error::{Error, Result};
use crate::gpu_params::{
    FilmLutParams, RoughLutParams, STACK_MAX_FILMS, STACK_MAX_RULES, STACK_TEXTURE_WIDTH, StackGpu,
    StackNode, StackParams,
};
use crate::load::LoadedRoughLut;
use crate::manifest::Manifest;
use crate::table_io::Table3;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Bytes per texel of the raw layout (RGBA × binary16).
pub const BYTES_PER_TEXEL: usize = 8;

/// One quantity of a table as a raw RGBA16F 3-D texture and its sidecar.
#[derive(Clone, Debug, PartialEq)]
pub struct RawTexture3d {
    /// Texels along x.
    pub width: usize,
    /// Texels along y.
    pub height: usize,
    /// Texels along z (slices).
    pub depth: usize,
    /// `width · height · depth · 8` bytes in the [module](self)'s layout.
    pub bytes: Vec<u8>,
    /// The JSON sidecar.
    pub sidecar: serde_json::Value,
}

/// The raw bytes of `table`: RGBA binary16 little-endian, x fastest, A = 1.
pub fn rgba16f_bytes(table: &Table3) -> Vec<u8> {
    let one = half::f16::from_f32(1.0).to_le_bytes();
    let mut bytes = Vec::with_capacity(table.data.len() / 3 * BYTES_PER_TEXEL);
    for rgb in table.data.chunks_exact(3) {
        for &v in rgb {
            bytes.extend_from_slice(&half::f16::from_f32(v).to_le_bytes());
        }
        bytes.extend_from_slice(&one);
    }
    bytes
}

/// Reads `quantity` (`reflectance` or `transmittance`) of the `film-lut` or `rough-film-lut`
/// table whose manifest is `manifest_path` and lays it out as a raw 3-D texture.
///
/// Errors: an unreadable manifest or table file (naming it), another kind of table or a
/// quantity the table lacks ([`Error::Invalid`] with context `--table` or `--quantity`).
pub fn export_raw(manifest_path: &Path, quantity: &str) -> Result<RawTexture3d> {
    let manifest = Manifest::read(manifest_path)?;
    if !matches!(quantity, "reflectance" | "transmittance") {
        return Err(Error::Invalid {
            context: crate::param::Param::Quantity.into(),
            message: format!("`{quantity}`: expected `reflectance` or `transmittance`").into(),
        });
    }
    let missing = || Error::Invalid {
        context: crate::param::Param::Quantity.into(),
        message: format!(
            "table `{}` ({}) has no {quantity}",
            manifest.name,
            manifest_path.display()
        )
        .into(),
    };
    let texel_centres = "texel i of an axis of count texels holds t = i/(count − 1), \
                         sampled at u = (t (count − 1) + 0.5)/count; linear filtering, clamp to edge";
    let (table, axes, mapping, params) = match manifest.kind {
        TableKind::FILM_LUT => {
            let axes = manifest
                .film_lut()
                .cloned()
                .ok_or_else(|| manifest.wrong_kind(manifest_path, "a film-lut"))?;
            let table = manifest
                .load_table(manifest_path, quantity)?
                .ok_or_else(missing)?;
            let has_t = manifest
                .load_table(manifest_path, "transmittance")?
                .is_some();
            let params = FilmLutParams::shader_params(&axes, has_t);
            let mapping = json!({
                "x": "t_x = sqrt(cos θ)",
                "y": "t_y = Δ/Δ_max, Δ = 2 d sqrt(n² − n₀² sin²θ), Δ_max = 2 thickness_max_nm ior_max",
                "z": "t_z = sqrt((q(n) − q(ior_min))/(q(ior_max) − q(ior_min))), q(n) = sqrt(n² − n₀² sin²θ)",
                "texel_centres": texel_centres,
            });
            (table, serde_json::to_value(&axes), mapping, params)
        }
        TableKind::ROUGH_FILM_LUT => {
            let loaded = LoadedRoughLut::load(manifest_path)?;
            let axes = loaded.lut.axes.clone();
            let has_t = loaded.lut.transmittance.is_some();
            let table = match quantity {
                "reflectance" => loaded.lut.reflectance,
                _ => loaded.lut.transmittance.ok_or_else(missing)?,
            };
            let params = RoughLutParams::shader_params(&axes, has_t);
            let mapping = json!({
                "x": "t_x = sqrt(cos θ_o)",
                "y": "t_y = Δ/Δ_max, Δ = 2 d q(n_f, c_ref), c_ref = cos θ_o + (2α − α²)(0.7 − 0.8 cos θ_o), per α block",
                "z": "slice = i_α · ior_count + i_n; t_n = sqrt((n_f − ior_min)/(ior_max − ior_min)), t_α = ln(α/alpha_min)/ln(alpha_max/alpha_min)",
                "texel_centres": texel_centres,
            });
            (table, serde_json::to_value(&axes), mapping, params)
        }
        other => {
            return Err(Error::Invalid {
                context: crate::param::Param::Table.into(),
                message: format!(
                    "table `{}` ({}) is a `{other}` table; export writes 3-D textures of \
                     `film-lut` and `rough-film-lut` tables",
                    manifest.name,
                    manifest_path.display()
                )
                .into(),
            });
        }
    };
    let axes = axes.map_err(|e| Error::Invalid {
        context: manifest_path.display().to_string().into(),
        message: format!("axes do not serialise: {e}").into(),
    })?;
    let sidecar = json!({
        "format": "rgba16f-le",
        "bytes_per_texel": BYTES_PER_TEXEL,
        "width": table.nx,
        "height": table.ny,
        "depth": table.nz,
        "texel_order": "x fastest, then y, then z: byte offset 8·((z·height + y)·width + x); RGBA binary16 little-endian, A = 1",
        "table": manifest.name,
        "kind": manifest.kind.to_string(),
        "quantity": quantity,
        "axes": axes,
        "mapping": mapping,
        "shader_params": params,
    });
    Ok(RawTexture3d {
        width: table.nx,
        height: table.ny,
        depth: table.nz,
        bytes: rgba16f_bytes(&table),
        sidecar,
    })
}

/// The sidecar path of a raw file: the same path with extension `json`.
pub fn sidecar_path(raw_path: &Path) -> PathBuf {
    raw_path.with_extension("json")
}

/// Writes `texture` to `raw_path` and its sidecar beside it ([`sidecar_path`]) as one atomic
/// unit. Errors: a `raw_path` without a file name or ending in `.json` (it would be its own
/// sidecar; the `out` parameter), or the write itself.
pub fn write_raw(raw_path: &Path, texture: &RawTexture3d) -> Result<PathBuf> {
    let invalid = |message: &str| Error::Invalid {
        context: crate::param::Param::Out.into(),
        message: format!("{}: {message}", raw_path.display()).into(),
    };
    let name = raw_path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| invalid("needs a file name (UTF-8)"))?;
    if raw_path.extension().is_some_and(|e| e == "json") {
        return Err(invalid(
            "ends in .json, the sidecar's extension (use e.g. .raw)",
        ));
    }
    let sidecar = sidecar_path(raw_path);
    let sidecar_name = sidecar
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| invalid("needs a file name (UTF-8)"))?
        .to_string();
    let dir = match raw_path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut json = serde_json::to_vec_pretty(&texture.sidecar).expect("JSON values serialise");
    json.push(b'\n');
    write_files_atomic(
        dir,
        &[
            (name.to_string(), texture.bytes.clone()),
            (sidecar_name, json),
        ],
    )?;
    Ok(sidecar)
}

/// Version of the stack JSON's schema (`"format": "nacre-film-stack"`).
pub const STACK_JSON_VERSION: u32 = 1;

/// The stack JSON of `gpu` (schema in docs/engines/README.md): `format`, `version`,
/// `technique`, `about` (what the caller says the numbers are: the stack, the colour
/// settings), `media`, `node_count`, `shader_params` (the fields of `StackParams` /
/// `NacreStackParams`, arrays in full), `nodes` (`wavelength_nm`, `weight` rgb), `indices`
/// ((n, κ) per node and medium, node-major) and `texture` (the engine libraries' RGBA32F
/// stack table: `width`, `height`, `format`, `texel_order`, `data` row-major, 4 floats a
/// texel). Every number is the f32 the GPU reads, printed so that it parses back exactly.
pub fn stack_json(gpu: &StackGpu, about: serde_json::Value) -> serde_json::Value {
    let p = &gpu.params;
    let texels = gpu.texels();
    json!({
        "format": "nacre-film-stack",
        "version": STACK_JSON_VERSION,
        "technique": "film_stack",
        "about": about,
        "media": gpu.media(),
        "node_count": gpu.nodes.len(),
        "shader_params": {
            "films": p.films,
            "dispersive": p.dispersive,
            "rule_count": p.rule_count,
            "fixed_rule": p.fixed_rule,
            "base_count": p.base_count,
            "count_per_opd_nm": p.count_per_opd_nm,
            "finesse": p.finesse,
            "rule_offset": p.rule_offset,
            "rule_size": p.rule_size,
            "layers": p.layers,
        },
        "nodes": gpu.nodes.iter().map(|n| json!({
            "wavelength_nm": n.wavelength_nm,
            "weight": [n.weight[0], n.weight[1], n.weight[2]],
        })).collect::<Vec<_>>(),
        "indices": gpu.indices,
        "texture": {
            "width": STACK_TEXTURE_WIDTH,
            "height": gpu.nodes.len(),
            "format": "rgba32f",
            "texel_order": "row k = node k, x fastest: texel (0, k) = (wavelength_nm, weight r, g, b); texel (1 + i, k) = (n, κ) of medium 2i, (n, κ) of medium 2i + 1; medium 0 ambient, 1 … films top first, films + 1 base",
            "data": texels.iter().flatten().copied().collect::<Vec<f32>>(),
        },
    })
}

/// Reads a stack JSON written by [`stack_json`] back into the GPU's numbers (`nodes`,
/// `indices` and `shader_params`; `texture` is derived from them and not read).
///
/// Errors ([`Error::Invalid`] naming `origin`, e.g. the file): another format or version, a
/// missing or mistyped field, a film count outside 1 to 8, rules outside the nodes, or an
/// index count other than nodes × media.
pub fn read_stack_json(value: &serde_json::Value, origin: &str) -> Result<StackGpu> {
    let bad = |message: String| Error::Invalid {
        context: origin.to_string().into(),
        message: message.into(),
    };
    if value["format"] != "nacre-film-stack" {
        return Err(bad(format!(
            "`format` is {}, expected \"nacre-film-stack\" (written by nacre export --layer …)",
            value["format"]
        )));
    }
    if value["version"] != STACK_JSON_VERSION {
        return Err(bad(format!(
            "`version` is {}, this nacre reads version {STACK_JSON_VERSION}",
            value["version"]
        )));
    }
    let field = |path: &str| -> Result<&serde_json::Value> {
        let mut v = value;
        for key in path.split('.') {
            v = v.get(key).ok_or_else(|| bad(format!("no `{path}`")))?;
        }
        Ok(v)
    };
    let float = |v: &serde_json::Value, what: &str| -> Result<f32> {
        v.as_f64()
            .map(|x| x as f32)
            .ok_or_else(|| bad(format!("`{what}` is {v}, expected a number")))
    };
    let uint = |path: &str| -> Result<u32> {
        let v = field(path)?;
        v.as_u64()
            .and_then(|x| u32::try_from(x).ok())
            .ok_or_else(|| bad(format!("`{path}` is {v}, expected an unsigned integer")))
    };
    let array = |path: &str| -> Result<&Vec<serde_json::Value>> {
        let v = field(path)?;
        v.as_array()
            .ok_or_else(|| bad(format!("`{path}` is not an array")))
    };
    let mut params = StackParams {
        films: uint("shader_params.films")?,
        dispersive: uint("shader_params.dispersive")?,
        rule_count: uint("shader_params.rule_count")?,
        fixed_rule: uint("shader_params.fixed_rule")?,
        base_count: float(
            field("shader_params.base_count")?,
            "shader_params.base_count",
        )?,
        count_per_opd_nm: float(
            field("shader_params.count_per_opd_nm")?,
            "shader_params.count_per_opd_nm",
        )?,
        finesse: float(field("shader_params.finesse")?, "shader_params.finesse")?,
        ..StackParams::default()
    };
    if !(1..=STACK_MAX_FILMS as u32).contains(&params.films) {
        return Err(bad(format!(
            "`shader_params.films` is {}, expected 1 to {STACK_MAX_FILMS}",
            params.films
        )));
    }
    if !(1..=STACK_MAX_RULES as u32).contains(&params.rule_count) {
        return Err(bad(format!(
            "`shader_params.rule_count` is {}, expected 1 to {STACK_MAX_RULES}",
            params.rule_count
        )));
    }
    for (key, out) in [
        ("shader_params.rule_offset", &mut params.rule_offset),
        ("shader_params.rule_size", &mut params.rule_size),
    ] {
        let values = array(key)?;
        if values.len() != STACK_MAX_RULES {
            return Err(bad(format!(
                "`{key}` holds {} values, expected {STACK_MAX_RULES}",
                values.len()
            )));
        }
        for (o, v) in out.iter_mut().zip(values) {
            *o = v
                .as_u64()
                .and_then(|x| u32::try_from(x).ok())
                .ok_or_else(|| bad(format!("`{key}` holds {v}, expected unsigned integers")))?;
        }
    }
    let layers = array("shader_params.layers")?;
    if layers.len() != STACK_MAX_FILMS {
        return Err(bad(format!(
            "`shader_params.layers` holds {} films, expected {STACK_MAX_FILMS}",
            layers.len()
        )));
    }
    for (j, layer) in layers.iter().enumerate() {
        let values = layer.as_array().filter(|a| a.len() == 4).ok_or_else(|| {
            bad(format!(
                "`shader_params.layers[{j}]` is {layer}, expected 4 numbers"
            ))
        })?;
        for (c, v) in values.iter().enumerate() {
            params.layers[j][c] = float(v, &format!("shader_params.layers[{j}][{c}]"))?;
        }
    }
    let nodes = array("nodes")?
        .iter()
        .enumerate()
        .map(|(k, n)| -> Result<StackNode> {
            let weight = n["weight"]
                .as_array()
                .filter(|a| a.len() == 3)
                .ok_or_else(|| bad(format!("`nodes[{k}].weight` is not 3 numbers")))?;
            let w = |c: usize| float(&weight[c], &format!("nodes[{k}].weight[{c}]"));
            Ok(StackNode {
                wavelength_nm: float(&n["wavelength_nm"], &format!("nodes[{k}].wavelength_nm"))?,
                _pad: [0.0; 3],
                weight: [w(0)?, w(1)?, w(2)?, 0.0],
            })
        })
        .collect::<Result<Vec<_>>>()?;
    for i in 0..params.rule_count as usize {
        let end = u64::from(params.rule_offset[i]) + u64::from(params.rule_size[i]);
        if params.rule_size[i] == 0 || end > nodes.len() as u64 {
            return Err(bad(format!(
                "rule {i} (nodes {} + {}) lies outside the {} nodes",
                params.rule_offset[i],
                params.rule_size[i],
                nodes.len()
            )));
        }
    }
    let indices = array("indices")?
        .iter()
        .enumerate()
        .map(|(i, n)| -> Result<[f32; 2]> {
            let pair = n
                .as_array()
                .filter(|a| a.len() == 2)
                .ok_or_else(|| bad(format!("`indices[{i}]` is {n}, expected [n, κ]")))?;
            Ok([
                float(&pair[0], &format!("indices[{i}][0]"))?,
                float(&pair[1], &format!("indices[{i}][1]"))?,
            ])
        })
        .collect::<Result<Vec<_>>>()?;
    let media = params.films as usize + 2;
    if indices.len() != nodes.len() * media {
        return Err(bad(format!(
            "`indices` holds {} values, expected nodes × media = {} × {media}",
            indices.len(),
            nodes.len()
        )));
    }
    Ok(StackGpu {
        nodes,
        indices,
        params,
    })
}

/// Writes `value` as pretty JSON to `path` atomically (no partial file on failure).
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    let mut json = serde_json::to_vec_pretty(value).expect("JSON values serialise");
    json.push(b'\n');
    crate::atomic::write_atomic(path, |w| w.write_all(&json))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::set::default_baked_dir;

    fn texel(bytes: &[u8], t: &RawTexture3d, x: usize, y: usize, z: usize) -> [f32; 4] {
        let o = BYTES_PER_TEXEL * ((z * t.height + y) * t.width + x);
        let h =
            |i: usize| half::f16::from_le_bytes([bytes[o + 2 * i], bytes[o + 2 * i + 1]]).to_f32();
        [h(0), h(1), h(2), h(3)]
    }

    #[test]
    fn film_lut_round_trips_through_the_raw_layout() {
        let path = default_baked_dir().join("soap-film.json");
        let m = Manifest::read(&path).unwrap();
        for quantity in ["reflectance", "transmittance"] {
            let table = m.load_table(&path, quantity).unwrap().unwrap();
            let raw = export_raw(&path, quantity).unwrap();
            assert_eq!(
                (raw.width, raw.height, raw.depth),
                (table.nx, table.ny, table.nz)
            );
            assert_eq!(
                raw.bytes.len(),
                table.nx * table.ny * table.nz * BYTES_PER_TEXEL
            );
            for (x, y, z) in [
                (0, 0, 0),
                (table.nx - 1, 3, 1),
                (5, table.ny - 1, table.nz - 1),
            ] {
                let got = texel(&raw.bytes, &raw, x, y, z);
                let want = table.texel(x, y, z);
                for c in 0..3 {
                    assert_eq!(
                        got[c],
                        half::f16::from_f32(want[c]).to_f32(),
                        "{quantity} ({x}, {y}, {z})"
                    );
                }
                assert_eq!(got[3], 1.0);
            }
            assert_eq!(raw.sidecar["width"], table.nx);
            assert_eq!(raw.sidecar["shader_params"]["has_transmittance"], 1);
        }
    }

    #[test]
    fn wrong_kinds_quantities_and_outputs_are_errors() {
        let dir = default_baked_dir();
        let e = export_raw(&dir.join("fourier-srgb.json"), "reflectance").unwrap_err();
        // Library messages name the parameter; the CLI renders it as its flag.
        assert!(e.to_string().starts_with("table: "), "{e}");
        let e = export_raw(&dir.join("film-gold.json"), "transmittance").unwrap_err();
        assert!(e.to_string().starts_with("quantity: "), "{e}");
        let e = export_raw(&dir.join("soap-film.json"), "albedo").unwrap_err();
        assert!(e.to_string().starts_with("quantity: "), "{e}");
        let e = export_raw(&dir.join("no-such-table.json"), "reflectance").unwrap_err();
        assert!(e.to_string().contains("no-such-table.json"), "{e}");
        let raw = export_raw(&dir.join("soap-film.json"), "reflectance").unwrap();
        let e = write_raw(Path::new("out.json"), &raw).unwrap_err();
        assert!(e.to_string().starts_with("out: "), "{e}");
    }

    #[test]
    fn a_stack_round_trips_through_its_json() {
        use nacre_optics::colour::Colorimeter;
        use nacre_optics::few_wavelengths::StackEvaluation;
        use nacre_optics::{C64, Layer, Material, Stack};
        let constant = |n: f64, k: f64| Material::constant("m", C64::new(n, k)).unwrap();
        let stack = Stack::new(
            constant(1.0, 0.0),
            vec![
                Layer {
                    material: constant(1.38, 0.0),
                    thickness_nm: 100.0,
                },
                Layer {
                    material: constant(0.2, 3.0),
                    thickness_nm: 12.0,
                },
            ],
            constant(1.5, 0.0),
        )
        .unwrap();
        let colorimeter = Colorimeter::new(
            "1931".parse().unwrap(),
            "d65".parse().unwrap(),
            "srgb".parse().unwrap(),
        );
        let eval = StackEvaluation::new(&colorimeter, &stack, &[0.0, 4.0], None)
            .unwrap()
            .with_channels(&[0, 2])
            .unwrap();
        let gpu = StackGpu::new(&eval);
        let value = stack_json(&gpu, json!({"note": "test"}));
        // Through text, as an engine reads it.
        let text = serde_json::to_string(&value).unwrap();
        let back = read_stack_json(&serde_json::from_str(&text).unwrap(), "test").unwrap();
        assert_eq!(back, gpu);
        assert_eq!(
            gpu.params.layers[1],
            [12.0, 4.0, gpu.params.layers[1][2], 2.0]
        );
        let texels = gpu.texels();
        assert_eq!(
            value["texture"]["data"].as_array().unwrap().len(),
            4 * texels.len()
        );
        // Node 3, medium 2 (the metal film) is texel (1 + 2/2, 3) = (2, 3), components x, y.
        let media = gpu.media();
        assert_eq!(
            texels[3 * STACK_TEXTURE_WIDTH + 2][0],
            gpu.indices[3 * media + 2][0]
        );
        assert_eq!(texels[3 * STACK_TEXTURE_WIDTH + 2][1], 3.0);
        assert_eq!(
            texels[3 * STACK_TEXTURE_WIDTH][0],
            gpu.nodes[3].wavelength_nm
        );
        // Tampered copies are errors naming the field.
        let mut broken = value.clone();
        broken["shader_params"]["films"] = json!(9);
        let e = read_stack_json(&broken, "x.json").unwrap_err();
        assert!(e.to_string().contains("shader_params.films"), "{e}");
        let mut broken = value.clone();
        broken["indices"].as_array_mut().unwrap().pop();
        let e = read_stack_json(&broken, "x.json").unwrap_err();
        assert!(e.to_string().contains("nodes × media"), "{e}");
        let mut broken = value;
        broken["format"] = json!("rgba16f-le");
        assert!(read_stack_json(&broken, "x.json").is_err());
    }
}
