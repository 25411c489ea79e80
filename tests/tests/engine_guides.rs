//! Every default the engine guides state matches the code: the values `docs/engines/unity.md`,
//! `docs/engines/unreal.md`, `docs/engines/README.md` and the HLSL wrapper give for the
//! default `soap-film` and `fourier-srgb` tables (against their manifests in
//! `tables/baked/`), and the fourier technique's default harmonic count M = 0 (automatic)
//! wherever a guide or library states it (against `TechniqueOptions::default()` and the
//! libraries' `NACRE_FOURIER_DEFAULT_HARMONICS`, and the three.js package's option default).
//!
//! Each check finds the guide's sentence by a marker and reads the numbers after it, so a
//! guide that changes a stated value, or drops the statement, fails here.

use nacre_format::Manifest;
use nacre_format::set::default_baked_dir;
use nacre_runtime::TechniqueOptions;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The text of `file` right after the first `marker`, `len` bytes at most (on a char boundary).
fn after<'a>(file: &str, text: &'a str, marker: &str, len: usize) -> &'a str {
    let at = text
        .find(marker)
        .unwrap_or_else(|| panic!("{file} no longer states `{marker}`"))
        + marker.len();
    let mut end = (at + len).min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    &text[at..end]
}

/// The numbers in `text`, in order (signs, decimals; `1.5` in `(float3)1.5` too).
fn numbers(text: &str) -> Vec<f64> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for c in text.chars().chain(std::iter::once(' ')) {
        if c.is_ascii_digit() || c == '.' || (c == '-' && cur.is_empty()) {
            cur.push(c);
        } else {
            if let Ok(v) = cur.trim_end_matches('.').parse::<f64>() {
                out.push(v);
            }
            cur.clear();
        }
    }
    out
}

/// The first `n` numbers after `marker` in `file`.
fn stated(file: &str, text: &str, marker: &str, n: usize) -> Vec<f64> {
    let v = numbers(after(file, text, marker, 200));
    assert!(
        v.len() >= n,
        "{file}: fewer than {n} numbers after `{marker}`: {v:?}"
    );
    v[..n].to_vec()
}

fn soap_film() -> [f64; 8] {
    let path = default_baked_dir().join("soap-film.json");
    let m = Manifest::read(&path).unwrap();
    let a = m.film_lut().expect("soap-film is a film-lut");
    [
        a.cos_theta_count as f64,
        a.opd_count as f64,
        a.ior_count as f64,
        a.thickness_min_nm,
        a.thickness_max_nm,
        a.ior_min,
        a.ior_max,
        a.ambient_index,
    ]
}

#[test]
fn unity_guide_states_the_soap_film_axes() {
    let file = "docs/engines/unity.md";
    let text = read(file);
    let a = soap_film();
    // "for the default `soap-film` table they are `cos_theta_count` 32, `opd_count` 640, …"
    let sentence = after(
        file,
        &text,
        "for the default `soap-film` table they are",
        400,
    );
    let names = [
        "cos_theta_count",
        "opd_count",
        "ior_count",
        "thickness_min_nm",
        "thickness_max_nm",
        "ior_min",
        "ior_max",
        "ambient_index",
    ];
    for (name, want) in names.iter().zip(a) {
        let got = stated(file, sentence, &format!("`{name}`"), 1)[0];
        assert_eq!(
            got, want,
            "{file}: soap-film `{name}` stated {got}, the manifest has {want}"
        );
    }
    // The hand-written shader's Properties defaults are the same table's.
    assert_eq!(
        stated(
            file,
            &text,
            "_NacreCounts (\"Texel counts (x, y, z, unused)\", Vector) =",
            3
        ),
        a[..3]
    );
    assert_eq!(
        stated(
            file,
            &text,
            "_NacreRanges (\"Thickness min/max nm, index min/max\", Vector) =",
            4
        ),
        a[3..7]
    );
    assert_eq!(
        stated(file, &text, "_NacreAmbient (\"Ambient index\", Float) =", 1),
        [a[7]]
    );
}

#[test]
fn unreal_guide_states_the_soap_film_axes() {
    let file = "docs/engines/unreal.md";
    let text = read(file);
    let a = soap_film();
    assert_eq!(
        stated(
            file,
            &text,
            "`(cos_theta_count, opd_count, ior_count)` — soap-film:",
            3
        ),
        a[..3]
    );
    assert_eq!(
        stated(
            file,
            &text,
            "`(thickness_min_nm, thickness_max_nm, ior_min, ior_max)` — soap-film:",
            4
        ),
        a[3..7]
    );
    assert_eq!(
        stated(file, &text, "`ambient_index` — soap-film:", 1),
        [a[7]]
    );
    // "32 and 640 for the default `soap-film` table; its `ior_count` is 8"
    let tiles = stated(file, &text, "(from `nacre info soap-film`:", 2);
    assert_eq!(tiles, a[..2]);
    assert_eq!(stated(file, &text, "its `ior_count` is", 1), [a[2]]);
}

#[test]
fn fourier_table_values_and_default_harmonics() {
    let path = default_baked_dir().join("fourier-srgb.json");
    let m = Manifest::read(&path).unwrap();
    let axes = m.fourier().expect("fourier-srgb is a fourier table");
    let unity = "docs/engines/unity.md";
    let text = read(unity);
    assert_eq!(
        stated(unity, &text, "`max_opd_nm`\n   (", 1),
        [axes.max_opd_nm],
        "{unity}: max_opd_nm of fourier-srgb"
    );

    // M = 0 (automatic) is the default of the runtime and of both libraries …
    let default_m = TechniqueOptions::default().harmonics;
    assert_eq!(default_m, 0, "the runtime's default harmonics");
    for lib in ["shaders/hlsl/nacre.hlsl", "shaders/glsl/nacre.glsl"] {
        let src = read(lib);
        let v = stated(lib, &src, "NACRE_FOURIER_DEFAULT_HARMONICS =", 1)[0];
        assert_eq!(
            v,
            f64::from(default_m),
            "{lib}: NACRE_FOURIER_DEFAULT_HARMONICS"
        );
    }
    // … and what every guide, wrapper and package says it is.
    for (file, marker) in [
        (unity, "Harmonics ("),
        (
            "shaders/hlsl/unity/NacreShaderGraph.hlsl",
            "Harmonics = M (",
        ),
        ("docs/engines/README.md", "`harmonics` M ("),
        ("integrations/three/src/material.js", "{ harmonics ="),
        ("integrations/three/src/webgpu.js", "{ harmonics ="),
    ] {
        let text = read(file);
        let v = stated(file, &text, marker, 1)[0];
        assert_eq!(
            v,
            f64::from(default_m),
            "{file}: the default harmonics after `{marker}`"
        );
        let context = after(file, &text, marker, 200);
        assert!(
            context.contains("automatic") || context.contains("0,") || context.contains("0;"),
            "{file}: `{marker}` no longer says what 0 means: {context}"
        );
    }
}
