//! The thickness map: a greyscale image g ∈ [0, 1] that the material maps to the film
//! thickness ([`crate::render::ThicknessMapping`]), read from a PNG or JPEG file or computed
//! ([`procedural_thickness_map`]); uploaded as (g, g²) with its mip chain. A colour map adds
//! channels G and B, which `film_stack`'s lower films may follow one channel per film (the
//! thesis's SVT with one map per layer, Sussenbach 2013 §4.2): uploaded as (g, g², g_G, g_B).

use crate::error::{Error, Result, ThicknessMapProblem};
use crate::image_io::{Level, decode_picture, mip_chain};
use std::path::Path;

/// Size of the built-in thickness map, texels (square).
pub const DEFAULT_THICKNESS_MAP_SIZE: usize = 256;

/// A thickness map: values g ∈ [0, 1], row-major, top row first, and for a colour map its
/// channels G and B. Values are data, not colours: a PNG's gamma or sRGB chunks are ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct ThicknessMap {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// `width × height` values in [0, 1]: the grey channel, or a colour map's R.
    pub values: Vec<f32>,
    /// A colour map's channels (G, B) per texel, in [0, 1], for a stack's films that follow
    /// them ([`crate::bindings::StackSetup::channels`]); `None` for a greyscale map (every
    /// film follows `values`).
    pub green_blue: Option<Vec<[f32; 2]>>,
}

impl ThicknessMap {
    /// Reads an 8- or 16-bit picture, PNG or JPEG, greyscale or colour (alpha ignored; 1-,
    /// 2- and 4-bit greyscale PNGs are expanded to 8 bits), g = value / (2^bits − 1); a
    /// colour picture's R is `values` and its G and B are `green_blue`.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read; [`Error::Image`] when it is not a valid
    /// PNG or JPEG; [`Error::ThicknessMap`] when it is not 8- or 16-bit; [`Error::ImageSize`]
    /// when a side is 0 or larger than [`crate::image_io::MAX_DIMENSION`] (checked before
    /// the pixels are decoded).
    pub fn load(path: &Path) -> Result<ThicknessMap> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let picture = decode_picture(path, "a thickness map", &bytes)?;
        let (width, height) = (picture.width() as usize, picture.height() as usize);
        let colour = |rgb: Vec<[f32; 3]>| ThicknessMap {
            width,
            height,
            values: rgb.iter().map(|c| c[0]).collect(),
            green_blue: Some(rgb.iter().map(|c| [c[1], c[2]]).collect()),
        };
        let values: Vec<f32> = match picture {
            image::DynamicImage::ImageLuma8(p) => {
                p.pixels().map(|v| f32::from(v.0[0]) / 255.0).collect()
            }
            image::DynamicImage::ImageLumaA8(p) => {
                p.pixels().map(|v| f32::from(v.0[0]) / 255.0).collect()
            }
            image::DynamicImage::ImageLuma16(p) => {
                p.pixels().map(|v| f32::from(v.0[0]) / 65535.0).collect()
            }
            image::DynamicImage::ImageLumaA16(p) => {
                p.pixels().map(|v| f32::from(v.0[0]) / 65535.0).collect()
            }
            image::DynamicImage::ImageRgb8(p) => {
                return Ok(colour(
                    p.pixels()
                        .map(|v| v.0.map(|c| f32::from(c) / 255.0))
                        .collect(),
                ));
            }
            image::DynamicImage::ImageRgba8(p) => {
                return Ok(colour(
                    p.pixels()
                        .map(|v| [v.0[0], v.0[1], v.0[2]].map(|c| f32::from(c) / 255.0))
                        .collect(),
                ));
            }
            image::DynamicImage::ImageRgb16(p) => {
                return Ok(colour(
                    p.pixels()
                        .map(|v| v.0.map(|c| f32::from(c) / 65535.0))
                        .collect(),
                ));
            }
            image::DynamicImage::ImageRgba16(p) => {
                return Ok(colour(
                    p.pixels()
                        .map(|v| [v.0[0], v.0[1], v.0[2]].map(|c| f32::from(c) / 65535.0))
                        .collect(),
                ));
            }
            other => {
                return Err(Error::ThicknessMap {
                    path: path.to_path_buf(),
                    problem: ThicknessMapProblem::ColourType(format!("{:?}", other.color())),
                });
            }
        };
        Ok(ThicknessMap {
            width,
            height,
            values,
            green_blue: None,
        })
    }

    /// [`ThicknessMap::load`] for a scene rendered with `technique`: a colour map (one channel
    /// per film) is for [`Technique::Stack`](crate::shaders::Technique::Stack) and
    /// [`Technique::Glass`](crate::shaders::Technique::Glass) only.
    ///
    /// # Errors
    /// Those of [`ThicknessMap::load`]; [`Error::ThicknessMap`] for a colour map with another
    /// technique, which would read its R channel as if it were grey.
    pub fn load_for(path: &Path, technique: crate::shaders::Technique) -> Result<ThicknessMap> {
        let map = ThicknessMap::load(path)?;
        use crate::shaders::Technique;
        if map.green_blue.is_some() && !matches!(technique, Technique::Stack | Technique::Glass) {
            return Err(Error::ThicknessMap {
                path: path.to_path_buf(),
                problem: ThicknessMapProblem::ColourForTechnique(technique.name().to_string()),
            });
        }
        Ok(map)
    }

    /// [`ThicknessMap::load`] (the name from when only PNG was read).
    pub fn load_png(path: &Path) -> Result<ThicknessMap> {
        ThicknessMap::load(path)
    }

    /// The mip chain of (g, g²) uploaded to the GPU.
    pub fn mip_chain(&self) -> Vec<Level<2>> {
        let texels = self
            .values
            .iter()
            .map(|&g| {
                let g = if g.is_finite() {
                    g.clamp(0.0, 1.0)
                } else {
                    0.5
                };
                [g, g * g]
            })
            .collect();
        mip_chain(self.width, self.height, texels)
    }

    /// The mip chain of (g, g², g_G, g_B) uploaded for the analytic scenes: a greyscale map
    /// repeats g in the last two.
    pub fn stack_mip_chain(&self) -> Vec<Level<4>> {
        let clean = |g: f32| {
            if g.is_finite() {
                g.clamp(0.0, 1.0)
            } else {
                0.5
            }
        };
        let texels = self
            .values
            .iter()
            .enumerate()
            .map(|(i, &g)| {
                let g = clean(g);
                let [gg, gb] = match &self.green_blue {
                    Some(c) => c.get(i).copied().unwrap_or([g, g]).map(clean),
                    None => [g, g],
                };
                [g, g * g, gg, gb]
            })
            .collect();
        mip_chain(self.width, self.height, texels)
    }
}

