//! KTX 2.0 textures (`NAME.QUANTITY.ktx2`, `NAME.ktx2`): a file that decodes has levels of
//! the sizes its header gives, and encodes back to a file that decodes to the same image.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nacre_format::ktx2::Ktx2Image;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.ktx2");
    let Ok(image) = Ktx2Image::decode(path, data) else {
        return;
    };
    for (k, level) in image.levels.iter().enumerate() {
        assert_eq!(Some(level.len() as u64), image.level_byte_length(k));
        let _ = image.level_f32(k);
    }
    if let Ok(bytes) = image.encode(path) {
        let again = Ktx2Image::decode(path, &bytes).expect("re-encoded image decodes");
        let shape = |i: &Ktx2Image| (i.format, i.width, i.height, i.depth, i.layers);
        assert_eq!(shape(&again), shape(&image));
        assert!(again.levels == image.levels, "level data differs");
        let keys = |i: &Ktx2Image| -> Vec<(String, usize)> {
            i.key_values
                .iter()
                .map(|(k, v)| (k.clone(), v.len()))
                .collect()
        };
        assert_eq!(keys(&again), keys(&image));
        assert!(
            again.key_values == image.key_values,
            "key/value data differs"
        );
    }
});
