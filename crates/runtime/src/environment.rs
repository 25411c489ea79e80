//! The environment: an equirectangular HDR image ([`EnvironmentMap`]), read from an OpenEXR
//! file (the default `tables/env/studio.exr`) or computed ([`procedural_environment`]), and
//! the sun direction the default light shares with it. Its GPU side (the box mip chain, the
//! GGX-prefiltered levels of [`crate::ibl`]) is uploaded by the renderer
//! ([`crate::render`], group 0).

use crate::error::{Error, Result};
use crate::image_io::{Level, check_image_size, mip_chain};
use half::f16;
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Size of the default environment, texels (width × height).
pub const DEFAULT_ENVIRONMENT_SIZE: (usize, usize) = (256, 128);

/// Direction of the default light and of the sun in [`procedural_environment`] (towards the
/// light: up, left and in front of the default cameras).
pub const SUN_DIRECTION: [f64; 3] = [-0.45, 0.70, 0.55];

/// An equirectangular HDR environment: linear RGB radiance, row 0 the zenith (+y), column
/// u = (i + 0.5)/width at azimuth φ = 2π(u − 0.5) from −z towards +x.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// `width × height` texels, row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
}

/// The committed default environment: `tables/env/studio.exr`.
pub fn default_environment_path() -> PathBuf {
    nacre_format::set::tables_dir()
        .join("env")
        .join("studio.exr")
}

impl EnvironmentMap {
    /// Reads an equirectangular image: OpenEXR (half or float `R`, `G`, `B` channels; other
    /// channels ignored), Radiance HDR (linear floats), or PNG/JPEG (8 or 16 bits, sRGB
    /// encoded: decoded to linear with the IEC 61966-2-1 transfer function, so 1.0 is the
    /// brightest a low-dynamic-range picture can hold). A file named `.exr`, or starting
    /// with the OpenEXR magic number, is read as OpenEXR; any other through the `image`
    /// crate. Negative values become 0.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read; [`Error::Image`] or [`Error::Table`] when it
    /// is not a valid flat single-part RGB OpenEXR image with finite values, or not a valid
    /// PNG, JPEG or Radiance HDR picture; [`Error::ImageSize`] when a side is 0 or larger
    /// than [`crate::image_io::MAX_DIMENSION`] (checked before the pixels are decoded).
    pub fn load(path: &Path) -> Result<EnvironmentMap> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
        let named_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if !named_exr && !bytes.starts_with(&EXR_MAGIC) {
            return Self::from_picture(path, &bytes);
        }
        // The header alone first, so that a huge image is refused before its pixels are
        // decoded; a panic in the decoder is an error naming the file.
        let meta = nacre_format::decode::guarded(
            || {
                exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes[..]), false).map_err(
                    |e| Error::Image {
                        path: path.to_path_buf(),
                        message: format!("not a valid OpenEXR file: {e}"),
                    },
                )
            },
            || Error::Image {
                path: path.to_path_buf(),
                message: "malformed OpenEXR header (the decoder failed)".into(),
            },
        )?;
        if let Some(h) = meta.headers.first() {
            check_image_size(path, "an environment", h.layer_size.0, h.layer_size.1)?;
        }
        let (atlas, _) = nacre_format::table_io::decode_exr_bytes(path, &bytes)?;
        check_image_size(path, "an environment", atlas.width, atlas.height)?;
        Ok(EnvironmentMap {
            width: atlas.width,
            height: atlas.height,
            rgb: atlas
                .data
                .chunks_exact(3)
                .map(|c| [c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)])
                .collect(),
        })
    }

    /// A PNG, JPEG or Radiance HDR environment (see [`EnvironmentMap::load`]).
    fn from_picture(path: &Path, bytes: &[u8]) -> Result<EnvironmentMap> {
        let picture = crate::image_io::decode_picture(path, "an environment", bytes)?;
        let (width, height) = (picture.width() as usize, picture.height() as usize);
        check_image_size(path, "an environment", width, height)?;
        let linear = matches!(
            picture,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        );
        let rgb = picture
            .to_rgb32f()
            .pixels()
            .map(|p| {
                p.0.map(|v| {
                    let v = if v.is_finite() { v.max(0.0) } else { 0.0 };
                    if linear { v } else { srgb_to_linear(v) }
                })
            })
            .collect();
        Ok(EnvironmentMap { width, height, rgb })
    }

    /// The default environment: [`default_environment_path`] when it exists, else the same
    /// image computed by [`procedural_environment`] and rounded to half floats.
    pub fn default_map() -> Result<EnvironmentMap> {
        let path = default_environment_path();
        if path.is_file() {
            return EnvironmentMap::load(&path);
        }
        let (w, h) = DEFAULT_ENVIRONMENT_SIZE;
        let mut env = procedural_environment(w, h);
        for t in &mut env.rgb {
            *t = t.map(|v| f16::from_f32(v).to_f32());
        }
        Ok(env)
    }

    /// Writes the environment as a half-float, ZIP-compressed OpenEXR file (atomically).
    pub fn write_exr(&self, path: &Path) -> Result<()> {
        let table = nacre_format::table_io::Table3 {
            nx: self.width,
            ny: self.height,
            nz: 1,
            data: self.rgb.iter().flatten().copied().collect(),
        };
        Ok(nacre_format::table_io::write_exr(
            path,
            &table,
            nacre_format::table_io::Precision::Half,
        )?)
    }

    /// The mip chain uploaded to the GPU (RGBA, alpha 1).
    pub fn mip_chain(&self) -> Vec<Level<4>> {
        // Rgba16Float holds at most 65504: brighter texels saturate there (not to infinity).
        let texels = self
            .rgb
            .iter()
            .map(|c| [c[0], c[1], c[2]].map(|v| v.clamp(0.0, 65504.0)))
            .map(|c| [c[0], c[1], c[2], 1.0])
            .collect();
        mip_chain(self.width, self.height, texels)
    }
}

