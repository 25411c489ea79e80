//! The bad-input matrix (issue 9): malformed recipes, material files, manifests, table files
//! (EXR, KTX2, PNG), glTF files and flag values, each fed to the `nacre` command that reads
//! it. Every case must exit with status 2 and one message on stderr that names the file
//! (and line) or flag and what was expected, must not panic, must print nothing on stdout,
//! and must leave the working folder byte-for-byte as it was — pre-existing outputs
//! (`out.csv`, `out.png`, the folder `out/`) included.
//!
//! Cases already covered by `cli.rs`, `plot.rs` and `material_db.rs` are not repeated here.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One malformed input: the command line (run in the fixture folder) and the fragments the
/// error message must contain.
struct Case {
    name: &'static str,
    args: Vec<String>,
    needles: Vec<&'static str>,
    /// Environment variables set for the run.
    env: Vec<(&'static str, &'static str)>,
    /// The exit status: 2, or 3 where no usable GPU is found.
    status: i32,
}

fn case(name: &'static str, args: &[&str], needles: &[&'static str]) -> Case {
    Case {
        name,
        args: args.iter().map(|a| a.to_string()).collect(),
        needles: needles.to_vec(),
        env: Vec::new(),
        status: 2,
    }
}

/// A case run with environment variables `env`.
fn case_env(
    name: &'static str,
    env: &[(&'static str, &'static str)],
    args: &[&str],
    needles: &[&'static str],
) -> Case {
    Case {
        env: env.to_vec(),
        ..case(name, args, needles)
    }
}

/// A case where no usable GPU is found: exit status 3.
fn no_gpu(
    name: &'static str,
    env: &[(&'static str, &'static str)],
    args: &[&str],
    needles: &[&'static str],
) -> Case {
    Case {
        status: 3,
        ..case_env(name, env, args, needles)
    }
}

/// A small valid film-lut recipe; line numbers: 1 kind, 2 [stack], 3 ambient, 4 base,
/// 5 [axes], 6 cos_theta_count, 7 thickness_nm, 8 opd_count, 9 film_ior, 10 film_ior_count.
const RECIPE: &str = "kind = \"film-lut\"
[stack]
ambient = \"1.0\"
base = \"1.5\"
[axes]
cos_theta_count = 4
thickness_nm = [0.0, 400.0]
opd_count = 8
film_ior = [1.2, 1.6]
film_ior_count = 2
";

/// A small valid fourier recipe; line 3 samples, 4 max_opd_nm, 5 levels.
const FOURIER: &str = "kind = \"fourier\"
[fourier]
samples = 64
max_opd_nm = 2000.0
levels = 2
";

/// A small valid `diffraction` recipe of layout "integrated"; line 3 synthetic,
/// 8 integrated_samples, 9 integrated_tolerance.
const INTEGRATED: &str = "kind = \"diffraction\"
[height_field]
synthetic = \"sine:1.6:0.05\"
[diffraction]
layout = \"integrated\"
coherence_diameter_um = 16.0
wavelengths = \"380:780:20\"
integrated_samples = 32
integrated_tolerance = 0.01
";

/// A refractiveindex.info file with a tabulated n,k section; data rows on lines 4–6.
const YAML: &str = "DATA:
  - type: tabulated nk
    data: |
        0.40 1.50 0.0
        0.50 1.49 0.0
        0.60 1.48 0.0
";

fn write(path: &Path, bytes: impl AsRef<[u8]>) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// `RECIPE` (or `FOURIER`) with `from` replaced by `to` (which must occur).
fn edited(base: &str, from: &str, to: &str) -> String {
    assert!(base.contains(from), "{from}");
    base.replacen(from, to, 1)
}

/// Every file under `dir` with its bytes (folders as empty entries).
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                out.insert(p.clone(), None);
                stack.push(p);
            } else {
                out.insert(p.clone(), Some(std::fs::read(&p).unwrap()));
            }
        }
    }
    out
}

fn nacre(dir: &Path, args: &[String]) -> std::process::Output {
    nacre_env(dir, args, &[])
}

fn nacre_env(dir: &Path, args: &[String], env: &[(&str, &str)]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .env_remove("NACRE_MATERIAL_DB")
        .output()
        .expect("run nacre")
}

/// Edits a manifest's JSON with `f` and writes it as `dir/name`.
fn manifest_variant(src: &Path, dir: &Path, name: &str, f: impl FnOnce(&mut serde_json::Value)) {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    f(&mut v);
    write(&dir.join(name), serde_json::to_string_pretty(&v).unwrap());
}

/// Copies every file of the baked table folder `from` into `to`.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
        }
    }
}

/// The SHA-256 of a file as manifests record it: damaged table files below get manifests
/// that match them, so that their decoders (not the checksum) must refuse them.
fn sha(path: &Path) -> String {
    nacre_format::table_io::sha256_hex(path).unwrap()
}

/// Keeps only the `files` entries of the manifest whose format is `format`.
fn only_format(v: &mut serde_json::Value, format: &str) {
    v["files"]
        .as_array_mut()
        .unwrap()
        .retain(|f| f["format"] == format);
}

/// A minimal glTF 2.0 JSON file with one triangle whose buffer is `buffer_uri` of
/// `byte_length` bytes; `extra` is spliced into the root object.
fn gltf(buffer_uri: &str, byte_length: usize, count: usize, extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"buffers":[{{"uri":"{buffer_uri}","byteLength":{byte_length}}}]{extra}}}"#
    )
}

