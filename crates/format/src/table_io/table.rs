//! The table a file holds ([`Table3`], its atlas [`Table3Atlas`], the stored [`Precision`]),
//! the checks every writer and reader applies (shape, finite values, size limits), and the
//! errors naming the file.

use crate::error::{Error, Result};
use std::path::Path;

/// Most texels (`width * height` of an atlas, `nx * ny * nz` of a table) a reader accepts
/// from a file, so that a corrupt header cannot request an absurd allocation: 2²⁷ texels
/// (e.g. 512³), 1.5 GiB of `f32` RGB data.
pub const MAX_TEXELS: usize = 1 << 27;

/// Largest width or height of an atlas image (the OpenEXR and PNG limit, 2³¹ − 1).
pub(super) const MAX_SIDE: usize = i32::MAX as usize;

/// A 3-D table of RGB `f32` texels, stored x-fastest (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct Table3 {
    /// Texels along x (the atlas width).
    pub nx: usize,
    /// Texels along y (rows per slice in the atlas).
    pub ny: usize,
    /// Texels along z (slices stacked vertically in the atlas).
    pub nz: usize,
    /// `nx * ny * nz * 3` floats: R, G, B of texel `((z * ny) + y) * nx + x`.
    pub data: Vec<f32>,
}

impl Table3 {
    /// A table of `nx * ny * nz` texels, all `[0, 0, 0]`.
    ///
    /// # Panics
    /// If `nx * ny * nz * 3` overflows `usize`.
    pub fn new(nx: usize, ny: usize, nz: usize) -> Self {
        let len = nx
            .checked_mul(ny)
            .and_then(|n| n.checked_mul(nz))
            .and_then(|n| n.checked_mul(3))
            .expect("Table3::new: nx * ny * nz * 3 overflows usize");
        Self {
            nx,
            ny,
            nz,
            data: vec![0.0; len],
        }
    }

    /// Offset of texel `(x, y, z)`'s red value in `data`.
    fn offset(&self, x: usize, y: usize, z: usize) -> usize {
        assert!(
            x < self.nx && y < self.ny && z < self.nz,
            "texel ({x}, {y}, {z}) outside a {}x{}x{} table",
            self.nx,
            self.ny,
            self.nz
        );
        (((z * self.ny) + y) * self.nx + x) * 3
    }

    /// The RGB value of texel `(x, y, z)`.
    ///
    /// # Panics
    /// If the coordinates are outside the table.
    pub fn texel(&self, x: usize, y: usize, z: usize) -> [f32; 3] {
        let i = self.offset(x, y, z);
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    /// Sets the RGB value of texel `(x, y, z)`.
    ///
    /// # Panics
    /// If the coordinates are outside the table.
    pub fn set(&mut self, x: usize, y: usize, z: usize, rgb: [f32; 3]) {
        let i = self.offset(x, y, z);
        self.data[i..i + 3].copy_from_slice(&rgb);
    }
}

/// A 2-D RGB atlas as read from an image, before it is cut into slices: `width * height`
/// texels, row-major from the top row, three floats (R, G, B) per texel. With
/// `width == nx` and `height == ny * nz` its `data` is exactly a [`Table3`]'s `data`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table3Atlas {
    /// Image width in texels.
    pub width: usize,
    /// Image height in texels.
    pub height: usize,
    /// `width * height * 3` floats: R, G, B of texel `row * width + column`.
    pub data: Vec<f32>,
}

/// Sample precision of an OpenEXR table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// 16-bit half float (`f16`): 11 significant bits, finite range ±65504.
    Half,
    /// 32-bit float (`f32`), stored exactly.
    Float,
}

pub(super) fn table_error(path: &Path, message: impl Into<String>) -> Error {
    Error::Table {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

pub(super) fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Checks that `table` is well formed and fits an atlas image; returns the atlas height.
pub(super) fn check_shape(path: &Path, table: &Table3) -> Result<usize> {
    let (nx, ny, nz) = (table.nx, table.ny, table.nz);
    if nx == 0 || ny == 0 || nz == 0 {
        return Err(table_error(
            path,
            format!("cannot write an empty {nx}x{ny}x{nz} table"),
        ));
    }
    let height = ny.checked_mul(nz).filter(|&h| h <= MAX_SIDE);
    let Some(height) = height.filter(|_| nx <= MAX_SIDE) else {
        return Err(table_error(
            path,
            format!(
                "a {nx}x{ny}x{nz} table gives an atlas larger than {MAX_SIDE} texels on a side"
            ),
        ));
    };
    let expected = nx.checked_mul(height).and_then(|n| n.checked_mul(3));
    if expected != Some(table.data.len()) {
        return Err(table_error(
            path,
            format!(
                "a {nx}x{ny}x{nz} table needs {nx}*{ny}*{nz}*3 floats but its data holds {}",
                table.data.len()
            ),
        ));
    }
    Ok(height)
}

/// Describes the location of float `i` of `table.data` for error messages.
pub(super) fn describe(table: &Table3, i: usize) -> String {
    let texel = i / 3;
    let channel = ["R", "G", "B"][i % 3];
    let x = texel % table.nx;
    let y = (texel / table.nx) % table.ny;
    let z = texel / (table.nx * table.ny);
    format!(
        "texel (x={x}, y={y}, z={z}) channel {channel} (atlas column {x}, row {})",
        texel / table.nx
    )
}

/// Refuses NaN and infinite values.
pub(super) fn check_finite(path: &Path, table: &Table3) -> Result<()> {
    match table.data.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(table_error(
            path,
            format!(
                "{} is {}; refusing to write a table with non-finite values",
                describe(table, i),
                table.data[i]
            ),
        )),
    }
}

/// Reads the file at `path` whole.
pub(super) fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(io_error(path))
}

/// Checks requested table dimensions; returns `(height, texels)`.
pub(super) fn table_dims(path: &Path, nx: usize, ny: usize, nz: usize) -> Result<(usize, usize)> {
    let dims = ny
        .checked_mul(nz)
        .and_then(|h| Some((h, h.checked_mul(nx)?)));
    match dims {
        Some((h, n)) if n > 0 && n <= MAX_TEXELS => Ok((h, n)),
        _ => Err(table_error(
            path,
            format!(
                "cannot read a {nx}x{ny}x{nz} table: expected between 1 and {MAX_TEXELS} texels"
            ),
        )),
    }
}