/// `a / |a|` (`a` non-zero).
fn unit(a: [f64; 3]) -> [f64; 3] {
    let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / len)
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The default environment, computed: a "studio under an open sky" in linear Rec. 709 RGB
/// radiance (1 = a white diffuse surface under unit irradiance × π), equirectangular as
/// [`EnvironmentMap`] describes:
///
/// * sky: a gradient from a light grey horizon (0.75) to a blue zenith (0.14, 0.26, 0.58);
/// * a sun-like hot spot towards [`SUN_DIRECTION`] (peak 60, angular radius ≈ 2°, plus a
///   wide glow);
/// * five soft rectangular area lights ("softboxes", radiance 2.2 to 6, edges blurred over
///   ≈ 3°): two behind the default cameras (what the sphere reflects), an overhead strip, a
///   large panel ahead and above (what the plane reflects) and a tall narrow strip ahead on
///   the left;
/// * a ground of warm grey tiles (a soft-edged 2-unit checker seen from 1.5 units up, ±22 %),
///   fading to its mean (0.15) with distance, below a soft horizon.
///
/// Every value is finite, non-negative and below the half-float limit. `tables/env/studio.exr`
/// is this function at 256 × 128 in half floats.
pub fn procedural_environment(width: usize, height: usize) -> EnvironmentMap {
    procedural_environment_with(width, height, true)
}

