//! 16-bit PNG table atlases (`NAME.QUANTITY.png`). The first three bytes choose the table
//! size the reader is asked for (1 to 256 each); the rest is the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let [x, y, z, file @ ..] = data else {
        return;
    };
    let (nx, ny, nz) = (
        usize::from(*x) + 1,
        usize::from(*y) + 1,
        usize::from(*z) + 1,
    );
    let path = Path::new("fuzz.png");
    if let Ok(table) = nacre_format::table_io::decode_png16_table(path, file, nx, ny, nz) {
        assert_eq!(table.data.len(), nx * ny * nz * 3);
        assert!(table.data.iter().all(|v| (0.0..=1.0).contains(v)));
    }
});
