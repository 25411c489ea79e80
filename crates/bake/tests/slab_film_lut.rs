//! A `film-lut` whose base is a coated slab (issue 31): the committed recipe
//! `tables/recipes/extra/film-spectacle-lens.toml` (a front film over a 2 mm BK7 lens with a
//! 99 nm MgF₂ back coating, the slab incoherent) baked, then looked up as `nacre color
//! --method lut:` does and compared with the exact `spectral` colour of the same stack.
//! Target: the film-lut's usual accuracy (`tests/tests/lut_accuracy.rs`), ΔE2000 p95 ≤ 0.3
//! and max ≤ 1.5, reflected and transmitted.

use nacre_bake::commands::color::{LoadedLut, Method, Point, Quantity, evaluate};
use nacre_bake::commands::stack_spec::StackSpec;
use nacre_bake::kinds::film_lut::{FilmLutRecipe, bake_recipe};
use nacre_format::Manifest;
use nacre_optics::colour::{delta_e_2000, xyz_to_lab};
use std::path::Path;

fn recipe_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables/recipes/extra/film-spectacle-lens.toml")
}

fn lens(front: &str, slab_incoherent: bool) -> nacre_optics::Stack {
    let slab = if slab_incoherent {
        "bk7@2mm:incoherent"
    } else {
        "bk7@2mm"
    };
    StackSpec::from_flags(
        Some("1.0"),
        &[front.into(), slab.into(), "mgf2@99nm".into()],
        Some("1.0"),
    )
    .unwrap()
    .build()
    .unwrap()
}

#[test]
fn slab_lut_matches_the_exact_colour_of_the_whole_lens() {
    let recipe = FilmLutRecipe::read(&recipe_path()).unwrap();
    assert_eq!(recipe.job.under_incoherent, vec![true, false]);
    let out = tempfile::tempdir().unwrap();
    let manifest_path = bake_recipe(&recipe, out.path(), &|| {}).unwrap();
    let manifest = Manifest::read(&manifest_path).unwrap();
    assert_eq!(manifest.under_incoherent, vec![true, false]);
    assert!(manifest.reconstruction.contains("whole pane"));
    let lut = LoadedLut::load(&manifest_path).unwrap();
    assert!(lut.transmittance.is_some(), "a lens in air transmits");

    let stack = lens("1.38@99", true);
    lut.check_stack(&manifest_path, &stack).unwrap();
    let c = &lut.colorimeter;
    let white = c.white_xyz();
    let lab = |v: [f64; 3]| xyz_to_lab(c.xyz_from_output(v), white);
    let mut points = Vec::new();
    for angle_deg in [0.0, 12.0, 27.0, 41.0, 55.0, 68.0, 79.0, 85.0] {
        for thickness_nm in [7.0, 48.0, 99.0, 131.0, 187.0, 246.0, 318.0, 393.0] {
            for film_ior in [1.23, 1.38, 1.57, 1.81, 1.98] {
                points.push(Point {
                    angle_deg,
                    thickness_nm: Some(thickness_nm),
                    film_ior: Some(film_ior),
                });
            }
        }
    }
    let method = Method::Lut(manifest_path.clone());
    for quantity in [Quantity::Reflectance, Quantity::Transmittance] {
        let looked_up = evaluate(&stack, &points, &method, c, quantity, Some(&lut)).unwrap();
        let exact = evaluate(&stack, &points, &Method::Spectral, c, quantity, None).unwrap();
        let mut de: Vec<f64> = looked_up
            .iter()
            .zip(&exact)
            .map(|(a, b)| delta_e_2000(lab(*a), lab(*b)))
            .collect();
        de.sort_by(f64::total_cmp);
        let p95 = de[(de.len() * 95).div_ceil(100) - 1];
        let max = *de.last().unwrap();
        let mean = de.iter().sum::<f64>() / de.len() as f64;
        eprintln!(
            "{quantity:?}: ΔE2000 mean {mean:.4}, p95 {p95:.4}, max {max:.4} over {} points",
            de.len()
        );
        assert!(
            p95 <= 0.3 && max <= 1.5,
            "{quantity:?}: p95 {p95}, max {max}"
        );
    }

    // The slab's back face matters: the same lens with the back-face returns left out (the
    // film on a semi-infinite BK7 base) is far from the table at normal incidence.
    let half = StackSpec::from_flags(Some("1.0"), &["1.38@99".into()], Some("bk7"))
        .unwrap()
        .build()
        .unwrap();
    let at = [Point {
        angle_deg: 0.0,
        thickness_nm: Some(99.0),
        film_ior: Some(1.38),
    }];
    let front_only = evaluate(
        &half,
        &at,
        &Method::Spectral,
        c,
        Quantity::Reflectance,
        None,
    )
    .unwrap()[0];
    let pane = evaluate(&stack, &at, &method, c, Quantity::Reflectance, Some(&lut)).unwrap()[0];
    assert!(
        pane[1] > 1.5 * front_only[1],
        "the back face should add reflectance: {pane:?} vs {front_only:?}"
    );

    // A stack whose slab is coherent, or without it, is not the table's.
    for other in [lens("1.38@99", false), half] {
        let e = lut
            .check_stack(&manifest_path, &other)
            .unwrap_err()
            .to_string();
        assert!(e.contains("baked for") || e.contains("fixed layer"), "{e}");
    }
}

#[test]
fn only_a_film_lut_takes_an_incoherent_layer_under_the_film() {
    let dir = tempfile::tempdir().unwrap();
    let rough = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables/recipes/rough-film-dielectric.toml");
    let text = std::fs::read_to_string(rough).unwrap().replace(
        "base = \"1.5\"\n",
        "base = \"1.0\"\nunder = [ { material = \"bk7\", thickness_nm = 2e6, incoherent = true } ]\n",
    );
    assert!(text.contains("incoherent = true"));
    let path = dir.path().join("rough-lens.toml");
    let message = match nacre_bake::kinds::rough_film_lut::RoughRecipe::parse(&path, text) {
        Ok(_) => panic!("a rough-film-lut took an incoherent layer"),
        Err(e) => e.to_string(),
    };
    assert!(
        message.contains("incoherent = true") && message.contains("rough-lens.toml:17"),
        "{message}"
    );
}
