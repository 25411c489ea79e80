//! The ΔE2000 comparison: the chosen technique's picture against the same view drawn with
//! the exact technique ([`REFERENCE`], `spectral`: the spectral sum per pixel), as the user
//! sees both — 8-bit sRGB after exposure and tone mapping — so the map shows where a
//! technique's colour is visibly off.
//!
//! Per pixel: the sRGB values are decoded (IEC 61966-2-1: c ≤ 0.04045 → c/12.92, else
//! ((c + 0.055)/1.055)^2.4), taken to XYZ and CIELAB with the D65 white of the sRGB space
//! (CIE 1931 observer; [`Colorimeter::xyz_from_output`], [`xyz_to_lab`]), and compared with
//! CIEDE2000 ([`delta_e_2000`], Sharma, Wu & Dalal 2005). The map paints ΔE on a colour
//! scale from 0 to a chosen maximum ([`scale_colour`]).

use nacre_optics::colour::{
    Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace, delta_e_2000, xyz_to_lab,
};
use nacre_runtime::Technique;
use nacre_runtime::render::RenderedImage;
use std::sync::LazyLock;

/// The technique the comparison takes as the exact colour.
pub const REFERENCE: Technique = Technique::Spectral;

/// The default top of the colour scale, ΔE2000 (a difference of 1 is about the smallest
/// a viewer notices side by side).
pub const DEFAULT_SCALE_MAX: f32 = 5.0;

static SRGB: LazyLock<Colorimeter> = LazyLock::new(|| {
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
});

/// The sRGB transfer function's inverse (IEC 61966-2-1) of an 8-bit value: linear light.
pub fn srgb_to_linear(v: u8) -> f64 {
    let c = f64::from(v) / 255.0;
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light → an 8-bit sRGB-encoded value (clipped to [0, 1]; IEC 61966-2-1).
pub fn linear_to_srgb(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let v = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0).round() as u8
}

/// CIELAB of an 8-bit sRGB pixel (D65 white, Y = 1 for (255, 255, 255)).
pub fn lab_of_srgb8(p: [u8; 3]) -> [f64; 3] {
    let linear = p.map(srgb_to_linear);
    xyz_to_lab(SRGB.xyz_from_output(linear), SRGB.white_xyz())
}

/// The difference map of two pictures and its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct DeltaE {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// ΔE2000 per pixel, row-major.
    pub values: Vec<f32>,
    /// Mean over the picture.
    pub mean: f64,
    /// 95th percentile over the picture (nearest rank).
    pub p95: f64,
    /// Largest.
    pub max: f64,
    /// Pixels that differ at all (ΔE > 0).
    pub differing: usize,
    /// Mean over the differing pixels (0 when none).
    pub mean_differing: f64,
    /// 95th percentile over the differing pixels (0 when none).
    pub p95_differing: f64,
}

/// The nearest-rank `q` quantile of sorted `v` (0 for an empty slice).
fn quantile(sorted: &[f32], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    f64::from(sorted[rank - 1])
}

/// ΔE2000 per pixel between `picture` and `reference` (the same size), or None when their
/// sizes differ.
pub fn delta_e(picture: &RenderedImage, reference: &RenderedImage) -> Option<DeltaE> {
    if (picture.width, picture.height) != (reference.width, reference.height)
        || picture.pixels.len() != reference.pixels.len()
    {
        return None;
    }
    let values: Vec<f32> = picture
        .pixels
        .chunks_exact(4)
        .zip(reference.pixels.chunks_exact(4))
        .map(|(a, b)| {
            if a[..3] == b[..3] {
                0.0
            } else {
                delta_e_2000(
                    lab_of_srgb8([a[0], a[1], a[2]]),
                    lab_of_srgb8([b[0], b[1], b[2]]),
                ) as f32
            }
        })
        .collect();
    let mut sorted = values.clone();
    sorted.sort_by(f32::total_cmp);
    let n = sorted.len().max(1) as f64;
    let mean = sorted.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let first = sorted.partition_point(|&v| v <= 0.0);
    let differ = &sorted[first..];
    let mean_differing = if differ.is_empty() {
        0.0
    } else {
        differ.iter().map(|&v| f64::from(v)).sum::<f64>() / differ.len() as f64
    };
    Some(DeltaE {
        width: picture.width,
        height: picture.height,
        mean,
        p95: quantile(&sorted, 0.95),
        max: sorted.last().map_or(0.0, |&v| f64::from(v)),
        differing: differ.len(),
        mean_differing,
        p95_differing: quantile(differ, 0.95),
        values,
    })
}

/// The colour scale's stops: black (0), blue, magenta, orange, yellow (1, the maximum).
const STOPS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [0.15, 0.2, 0.85],
    [0.8, 0.2, 0.6],
    [1.0, 0.55, 0.1],
    [1.0, 1.0, 0.6],
];

/// The map's 8-bit colour for ΔE = `value` on a scale from 0 to `max` (clipped): linear
/// interpolation between [`STOPS`].
pub fn scale_colour(value: f32, max: f32) -> [u8; 3] {
    let t = if max > 0.0 {
        (value / max).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    std::array::from_fn(|c| {
        let v = STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c]);
        (v * 255.0).round() as u8
    })
}

impl DeltaE {
    /// The map as RGBA8 pixels on a scale from 0 to `max`.
    pub fn map_rgba(&self, max: f32) -> Vec<u8> {
        self.values
            .iter()
            .flat_map(|&v| {
                let [r, g, b] = scale_colour(v, max);
                [r, g, b, 255]
            })
            .collect()
    }
}
