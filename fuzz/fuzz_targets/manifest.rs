//! Table manifests (`NAME.json`, what `nacre info`, `--method lut:` and the runtime read).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // A folder that does not exist: any file the manifest names is missing.
    let path = Path::new("/nonexistent-nacre-fuzz/table.json");
    let Ok(manifest) = nacre_format::Manifest::parse(path, text) else {
        return;
    };
    let _ = manifest.colorimeter(path);
    let _ = manifest.embedded_json();
    let _ = manifest.load_table(path, "reflectance");
    let _ = manifest.load_fourier(path);
    let _ = manifest.load_diffraction(path);
    let _ = manifest.load_diffraction_integrated(path);
});
