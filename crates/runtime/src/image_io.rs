//! CPU images: the size limit of every picture the runtime reads or renders, mip levels and
//! their 2×2 box-filtered chains (uploaded as textures by the renderer).

use crate::error::{Error, Result};
use std::path::Path;

/// Largest width or height of a rendered image, an environment map or a thickness map.
pub const MAX_DIMENSION: u32 = 8192;

/// One mip level: width, height, texels (row-major, top row first).
pub type Level<const C: usize> = (usize, usize, Vec<[f32; C]>);

/// The full mip chain of an image down to 1 × 1: level k + 1 averages (2×2 box filter) the
/// texels 2x, 2x + 1 (clamped to the edge for odd sizes) of level k. An empty or inconsistent
/// image is returned as its only level.
pub(crate) fn mip_chain<const C: usize>(
    width: usize,
    height: usize,
    texels: Vec<[f32; C]>,
) -> Vec<Level<C>> {
    let empty = width == 0 || height == 0 || texels.len() != width * height;
    let mut levels = vec![(width, height, texels)];
    if empty {
        return levels;
    }
    loop {
        let (w, h, src) = levels.last().expect("at least one level");
        let (w, h) = (*w, *h);
        if w == 1 && h == 1 {
            break;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut dst = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            let (y0, y1) = ((2 * y).min(h - 1), (2 * y + 1).min(h - 1));
            for x in 0..nw {
                let (x0, x1) = ((2 * x).min(w - 1), (2 * x + 1).min(w - 1));
                let mut acc = [0.0f32; C];
                for (xx, yy) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                    let t = src[yy * w + xx];
                    for c in 0..C {
                        acc[c] += t[c];
                    }
                }
                dst.push(acc.map(|v| 0.25 * v));
            }
        }
        levels.push((nw, nh, dst));
    }
    levels
}

pub(crate) fn check_image_size(path: &Path, what: &str, width: usize, height: usize) -> Result<()> {
    let max = MAX_DIMENSION as usize;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::Invalid {
            context: path.display().to_string(),
            message: format!(
                "{what} of {width}x{height} texels (expected 1 to {max} texels on each side)"
            ),
        });
    }
    Ok(())
}
