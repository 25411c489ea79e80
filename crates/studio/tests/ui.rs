//! The studio driven as a user drives it, by its accessible labels (`egui_kittest`; the
//! UI rendered through egui-wgpu, the view through the runtime, both on whatever adapter
//! wgpu finds: lavapipe in CI). A missing adapter fails these tests; they never skip.
//!
//! * A typed film thickness changes the sphere's centre pixel to the colour `nacre color`
//!   (the spectral method, [`nacre_studio::curves::exact_colours`]) gives for that
//!   thickness at 0°, under the uniform sky (`uniform_sky_pixel`); on screen too.
//! * An invalid material or thickness shows an error and changes neither the stack nor the
//!   picture.
//! * "Save recipe" writes a recipe that the CLI's reader (`--recipe`) reads back as the same
//!   stack, and "Open recipe" opens it; undo and redo step through edits.

use egui_kittest::kittest::Queryable;
use nacre_studio::doc::{Film, PRESETS, StackDoc};

mod support;

use support::{TOLERANCE, centre, distance, harness, settle};

/// The pixel `nacre color` predicts for a stack of one water film `d_nm` thick in air.
fn predicted(d_nm: f64) -> [u8; 3] {
    support::predicted(&StackDoc {
        films: vec![Film::new("water", d_nm)],
        ..StackDoc::default()
    })
}

#[test]
fn typed_thickness_changes_the_centre_pixel_to_nacre_colors_colour() {
    let mut h = harness(StackDoc::default());
    settle(&mut h);
    assert_eq!(h.state().doc.films[0].material, "water");
    let mut previous = centre(h.state());
    for d_nm in [250.0, 520.0, 130.0] {
        h.get_by_label("Film 1 thickness (nm)")
            .set_text_value_accesskit(&format!("{d_nm}"));
        settle(&mut h);
        assert_eq!(h.state().doc.films[0].thickness_nm, d_nm);
        assert_eq!(h.state().stack().0.films[0].thickness_nm, d_nm);
        let got = centre(h.state());
        let want = predicted(d_nm);
        assert!(
            distance(got, want) <= TOLERANCE,
            "{d_nm} nm: centre pixel {got:?}, nacre color predicts {want:?}"
        );
        assert!(
            distance(got, previous) > 4 * TOLERANCE,
            "{d_nm} nm: the picture did not change ({previous:?} → {got:?})"
        );
        previous = got;
    }
    // The picture reaches the screen: the live view's centre in the rendered UI.
    let rect = h.get_by_label("Live view").rect();
    let screen = h.render().expect("the UI renders");
    let ppp = 1.0; // the harness's default pixels per point
    let (x, y) = (
        (rect.center().x * ppp) as u32,
        (rect.center().y * ppp) as u32,
    );
    let p = screen.get_pixel(x, y).0;
    assert!(
        distance([p[0], p[1], p[2]], previous) <= 2,
        "on screen {p:?}, the view's picture {previous:?}"
    );
}

#[test]
fn an_invalid_entry_shows_an_error_and_changes_nothing() {
    let mut h = harness(StackDoc::default());
    settle(&mut h);
    let before_stack = h.state().stack().0.clone();
    let before_pixels = h.state().frame.as_ref().unwrap().image.pixels.clone();
    let frames = h.state().frames_drawn;

    h.get_by_label("Film 1 material")
        .set_text_value_accesskit("unobtainium");
    settle(&mut h);
    let error = h.state().stack_error.clone().expect("an error is shown");
    assert!(error.contains("unobtainium"), "{error}");
    assert!(h.query_by_label_contains("Not applied").is_some());
    assert_eq!(h.state().stack().0, before_stack);
    assert_eq!(h.state().frames_drawn, frames, "no new frame");
    assert_eq!(
        h.state().frame.as_ref().unwrap().image.pixels,
        before_pixels
    );
    // Exporting is refused while the fields hold an error.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("refused.toml");
    assert!(h.state_mut().export_recipe(&path).is_err());
    assert!(!path.exists(), "no partial output");

    // Back to a valid material: applied again.
    h.get_by_label("Film 1 material")
        .set_text_value_accesskit("1.33");
    settle(&mut h);
    assert!(h.state().stack_error.is_none());
    assert_eq!(h.state().stack().0.films[0].material, "1.33");

    // A bad typed thickness: shown beside the field; the thickness stays.
    let d = h.state().doc.films[0].thickness_nm;
    h.get_by_label("Film 1 thickness (nm)")
        .set_text_value_accesskit("12 parsecs");
    settle(&mut h);
    assert_eq!(h.state().doc.films[0].thickness_nm, d);
    assert!(h.query_by_label_contains("12 parsecs").is_some());
}

#[test]
fn saved_recipe_reads_back_through_the_clis_reader_and_undo_redo_step() {
    let mut h = harness(PRESETS[2].doc());
    settle(&mut h);
    h.get_by_label("Film 1 thickness (nm)")
        .set_text_value_accesskit("120");
    settle(&mut h);
    h.get_by_label("Add film").click();
    settle(&mut h);
    h.get_by_label("Film 2 material")
        .set_text_value_accesskit("0.27+2.9i");
    settle(&mut h);
    assert!(
        h.state().stack_error.is_none(),
        "{:?}",
        h.state().stack_error
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("design.toml");
    h.get_by_label("Recipe file")
        .set_text_value_accesskit(path.to_str().unwrap());
    h.step();
    h.get_by_label("Save recipe").click();
    settle(&mut h);
    assert!(path.exists(), "status: {:?}", h.state().status);
    // The CLI's reader (`--recipe`).
    let recipe = nacre_bake::commands::stack_spec::StackRecipe::read(&path).unwrap();
    let s = recipe.stack;
    assert_eq!(s.ambient.spec, "1.0");
    assert_eq!(s.substrate.spec, "bk7");
    let layers: Vec<(&str, f64)> = s
        .layers
        .iter()
        .map(|(m, d)| (m.spec.as_str(), *d))
        .collect();
    assert_eq!(layers, [("mgf2", 120.0), ("0.27+2.9i", 100.0)]);
    s.build().unwrap();

    // Undo back to the preset, redo to the design.
    let design = h.state().doc.clone();
    for _ in 0..3 {
        h.get_by_label("Undo").click();
        settle(&mut h);
    }
    assert_eq!(h.state().doc, PRESETS[2].doc());
    assert_eq!(h.state().stack().0, PRESETS[2].doc());
    for _ in 0..3 {
        h.get_by_label("Redo").click();
        settle(&mut h);
    }
    assert_eq!(h.state().doc, design);

    // Open the saved file in a fresh studio.
    let mut g = harness(StackDoc::default());
    settle(&mut g);
    g.get_by_label("Recipe file")
        .set_text_value_accesskit(path.to_str().unwrap());
    g.step();
    g.get_by_label("Open recipe").click();
    settle(&mut g);
    let opened = &g.state().stack().0;
    assert_eq!(opened.films.len(), 2);
    assert_eq!(opened.films[1].material, "0.27+2.9i");
    assert_eq!(opened.substrate, "bk7");
}

#[test]
fn every_preset_and_technique_draws() {
    let mut h = harness(StackDoc::default());
    settle(&mut h);
    for p in PRESETS {
        h.state_mut().set_doc(p.doc());
        for t in nacre_studio::app::TECHNIQUES {
            h.state_mut().settings.technique = t;
            settle(&mut h);
            assert!(
                h.state().view_error.is_none() || t == nacre_runtime::Technique::Lut,
                "{} with {}: {:?}",
                p.name,
                t.name(),
                h.state().view_error
            );
        }
    }
}
