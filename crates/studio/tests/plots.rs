//! The plots' values, and what hovering one reads (`egui_kittest`; the view on whatever
//! adapter wgpu finds: lavapipe in CI).
//!
//! * The family of spectra holds `nacre spectrum`'s R and T at each of its angles (the same
//!   library call, to the last bit); the colour against thickness at the stack's own
//!   thickness is the colour against angle at 0°; the chromaticity trajectory over angle
//!   starts at `nacre color --space xyz`'s xy at 0°.
//! * The pointer over the reflectance family's plot reads the nearest data point: its
//!   series, wavelength and R are the curves' own, and the label shows R to 4 decimals.

use egui_kittest::kittest::Queryable;
use nacre_bake::commands::color::Point;
use nacre_studio::app::{BY_ANGLE, FAMILY_R};
use nacre_studio::curves::{
    FAMILY_ANGLES_DEG, THICKNESS_SWEEP_NM, chromaticity, exact_colours_at, wavelengths,
};
use nacre_studio::doc::{Film, StackDoc};
use std::time::{Duration, Instant};

mod support;

#[test]
fn plot_values_are_the_libraries_and_hovering_reads_them() {
    let doc = StackDoc {
        films: vec![Film::new("water", 300.0)],
        ..StackDoc::default()
    };
    let mut h = support::harness_of(support::new_studio(doc.clone(), [64, 48]), [1600.0, 1400.0]);
    let start = Instant::now();
    while !h.state().curves_current() {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(120), "no curves");
        std::thread::sleep(Duration::from_millis(20));
    }
    h.run_steps(2);
    let c = h.state().curves.clone().unwrap();
    let stack = doc.build().unwrap();
    let wl = wavelengths();
    assert_eq!(c.family_reflectance.len(), FAMILY_ANGLES_DEG.len());
    for (k, &a) in FAMILY_ANGLES_DEG.iter().enumerate() {
        let powers = nacre_bake::commands::spectrum::compute(&stack, &[a], &wl).unwrap();
        let r: Vec<f64> = powers.iter().map(|p| p.R()).collect();
        let t: Vec<f64> = powers.iter().map(|p| p.T()).collect();
        assert_eq!(c.family_reflectance[k], r, "R at {a}°");
        assert_eq!(c.family_transmittance[k], t, "T at {a}°");
    }
    // R rises with angle towards grazing at every wavelength for water in air.
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(mean(&c.family_reflectance[3]) > mean(&c.family_reflectance[0]));
    // Film 1 at its own 300 nm in the thickness sweep = the stack at 0°.
    let (lo, _, step) = THICKNESS_SWEEP_NM;
    let i300 = ((300.0 - lo) / step).round() as usize;
    assert_eq!(c.thicknesses_nm[i300], 300.0);
    for ch in 0..3 {
        assert!(
            (c.colour_by_thickness[i300][ch] - c.colour_by_angle[0][ch]).abs() < 1e-9,
            "{:?} vs {:?}",
            c.colour_by_thickness[i300],
            c.colour_by_angle[0]
        );
    }
    let xyz = exact_colours_at(
        &stack,
        &[Point {
            angle_deg: 0.0,
            thickness_nm: None,
            film_ior: None,
        }],
        Some("xyz"),
    )
    .unwrap()[0];
    assert_eq!(c.xy_by_angle[0], chromaticity(xyz));
    assert_eq!(c.xy_by_angle.len(), 90);
    assert_eq!(c.xy_by_thickness.len(), c.thicknesses_nm.len());
    assert!(!BY_ANGLE.is_empty());

    // Move the pointer down through the reflectance family's plot, a third of the way
    // across, until it comes near a line (egui_plot labels the nearest point within a few
    // pixels).
    let label = h
        .get_by_label("R (unpolarised) at 0°, 30°, 60°, 75°")
        .rect();
    for dy in (4..140).step_by(3) {
        let pos = eframe::egui::pos2(label.left() + 110.0, label.bottom() + dy as f32);
        h.hover_at(pos);
        h.run_steps(2);
        if h.state()
            .plot_readout
            .as_ref()
            .is_some_and(|r| r.plot == FAMILY_R)
        {
            break;
        }
    }
    let r = h
        .state()
        .plot_readout
        .clone()
        .expect("the plot read a point");
    assert_eq!(r.plot, FAMILY_R, "{r:?}");
    let k = FAMILY_ANGLES_DEG
        .iter()
        .position(|a| r.series == format!("R {a:.0}°"))
        .unwrap_or_else(|| panic!("series {}", r.series));
    assert_eq!(r.x, wl[r.index]);
    assert_eq!(r.y, c.family_reflectance[k][r.index]);
    assert_eq!(
        r.text,
        format!(
            "R {:.0}° at {:.0} nm: {:.4}",
            FAMILY_ANGLES_DEG[k], r.x, r.y
        )
    );
}
