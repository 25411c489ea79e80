//! The engine HLSL compiled by Slang: `scripts/hlsl_slang.py` builds a compute probe around
//! `shaders/hlsl/nacre.hlsl` (film-lut, fourier, rough-film-lut) and one around
//! `shaders/hlsl/unity/NacreShaderGraph.hlsl` (with stand-ins of Shader Graph's texture
//! structs) and compiles both with PyPI's `slangpy` (Slang's HLSL front end and its CPU
//! target). Unity and Unreal compile this HLSL with FXC or DXC, neither of which installs
//! on Linux from the registries; Slang is a second HLSL compiler beside glslangValidator
//! (`engine_shaders_gpu`, `crates/runtime/tests/engine_shaders.rs`).
//!
//! The Python that has slangpy: `$NACRE_SLANGPY_PYTHON`, else `python3`. Without slangpy the
//! test fails in CI (`CI` set; `scripts/test.sh` installs it there) and elsewhere prints why it
//! skips.

use std::path::Path;
use std::process::Command;

#[test]
fn nacre_hlsl_compiles_with_slang() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let python = std::env::var("NACRE_SLANGPY_PYTHON").unwrap_or_else(|_| "python3".into());
    let has_slangpy = Command::new(&python)
        .args(["-c", "import slangpy"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !has_slangpy {
        let why = format!(
            "`{python} -c 'import slangpy'` failed: install slangpy from PyPI \
             (pip install slangpy) or set NACRE_SLANGPY_PYTHON to a Python that has it"
        );
        if std::env::var_os("CI").is_some() {
            panic!("hlsl_slang: {why} (scripts/test.sh installs it in CI)");
        }
        eprintln!("SKIP hlsl_slang: {why}");
        return;
    }
    let out = Command::new(&python)
        .arg(root.join("scripts/hlsl_slang.py"))
        .output()
        .expect("running scripts/hlsl_slang.py");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    print!("{stdout}");
    assert!(
        out.status.success(),
        "Slang did not compile the engine HLSL:\n{stdout}\n{stderr}"
    );
    for probe in ["nacre.hlsl", "unity/NacreShaderGraph.hlsl"] {
        assert!(
            stdout.contains(&format!("{probe} compiles with Slang")),
            "no result for {probe}:\n{stdout}"
        );
    }
}
