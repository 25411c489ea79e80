//! OpenEXR table atlases (`NAME.QUANTITY.exr`, `NAME.levelK.exr`): a file that decodes
//! holds finite values and as many as its size says.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.exr");
    if let Ok((atlas, _)) = nacre_format::table_io::decode_exr_bytes(path, data) {
        assert_eq!(atlas.data.len(), atlas.width * atlas.height * 3);
        assert!(atlas.data.iter().all(|v| v.is_finite()));
    }
});
