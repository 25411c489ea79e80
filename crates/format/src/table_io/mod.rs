//! Writing and reading 3-D lookup tables as 2-D image *atlases* (OpenEXR and 16-bit PNG).
//!
//! # Table layout
//!
//! A [`Table3`] is a 3-D array of RGB `f32` texels with dimensions `(nx, ny, nz)`, stored
//! x-fastest with three floats per texel:
//!
//! ```text
//! texel index = ((z * ny) + y) * nx + x,   floats data[3 * index .. 3 * index + 3] = R, G, B
//! ```
//!
//! # Atlas layout
//!
//! The table is written as a 2-D image of `width = nx` and `height = ny * nz` texels. The
//! slices are stacked vertically: slice `z` occupies image rows `[z * ny, (z + 1) * ny)`,
//! and row `y` of slice `z` is image row `z * ny + y`, counted from the top (row 0 is the
//! first row stored in the file). Column `x` is image column `x`. Because image rows are
//! themselves stored left to right and top to bottom, the atlas texel order is exactly the
//! table's memory order: atlas texel `(column x, row r)` is table texel `r * nx + x`.
//!
//! ```text
//!            x = 0 .. nx-1
//!          +---------------+
//!  row 0   | z = 0, y = 0  |
//!   ...    |      ...      |
//!  ny-1    | z = 0, y=ny-1 |
//!  ny      | z = 1, y = 0  |
//!   ...    |      ...      |
//!  ny*nz-1 | z=nz-1,y=ny-1 |
//!          +---------------+
//! ```
//!
//! # Formats
//!
//! * **OpenEXR** ([`write_exr`], [`read_exr`], [`read_exr_table`]): one single-part
//!   scan-line image with exactly the channels `R`, `G`, `B` (no alpha), ZIP compression
//!   (lossless, 16 scan lines per block), increasing line order, samples stored as half
//!   (`f16`, converted with round-to-nearest-even) or full (`f32`) float. The encoder runs
//!   sequentially and writes no time stamps, so the same table always gives the same bytes.
//! * **16-bit PNG** ([`write_png16`], [`read_png16_table`]): RGB, 16 bits per channel,
//!   value `v` stored as `round(v * 65535)`; only possible when every value lies in
//!   `[0, 1]`. No colour-space chunks are written: the values are data, not colours to be
//!   gamma-corrected.
//!
//! Every writer refuses non-finite values (and, for half floats, values beyond the `f16`
//! range) before touching the file system, and writes atomically through
//! [`crate::atomic::write_atomic`]: an existing file is replaced only by a complete new
//! one and is left untouched when writing fails. Readers validate the dimensions, channels
//! and values and never panic on malformed or truncated files; every error names the file.

mod exr;
mod png16;
mod table;
#[cfg(test)]
mod tests;

pub use crate::checksum::sha256_hex;
pub use exr::{decode_exr_bytes, read_exr, read_exr_table, write_exr};
pub use png16::{decode_png16_table, read_png16_table, write_png16};
pub use table::{MAX_TEXELS, Precision, Table3, Table3Atlas};
