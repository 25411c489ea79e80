//! What the plots beside the view show, computed by the CLI's library calls: the stack's
//! reflectance and transmittance spectra at one angle (s, p, unpolarised;
//! `nacre spectrum`'s [`nacre_bake::commands::spectrum::compute`]) and its exact colour
//! against the angle (`nacre color`'s spectral method, [`exact_colours`]); the unpolarised
//! spectra at a family of angles ([`FAMILY_ANGLES_DEG`]); the exact colour at 0° against the
//! top film's thickness ([`THICKNESS_SWEEP_NM`]); and the chromaticity trajectories (CIE 1931
//! xy = (X, Y)/(X + Y + Z), D65) as the angle and as the thickness vary.

use nacre_bake::commands::color::{Method, Point, Quantity};
use nacre_bake::commands::color_request::{self, ColorRequest, ColourSettings};
use nacre_optics::Stack;

/// The spectra's wavelength range and step, nm (the visible range of `nacre spectrum`'s
/// default, 380–780 nm, every 2 nm).
pub const WAVELENGTHS_NM: (f64, f64, f64) = (380.0, 780.0, 2.0);

/// The angles of the colour-against-angle strip, degrees (0 to 89 every degree).
pub const STRIP_ANGLES_DEG: usize = 90;

/// The angles of the spectra family, degrees.
pub const FAMILY_ANGLES_DEG: [f64; 4] = [0.0, 30.0, 60.0, 75.0];

/// The top film's thickness sweep, nm: from, to, step.
pub const THICKNESS_SWEEP_NM: (f64, f64, f64) = (0.0, 1000.0, 5.0);

/// Spectra at one angle and colours against angle.
#[derive(Clone, Debug, PartialEq)]
pub struct Curves {
    /// The incidence angle of the spectra, degrees in the ambient.
    pub angle_deg: f64,
    /// Wavelengths, nm.
    pub wavelengths_nm: Vec<f64>,
    /// R_s, R_p, R (unpolarised) per wavelength.
    pub reflectance: [Vec<f64>; 3],
    /// T_s, T_p, T per wavelength.
    pub transmittance: [Vec<f64>; 3],
    /// The exact reflectance colour (linear sRGB, D65, CIE 1931) at 0°, 1°, … 89°.
    pub colour_by_angle: Vec<[f64; 3]>,
    /// R (unpolarised) per wavelength at each of [`FAMILY_ANGLES_DEG`].
    pub family_reflectance: Vec<Vec<f64>>,
    /// T (unpolarised) per wavelength at each of [`FAMILY_ANGLES_DEG`].
    pub family_transmittance: Vec<Vec<f64>>,
    /// The top film's thicknesses of the sweep, nm (empty without a film).
    pub thicknesses_nm: Vec<f64>,
    /// The exact reflectance colour (linear sRGB) at 0° at each of `thicknesses_nm`.
    pub colour_by_thickness: Vec<[f64; 3]>,
    /// CIE 1931 xy of the reflected colour at 0°, 1°, … 89°.
    pub xy_by_angle: Vec<[f64; 2]>,
    /// CIE 1931 xy of the reflected colour at 0° at each of `thicknesses_nm`.
    pub xy_by_thickness: Vec<[f64; 2]>,
}

/// The thicknesses of [`THICKNESS_SWEEP_NM`].
pub fn thicknesses() -> Vec<f64> {
    let (lo, hi, step) = THICKNESS_SWEEP_NM;
    let n = ((hi - lo) / step).round() as usize;
    (0..=n).map(|k| lo + step * k as f64).collect()
}

/// xy = (X, Y)/(X + Y + Z); a black colour (X + Y + Z = 0) has the white point's (D65:
/// 0.3127, 0.3290).
pub fn chromaticity(xyz: [f64; 3]) -> [f64; 2] {
    let sum = xyz[0] + xyz[1] + xyz[2];
    if sum > 0.0 {
        [xyz[0] / sum, xyz[1] / sum]
    } else {
        [0.3127, 0.3290]
    }
}

/// The wavelengths of [`WAVELENGTHS_NM`].
pub fn wavelengths() -> Vec<f64> {
    let (lo, hi, step) = WAVELENGTHS_NM;
    let n = ((hi - lo) / step).round() as usize;
    (0..=n).map(|k| lo + step * k as f64).collect()
}

/// The exact (spectral) reflectance colour of `stack` at each angle, degrees: what
/// `nacre color --method spectral` prints (linear sRGB, D65, CIE 1931).
pub fn exact_colours(stack: &Stack, angles_deg: &[f64]) -> nacre_bake::Result<Vec<[f64; 3]>> {
    let points: Vec<Point> = angles_deg
        .iter()
        .map(|&angle_deg| Point {
            angle_deg,
            thickness_nm: None,
            film_ior: None,
        })
        .collect();
    exact_colours_at(stack, &points, None)
}

