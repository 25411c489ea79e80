//! The colour of coated glass with an incoherent slab (issue 31): `nacre color --method
//! spectral` of a 2 mm pane with an anti-reflection coating on each face, the slab
//! incoherent, against a brute-force coherent average — the same stack with the slab
//! coherent, its reflectance and transmittance averaged at every wavelength of the rule over
//! one period of the slab's phase (many fringes of the coherent spectrum) in 256 thicknesses.
//! Target: ΔE2000 ≤ 0.01, reflected and transmitted, 0–80°.

use nacre_bake::commands::color::{Method, Point, Quantity, evaluate};
use nacre_bake::commands::stack_spec::StackSpec;
use nacre_optics::colour::{delta_e_2000, xyz_to_lab};
use nacre_optics::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace, SpectralRule};

#[test]
fn coated_pane_colour_matches_the_coherent_thickness_average() {
    let spec = StackSpec::from_flags(
        Some("1.0"),
        &[
            "mgf2@99nm".into(),
            "tio2@60nm".into(),
            "bk7@2mm:incoherent".into(),
            "tio2@60nm".into(),
            "mgf2@99nm".into(),
        ],
        Some("1.0"),
    )
    .unwrap();
    let pane = spec.build().unwrap();
    assert!(pane.is_incoherent(3));
    let coherent = pane.clone().with_incoherent(vec![false; 5]).unwrap();
    let colorimeter = Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    );
    let white = colorimeter.white_xyz();
    let lab = |c: [f64; 3]| xyz_to_lab(colorimeter.xyz_from_output(c), white);
    let mut worst: f64 = 0.0;
    for angle in [0.0, 30.0, 60.0, 80.0] {
        let point = Point {
            angle_deg: angle,
            thickness_nm: None,
            film_ior: None,
        };
        // The rule of the coherent coatings; the brute force uses the same nodes.
        let rule =
            SpectralRule::for_stack(&colorimeter, &pane, &[angle], pane.max_opd_nm(None)).unwrap();
        let n = 256;
        let mut mean_r = Vec::new();
        let mut mean_t = Vec::new();
        for &wl in rule.wavelengths_nm() {
            let n_slab = pane.layers()[2].material.index_at(wl).unwrap().re;
            let sin_in = angle.to_radians().sin() / n_slab;
            let period = wl / (2.0 * n_slab * (1.0 - sin_in * sin_in).sqrt());
            let ds: Vec<f64> = (0..n).map(|m| 2e6 + period * m as f64 / n as f64).collect();
            let p = coherent.sweep_thickness(3, &[angle], &[wl], &ds).unwrap();
            mean_r.push(p.iter().map(|p| p.R()).sum::<f64>() / n as f64);
            mean_t.push(p.iter().map(|p| p.T()).sum::<f64>() / n as f64);
        }
        for (quantity, mean) in [
            (Quantity::Reflectance, &mean_r),
            (Quantity::Transmittance, &mean_t),
        ] {
            let ours = evaluate(
                &pane,
                std::slice::from_ref(&point),
                &Method::Spectral,
                &colorimeter,
                quantity,
                None,
            )
            .unwrap()[0];
            let brute = rule.colour(mean.iter().copied());
            let de = delta_e_2000(lab(ours), lab(brute));
            eprintln!(
                "{angle}° {quantity:?}: ours {ours:?}, brute force {brute:?}, ΔE2000 {de:.2e}"
            );
            worst = worst.max(de);
        }
    }
    eprintln!("worst ΔE2000 {worst:.2e}");
    assert!(worst <= 0.01, "worst ΔE2000 {worst}");
}

#[test]
fn methods_without_slab_physics_refuse_it() {
    let spec = StackSpec::from_flags(
        None,
        &["mgf2@99nm".into(), "bk7@2mm:incoherent".into()],
        Some("1.0"),
    )
    .unwrap();
    let pane = spec.build().unwrap();
    let colorimeter = Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    );
    let point = Point {
        angle_deg: 10.0,
        thickness_nm: None,
        film_ior: None,
    };
    let run = |m: &str| {
        evaluate(
            &pane,
            std::slice::from_ref(&point),
            &Method::parse(m).unwrap(),
            &colorimeter,
            Quantity::Reflectance,
            None,
        )
    };
    for ok in ["spectral", "rgb3", "samples:16", "stack"] {
        let c = run(ok).unwrap()[0];
        assert!(c.iter().all(|v| v.is_finite() && *v > 0.0), "{ok}: {c:?}");
    }
    for refused in ["fourier", "fourier-exact", "gaussian"] {
        let e = run(refused).unwrap_err().to_string();
        assert!(e.contains("layer 2 is incoherent"), "{refused}: {e}");
    }
}