/// The 36 bytes of one triangle's positions.
fn triangle() -> Vec<u8> {
    [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// Builds the fixtures in `d` and returns the cases.
fn fixtures(d: &Path) -> Vec<Case> {
    // Pre-existing outputs that every case must leave alone.
    write(&d.join("out.csv"), "existing csv\n");
    write(&d.join("out.png"), "existing png\n");
    write(&d.join("out/keep.txt"), "existing folder\n");

    // A tiny valid film-lut and fourier table, baked by nacre itself, as the source of the
    // manifest and table-file variants.
    write(
        &d.join("src/tiny.toml"),
        format!("description = \"tiny\"\n{RECIPE}"),
    );
    write(&d.join("src/tinyf.toml"), FOURIER);
    // A table wider than any device's 3-D texture limit (20 000 texels along cos θ).
    write(
        &d.join("src/wide.toml"),
        RECIPE
            .replace("cos_theta_count = 4", "cos_theta_count = 20000")
            .replace("opd_count = 8", "opd_count = 2")
            .replace("film_ior = [1.2, 1.6]", "film_ior = [1.5, 1.5]")
            .replace("film_ior_count = 2", "film_ior_count = 1"),
    );
    let o = nacre(
        d,
        &[
            "bake".into(),
            "src/tiny.toml".into(),
            "src/tinyf.toml".into(),
            "src/wide.toml".into(),
            "--out".into(),
            "good".into(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let good = d.join("good");
    let tiny = good.join("tiny.json");

    // Recipes (`nacre bake r/NAME.toml --out out`).
    let recipes: &[(&str, String)] = &[
        ("syntax", edited(RECIPE, "[axes]", "[axes")),
        (
            "no-axes",
            RECIPE.split("[axes]").next().unwrap().to_string(),
        ),
        (
            "negative-count",
            edited(RECIPE, "cos_theta_count = 4", "cos_theta_count = -4"),
        ),
        (
            "one-texel",
            edited(RECIPE, "opd_count = 8", "opd_count = 1"),
        ),
        (
            "absurd-counts",
            edited(
                &edited(
                    RECIPE,
                    "cos_theta_count = 4",
                    "cos_theta_count = 4294967296",
                ),
                "opd_count = 8",
                "opd_count = 4294967296",
            ),
        ),
        (
            "overflowing-counts",
            edited(
                &edited(
                    RECIPE,
                    "cos_theta_count = 4",
                    "cos_theta_count = 18446744073709551615",
                ),
                "opd_count = 8",
                "opd_count = 18446744073709551615",
            ),
        ),
        (
            "inverted-thickness",
            edited(RECIPE, "[0.0, 400.0]", "[400.0, 100.0]"),
        ),
        (
            "nan-thickness",
            edited(RECIPE, "[0.0, 400.0]", "[0.0, nan]"),
        ),
        (
            "inf-thickness",
            edited(RECIPE, "[0.0, 400.0]", "[0.0, inf]"),
        ),
        ("one-thickness", edited(RECIPE, "[0.0, 400.0]", "[400.0]")),
        (
            "ior-below-ambient",
            edited(RECIPE, "[1.2, 1.6]", "[0.5, 1.6]"),
        ),
        (
            "unknown-key",
            edited(RECIPE, "opd_count = 8", "opd_count = 8\nopd_cuont = 9"),
        ),
        (
            "bad-observer",
            format!("{RECIPE}[colour]\nobserver = \"1900\"\n"),
        ),
        (
            "bad-precision",
            format!("{RECIPE}[output]\nprecision = \"double\"\n"),
        ),
        (
            "bad-transmittance",
            format!("{RECIPE}[output]\ntransmittance = \"maybe\"\n"),
        ),
        (
            "negative-under",
            edited(
                RECIPE,
                "base = \"1.5\"",
                "base = \"1.5\"\nunder = [ { material = \"water\", thickness_nm = -5.0 } ]",
            ),
        ),
        (
            "missing-material",
            edited(RECIPE, "base = \"1.5\"", "base = \"nosuch.yml\""),
        ),
        (
            "bad-yaml-material",
            edited(RECIPE, "base = \"1.5\"", "base = \"nan.yml\""),
        ),
        ("no-kind", RECIPE.replacen("kind = \"film-lut\"\n", "", 1)),
        (
            "fourier-few-samples",
            edited(FOURIER, "samples = 64", "samples = 10"),
        ),
        (
            "fourier-huge-samples",
            edited(FOURIER, "samples = 64", "samples = 1000000000000"),
        ),
        (
            "fourier-no-levels",
            edited(FOURIER, "levels = 2", "levels = 0"),
        ),
        (
            "fourier-many-levels",
            edited(FOURIER, "levels = 2", "levels = 40"),
        ),
        // Found by the `recipe` fuzz target: a shift by 69 bits overflowed.
        (
            "fourier-70-levels",
            edited(FOURIER, "levels = 2", "levels = 70"),
        ),
        ("fourier-negative-opd", edited(FOURIER, "2000.0", "-1.0")),
        ("fourier-nan-opd", edited(FOURIER, "2000.0", "nan")),
        (
            "integrated-zero-tolerance",
            edited(
                INTEGRATED,
                "integrated_tolerance = 0.01",
                "integrated_tolerance = 0.0",
            ),
        ),
        (
            "integrated-absurd-samples",
            edited(
                INTEGRATED,
                "integrated_samples = 32",
                "integrated_samples = 1000000000",
            ),
        ),
        (
            "integrated-too-large",
            edited(
                INTEGRATED,
                "integrated_samples = 32",
                "integrated_samples = 4096\ntaylor_tolerance = 1e-12",
            ),
        ),
        (
            "integrated-keys-on-terms",
            edited(INTEGRATED, "layout = \"integrated\"", "layout = \"terms\""),
        ),
        (
            "integrated-tall",
            edited(INTEGRATED, "sine:1.6:0.05", "blazed:2.5:1.0"),
        ),
    ];
    for (name, text) in recipes {
        write(&d.join(format!("r/{name}.toml")), text);
    }
    write(
        &d.join("r/stack-incoherent-substrate.toml"),
        "substrate = \"bk7:incoherent\"\n[[layers]]\nmaterial = \"mgf2\"\nthickness_nm = 100\n",
    );
    write(
        &d.join("r/stack-metre.toml"),
        "substrate = \"1.0\"\n[[layers]]\nmaterial = \"bk7\"\nthickness_nm = 1e9\nincoherent = true\n",
    );
    write(&d.join("r/bad name.toml"), RECIPE);
    write(
        &d.join("r/binary.toml"),
        b"kind = \"film-lut\"\n\xff\xfe\x00junk\n",
    );
    std::fs::create_dir_all(d.join("r/folder.toml")).unwrap();

    // Material files (read by `nacre spectrum --substrate FILE` and by recipes).
    write(
        &d.join("r/nan.yml"),
        YAML.replace("0.50 1.49 0.0", "0.50 nan 0.0"),
    );
    // Rows out of order are sorted with a warning (docs/materials.md, tested in
    // material_db.rs); a page giving only k stays an error.
    write(
        &d.join("mat/k-only.yml"),
        YAML.replace("tabulated nk", "tabulated k")
            .replace(" 0.0\n", "\n"),
    );
    write(
        &d.join("mat/formula.yml"),
        "DATA:\n  - type: formula 99\n    wavelength_range: 0.3 2.5\n    coefficients: 0 1 2\n",
    );
    write(
        &d.join("mat/empty.yml"),
        "DATA:\n  - type: tabulated nk\n    data: |\n",
    );
    write(&d.join("mat/not-yaml.yml"), "DATA: [unclosed\n");
    write(
        &d.join("mat/negative-n.csv"),
        "wavelength_nm,n,k\n400,1.5,0\n500,-1.5,0\n",
    );
    write(
        &d.join("mat/duplicate.csv"),
        "wavelength_nm,n,k\n400,1.5,0\n400,1.6,0\n",
    );
    write(
        &d.join("mat/inf.csv"),
        "wavelength_nm,n,k\n400,1.5,0\n500,inf,0\n",
    );
    write(
        &d.join("mat/negative-k.csv"),
        "wavelength_nm,n,k\n400,1.5,0\n500,1.5,-0.1\n",
    );
    write(&d.join("mat/header-only.csv"), "wavelength_nm,n,k\n");

    // Manifests and table files (read by `color --method lut:`, `info`, `render --tables`).
    let m = d.join("m");
    copy_dir(&good, &m);
    std::fs::write(
        m.join("syntax.json"),
        "{\n  \"format\": \"nacre-table/1\",\n  oops\n}\n",
    )
    .unwrap();
    manifest_variant(&tiny, &m, "format.json", |v| {
        v["format"] = "nacre-table/99".into()
    });
    manifest_variant(&tiny, &m, "no-files.json", |v| {
        v.as_object_mut().unwrap().remove("files");
    });
    manifest_variant(&tiny, &m, "missing-exr.json", |v| {
        v["files"][0]["path"] = "gone.reflectance.exr".into()
    });
    manifest_variant(&tiny, &m, "wrong-count.json", |v| {
        v["film_lut"]["cos_theta_count"] = 5.into()
    });
    manifest_variant(&tiny, &m, "zero-count.json", |v| {
        v["film_lut"]["opd_count"] = 0.into()
    });
    manifest_variant(&tiny, &m, "absurd-count.json", |v| {
        v["film_lut"]["opd_count"] = 1_000_000_000_000u64.into()
    });
    manifest_variant(&tiny, &m, "negative-count.json", |v| {
        v["film_lut"]["opd_count"] = (-8).into()
    });
    manifest_variant(&tiny, &m, "bad-space.json", |v| v["space"] = "lab".into());
    manifest_variant(&tiny, &m, "sha.json", |v| {
        v["files"][0]["sha256"] = "0".repeat(64).into()
    });
    let exr = std::fs::read(good.join("tiny.reflectance.exr")).unwrap();
    std::fs::write(m.join("truncated.reflectance.exr"), &exr[..exr.len() / 2]).unwrap();
    manifest_variant(&tiny, &m, "truncated-exr.json", |v| {
        v["files"][0]["path"] = "truncated.reflectance.exr".into();
        v["files"][0]["sha256"] = sha(&m.join("truncated.reflectance.exr")).into();
    });
    std::fs::write(
        m.join("garbage.reflectance.exr"),
        [0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 0xff, 0xff],
    )
    .unwrap();
    manifest_variant(&tiny, &m, "garbage-exr.json", |v| {
        v["files"][0]["path"] = "garbage.reflectance.exr".into();
        v["files"][0]["sha256"] = sha(&m.join("garbage.reflectance.exr")).into();
    });
    let ktx2 = std::fs::read(good.join("tiny.reflectance.ktx2")).unwrap();
    std::fs::write(
        m.join("truncated.reflectance.ktx2"),
        &ktx2[..ktx2.len() - 100],
    )
    .unwrap();
    manifest_variant(&tiny, &m, "truncated-ktx2.json", |v| {
        only_format(v, "ktx2");
        v["files"][0]["path"] = "truncated.reflectance.ktx2".into();
        v["files"][0]["sha256"] = sha(&m.join("truncated.reflectance.ktx2")).into();
    });
    manifest_variant(&tiny, &m, "ktx2-wrong-count.json", |v| {
        only_format(v, "ktx2");
        v["film_lut"]["ior_count"] = 3.into();
    });
    let tinyf = good.join("tinyf.json");
    manifest_variant(&tinyf, &m, "fourier-missing-level.json", |v| {
        v["files"][1]["path"] = "gone.level1.exr".into()
    });
    manifest_variant(&tinyf, &m, "fourier-wrong-samples.json", |v| {
        v["fourier"]["samples"] = 128.into();
        v["fourier"]["level_samples"] = serde_json::json!([128, 64]);
    });
    manifest_variant(&tinyf, &m, "fourier-inconsistent.json", |v| {
        v["fourier"]["samples"] = 128.into()
    });

    // Render inputs: environment maps, thickness maps and glTF files.
    let mut png = Vec::new();
    {
        let pixels: Vec<u16> = (0..256)
            .map(|i| u16::from_be_bytes([(2 * i * 37 % 251) as u8, ((2 * i + 1) * 37 % 251) as u8]))
            .collect();
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(16, 16, pixels)
            .unwrap()
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
    }
    write(&d.join("g/truncated16.png"), &png[..png.len() - 20]);
    image::RgbImage::from_pixel(4, 4, image::Rgb([10, 200, 90]))
        .save(d.join("g/colour.png"))
        .unwrap();
    write(&d.join("g/truncated.exr"), &exr[..exr.len() - 40]);
    // Height fields for `nacre diffraction` (CSV rows of heights; line 2 is bad).
    write(&d.join("h/nan.csv"), "0,0.1,0\n0.1,NaN,0.1\n0,0.1,0\n");
    write(&d.join("h/text.csv"), "0,0.1,0\n0.1,deep,0.1\n0,0.1,0\n");
    write(&d.join("h/empty.csv"), "");
    write(&d.join("g/tri.bin"), triangle());
    write(
        &d.join("g/missing-buffer.gltf"),
        gltf("nope.bin", 36, 3, ""),
    );
    write(&d.join("g/short-buffer.gltf"), gltf("tri.bin", 360, 3, ""));
    write(&d.join("g/tri.gltf"), gltf("tri.bin", 36, 3, ""));
    write(
        &d.join("g/accessor-overrun.gltf"),
        gltf("tri.bin", 36, 30, ""),
    );
    write(
        &d.join("g/bad-index.gltf"),
        gltf("tri.bin", 36, 3, "").replace(
            "\"attributes\":{\"POSITION\":0}",
            "\"attributes\":{\"POSITION\":7}",
        ),
    );
    write(
        &d.join("g/bad-material.gltf"),
        gltf("tri.bin", 36, 3, "").replace("{\"POSITION\":0}}", "{\"POSITION\":0},\"material\":3}"),
    );
    write(
        &d.join("g/not-json.gltf"),
        "{\"asset\": {\"version\": \"2.0\"},",
    );
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&1_000_000u32.to_le_bytes());
    glb.extend_from_slice(&[0; 8]);
    write(&d.join("g/lying-length.glb"), glb);
    write(
        &d.join("g/version1.gltf"),
        gltf("tri.bin", 36, 3, "").replace("\"2.0\"", "\"1.0\""),
    );
    // KHR_texture_basisu: the project's ETC1S quad with its KTX2 cut inside the level index,
    // and with a supercompression scheme the extension does not allow (ZLIB, 3).
    let basisu = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/golden/gltf/basisu");
    let quad = std::fs::read(basisu.join("quad-etc1s.gltf")).unwrap();
    let ktx2 = std::fs::read(basisu.join("etc1s.ktx2")).unwrap();
    write(&d.join("g/basisu-cut/quad-etc1s.gltf"), &quad);
    write(&d.join("g/basisu-cut/etc1s.ktx2"), &ktx2[..100]);
    let mut zlib = ktx2.clone();
    zlib[44..48].copy_from_slice(&3u32.to_le_bytes());
    write(&d.join("g/basisu-scheme/quad-etc1s.gltf"), &quad);
    write(&d.join("g/basisu-scheme/etc1s.ktx2"), &zlib);

    let lut = |manifest: &str| {
        vec![
            "color".to_string(),
            "--ambient".into(),
            "1.0".into(),
            "--layer".into(),
            "1.4@200".into(),
            "--substrate".into(),
            "1.5".into(),
            "--angles".into(),
            "0:60:30".into(),
            "--method".into(),
            format!("lut:m/{manifest}"),
            "-o".into(),
            "out.csv".into(),
        ]
    };
    let fourier = |manifest: &str| {
        vec![
            "color".to_string(),
            "--ambient".into(),
            "1.0".into(),
            "--layer".into(),
            "1.4@200".into(),
            "--substrate".into(),
            "1.5".into(),
            "--angles".into(),
            "0".into(),
            "--method".into(),
            "fourier:3".into(),
            "--fourier-table".into(),
            format!("m/{manifest}"),
            "-o".into(),
            "out.csv".into(),
        ]
    };
    let bake = |name: &str| {
        vec![
            "bake".to_string(),
            format!("r/{name}"),
            "--out".into(),
            "out".into(),
        ]
    };
    let substrate = |file: &str| {
        vec![
            "spectrum".to_string(),
            "--substrate".into(),
            format!("mat/{file}"),
            "--wavelengths".into(),
            "450".into(),
            "-o".into(),
            "out.csv".into(),
        ]
    };
    let render = |args: &[&str]| {
        let mut v: Vec<String> = ["render", "--width", "8", "--height", "8"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        v.extend(args.iter().map(|s| s.to_string()));
        v.extend(["-o".to_string(), "out.png".into()]);
        v
    };
    let with = |name, args: Vec<String>, needles: &[&'static str]| Case {
        name,
        args,
        needles: needles.to_vec(),
        env: Vec::new(),
        status: 2,
    };

    vec![
        // --- recipe TOML ---
        with(
            "recipe: TOML syntax",
            bake("syntax.toml"),
            &["syntax.toml:5"],
        ),
        with(
            "recipe: missing [axes]",
            bake("no-axes.toml"),
            &["no-axes.toml:", "axes"],
        ),
        with(
            "recipe: negative count",
            bake("negative-count.toml"),
            &["negative-count.toml:6"],
        ),
        with(
            "recipe: one texel",
            bake("one-texel.toml"),
            &["one-texel.toml:", "opd_count = 1", "at least 2"],
        ),
        with(
            "recipe: absurd counts",
            bake("absurd-counts.toml"),
            &["absurd-counts.toml", "exceeds the limit"],
        ),
        with(
            "recipe: overflowing counts",
            bake("overflowing-counts.toml"),
            &["overflowing-counts.toml", "exceeds the limit"],
        ),
        with(
            "recipe: inverted thickness",
            bake("inverted-thickness.toml"),
            &["inverted-thickness.toml:", "thickness_nm", "min < max"],
        ),
        with(
            "recipe: NaN thickness",
            bake("nan-thickness.toml"),
            &["nan-thickness.toml:", "thickness_nm"],
        ),
        with(
            "recipe: infinite thickness",
            bake("inf-thickness.toml"),
            &["inf-thickness.toml:", "thickness_nm"],
        ),
        with(
            "recipe: one-element range",
            bake("one-thickness.toml"),
            &["one-thickness.toml:7"],
        ),
        with(
            "recipe: film index below ambient",
            bake("ior-below-ambient.toml"),
            &["ior-below-ambient.toml:", "below the ambient"],
        ),
        with(
            "recipe: unknown key",
            bake("unknown-key.toml"),
            &["unknown-key.toml:9", "opd_cuont"],
        ),
        with(
            "recipe: unknown observer",
            bake("bad-observer.toml"),
            &["bad-observer.toml:12", "1900"],
        ),
        with(
            "recipe: unknown precision",
            bake("bad-precision.toml"),
            &["bad-precision.toml:12", "double"],
        ),
        with(
            "recipe: bad transmittance",
            bake("bad-transmittance.toml"),
            &[
                "bad-transmittance.toml",
                "[output] transmittance = \"maybe\"",
                "auto",
            ],
        ),
        with(
            "recipe: negative fixed layer",
            bake("negative-under.toml"),
            &["negative-under.toml:5", "non-negative"],
        ),
        with(
            "recipe: missing material file",
            bake("missing-material.toml"),
            &["missing-material.toml:4", "nosuch.yml", "cannot read"],
        ),
        with(
            "recipe: NaN in its material file",
            bake("bad-yaml-material.toml"),
            &["nan.yml:5", "nan"],
        ),
        with(
            "recipe: no kind",
            bake("no-kind.toml"),
            &["no-kind.toml", "kind"],
        ),
        with(
            "recipe: fourier samples too few",
            bake("fourier-few-samples.toml"),
            &["fourier-few-samples.toml:3", "64 to"],
        ),
        with(
            "recipe: fourier samples absurd",
            bake("fourier-huge-samples.toml"),
            &["fourier-huge-samples.toml:3", "64 to"],
        ),
        with(
            "recipe: fourier no levels",
            bake("fourier-no-levels.toml"),
            &["fourier-no-levels.toml:5", "levels = 0"],
        ),
        with(
            "recipe: fourier too many levels",
            bake("fourier-many-levels.toml"),
            &["fourier-many-levels.toml:5", "levels = 40"],
        ),
        with(
            "recipe: fourier 70 levels",
            bake("fourier-70-levels.toml"),
            &["fourier-70-levels.toml:5", "levels = 70"],
        ),
        with(
            "recipe: fourier negative max_opd_nm",
            bake("fourier-negative-opd.toml"),
            &["fourier-negative-opd.toml:4", "positive"],
        ),
        with(
            "recipe: fourier NaN max_opd_nm",
            bake("fourier-nan-opd.toml"),
            &["fourier-nan-opd.toml:4", "positive"],
        ),
        with(
            "recipe: file name not a table name",
            bake("bad name.toml"),
            &["bad name.toml", "letters, digits"],
        ),
        with(
            "recipe: not UTF-8",
            bake("binary.toml"),
            &["binary.toml", "UTF-8"],
        ),
        with("recipe: a folder", bake("folder.toml"), &["folder.toml"]),
        with(
            "recipe: integrated tolerance zero",
            bake("integrated-zero-tolerance.toml"),
            &[
                "integrated-zero-tolerance.toml:9",
                "integrated_tolerance",
                "positive",
            ],
        ),
        with(
            "recipe: integrated resolution absurd",
            bake("integrated-absurd-samples.toml"),
            &[
                "integrated-absurd-samples.toml:8",
                "integrated_samples",
                "4096",
            ],
        ),
        with(
            "recipe: integrated table beyond the size limit",
            bake("integrated-too-large.toml"),
            &["integrated-too-large.toml:8", "bytes", "limit"],
        ),
        with(
            "recipe: integrated keys on the terms layout",
            bake("integrated-keys-on-terms.toml"),
            &[
                "integrated-keys-on-terms.toml:8",
                "layout = \"integrated\" only",
            ],
        ),
        with(
            "recipe: integrated layout of a tall structure",
            bake("integrated-tall.toml"),
            &[
                "integrated-tall.toml",
                "exceeds integrated_tolerance 0.01",
                "cancels catastrophically",
                "layout = \"terms\"",
            ],
        ),
        // --- material YAML / CSV ---
        with(
            "yaml: k without n",
            substrate("k-only.yml"),
            &["k-only.yml:2", "gives the real index n"],
        ),
        with(
            "yaml: unsupported formula",
            substrate("formula.yml"),
            &["formula.yml:2", "formula 99"],
        ),
        with(
            "yaml: empty data",
            substrate("empty.yml"),
            &["empty.yml", "no data"],
        ),
        with(
            "yaml: malformed",
            substrate("not-yaml.yml"),
            &["not-yaml.yml:"],
        ),
        with(
            "csv: negative n",
            substrate("negative-n.csv"),
            &["negative-n.csv:3", "n "],
        ),
        with(
            "csv: duplicate wavelength",
            substrate("duplicate.csv"),
            &["duplicate.csv:3", "strictly increase"],
        ),
        with(
            "csv: infinite n",
            substrate("inf.csv"),
            &["inf.csv:3", "finite"],
        ),
        with(
            "csv: negative k",
            substrate("negative-k.csv"),
            &["negative-k.csv:3", "k = -0.1", "non-negative"],
        ),
        with(
            "csv: no rows",
            substrate("header-only.csv"),
            &["header-only.csv", "no data"],
        ),
        // --- manifests ---
        with(
            "manifest: JSON syntax",
            vec!["info".into(), "m/syntax.json".into()],
            &["syntax.json:3", "not a nacre table manifest"],
        ),
        with(
            "manifest: unknown format",
            vec!["info".into(), "m/format.json".into()],
            &["format.json", "nacre-table/99"],
        ),
        with(
            "manifest: no files",
            lut("no-files.json"),
            &["no-files.json", "files"],
        ),
        with(
            "manifest: data file missing",
            lut("missing-exr.json"),
            &["gone.reflectance.exr"],
        ),
        with(
            "manifest: axis count does not match the file",
            lut("wrong-count.json"),
            &["tiny.reflectance.exr", "nx=5"],
        ),
        with(
            "manifest: zero axis count",
            lut("zero-count.json"),
            &["zero-count.json: film_lut", "opd_count = 0"],
        ),
        with(
            "manifest: absurd axis count",
            lut("absurd-count.json"),
            &["absurd-count.json: film_lut", "exceeds the limit"],
        ),
        with(
            "manifest: negative axis count",
            lut("negative-count.json"),
            &["negative-count.json:", "not a nacre table manifest"],
        ),
        with(
            "manifest: unknown colour space",
            lut("bad-space.json"),
            &["bad-space.json", "lab"],
        ),
        with(
            "manifest: SHA-256 mismatch",
            lut("sha.json"),
            &["tiny.reflectance.exr", "SHA-256"],
        ),
        with(
            "manifest: fourier level file missing",
            fourier("fourier-missing-level.json"),
            &["gone.level1.exr"],
        ),
        with(
            "manifest: fourier samples do not match the files",
            fourier("fourier-wrong-samples.json"),
            &["tinyf.level0.exr", "128"],
        ),
        with(
            "manifest: fourier samples contradict level_samples",
            fourier("fourier-inconsistent.json"),
            &["fourier-inconsistent.json: fourier", "samples = 128"],
        ),
        with(
            "manifest: runtime load with SHA mismatch",
            render(&["--tables", "m/sha.json", "--tables", "fourier-srgb"]),
            &["tiny.reflectance.exr", "SHA-256"],
        ),
        // --- table files ---
        with(
            "table: truncated EXR",
            lut("truncated-exr.json"),
            &["truncated.reflectance.exr", "OpenEXR"],
        ),
        with(
            "table: garbage EXR",
            lut("garbage-exr.json"),
            &["garbage.reflectance.exr", "OpenEXR"],
        ),
        with(
            "table: truncated KTX2",
            lut("truncated-ktx2.json"),
            &["truncated.reflectance.ktx2", "truncated KTX2"],
        ),
        with(
            "table: KTX2 depth does not match the manifest",
            lut("ktx2-wrong-count.json"),
            &["tiny.reflectance.ktx2", "3"],
        ),
        with(
            "table: truncated 16-bit PNG thickness map",
            render(&["--thickness-map", "g/truncated16.png"]),
            &["truncated16.png"],
        ),
        with(
            "render: a colour thickness map without --technique stack",
            render(&["--technique", "lut", "--thickness-map", "g/colour.png"]),
            &["colour.png", "technique `stack`"],
        ),
        with(
            "render: the top film on another map channel",
            render(&[
                "--technique",
                "stack",
                "--layer",
                "1.4@350",
                "--layer",
                "1.33@350",
                "--layer-channel",
                "g",
                "--layer-channel",
                "r",
            ]),
            &["top film's map channel"],
        ),
        with(
            "render: one map channel for two films",
            render(&[
                "--technique",
                "stack",
                "--layer",
                "1.4@350",
                "--layer",
                "1.33@350",
                "--layer-channel",
                "r",
            ]),
            &["map channels given", "one per film"],
        ),
        with(
            "table: truncated EXR environment",
            render(&["--env", "g/truncated.exr"]),
            &["truncated.exr"],
        ),
        // --- glTF ---
        with(
            "gltf: buffer file missing",
            render(&["--gltf", "g/missing-buffer.gltf"]),
            &["nope.bin"],
        ),
        with(
            "gltf: buffer shorter than declared",
            render(&["--gltf", "g/short-buffer.gltf"]),
            &["short-buffer.gltf", "360"],
        ),
        with(
            "gltf: accessor past its buffer view",
            render(&["--gltf", "g/accessor-overrun.gltf"]),
            &["accessor-overrun.gltf"],
        ),
        with(
            "gltf: attribute index out of range",
            render(&["--gltf", "g/bad-index.gltf"]),
            &["bad-index.gltf", "accessor 7 does not exist"],
        ),
        with(
            "gltf: material index out of range",
            render(&["--gltf", "g/bad-material.gltf"]),
            &["bad-material.gltf"],
        ),
        with(
            "gltf: not JSON",
            render(&["--gltf", "g/not-json.gltf"]),
            &["not-json.gltf"],
        ),
        with(
            "glb: length header past the end",
            render(&["--gltf", "g/lying-length.glb"]),
            &["lying-length.glb"],
        ),
        with(
            "gltf: asset version 1.0",
            render(&["--gltf", "g/version1.gltf"]),
            &["version1.gltf", "2.x"],
        ),
        with(
            "gltf: KHR_texture_basisu KTX2 truncated",
            render(&["--gltf", "g/basisu-cut/quad-etc1s.gltf"]),
            &["quad-etc1s.gltf", "texture 0", "image 0", "truncated"],
        ),
        with(
            "gltf: KHR_texture_basisu KTX2 with a ZLIB supercompression",
            render(&["--gltf", "g/basisu-scheme/quad-etc1s.gltf"]),
            &["quad-etc1s.gltf", "texture 0", "supercompression scheme 3"],
        ),
        // --- height fields (`nacre diffraction`) ---
        case(
            "height field: truncated PNG",
            &[
                "diffraction",
                "g/truncated16.png",
                "--pitch",
                "0.1",
                "-o",
                "out.csv",
            ],
            &["truncated16.png"],
        ),
        case(
            "height field: truncated EXR",
            &[
                "diffraction",
                "g/truncated.exr",
                "--pitch",
                "0.1",
                "-o",
                "out.csv",
            ],
            &["truncated.exr"],
        ),
        case(
            "height field: NaN height in a CSV",
            &[
                "diffraction",
                "h/nan.csv",
                "--pitch",
                "0.1",
                "-o",
                "out.csv",
            ],
            &["nan.csv:2"],
        ),
        case(
            "height field: text in a CSV",
            &[
                "diffraction",
                "h/text.csv",
                "--pitch",
                "0.1",
                "-o",
                "out.csv",
            ],
            &["text.csv:2"],
        ),
        case(
            "height field: empty CSV",
            &[
                "diffraction",
                "h/empty.csv",
                "--pitch",
                "0.1",
                "-o",
                "out.csv",
            ],
            &["empty.csv"],
        ),
        case(
            "height field: negative height scale",
            &[
                "diffraction",
                "h/nan.csv",
                "--pitch",
                "0.1",
                "--height-scale",
                "-1",
                "-o",
                "out.csv",
            ],
            &["--height-scale"],
        ),
        // --- the GPU runtime ---
        no_gpu(
            "runtime: no adapter for the requested backend",
            &[("WGPU_BACKEND", "dx12")],
            &["render", "--width", "8", "--height", "8", "-o", "out.png"],
            &["no GPU adapter"],
        ),
        no_gpu(
            "runtime: WGPU_ADAPTER_NAME matches no adapter",
            &[("WGPU_ADAPTER_NAME", "no-such-gpu")],
            &["render", "--width", "8", "--height", "8", "-o", "out.png"],
            &["WGPU_ADAPTER_NAME=no-such-gpu", "matches none"],
        ),
        // wgpu errors injected through the test hook (nacre_runtime::Fault): wgpu refuses
        // the object, and the render fails with the runtime's error, not wgpu's panic.
        case_env(
            "runtime: a shader that does not compile (injected)",
            &[("NACRE_TEST_GPU_FAULT", "broken-shader")],
            &["render", "--width", "8", "--height", "8", "-o", "out.png"],
            &["render: GPU error while", "injected broken shader"],
        ),
        case_env(
            "runtime: a texture beyond the device's limits (injected)",
            &[("NACRE_TEST_GPU_FAULT", "impossible-texture")],
            &["render", "--width", "8", "--height", "8", "-o", "out.png"],
            &["render: GPU error while", "injected impossible texture"],
        ),
        case_env(
            "runtime: a shader that does not compile in the glTF renderer (injected)",
            &[("NACRE_TEST_GPU_FAULT", "broken-shader")],
            &[
                "render",
                "--gltf",
                "g/tri.gltf",
                "--width",
                "8",
                "--height",
                "8",
                "-o",
                "out.png",
            ],
            &["render: GPU error while", "injected broken shader"],
        ),
        with(
            "runtime: table beyond the device's 3-D texture limit",
            render(&["--tables", "good/wide.json", "--tables", "fourier-srgb"]),
            &["film-lut `wide` cos θ axis needs 20000", "at most"],
        ),
        // --- diffraction scenes ---
        with(
            "render: diffraction wavelength step 0",
            render(&["--scene", "cd-disc", "--wavelength-step", "0"]),
            &["--wavelength-step", "0 nm"],
        ),
        with(
            "render: diffraction wavelength step with an integrated table",
            render(&[
                "--scene",
                "cd-disc",
                "--tables",
                "cd-tracks-fast",
                "--wavelength-step",
                "5",
            ]),
            &["--wavelength-step", "cd-tracks-fast", "\"integrated\""],
        ),
        with(
            "render: diffraction environment samples beyond 8",
            render(&["--scene", "snake-skin", "--env-samples", "99"]),
            &["99"],
        ),
        with(
            "render: --lighting on rough-row",
            render(&["--scene", "rough-row", "--lighting", "light"]),
            &["--lighting", "light", "rough-row"],
        ),
        with(
            "render: --lighting with --gltf",
            render(&[
                "--gltf",
                "g/missing-buffer.gltf",
                "--lighting",
                "environment",
            ]),
            &["--lighting", "environment", "glTF"],
        ),
        with(
            "render: --lighting unknown",
            render(&["--scene", "cd-disc", "--lighting", "sun"]),
            &["--lighting", "sun"],
        ),
        with(
            "render: diffraction roughness negative",
            render(&["--scene", "cd-disc", "--roughness", "-0.1"]),
            &["--roughness", "-0.1", "0 to 1"],
        ),
        with(
            "render: dvd-disc roughness negative",
            render(&["--scene", "dvd-disc", "--roughness", "-0.1"]),
            &["--roughness", "-0.1", "0 to 1"],
        ),
        with(
            "render: dvd-disc --lighting unknown",
            render(&["--scene", "dvd-disc", "--lighting", "lamp"]),
            &["--lighting", "lamp"],
        ),
        with(
            "render: dvd-disc given a film-lut table",
            render(&["--scene", "dvd-disc", "--tables", "soap-film"]),
            &["soap-film", "diffraction table"],
        ),
        with(
            "render: diffraction roughness above 1",
            render(&["--scene", "grating-plane", "--roughness", "1.5"]),
            &["--roughness", "1.5", "0 to 1"],
        ),
        with(
            "render: diffraction roughness NaN",
            render(&["--scene", "snake-skin", "--roughness", "nan"]),
            &["--roughness", "NaN"],
        ),
        with(
            "render: roughness on a film scene",
            render(&["--scene", "sphere", "--roughness", "0.1"]),
            &["--roughness", "diffraction scenes"],
        ),
        with(
            "render: negative roughness with an integrated table",
            render(&[
                "--scene",
                "cd-disc",
                "--tables",
                "cd-tracks-fast",
                "--roughness",
                "-0.2",
            ]),
            &["--roughness", "-0.2", "0 to 1"],
        ),
        with(
            "render: NaN roughness with an integrated table",
            render(&[
                "--scene",
                "cd-disc",
                "--tables",
                "cd-tracks-fast",
                "--roughness",
                "NaN",
            ]),
            &["--roughness", "NaN"],
        ),
        with(
            "render: roughness with environment samples",
            render(&[
                "--scene",
                "cd-disc",
                "--env-samples",
                "2",
                "--roughness",
                "0.1",
            ]),
            &["--roughness", "--env-samples"],
        ),
        with(
            "render: footprint filter switch on a film scene",
            render(&["--scene", "bubble", "--footprint-filter", "off"]),
            &["--footprint-filter", "diffraction scenes"],
        ),
        with(
            "render: diffraction scene given a film-lut table",
            render(&["--scene", "cd-disc", "--tables", "film-dielectric"]),
            &["film-dielectric", "diffraction table"],
        ),
        // --- flags ---
        case(
            "fit gltf: inverted thickness range",
            &["fit", "gltf", "--thicknesses", "600:200", "-o", "out.json"],
            &["--thicknesses `600:200`", "START must be below END"],
        ),
        case(
            "fit gltf: thickness range without an end",
            &["fit", "gltf", "--thicknesses", "300", "-o", "out.json"],
            &["--thicknesses `300`", "START:END"],
        ),
        case(
            "fit gltf: NaN thickness range end",
            &["fit", "gltf", "--thicknesses", "100:nan", "-o", "out.json"],
            &["--thicknesses `nan`"],
        ),
        case(
            "fit gltf: a stack without a film",
            &["fit", "gltf", "--substrate", "1.5", "-o", "out.json"],
            &["--layer", "at least one film"],
        ),
        case(
            "flag: NaN angle",
            &["spectrum", "--angles", "nan", "-o", "out.csv"],
            &["--angles `nan`", "finite"],
        ),
        case(
            "flag: infinite range end",
            &["spectrum", "--wavelengths", "400:inf:1", "-o", "out.csv"],
            &["--wavelengths `400:inf:1`", "finite"],
        ),
        case(
            "flag: range with four parts",
            &["spectrum", "--angles", "0:1:2:3", "-o", "out.csv"],
            &["--angles `0:1:2:3`", "START:END:STEP"],
        ),
        case(
            "flag: NaN thickness",
            &["spectrum", "--layer", "water@nan", "-o", "out.csv"],
            &["--layer `water@nan`"],
        ),
        case(
            "flag: infinite thickness",
            &["spectrum", "--layer", "water@1e400", "-o", "out.csv"],
            &["--layer `water@1e400`"],
        ),
        case(
            "flag: empty layer material",
            &["spectrum", "--layer", "@100", "-o", "out.csv"],
            &["--layer `@100`", "empty"],
        ),
        case(
            "flag: --jacobian with an incoherent layer",
            &[
                "spectrum",
                "--layer",
                "1.5@1000000:incoherent",
                "--layer",
                "mgf2@100",
                "--jacobian",
                "-o",
                "out.csv",
            ],
            &["--jacobian", "derivatives", "layer 1", "incoherent"],
        ),
        case(
            "flag: incoherent substrate",
            &[
                "spectrum",
                "--layer",
                "mgf2@100",
                "--substrate",
                "bk7:incoherent",
                "-o",
                "out.csv",
            ],
            &[
                "--substrate `bk7:incoherent`",
                "semi-infinite",
                "marks a layer",
            ],
        ),
        case(
            "flag: incoherent ambient",
            &[
                "color",
                "--ambient",
                "1.0:incoherent",
                "--layer",
                "bk7@2mm:incoherent",
                "-o",
                "out.csv",
            ],
            &["--ambient `1.0:incoherent`", "semi-infinite"],
        ),
        case(
            "flag: unknown layer suffix",
            &["spectrum", "--layer", "bk7@2mm:incoherant", "-o", "out.csv"],
            &[
                "--layer `bk7@2mm:incoherant`",
                "unknown suffix `:incoherant`",
                ":incoherent",
            ],
        ),
        case(
            "flag: a metre-thick layer",
            &[
                "spectrum",
                "--layer",
                "bk7@1000mm:incoherent",
                "-o",
                "out.csv",
            ],
            &["--layer `bk7@1000mm:incoherent`", "thinner than 1 m"],
        ),
        case(
            "flag: a slab in render --technique stack",
            &[
                "render",
                "--width",
                "8",
                "--height",
                "8",
                "--technique",
                "stack",
                "--layer",
                "mgf2@100nm",
                "--layer",
                "bk7@2mm:incoherent",
                "-o",
                "out.png",
            ],
            &[
                "--layer `bk7@2mm:incoherent`",
                "layer 2 is incoherent",
                "only `--technique glass` draws an incoherent slab",
            ],
        ),
        case(
            "flag: two slabs in render --technique glass",
            &[
                "render",
                "--width",
                "8",
                "--height",
                "8",
                "--technique",
                "glass",
                "--layer",
                "bk7@2mm:incoherent",
                "--layer",
                "mgf2@100nm",
                "--layer",
                "bk7@3mm:incoherent",
                "-o",
                "out.png",
            ],
            &[
                "--layer `bk7@3mm:incoherent`",
                "layer 3 is a second incoherent slab",
                "one slab",
            ],
        ),
        case(
            "flag: a slab in render's unused stack flags",
            &[
                "render",
                "--width",
                "8",
                "--height",
                "8",
                "--layer",
                "bk7@2mm:incoherent",
                "-o",
                "out.png",
            ],
            &[
                "--layer `bk7@2mm:incoherent`",
                "only `--technique glass` draws an incoherent slab",
            ],
        ),
        case(
            "flag: a slab that absorbs everything",
            &[
                "spectrum",
                "--layer",
                "1.5+0.01i@1mm:incoherent",
                "-o",
                "out.csv",
            ],
            &["layer 1", "absorbs everything", "1000000 nm"],
        ),
        case(
            "flag: a colour method that takes no slab",
            &[
                "color",
                "--layer",
                "mgf2@100",
                "--layer",
                "bk7@2mm:incoherent",
                "--method",
                "fourier",
                "-o",
                "out.csv",
            ],
            &["--method fourier", "layer 2 is incoherent", "spectral"],
        ),
        case(
            "recipe: incoherent substrate",
            &[
                "spectrum",
                "--recipe",
                "r/stack-incoherent-substrate.toml",
                "-o",
                "out.csv",
            ],
            &["r/stack-incoherent-substrate.toml:1", "semi-infinite"],
        ),
        case(
            "recipe: a metre-thick layer",
            &[
                "spectrum",
                "--recipe",
                "r/stack-metre.toml",
                "-o",
                "out.csv",
            ],
            &["r/stack-metre.toml:4", "thinner than 1 m"],
        ),
        case(
            "flag: negative thickness step",
            &["compare", "--thicknesses", "0:100:-1", "-o", "out"],
            &["--thicknesses `0:100:-1`", "STEP"],
        ),
        case(
            "flag: negative thickness",
            &["compare", "--thicknesses", "-10:10:5", "-o", "out"],
            &["--thicknesses", "non-negative"],
        ),
        case(
            "flag: absurd compare grid",
            &["compare", "--angles", "0:89:0.0001", "-o", "out"],
            &["--angles", "exceeds the limit"],
        ),
        case(
            "flag: --wavelengths over the limit",
            &[
                "render",
                "--technique",
                "spectral",
                "--wavelengths",
                "100000",
                "-o",
                "out.png",
            ],
            &["100000", "4096"],
        ),
        case(
            "flag: NaN exposure on a glTF",
            &[
                "render",
                "--gltf",
                "g/missing-buffer.gltf",
                "--exposure",
                "inf",
                "-o",
                "out.png",
            ],
            &["exposure"],
        ),
        case(
            "flag: bench-gpu film index not a number",
            &["bench-gpu", "--film-ior", "nan", "--frames", "1"],
            &["--film-ior", "NaN", "1 to 4"],
        ),
        case(
            "flag: bench-gpu base index below 1",
            &["bench-gpu", "--base-ior", "0.5", "--frames", "1"],
            &["--base-ior", "0.5", "1 to 4"],
        ),
        case(
            "flag: bench-gpu zero width",
            &["bench-gpu", "--width", "0", "--frames", "1"],
            &["0×1080", "1 to"],
        ),
        case(
            "flag: bench-gpu diffraction step with an integrated table",
            &[
                "bench-gpu",
                "--diffraction",
                "cd-tracks-fast",
                "--diffraction-step",
                "5",
            ],
            &["--diffraction-step", "cd-tracks-fast", "\"integrated\""],
        ),
        case(
            "flag: bench-gpu zero frames",
            &[
                "bench-gpu",
                "--width",
                "8",
                "--height",
                "8",
                "--frames",
                "0",
            ],
            &["frames"],
        ),
        case(
            "flag: material database missing",
            &[
                "--material-db",
                "nowhere",
                "spectrum",
                "--substrate",
                "main/Au/Johnson",
                "-o",
                "out.csv",
            ],
            &["--substrate", "nowhere", "--material-db"],
        ),
        case(
            "flag: conformance output is a file",
            &["conformance", "--quick", "-o", "out.csv"],
            &["out.csv"],
        ),
        case(
            "flag: bake output is a file",
            &["bake", "src/tiny.toml", "--out", "out.csv"],
            &["out.csv", "not a folder"],
        ),
    ]
}

#[test]
fn every_bad_input_exits_2_naming_the_culprit_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases = fixtures(d);
    assert!(cases.len() >= 40, "{} cases", cases.len());
    let before = snapshot(d);
    let mut failures = Vec::new();
    for c in &cases {
        let o = nacre_env(d, &c.args, &c.env);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        let mut problems = Vec::new();
        if o.status.code() != Some(c.status) {
            problems.push(format!("exit status {:?}", o.status.code()));
        }
        if err.contains("panicked") {
            problems.push("panicked".into());
        }
        if !o.stdout.is_empty() {
            problems.push(format!(
                "stdout: {}",
                String::from_utf8_lossy(&o.stdout)
                    .lines()
                    .next()
                    .unwrap_or("")
            ));
        }
        let missing: Vec<_> = c.needles.iter().filter(|n| !err.contains(**n)).collect();
        if !missing.is_empty() {
            problems.push(format!("message lacks {missing:?}"));
        }
        let after = snapshot(d);
        if after != before {
            let changed: Vec<_> = after
                .iter()
                .filter(|(p, b)| before.get(*p) != Some(b))
                .map(|(p, _)| p.strip_prefix(d).unwrap().display().to_string())
                .chain(
                    before
                        .keys()
                        .filter(|p| !after.contains_key(*p))
                        .map(|p| format!("removed {}", p.strip_prefix(d).unwrap().display())),
                )
                .collect();
            problems.push(format!("files changed: {changed:?}"));
            // Restore the folder for the next case.
            for p in after.keys().filter(|p| !before.contains_key(*p)).rev() {
                let _ = std::fs::remove_dir_all(p).or_else(|_| std::fs::remove_file(p));
            }
            for (p, bytes) in &before {
                if let Some(bytes) = bytes
                    && after.get(p) != Some(&Some(bytes.clone()))
                {
                    std::fs::write(p, bytes).unwrap();
                }
            }
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{}: {}\n    args: {:?}\n    stderr: {}",
                c.name,
                problems.join("; "),
                c.args,
                err.trim_end().replace('\n', "\n            ")
            ));
        }
    }
    eprintln!("{} bad inputs checked", cases.len());
    assert!(
        failures.is_empty(),
        "{} of {} bad inputs misbehaved:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
