//! The studio driven as a user drives it, by its accessible labels (`egui_kittest`; the
//! UI rendered through egui-wgpu, the view through the runtime, both on whatever adapter
//! wgpu finds: lavapipe in CI). A missing adapter fails these tests; they never skip.
//!
//! * A typed film thickness changes the sphere's centre pixel to the colour `nacre color`
//!   (the spectral method, [`nacre_studio::curves::exact_colours`]) gives for that
//!   thickness at 0°, under the uniform sky ([`uniform_sky_pixel`]); on screen too.
//! * An invalid material or thickness shows an error and changes neither the stack nor the
//!   picture.
//! * "Save recipe" writes a recipe that the CLI's reader (`--recipe`) reads back as the same
//!   stack, and "Open recipe" opens it; undo and redo step through edits.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use nacre_runtime::GpuContext;
use nacre_studio::curves::exact_colours;
use nacre_studio::doc::{Film, PRESETS, StackDoc};
use nacre_studio::view::{Lighting, uniform_sky_pixel};
use nacre_studio::{Studio, View};
use std::time::{Duration, Instant};

/// The view's picture size in the tests, pixels.
const VIEW: [u32; 2] = [96, 72];

/// A mirror-smooth roughness, so that the centre pixel is the film at normal incidence.
const ALPHA: f32 = 0.001;

fn studio(doc: StackDoc) -> Studio {
    let ctx = GpuContext::new_headless().expect("a wgpu adapter (lavapipe in CI)");
    let view = View::new(ctx).expect("the default tables load");
    let mut s = Studio::new(Ok(view), doc, VIEW);
    s.settings.lighting = Lighting::Uniform;
    s.settings.roughness_alpha = ALPHA;
    s
}

fn harness(doc: StackDoc) -> Harness<'static, Studio> {
    Harness::builder()
        .with_size([1400.0, 900.0])
        .wgpu()
        .build_ui_state(|ui, s: &mut Studio| s.ui(ui), studio(doc))
}

/// Steps until the plots show the current stack (the worker thread), at most 60 s.
fn settle(h: &mut Harness<'_, Studio>) {
    let start = Instant::now();
    loop {
        h.step();
        if h.state().curves_current() && h.state().frame.is_some() {
            h.step();
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the plots never caught up: {:?}",
            h.state().curves_error
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn centre(s: &Studio) -> [u8; 3] {
    let img = &s.frame.as_ref().expect("a frame").image;
    let (x, y) = (img.width as usize / 2, img.height as usize / 2);
    let i = 4 * (y * img.width as usize + x);
    [img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]]
}

/// The pixel `nacre color` predicts for a stack of one water film `d_nm` thick in air.
fn predicted(d_nm: f64) -> [u8; 3] {
    let doc = StackDoc {
        films: vec![Film::new("water", d_nm)],
        ..StackDoc::default()
    };
    let rgb = exact_colours(&doc.build().unwrap(), &[0.0]).unwrap()[0];
    uniform_sky_pixel(rgb, f64::from(ALPHA))
}

fn distance(a: [u8; 3], b: [u8; 3]) -> i32 {
    (0..3)
        .map(|k| (i32::from(a[k]) - i32::from(b[k])).abs())
        .max()
        .unwrap()
}

/// The film_stack technique's few fitted wavelengths against the exact spectral sum, in
/// 8-bit sRGB levels at the sphere's centre (measured ≤ 3 over the thicknesses below).
const TOLERANCE: i32 = 4;

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