/// [`procedural_environment`] with or without its sun and glow (`sun = false`: the studio
/// and sky only, for scenes whose sun is the directional light alone — the rough-sphere
/// comparisons of `nacre_runtime::rough_reference`).
pub fn procedural_environment_with(width: usize, height: usize, sun_on: bool) -> EnvironmentMap {
    use std::f64::consts::PI;
    let sun = unit(SUN_DIRECTION);
    // Softboxes: (azimuth from, to; elevation from, to) in degrees, radiance RGB. Azimuth 0
    // looks down −z, +90 towards +x, ±180 towards +z (behind the default cameras).
    let boxes: [(f64, f64, f64, f64, [f64; 3]); 5] = [
        (140.0, 162.0, 8.0, 48.0, [6.0, 5.8, 5.4]),
        (-165.0, -128.0, 22.0, 58.0, [3.2, 3.6, 4.2]),
        (-70.0, 70.0, 72.0, 84.0, [4.0, 4.0, 4.0]),
        (-52.0, -40.0, 2.0, 40.0, [3.0, 2.9, 2.7]),
        (-60.0, 60.0, 20.0, 62.0, [2.2, 2.2, 2.3]),
    ];
    let mut rgb = Vec::with_capacity(width * height);
    for j in 0..height {
        let theta = PI * (j as f64 + 0.5) / height as f64;
        for i in 0..width {
            let phi = 2.0 * PI * ((i as f64 + 0.5) / width as f64 - 0.5);
            let dir = [
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            ];
            let y = dir[1];
            // Sky.
            let t = y.max(0.0).powf(0.4);
            let horizon = [0.75, 0.73, 0.7];
            let zenith = [0.14, 0.26, 0.58];
            let sky: [f64; 3] = std::array::from_fn(|c| horizon[c] + (zenith[c] - horizon[c]) * t);
            // Ground: soft-edged checker tiles 2 units wide, 1.5 units below the viewer.
            let down = (-y).max(1e-4);
            let (gx, gz) = (dir[0] * 1.5 / down, dir[2] * 1.5 / down);
            let square = |x: f64| (4.0 * (2.0 * PI * x / 4.0).sin()).clamp(-1.0, 1.0);
            let distance = (gx * gx + gz * gz).sqrt();
            let contrast = 1.0 - smoothstep(6.0, 30.0, distance);
            let tile = 1.0 + 0.22 * square(gx) * square(gz) * contrast;
            let ground = [0.15 * tile, 0.135 * tile, 0.12 * tile];
            let w = smoothstep(-0.012, 0.012, y);
            let mut c: [f64; 3] = std::array::from_fn(|k| ground[k] + (sky[k] - ground[k]) * w);
            // Sun and glow.
            let cos_gamma = (dir[0] * sun[0] + dir[1] * sun[1] + dir[2] * sun[2]).clamp(-1.0, 1.0);
            let gamma = cos_gamma.acos();
            let sun_radiance = if sun_on {
                60.0 * (-(gamma / 0.035).powi(2)).exp() + 1.5 * (-(gamma / 0.3).powi(2)).exp()
            } else {
                0.0
            };
            let sun_colour = [1.0, 0.93, 0.82];
            for k in 0..3 {
                c[k] += sun_radiance * sun_colour[k];
            }
            // Softboxes.
            let azimuth = phi.to_degrees();
            let elevation = 90.0 - theta.to_degrees();
            for &(a0, a1, e0, e1, radiance) in &boxes {
                let edge = 3.0;
                let wa = smoothstep(a0 - edge, a0 + edge, azimuth)
                    * (1.0 - smoothstep(a1 - edge, a1 + edge, azimuth));
                let we = smoothstep(e0 - edge, e0 + edge, elevation)
                    * (1.0 - smoothstep(e1 - edge, e1 + edge, elevation));
                for k in 0..3 {
                    c[k] += wa * we * radiance[k];
                }
            }
            rgb.push(c.map(|v| v.clamp(0.0, 60000.0) as f32));
        }
    }
    EnvironmentMap { width, height, rgb }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): an encoded value in [0, 1]
/// to linear.
fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod picture_tests {
    use super::*;

    /// PNG environments are sRGB-decoded to linear; Radiance HDR ones are read as linear
    /// floats; a junk file named `.png` is an error naming the file.
    #[test]
    fn png_and_hdr_environments_load_as_linear_radiance() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("env.png");
        let img = image::RgbImage::from_fn(4, 2, |x, _| match x {
            0 => image::Rgb([0, 0, 0]),
            1 => image::Rgb([255, 255, 255]),
            _ => image::Rgb([128, 10, 250]),
        });
        img.save(&png).unwrap();
        let env = EnvironmentMap::load(&png).unwrap();
        assert_eq!((env.width, env.height), (4, 2));
        assert_eq!(env.rgb[0], [0.0; 3]);
        assert_eq!(env.rgb[1], [1.0; 3]);
        let expect = [128.0f32, 10.0, 250.0].map(|v| srgb_to_linear(v / 255.0));
        for (got, want) in env.rgb[2].iter().zip(expect) {
            assert!((got - want).abs() < 1e-6, "{:?}", env.rgb[2]);
        }
        assert!((env.rgb[2][0] - 0.2158605).abs() < 1e-6);

        let hdr = dir.path().join("env.hdr");
        let pixels: Vec<f32> = (0..4 * 2)
            .flat_map(|i| [i as f32 * 2.5, 0.25, 40.0])
            .collect();
        image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_raw(4, 2, pixels).unwrap())
            .save(&hdr)
            .unwrap();
        let env = EnvironmentMap::load(&hdr).unwrap();
        assert_eq!((env.width, env.height), (4, 2));
        // Radiance HDR stores an 8-bit mantissa per channel with a shared exponent.
        for (i, t) in env.rgb.iter().enumerate() {
            let want = [i as f32 * 2.5, 0.25, 40.0];
            for c in 0..3 {
                assert!(
                    (t[c] - want[c]).abs() <= want[c].abs() / 64.0 + 1e-3,
                    "{t:?} {want:?}"
                );
            }
        }

        let junk = dir.path().join("junk.png");
        std::fs::write(&junk, b"not a picture").unwrap();
        let e = EnvironmentMap::load(&junk).unwrap_err().to_string();
        assert!(e.contains("junk.png"), "{e}");
    }
}
