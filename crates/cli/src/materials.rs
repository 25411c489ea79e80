//! `nacre materials`: the bundled materials and their wavelength ranges.

use crate::error::Result;
use nacre_format::materials::{BUNDLED, load_bundled};

pub fn run() -> Result<()> {
    // The ranges exactly as the data give them (not rounded: each bound printed is
    // accepted).
    for b in BUNDLED {
        let m = load_bundled(b)?;
        let (lo, hi) = m.range_nm();
        println!(
            "{:<13} {:<26} {}",
            b.name,
            format!("{lo}–{hi} nm"),
            b.description
        );
    }
    Ok(())
}