/// The exact (spectral) reflectance colour of `stack` at `points` (angle, and the top
/// film's thickness) in `space` (None: linear sRGB; `Some("xyz")`: CIE XYZ), D65, CIE 1931:
/// `nacre color --method spectral --space SPACE`.
pub fn exact_colours_at(
    stack: &Stack,
    points: &[Point],
    space: Option<&str>,
) -> nacre_bake::Result<Vec<[f64; 3]>> {
    if points.is_empty() {
        return Ok(Vec::new());
    }
    let prepared = color_request::prepare(
        stack,
        Method::Spectral,
        &ColorRequest {
            method: "spectral",
            roughness: None,
            colour: ColourSettings {
                space,
                ..ColourSettings::default()
            },
            fourier_table: None,
        },
    )?;
    let out = color_request::compute(stack, points, &prepared, Quantity::Reflectance)?;
    Ok(out.colours)
}

/// The curves of `stack` with the spectra at `angle_deg`.
pub fn compute(stack: &Stack, angle_deg: f64) -> nacre_bake::Result<Curves> {
    let wavelengths_nm = wavelengths();
    let powers = nacre_bake::commands::spectrum::compute(stack, &[angle_deg], &wavelengths_nm)?;
    let pick = |f: &dyn Fn(&nacre_optics::Power) -> f64| powers.iter().map(f).collect::<Vec<_>>();
    let reflectance = [pick(&|p| p.R_s), pick(&|p| p.R_p), pick(&|p| p.R())];
    let transmittance = [pick(&|p| p.T_s), pick(&|p| p.T_p), pick(&|p| p.T())];
    let angles: Vec<f64> = (0..STRIP_ANGLES_DEG).map(|a| a as f64).collect();
    let colour_by_angle = exact_colours(stack, &angles)?;
    let mut family_reflectance = Vec::new();
    let mut family_transmittance = Vec::new();
    for a in FAMILY_ANGLES_DEG {
        let powers = nacre_bake::commands::spectrum::compute(stack, &[a], &wavelengths_nm)?;
        family_reflectance.push(powers.iter().map(|p| p.R()).collect());
        family_transmittance.push(powers.iter().map(|p| p.T()).collect());
    }
    let at = |angle_deg: f64, thickness_nm: Option<f64>| Point {
        angle_deg,
        thickness_nm,
        film_ior: None,
    };
    let thicknesses_nm = if stack.layers().is_empty() {
        Vec::new()
    } else {
        thicknesses()
    };
    let by_thickness: Vec<Point> = thicknesses_nm.iter().map(|&d| at(0.0, Some(d))).collect();
    let colour_by_thickness = exact_colours_at(stack, &by_thickness, None)?;
    let by_angle: Vec<Point> = angles.iter().map(|&a| at(a, None)).collect();
    let xy = |xyz: Vec<[f64; 3]>| xyz.into_iter().map(chromaticity).collect::<Vec<_>>();
    let xy_by_angle = xy(exact_colours_at(stack, &by_angle, Some("xyz"))?);
    let xy_by_thickness = xy(exact_colours_at(stack, &by_thickness, Some("xyz"))?);
    Ok(Curves {
        angle_deg,
        wavelengths_nm,
        reflectance,
        transmittance,
        colour_by_angle,
        family_reflectance,
        family_transmittance,
        thicknesses_nm,
        colour_by_thickness,
        xy_by_angle,
        xy_by_thickness,
    })
}

/// A background worker for [`compute`]: the newest request wins, so that dragging a slider
/// never queues stale work; the UI polls [`CurveWorker::take`] every frame.
pub struct CurveWorker {
    request: std::sync::mpsc::Sender<(u64, Stack, f64)>,
    result: std::sync::mpsc::Receiver<(u64, Result<Curves, String>)>,
    sent: u64,
}

impl Default for CurveWorker {
    fn default() -> Self {
        Self::new()
    }
}

impl CurveWorker {
    /// Starts the worker thread.
    pub fn new() -> CurveWorker {
        let (request, requests) = std::sync::mpsc::channel::<(u64, Stack, f64)>();
        let (results, result) = std::sync::mpsc::channel();
        std::thread::Builder::new()
            .name("nacre-studio curves".into())
            .spawn(move || {
                while let Ok(mut job) = requests.recv() {
                    // Skip to the newest request.
                    while let Ok(newer) = requests.try_recv() {
                        job = newer;
                    }
                    let (id, stack, angle) = job;
                    let out = compute(&stack, angle).map_err(|e| e.to_string());
                    if results.send((id, out)).is_err() {
                        break;
                    }
                }
            })
            .expect("the curve worker thread starts");
        CurveWorker {
            request,
            result,
            sent: 0,
        }
    }

    /// Asks for the curves of `stack` at `angle_deg`; returns the request's number.
    pub fn ask(&mut self, stack: Stack, angle_deg: f64) -> u64 {
        self.sent += 1;
        // A worker that has stopped only happens at exit; nothing to report then.
        let _ = self.request.send((self.sent, stack, angle_deg));
        self.sent
    }

    /// The newest finished result, if any arrived since the last call, with its number.
    pub fn take(&mut self) -> Option<(u64, Result<Curves, String>)> {
        let mut newest = None;
        while let Ok(r) = self.result.try_recv() {
            newest = Some(r);
        }
        newest
    }

    /// The number of the last request.
    pub fn last_request(&self) -> u64 {
        self.sent
    }
}
