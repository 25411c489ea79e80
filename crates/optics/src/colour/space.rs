//! Linear RGB output spaces (their primaries and whites), the XYZ → RGB matrix of a space,
//! and Bradford chromatic adaptation between whites.

use super::cie::{Illuminant, Observer, xy_to_xyz};
use super::matrix::{Mat3, diag, mat_inv, mat_mul, mat_vec};
use crate::error::{Error, Result};
use std::fmt;
use std::str::FromStr;

/// A linear (scene-referred, no transfer function) RGB colour space, defined by the
/// chromaticities of its three primaries and of its white.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RgbSpace {
    /// Linear sRGB, with the ITU-R BT.709 primaries: R (0.64, 0.33), G (0.30, 0.60),
    /// B (0.15, 0.06), white D65 (0.3127, 0.3290). IEC 61966-2-1:1999. Parsed from `srgb`.
    Srgb,
    /// ITU-R BT.2020 (Rec. 2020): R (0.708, 0.292), G (0.170, 0.797), B (0.131, 0.046),
    /// white D65 (0.3127, 0.3290). Parsed from `rec2020`.
    Rec2020,
    /// Display P3 (the DCI-P3 primaries with a D65 white, SMPTE EG 432-1:2010; Apple's
    /// Display P3): R (0.680, 0.320), G (0.265, 0.690), B (0.150, 0.060), white D65
    /// (0.3127, 0.3290). Parsed from `p3`.
    DisplayP3,
    /// ACEScg, the ACES AP1 primaries (Academy S-2014-004): R (0.713, 0.293),
    /// G (0.165, 0.830), B (0.128, 0.044), with the ACES white (0.32168, 0.33767) of
    /// SMPTE ST 2065-1:2012 (≈ D60; a chromaticity, with no spectrum). Parsed from `acescg`.
    AcesCg,
}

impl RgbSpace {
    /// All four spaces.
    pub const ALL: [RgbSpace; 4] = [
        RgbSpace::Srgb,
        RgbSpace::Rec2020,
        RgbSpace::DisplayP3,
        RgbSpace::AcesCg,
    ];

    /// The short name that [`FromStr`] accepts: `srgb`, `rec2020`, `p3` or `acescg`.
    pub fn name(&self) -> &'static str {
        match self {
            RgbSpace::Srgb => "srgb",
            RgbSpace::Rec2020 => "rec2020",
            RgbSpace::DisplayP3 => "p3",
            RgbSpace::AcesCg => "acescg",
        }
    }

    /// Chromaticities (x, y) of the red, green and blue primaries, as published.
    pub fn primaries_xy(&self) -> [[f64; 2]; 3] {
        match self {
            RgbSpace::Srgb => [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]],
            RgbSpace::Rec2020 => [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]],
            RgbSpace::DisplayP3 => [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]],
            RgbSpace::AcesCg => [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]],
        }
    }

    /// The nominal white chromaticity (x, y), as published: D65 (0.3127, 0.3290), or
    /// the ACES white (0.32168, 0.33767).
    pub fn white_xy(&self) -> [f64; 2] {
        match self {
            RgbSpace::AcesCg => [0.32168, 0.33767],
            _ => [0.3127, 0.3290],
        }
    }

    /// The CIE illuminant whose chromaticity the space's white is: D65 for sRGB,
    /// Rec. 2020 and Display P3; `None` for ACEScg, whose white is a bare chromaticity.
    pub fn white_illuminant(&self) -> Option<Illuminant> {
        match self {
            RgbSpace::AcesCg => None,
            _ => Some(Illuminant::D65),
        }
    }

    /// The space's white XYZ (Y = 1) "computed the same way" as an illuminant white for
    /// `observer`: [`Illuminant::white_xyz`] of [`RgbSpace::white_illuminant`] (so D65
    /// integrated against this observer's CMFs), or, for ACEScg, `xy_to_xyz` of the
    /// nominal white. This is the white that [`Colorimeter`] adapts to.
    pub fn white_xyz(&self, observer: Observer) -> [f64; 3] {
        match self.white_illuminant() {
            Some(illuminant) => illuminant.white_xyz(observer),
            None => xy_to_xyz(self.white_xy()),
        }
    }

    /// The normalised primary matrix (linear RGB → XYZ, white Y = 1) from the published
    /// primaries and nominal white; see [`normalised_primary_matrix`]. For sRGB:
    /// [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]].
    pub fn rgb_to_xyz_matrix(&self) -> Mat3 {
        normalised_primary_matrix(self.primaries_xy(), xy_to_xyz(self.white_xy()))
    }

    /// XYZ → linear RGB, the inverse of [`RgbSpace::rgb_to_xyz_matrix`]. For sRGB it
    /// agrees with IEC 61966-2-1's published [[3.2406, −1.5372, −0.4986],
    /// [−0.9689, 1.8758, 0.0415], [0.0557, −0.2040, 1.0570]] to 4 × 10⁻⁴ (the IEC values
    /// come from a rounded forward matrix).
    pub fn xyz_to_rgb_matrix(&self) -> Mat3 {
        mat_inv(&self.rgb_to_xyz_matrix())
    }
}

impl fmt::Display for RgbSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RgbSpace {
    type Err = Error;

