//! Inputs the fuzz targets (`fuzz/`) once failed on, kept in `fuzz/regressions/TARGET/`:
//! each must now be refused with an error naming the file, quickly and without a large
//! allocation.

use nacre_format::ktx2::Ktx2Image;
use nacre_format::table_io::decode_exr_bytes;
use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions")
        .join(target);
    let mut out: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no inputs in {}", dir.display());
    out
}

/// A KTX2 file whose key/value pairs are not sorted (KTX 2.0 §3.11) decoded, and did not
/// encode back to the same image.
#[test]
fn ktx2_regressions_are_refused() {
    for (path, bytes) in inputs("ktx2") {
        let e = Ktx2Image::decode(&path, &bytes).expect_err(&path.display().to_string());
        let message = e.to_string();
        assert!(message.contains(&*path.to_string_lossy()), "{message}");
    }
}

/// A 512-byte OpenEXR file whose chunk claimed about 2 GB made the decoder allocate it;
/// a B44 block made the `exr` crate's B44 decoder overflow (a panic with overflow checks).
#[test]
fn exr_regressions_are_refused_quickly() {
    for (path, bytes) in inputs("exr") {
        let start = std::time::Instant::now();
        let e = decode_exr_bytes(&path, &bytes).expect_err(&path.display().to_string());
        let message = e.to_string();
        assert!(
            message.contains("runs past the end of the file") || message.contains("b44"),
            "{message}"
        );
        assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
    }
}

/// A fourier recipe with `levels = 70` overflowed the shift `samples >> (levels - 1)`; a
/// CD-like diffraction recipe with a 205.5 µm pitch (a 53 mm patch) set out to rasterise
/// billions of pits at parse time (a fuzzer timeout).
#[test]
fn recipe_regressions_are_refused_quickly() {
    for (path, bytes) in inputs("recipe") {
        let start = std::time::Instant::now();
        let text = String::from_utf8(bytes).unwrap();
        let e = nacre_bake::kinds::parse_recipe(&path, text)
            .err()
            .unwrap_or_else(|| panic!("{} parsed", path.display()));
        let message = e.to_string();
        assert!(message.contains(&*path.to_string_lossy()), "{message}");
        assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
    }
}
