//! Material data files: refractiveindex.info YAML and `wavelength_nm,n,k` CSV. A material
//! that parses must answer `index_at` over its own range with a finite index.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nacre_optics::Material;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let material = if selector & 1 == 0 {
        Material::from_refractiveindex_yaml("fuzz", "fuzz.yml", text)
    } else {
        Material::from_nk_csv("fuzz", "fuzz.csv", text)
    };
    let Ok(material) = material else {
        return;
    };
    let (lo, hi) = material.range_nm();
    for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
        let wavelength_nm = lo + t * (hi - lo);
        if let Ok(n) = material.index_at(wavelength_nm) {
            assert!(
                n.re.is_finite() && n.im.is_finite(),
                "index {n} at {wavelength_nm} nm"
            );
        }
    }
});
