//! The catalogue of diffraction scenes of `nacre render --scene cd-disc | dvd-disc |
//! snake-skin | grating-plane`: each scene's name, default table, shape, camera, light and
//! Fresnel term (the framing the Mitsuba reference in `python/pysrc/nacre/reference/_scenes.py`
//! copies). How a scene is drawn — its options, uniforms and pass — is in `scene.rs`.

use crate::error::{Error, Result};
use crate::render::{Camera, Light};
use nacre_optics::diffraction::FresnelTerm;
use std::str::FromStr;

/// The diffraction scenes of `nacre render` (`shaders/diffraction_scene.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DiffractionScene {
    /// A CD-like disc (an annulus in y = 0, radius 1) with circular tracks, seen at an angle.
    CdDisc,
    /// A DVD-like disc: the CD's disc, camera and shape with the tracks 0.74 µm apart
    /// (`dvd-tracks`), under a light from the left and nearly overhead that brings the
    /// first orders onto the disc in view ([`DiffractionScene::light`]).
    DvdDisc,
    /// A patch of a cylinder (a snake's body) tiled with domed scales whose ridges run along
    /// the body, rotated and fanned per scale.
    SnakeSkin,
    /// A flat 1200 lines/mm grating: the square |x|, |z| ≤ 1 in the plane y = 0 with its
    /// grooves along x (t = +z across them), seen from the +z side; under the overhead light
    /// its first order runs along the plane's middle from violet (near) to red (far)
    /// ([`DiffractionScene::camera`], [`DiffractionScene::light`]: the framing the Mitsuba
    /// reference copies).
    GratingPlane,
}

impl DiffractionScene {
    /// Every scene.
    pub const ALL: [DiffractionScene; 4] = [
        DiffractionScene::CdDisc,
        DiffractionScene::DvdDisc,
        DiffractionScene::SnakeSkin,
        DiffractionScene::GratingPlane,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            DiffractionScene::CdDisc => "cd-disc",
            DiffractionScene::DvdDisc => "dvd-disc",
            DiffractionScene::SnakeSkin => "snake-skin",
            DiffractionScene::GratingPlane => "grating-plane",
        }
    }

    /// The default-set table the scene uses.
    pub fn default_table(self) -> &'static str {
        match self {
            DiffractionScene::CdDisc => "cd-tracks",
            DiffractionScene::DvdDisc => "dvd-tracks",
            DiffractionScene::SnakeSkin => "snake-ridges",
            DiffractionScene::GratingPlane => "grating-1200",
        }
    }

    /// The geometry's number in `shaders/diffraction_scene.wgsl` (`view.scene`): the DVD
    /// is the CD's disc.
    pub(super) fn id(self) -> u32 {
        match self {
            DiffractionScene::CdDisc | DiffractionScene::DvdDisc => 0,
            DiffractionScene::SnakeSkin => 1,
            DiffractionScene::GratingPlane => 3,
        }
    }

    /// The scene's camera (a pinhole, vertical field of view `fov_y_deg`, square pixels; the
    /// image's aspect ratio is the render's width / height). `grating-plane`: eye
    /// (0, 1.8, 2.0), looking at the origin, y up, 40°; `dvd-disc` the CD's.
    pub fn camera(self) -> Camera {
        match self {
            DiffractionScene::CdDisc | DiffractionScene::DvdDisc => Camera {
                eye: [0.0, 1.9, 2.2],
                target: [0.0, -0.12, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 40.0,
            },
            DiffractionScene::SnakeSkin => Camera {
                eye: [0.35, 2.6, 2.3],
                target: [0.0, 0.55, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 42.0,
            },
            DiffractionScene::GratingPlane => Camera {
                eye: [0.0, 1.8, 2.0],
                target: [0.0, 0.0, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_deg: 40.0,
            },
        }
    }

    /// The scene's Fresnel factor: 1 for the discs and the grating plane (aluminium-coated,
    /// ~90 %), the Fresnel reflectance of keratin (n = 1.56, about 5 % at normal incidence) for the
    /// snake's scales.
    pub fn fresnel(self) -> FresnelTerm {
        match self {
            DiffractionScene::CdDisc
            | DiffractionScene::DvdDisc
            | DiffractionScene::GratingPlane => FresnelTerm::Unity,
            DiffractionScene::SnakeSkin => FresnelTerm::Index(nacre_optics::C64::new(1.56, 0.0)),
        }
    }

    /// The scene's light: a white directional light (the sun) from behind and to the left
    /// of the camera for the CD, from the left and nearly overhead for the DVD, from above and behind for the snake, straight overhead
    /// (towards the light (0, 1, 0)) for the grating plane. The grating equation for the
    /// tangential components along t (Stam 1999: peaks of |P̃(k u, k v)|² at u = mλ/d),
    /// ω_i·t + ω_r·t = mλ/d with ω_r·t = sin θ_r (θ_r from the normal, positive towards the
    /// camera, +z), then puts the first order m = 1 at sin θ_r = λ/d (d = 0.8333 µm: 27.1° at
    /// 380 nm, 41.8° at 555 nm, 69.4° at 780 nm), where the camera sees the plane's middle
    /// line x = 0.
    ///
    /// The DVD's light comes from the left, 16.7° from the zenith (towards the light
    /// (−0.3, 1, 0)), not from the CD's direction: on circular tracks t is the radial
    /// direction and the first order lies where |ω_i·t + ω_r·t| = λ/d with
    /// ω_i·s + ω_r·s = 0 along the tracks (s). Under the CD's light the disc in view offers
    /// |ω_i·t + ω_r·t| from 0.12 to 0.68 on that line, enough for the CD's 1.6 µm pitch
    /// (λ/d = 0.24 to 0.49) but only up to 505 nm for the DVD's d = 0.74 µm (λ/d = 0.51 at
    /// 380 nm, 0.75 at 555 nm, 0.94 at 700 nm); under this light it offers 0.57 to 0.94,
    /// the DVD's first order from 419 to 694 nm (no pixel between 578 and 619 nm, where the
    /// line crosses the disc's hole) — counted on a 128² picture of the scene's camera.
    pub fn light(self) -> Light {
        match self {
            DiffractionScene::CdDisc => Light {
                direction: [-0.35, 0.8, -0.5],
                colour: [1.0, 0.97, 0.92],
                intensity: 3.0,
            },
            DiffractionScene::DvdDisc => Light {
                direction: [-0.3, 1.0, 0.0],
                colour: [1.0, 0.97, 0.92],
                intensity: 3.0,
            },
            DiffractionScene::SnakeSkin => Light {
                direction: [0.3, 0.85, -0.45],
                colour: [1.0, 0.97, 0.92],
                intensity: 3.0,
            },
            DiffractionScene::GratingPlane => Light {
                direction: [0.0, 1.0, 0.0],
                colour: [1.0, 0.97, 0.92],
                intensity: 3.0,
            },
        }
    }
}

impl FromStr for DiffractionScene {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        DiffractionScene::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::UnknownName {
                what: "diffraction scene",
                name: s.to_string(),
                expected: "cd-disc, dvd-disc, snake-skin or grating-plane".into(),
            })
    }
}
