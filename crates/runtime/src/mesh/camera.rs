//! The glTF renderer's cameras: an orbit fitted to the scene's bounds, or one of the file's
//! own (glTF 2.0 §3.10), as a view-projection with depth in [0, 1].

use crate::error::{Error, Result};
use crate::gltf_scene::{GltfCamera, GltfPrimitive, GltfProjection, GltfScene};
use nacre_format::msg;
use nacre_format::param::Param;

/// A camera for the glTF renderer: eye, target, up and field of view (for the view uniform
/// and the background) and its view-projection (world → clip, column-major, depth in [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedCamera {
    /// Eye position (for an orthographic camera, a point far behind it along the view
    /// direction, so that every view vector is nearly parallel).
    pub eye: [f32; 3],
    /// A point on the view axis in front of the eye (the box centre for an orbit camera).
    pub target: [f32; 3],
    /// The camera's up direction.
    pub up: [f32; 3],
    /// Vertical field of view, degrees (the background's; 1° for an orthographic camera).
    pub fov_y_deg: f32,
    /// World → clip.
    pub view_proj: [[f32; 4]; 4],
}

/// An orbit camera around the scene's bounding box: `nacre render --yaw --pitch --distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Rotation about +y of the direction from the box centre to the eye, degrees (0: the
    /// eye on the +z side; 90: on the +x side).
    pub yaw_deg: f64,
    /// Elevation of the eye above the box centre's horizontal plane, degrees, in (−89, 89).
    pub pitch_deg: f64,
    /// Distance from the box centre, world units (None: the smallest at which the whole box
    /// is in the frame, with a 5 % margin).
    pub distance: Option<f64>,
}

/// The default orbit's elevation: the direction (0, 0.2, 1), atan(0.2) = 11.31°.
pub const DEFAULT_PITCH_DEG: f64 = 11.309_932_474_020_215;

impl Default for Orbit {
    fn default() -> Self {
        Orbit {
            yaw_deg: 0.0,
            pitch_deg: DEFAULT_PITCH_DEG,
            distance: None,
        }
    }
}

/// Where the glTF renderer looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewPoint {
    /// An orbit camera fitted to the scene's bounds.
    Orbit(Orbit),
    /// The file's camera K (0-based, [`GltfScene::cameras`]).
    File(usize),
}

impl Default for ViewPoint {
    fn default() -> Self {
        ViewPoint::Orbit(Orbit::default())
    }
}

/// Largest vertical field of view of the fitted camera, degrees.
pub const FIT_FOV_Y_DEG: f64 = 30.0;

/// Largest horizontal field of view of the fitted camera, degrees.
pub const FIT_FOV_X_DEG: f64 = 40.0;

/// Fits a camera to the box (lo, hi) for an image of aspect `aspect` (width / height): it
/// looks at the box centre along −z, from slightly above (the direction (0, 0.2, 1)), with
/// the field of view of [`FIT_FOV_Y_DEG`] × [`FIT_FOV_X_DEG`] at most, at the
/// smallest distance at which every corner lies inside the frame (5 % margin); near and far
/// planes enclose the box.
pub fn fit_camera(lo: [f32; 3], hi: [f32; 3], aspect: f64) -> Result<FittedCamera> {
    orbit_camera(lo, hi, aspect, &Orbit::default())
}

