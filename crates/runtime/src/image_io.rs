//! CPU images: the size limit of every picture the runtime reads or renders, mip levels and
//! their 2×2 box-filtered chains (uploaded by `crate::gpu::upload_mips`).

use crate::error::{Error, Result};
use std::path::Path;

/// Largest width or height of a rendered image, an environment map or a thickness map.
pub const MAX_DIMENSION: u32 = 8192;

/// Decodes the picture `bytes` read from `path` (PNG, JPEG or Radiance HDR, told apart by
/// their content): its size is checked against [`MAX_DIMENSION`] (`what` names the picture
/// in the error) before the pixels are decoded, and a decoder failure is an error, not a
/// panic (the decoders run under [`nacre_format::decode::guarded`], as every decoder of an
/// untrusted file does).
///
/// # Errors
/// [`Error::Image`] or [`Error::ImageSize`] naming `path`: not a picture of those formats, malformed, or too large.
pub(crate) fn decode_picture(path: &Path, what: &str, bytes: &[u8]) -> Result<image::DynamicImage> {
    let invalid = |message: String| Error::Image {
        path: path.to_path_buf(),
        message,
    };
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| invalid(format!("not a readable picture: {e}")))
    };
    let decode = || -> Result<image::DynamicImage> {
        if reader()?.format().is_none() {
            return Err(invalid("not a PNG, JPEG or Radiance HDR picture".into()));
        }
        let (width, height) = reader()?
            .into_dimensions()
            .map_err(|e| invalid(format!("not a valid picture: {e}")))?;
        check_image_size(path, what, width as usize, height as usize)?;
        let mut r = reader()?;
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(1 << 30);
        r.limits(limits);
        r.decode()
            .map_err(|e| invalid(format!("not a valid picture: {e}")))
    };
    nacre_format::decode::guarded(decode, || {
        invalid("malformed picture data (the decoder failed)".into())
    })
}

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
        return Err(Error::ImageSize {
            path: path.to_path_buf(),
            what: what.to_string(),
            width: width as u64,
            height: height as u64,
            max: max as u64,
        });
    }
    Ok(())
}

/// An image rendered by [`Renderer::render`](crate::render::Renderer::render).
#[derive(Clone, Debug)]
pub struct RenderedImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// RGBA8, sRGB-encoded, alpha 255, row-major, top row first.
    pub pixels: Vec<u8>,
    /// Wall-clock seconds from submitting the render pass to its completion (excludes
    /// pipeline creation, uploads and the readback; includes any shader compilation the driver
    /// defers to the first draw, as lavapipe does without a warm shader cache).
    pub gpu_seconds: f64,
}

impl RenderedImage {
    /// The image as an 8-bit RGB PNG with an sRGB chunk. Written with the `png` crate, the
    /// one picture outside the table atlases that is not: the `image` crate's PNG encoder
    /// cannot write the sRGB chunk that tells viewers how the bytes are encoded.
    pub fn encode_png(&self) -> Result<Vec<u8>> {
        let err = |e: png::EncodingError| Error::Image {
            path: "encoding the PNG".into(),
            message: e.to_string(),
        };
        let rgb: Vec<u8> = self
            .pixels
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            encoder.set_compression(png::Compression::Balanced);
            let mut writer = encoder.write_header().map_err(err)?;
            writer.write_image_data(&rgb).map_err(err)?;
            writer.finish().map_err(err)?;
        }
        Ok(bytes)
    }

    /// Writes [`RenderedImage::encode_png`] to `path` atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        let bytes = self.encode_png()?;
        Ok(nacre_format::atomic::write_atomic(path, |w| {
            w.write_all(&bytes)
        })?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mip_chain_averages_and_ends_at_one_texel() {
        let texels: Vec<[f32; 1]> = (0..15).map(|i| [i as f32]).collect();
        let chain = mip_chain(5, 3, texels);
        let sizes: Vec<(usize, usize)> = chain.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(sizes, vec![(5, 3), (2, 1), (1, 1)]);
        // Level 1 texel 0 averages (0, 0), (1, 0), (0, 1), (1, 1) = 0, 1, 5, 6.
        assert_eq!(chain[1].2[0][0], 3.0);
    }
}