/// The built-in thickness map: `size` × `size` marbled swirls, tileable (every term is
/// periodic with period 1 in both coordinates), each channel normalised to span [0, 1]: R
/// (the grey value every technique reads) and, for stacks whose films follow their own
/// channel, G and B, the same swirls with every phase shifted by 2 and 4 radians.
///
/// g(x, y) = ½ + ½ Σ_k a_k sin(2π(m_k u + n_k v) + φ_k) after three rounds of domain warping
/// (u, v) ← (u, v) + A sin(2π(integer frequencies) + phase).
pub fn procedural_thickness_map(size: usize) -> ThicknessMap {
    let size = size.max(1);
    let (red, green, blue) = (swirls(size, 0.0), swirls(size, 2.0), swirls(size, 4.0));
    ThicknessMap {
        width: size,
        height: size,
        values: red,
        green_blue: Some(green.into_iter().zip(blue).map(|(g, b)| [g, b]).collect()),
    }
}

/// One channel of [`procedural_thickness_map`], every phase shifted by `shift_rad`.
fn swirls(size: usize, shift_rad: f64) -> Vec<f32> {
    use std::f64::consts::TAU;
    // Warps: amplitude; integer frequencies (x, y) and phase of the u displacement; of the v one.
    type Warp = (f64, [f64; 2], f64, [f64; 2], f64);
    let warps: [Warp; 3] = [
        (0.12, [1.0, 2.0], 0.3, [2.0, -1.0], 1.7),
        (0.07, [3.0, -2.0], 2.1, [-1.0, 3.0], 0.4),
        (0.035, [4.0, 5.0], 4.0, [5.0, -3.0], 2.9),
    ];
    let waves: [(f64, [f64; 2], f64); 4] = [
        (0.55, [2.0, 1.0], 0.0),
        (0.35, [-1.0, 3.0], 1.0),
        (0.2, [4.0, -2.0], 2.2),
        (0.1, [5.0, 6.0], 0.7),
    ];
    let mut raw = Vec::with_capacity(size * size);
    for j in 0..size {
        for i in 0..size {
            let (mut u, mut v) = (
                (i as f64 + 0.5) / size as f64,
                (j as f64 + 0.5) / size as f64,
            );
            for &(a, fu, pu, fv, pv) in &warps {
                let du = a * (TAU * (fu[0] * u + fu[1] * v) + (pu + shift_rad)).sin();
                let dv = a * (TAU * (fv[0] * u + fv[1] * v) + (pv + shift_rad)).sin();
                u += du;
                v += dv;
            }
            let g: f64 = waves
                .iter()
                .map(|&(a, f, p)| a * (TAU * (f[0] * u + f[1] * v) + (p + shift_rad)).sin())
                .sum();
            raw.push(g);
        }
    }
    let lo = raw.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = raw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = (hi - lo).max(1e-12);
    raw.iter().map(|&g| ((g - lo) / span) as f32).collect()
}