/// [`fit_camera`] from any orbit: the eye in the direction (sin ψ cos φ, sin φ, cos ψ cos φ)
/// from the box centre (yaw ψ, pitch φ), at `orbit.distance` or the fitted distance.
pub fn orbit_camera(
    lo: [f32; 3],
    hi: [f32; 3],
    aspect: f64,
    orbit: &Orbit,
) -> Result<FittedCamera> {
    let bad = |problem: String| Error::Camera {
        name: None,
        problem,
    };
    if !lo.iter().chain(&hi).all(|x| x.is_finite()) || (0..3).any(|k| lo[k] > hi[k]) {
        return Err(bad(format!("scene bounds {lo:?} – {hi:?}")));
    }
    if !(aspect > 0.0 && aspect.is_finite()) {
        return Err(bad(format!("aspect ratio {aspect}")));
    }
    let refused = |param: Param, value: String, expected: &str| Error::Refused {
        context: "camera".into(),
        message: msg![param.given(value), format!(": expected {expected}")],
    };
    if !orbit.yaw_deg.is_finite() {
        return Err(refused(
            Param::Yaw,
            orbit.yaw_deg.to_string(),
            "a finite angle in degrees",
        ));
    }
    if orbit.pitch_deg.is_nan() || orbit.pitch_deg.abs() >= 89.0 {
        return Err(refused(
            Param::Pitch,
            orbit.pitch_deg.to_string(),
            "degrees between −89 and 89",
        ));
    }
    if let Some(d) = orbit.distance
        && !(d > 0.0 && d.is_finite())
    {
        return Err(refused(
            Param::Distance,
            d.to_string(),
            "a positive distance in the file's units",
        ));
    }
    let c: [f64; 3] = std::array::from_fn(|k| 0.5 * (f64::from(lo[k]) + f64::from(hi[k])));
    let extent: f64 = (0..3)
        .map(|k| f64::from(hi[k]) - f64::from(lo[k]))
        .fold(0.0, f64::max)
        .max(1e-6);
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let b = if *orbit == Orbit::default() {
        // The default direction exactly as before `Orbit` (golden images).
        let v = [0.0, 0.2, 1.0];
        let l = len(v);
        v.map(|x| x / l)
    } else {
        let (yaw, pitch) = (orbit.yaw_deg.to_radians(), orbit.pitch_deg.to_radians());
        [
            yaw.sin() * pitch.cos(),
            pitch.sin(),
            yaw.cos() * pitch.cos(),
        ]
    };
    // Basis: back b (towards the eye), right = up × b, true up = b × right.
    let right = {
        let v = [b[2], 0.0, -b[0]];
        let l = len(v);
        v.map(|x| x / l)
    };
    let up = [
        b[1] * right[2] - b[2] * right[1],
        b[2] * right[0] - b[0] * right[2],
        b[0] * right[1] - b[1] * right[0],
    ];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // At most FIT_FOV_Y_DEG vertically and FIT_FOV_X_DEG horizontally (a wide image gets a
    // longer lens rather than the stretched edges of a wide angle).
    let ty = (0.5 * FIT_FOV_Y_DEG.to_radians())
        .tan()
        .min((0.5 * FIT_FOV_X_DEG.to_radians()).tan() / aspect);
    let tx = ty * aspect;
    let mut distance: f64 = 0.0;
    let mut depth: f64 = 0.0;
    for corner in 0..8 {
        let p: [f64; 3] = std::array::from_fn(|k| {
            let v = if corner >> k & 1 == 1 { hi[k] } else { lo[k] };
            f64::from(v) - c[k]
        });
        let (x, y, z) = (dot(p, right), dot(p, up), dot(p, b));
        distance = distance.max(z + (x.abs() / tx).max(y.abs() / ty));
        depth = depth.max(len(p));
    }
    let distance = orbit
        .distance
        .unwrap_or((distance * 1.05).max(extent * 1e-3));
    let eye: [f64; 3] = std::array::from_fn(|k| c[k] + distance * b[k]);
    let near = (distance - depth * 1.1).max(distance * 1e-3);
    let far = distance + depth * 1.1 + extent * 1e-3;
    let f = 1.0 / ty;
    let (pa, pb) = (far / (near - far), near * far / (near - far));
    // View: rows right, up, b; translation −(row · eye).
    let view = [
        [right[0], right[1], right[2], -dot(right, eye)],
        [up[0], up[1], up[2], -dot(up, eye)],
        [b[0], b[1], b[2], -dot(b, eye)],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let proj = [
        [f / aspect, 0.0, 0.0, 0.0],
        [0.0, f, 0.0, 0.0],
        [0.0, 0.0, pa, pb],
        [0.0, 0.0, -1.0, 0.0],
    ];
    let m: [[f64; 4]; 4] = std::array::from_fn(|r| {
        std::array::from_fn(|col| (0..4).map(|k| proj[r][k] * view[k][col]).sum())
    });
    Ok(FittedCamera {
        eye: eye.map(|x| x as f32),
        target: c.map(|x| x as f32),
        up: up.map(|x| x as f32),
        fov_y_deg: (2.0 * ty.atan()).to_degrees() as f32,
        view_proj: std::array::from_fn(|col| std::array::from_fn(|r| m[r][col] as f32)),
    })
}

/// The file's camera `camera` for an image of aspect `aspect` (glTF 2.0 §3.10): the node's
/// world transform with its scale removed (axes normalised, up re-orthogonalised) is the
/// camera-to-world transform, looking down −z. Perspective: `yfov` and the image's aspect
/// (not the file's `aspectRatio`, so the picture is never stretched), `znear`, and `zfar` or
/// an infinite far plane. Orthographic: `ymag` and a width of `ymag` × the aspect. The box
/// (lo, hi) sets the shading eye of an orthographic camera.
pub fn file_camera(
    camera: &GltfCamera,
    lo: [f32; 3],
    hi: [f32; 3],
    aspect: f64,
) -> Result<FittedCamera> {
    let bad = |problem: String| Error::Camera {
        name: Some(camera.name.clone()),
        problem,
    };
    if !(aspect > 0.0 && aspect.is_finite()) {
        return Err(bad(format!("aspect ratio {aspect}")));
    }
    let w = camera.world.map(|c| c.map(f64::from));
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let unit = |v: [f64; 3]| {
        let l = len(v);
        (l > 1e-12 && l.is_finite()).then(|| v.map(|x| x / l))
    };
    let axis = |k: usize| [w[k][0], w[k][1], w[k][2]];
    let eye = [w[3][0], w[3][1], w[3][2]];
    let (Some(b), Some(x)) = (unit(axis(2)), unit(axis(0))) else {
        return Err(bad("its node's transform has a zero axis".into()));
    };
    let Some(up) = unit(cross(b, x)) else {
        return Err(bad("its node's x and z axes are parallel".into()));
    };
    let right = cross(up, b);
    let extent: f64 = (0..3)
        .map(|k| f64::from(hi[k]) - f64::from(lo[k]))
        .fold(0.0, f64::max)
        .max(1e-6);
    let (proj, shading_eye, fov_y_deg) = match camera.projection {
        GltfProjection::Perspective {
            yfov_rad,
            znear,
            zfar,
        } => {
            let f = 1.0 / (0.5 * f64::from(yfov_rad)).tan();
            let near = f64::from(znear);
            let (pa, pb) = match zfar {
                Some(far) => {
                    let far = f64::from(far);
                    (far / (near - far), near * far / (near - far))
                }
                None => (-1.0, -near),
            };
            let proj = [
                [f / aspect, 0.0, 0.0, 0.0],
                [0.0, f, 0.0, 0.0],
                [0.0, 0.0, pa, pb],
                [0.0, 0.0, -1.0, 0.0],
            ];
            (proj, eye, f64::from(yfov_rad).to_degrees())
        }
        GltfProjection::Orthographic {
            ymag, znear, zfar, ..
        } => {
            let (near, far) = (f64::from(znear), f64::from(zfar));
            let ymag = f64::from(ymag);
            let proj = [
                [1.0 / (ymag * aspect), 0.0, 0.0, 0.0],
                [0.0, 1.0 / ymag, 0.0, 0.0],
                [0.0, 0.0, 1.0 / (near - far), near / (near - far)],
                [0.0, 0.0, 0.0, 1.0],
            ];
            let back = 1e4 * extent.max(far);
            (proj, std::array::from_fn(|k| eye[k] + back * b[k]), 1.0)
        }
    };
    let view = [
        [right[0], right[1], right[2], -dot(right, eye)],
        [up[0], up[1], up[2], -dot(up, eye)],
        [b[0], b[1], b[2], -dot(b, eye)],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let m: [[f64; 4]; 4] = std::array::from_fn(|r| {
        std::array::from_fn(|col| (0..4).map(|k| proj[r][k] * view[k][col]).sum())
    });
    if !m.iter().flatten().all(|x| x.is_finite()) {
        return Err(bad("its view-projection is not finite".into()));
    }
    Ok(FittedCamera {
        eye: shading_eye.map(|x| x as f32),
        target: std::array::from_fn(|k| (eye[k] - b[k]) as f32),
        up: up.map(|x| x as f32),
        fov_y_deg: fov_y_deg as f32,
        view_proj: std::array::from_fn(|col| std::array::from_fn(|r| m[r][col] as f32)),
    })
}

/// The camera of `view` for `scene` and an image of aspect `aspect` (width / height): checks
/// the orbit's angles and distance, or that the file has the camera asked for.
pub fn view_camera(scene: &GltfScene, view: ViewPoint, aspect: f64) -> Result<FittedCamera> {
    let (lo, hi) = scene.bounds();
    match view {
        ViewPoint::Orbit(orbit) => orbit_camera(lo, hi, aspect, &orbit),
        ViewPoint::File(k) => match scene.cameras.get(k) {
            Some(c) => file_camera(c, lo, hi, aspect),
            None => Err(Error::Refused {
                context: format!("glTF {}", scene.path.display()),
                message: msg![
                    Param::Camera.given(k.to_string()),
                    format!(
                        ": the file has {} camera(s), numbered from 0",
                        scene.cameras.len()
                    )
                ],
            }),
        },
    }
}

/// The clip-space w (distance along the view axis) of a primitive's bounding-box centre:
/// the sort key of blended primitives (larger = farther, drawn first).
pub(super) fn view_depth(camera: &FittedCamera, p: &GltfPrimitive) -> f64 {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for x in &p.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    let c: [f32; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let m = camera.view_proj;
    let w = m[0][3] * c[0] + m[1][3] * c[1] + m[2][3] * c[2] + m[3][3];
    if w.is_finite() { f64::from(w) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_camera_frames_every_corner() {
        let (lo, hi) = ([-5.0, -1.0, -1.0], [5.0, 1.0, 1.0]);
        let cam = fit_camera(lo, hi, 4.0).unwrap();
        let m = cam.view_proj;
        for corner in 0..8 {
            let p: [f32; 3] =
                std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            let clip: [f32; 4] =
                std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
            let ndc = [clip[0] / clip[3], clip[1] / clip[3], clip[2] / clip[3]];
            assert!(ndc[0].abs() <= 1.0 && ndc[1].abs() <= 1.0, "{ndc:?}");
            assert!((0.0..=1.0).contains(&ndc[2]), "{ndc:?}");
        }
        assert!(fit_camera([0.0; 3], [f32::NAN; 3], 1.0).is_err());
    }

    fn project(m: &[[f32; 4]; 4], p: [f32; 3]) -> [f32; 3] {
        let clip: [f32; 4] =
            std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
        [clip[0] / clip[3], clip[1] / clip[3], clip[2] / clip[3]]
    }

    #[test]
    fn orbits_turn_around_the_box_and_still_frame_it() {
        let (lo, hi) = ([-1.0, -0.5, -2.0], [1.0, 0.5, 2.0]);
        assert_eq!(
            orbit_camera(lo, hi, 1.5, &Orbit::default()).unwrap(),
            fit_camera(lo, hi, 1.5).unwrap()
        );
        for (yaw, pitch) in [(90.0, 0.0), (-45.0, 60.0), (180.0, -30.0)] {
            let orbit = Orbit {
                yaw_deg: yaw,
                pitch_deg: pitch,
                distance: None,
            };
            let cam = orbit_camera(lo, hi, 1.5, &orbit).unwrap();
            // The eye lies in the orbit's direction from the centre.
            let d: [f32; 3] = std::array::from_fn(|k| cam.eye[k] - cam.target[k]);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let (y, p) = (f64::to_radians(yaw), f64::to_radians(pitch));
            let want = [y.sin() * p.cos(), p.sin(), y.cos() * p.cos()];
            for k in 0..3 {
                assert!(
                    (f64::from(d[k] / len) - want[k]).abs() < 1e-5,
                    "{d:?} {want:?}"
                );
            }
            for corner in 0..8 {
                let q: [f32; 3] =
                    std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
                let ndc = project(&cam.view_proj, q);
                assert!(
                    ndc[0].abs() <= 1.0 && ndc[1].abs() <= 1.0,
                    "{yaw} {pitch}: {ndc:?}"
                );
                assert!((0.0..=1.0).contains(&ndc[2]), "{ndc:?}");
            }
        }
        // A given distance is kept.
        let far = Orbit {
            distance: Some(40.0),
            ..Orbit::default()
        };
        let cam = orbit_camera(lo, hi, 1.0, &far).unwrap();
        let d: f32 = (0..3).map(|k| (cam.eye[k] - cam.target[k]).powi(2)).sum();
        assert!((d.sqrt() - 40.0).abs() < 1e-4);
        // Bad angles and distances name their parameter.
        for (orbit, param) in [
            (
                Orbit {
                    pitch_deg: 90.0,
                    ..Orbit::default()
                },
                Param::Pitch,
            ),
            (
                Orbit {
                    yaw_deg: f64::NAN,
                    ..Orbit::default()
                },
                Param::Yaw,
            ),
            (
                Orbit {
                    distance: Some(-1.0),
                    ..Orbit::default()
                },
                Param::Distance,
            ),
        ] {
            match orbit_camera(lo, hi, 1.0, &orbit) {
                Err(Error::Refused { message, .. }) => {
                    assert!(message.to_string().starts_with(param.name()), "{message}")
                }
                other => panic!("{orbit:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn file_cameras_look_down_their_nodes_minus_z() {
        // A perspective camera at (0, 1, 5), turned 90° about +y (it looks along −x), with a
        // uniform scale of 2 that must not matter.
        let (c, s) = (0.0f32, 1.0f32);
        let world = [
            [2.0 * c, 0.0, -2.0 * s, 0.0],
            [0.0, 2.0, 0.0, 0.0],
            [2.0 * s, 0.0, 2.0 * c, 0.0],
            [0.0, 1.0, 5.0, 1.0],
        ];
        let camera = GltfCamera {
            name: "test".into(),
            world,
            projection: GltfProjection::Perspective {
                yfov_rad: 0.8,
                znear: 0.1,
                zfar: Some(100.0),
            },
        };
        let cam = file_camera(&camera, [-1.0; 3], [1.0; 3], 2.0).unwrap();
        assert_eq!(cam.eye, [0.0, 1.0, 5.0]);
        let ahead = project(&cam.view_proj, [-3.0, 1.0, 5.0]);
        assert!(ahead[0].abs() < 1e-6 && ahead[1].abs() < 1e-6, "{ahead:?}");
        assert!((0.0..1.0).contains(&ahead[2]));
        // Up in the world is up in the picture; the field of view is yfov.
        let above = project(&cam.view_proj, [-3.0, 1.0 + 3.0 * (0.4f32).tan(), 5.0]);
        assert!((above[1] - 1.0).abs() < 1e-4, "{above:?}");
        assert!((cam.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4);
        // Behind the camera is outside the depth range; an infinite far plane works.
        let behind = project(&cam.view_proj, [3.0, 1.0, 5.0]);
        assert!(!(0.0..=1.0).contains(&behind[2]) || behind[0].abs() > 1.0);
        let infinite = GltfCamera {
            projection: GltfProjection::Perspective {
                yfov_rad: 0.8,
                znear: 0.1,
                zfar: None,
            },
            ..camera.clone()
        };
        let cam = file_camera(&infinite, [-1.0; 3], [1.0; 3], 2.0).unwrap();
        let far_away = project(&cam.view_proj, [-1e5, 1.0, 5.0]);
        assert!((0.0..=1.0).contains(&far_away[2]), "{far_away:?}");
        // Orthographic: ymag is the half-height.
        let ortho = GltfCamera {
            projection: GltfProjection::Orthographic {
                xmag: 3.0,
                ymag: 1.5,
                znear: 0.0,
                zfar: 50.0,
            },
            ..camera
        };
        let cam = file_camera(&ortho, [-1.0; 3], [1.0; 3], 2.0).unwrap();
        let top = project(&cam.view_proj, [-10.0, 2.5, 5.0]);
        assert!((top[1] - 1.0).abs() < 1e-5, "{top:?}");
        let side = project(&cam.view_proj, [-10.0, 1.0, 5.0 - 3.0]);
        assert!((side[0].abs() - 1.0).abs() < 1e-5, "{side:?}");
    }
}