    /// `srgb`, `rec2020`, `p3` or `acescg`, in any case (surrounding spaces ignored).
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "srgb" => Ok(RgbSpace::Srgb),
            "rec2020" => Ok(RgbSpace::Rec2020),
            "p3" => Ok(RgbSpace::DisplayP3),
            "acescg" => Ok(RgbSpace::AcesCg),
            _ => Err(Error::UnknownName {
                what: "RGB space",
                name: s.to_string(),
                expected: "srgb, rec2020, p3, acescg",
            }),
        }
    }
}

/// The normalised primary matrix N (linear RGB → XYZ) of primaries (x, y)ᵣ,g,b and white
/// XYZ `white_xyz`, by the derivation of SMPTE RP 177-1993:
///
/// ```text
/// P = [ xᵣ/yᵣ  x_g/y_g  x_b/y_b ;  1  1  1 ;  zᵣ/yᵣ  z_g/y_g  z_b/y_b ],   z = 1 − x − y
/// S = P⁻¹ · W,    N = P · diag(S)
/// ```
///
/// so that the columns of N are the primaries' XYZ and N·(1, 1, 1) = W exactly (up to
/// rounding).
pub fn normalised_primary_matrix(primaries_xy: [[f64; 2]; 3], white_xyz: [f64; 3]) -> Mat3 {
    let cols = primaries_xy.map(xy_to_xyz);
    let p = [
        [cols[0][0], cols[1][0], cols[2][0]],
        [cols[0][1], cols[1][1], cols[2][1]],
        [cols[0][2], cols[1][2], cols[2][2]],
    ];
    let s = mat_vec(&mat_inv(&p), white_xyz);
    mat_mul(&p, &diag(s))
}

/// The Bradford cone-response matrix M_BFD (XYZ → "sharpened" cone space ρ, γ, β) of
/// Lam (1985), linearised as in ICC.1 (Annex E) and Lindbloom.
pub const BRADFORD: Mat3 = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

/// The linear Bradford chromatic adaptation transform from a source white to a
/// destination white (XYZ, any common scale): a von Kries scaling in the Bradford cone
/// space,
///
/// ```text
/// A = M_BFD⁻¹ · diag(ρ_d/ρ_s, γ_d/γ_s, β_d/β_s) · M_BFD,   (ρ, γ, β)_s,d = M_BFD · W_s,d
/// ```
///
/// so that A·W_s = W_d. Sources: K. M. Lam, *Metamerism and Colour Constancy*, PhD
/// thesis, University of Bradford (1985); ICC.1:2010 Annex E; B. Lindbloom, "Chromatic
/// Adaptation", <http://www.brucelindbloom.com/Eqn_ChromAdapt.html>; reviewed in
/// CIE 160:2004. With Lindbloom's D65 → D50 whites it reproduces his published matrix
/// [[1.0478112, 0.0228866, −0.0501270], …].
pub fn bradford(src_white_xyz: [f64; 3], dst_white_xyz: [f64; 3]) -> Mat3 {
    let s = mat_vec(&BRADFORD, src_white_xyz);
    let d = mat_vec(&BRADFORD, dst_white_xyz);
    let scale = diag([d[0] / s[0], d[1] / s[1], d[2] / s[2]]);
    mat_mul(&mat_inv(&BRADFORD), &mat_mul(&scale, &BRADFORD))
}

/// Where a [`Colorimeter`]'s colours are expressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OutputSpace {
    /// CIE XYZ under the illuminant itself, scaled so that the perfect reflector has
    /// Y = 1 (no chromatic adaptation). Parsed from `xyz`.
    Xyz,
    /// Linear RGB in the given space, adapted so that the perfect reflector is (1, 1, 1).
    /// Parsed from `srgb`, `rec2020`, `p3` or `acescg`.
    Rgb(RgbSpace),
}

impl OutputSpace {
    /// Every output space: XYZ then the RGB spaces.
    pub const ALL: [OutputSpace; 5] = [
        OutputSpace::Xyz,
        OutputSpace::Rgb(RgbSpace::Srgb),
        OutputSpace::Rgb(RgbSpace::Rec2020),
        OutputSpace::Rgb(RgbSpace::DisplayP3),
        OutputSpace::Rgb(RgbSpace::AcesCg),
    ];

    /// The short name that [`FromStr`] accepts: `xyz`, `srgb`, `rec2020`, `p3`, `acescg`.
    pub fn name(&self) -> &'static str {
        match self {
            OutputSpace::Xyz => "xyz",
            OutputSpace::Rgb(space) => space.name(),
        }
    }

    /// Channel names: `["X", "Y", "Z"]` or `["R", "G", "B"]`.
    pub fn channel_names(&self) -> [&'static str; 3] {
        match self {
            OutputSpace::Xyz => ["X", "Y", "Z"],
            OutputSpace::Rgb(_) => ["R", "G", "B"],
        }
    }
}

impl fmt::Display for OutputSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for OutputSpace {
    type Err = Error;

    /// `xyz`, `srgb`, `rec2020`, `p3` or `acescg`, in any case (surrounding spaces
    /// ignored).
    fn from_str(s: &str) -> Result<Self> {
        if s.trim().eq_ignore_ascii_case("xyz") {
            return Ok(OutputSpace::Xyz);
        }
        s.parse::<RgbSpace>()
            .map(OutputSpace::Rgb)
            .map_err(|_| Error::UnknownName {
                what: "output space",
                name: s.to_string(),
                expected: "xyz, srgb, rec2020, p3, acescg",
            })
    }
}
