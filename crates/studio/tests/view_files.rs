//! The view's files and the `lut` technique on any stack, driven by the accessible labels
//! (`egui_kittest`; the view on whatever adapter wgpu finds: lavapipe in CI; a missing
//! adapter fails these tests).
//!
//! * "Environment file" + "Open environment": a Radiance HDR sky of one colour lights the
//!   sphere in that colour alone (the other channels stay black in every pixel); a broken
//!   file shows an error naming it and changes nothing.
//! * "Thickness map" + "Open thickness map": a uniform grey map g sets film 1 to
//!   d + r(2g − 1), so the sphere's centre is the colour `nacre color` gives for that
//!   thickness; a colour map drives film 2 by the channel "Film 2 follows" names.
//! * `lut` on a stack the bundled table does not hold: the view draws the stack exactly
//!   (`stack`) at once while the stack's own table bakes, then draws `lut` from it (close to
//!   the exact colour); a thickness edit inside the table's axes redraws without a bake; a
//!   new base bakes a new table; a new studio finds the table in the cache.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use nacre_runtime::Technique;
use nacre_studio::Studio;
use nacre_studio::doc::{Film, StackDoc};
use nacre_studio::live_lut::LiveLut;
use nacre_studio::view::Lighting;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

mod support;

use support::{TOLERANCE, centre, distance, harness_of, pixels, predicted, settle, studio};

fn harness(s: Studio) -> Harness<'static, Studio> {
    harness_of(s, [1400.0, 900.0])
}

/// A Radiance HDR file of one radiance `rgb` everywhere (64 × 32).
fn uniform_hdr(path: &Path, rgb: [f32; 3]) {
    let pixels = vec![image::Rgb(rgb); 64 * 32];
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&pixels, 64, 32)
        .unwrap();
}

fn open(h: &mut Harness<'_, Studio>, field: &str, button: &str, path: &Path) {
    h.get_by_label(field)
        .set_text_value_accesskit(path.to_str().unwrap());
    h.step();
    h.get_by_label(button).click();
    settle(h);
}

#[test]
fn an_environment_file_lights_the_sphere_in_its_colour_and_a_broken_one_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = studio(StackDoc::default());
    s.settings.lighting = Lighting::Studio;
    s.settings.roughness_alpha = 0.2;
    let mut h = harness(s);
    settle(&mut h);
    let studio_picture = pixels(h.state());
    let lit = |p: &[[u8; 3]], c: usize| p.iter().filter(|v| v[c] > 8).count();
    assert!(
        (0..3).all(|c| lit(&studio_picture, c) > 100),
        "the studio environment lights every channel"
    );

    // Radiance 0.5: below PBR Neutral's highlight compression, which would desaturate it.
    for (channel, rgb) in [(0, [0.5, 0.0, 0.0]), (1, [0.0, 0.5, 0.0])] {
        let path = dir.path().join(format!("sky-{channel}.hdr"));
        uniform_hdr(&path, rgb);
        open(&mut h, "Environment file", "Open environment", &path);
        assert!(
            h.state().environment_error.is_none(),
            "{:?}",
            h.state().environment_error
        );
        assert_eq!(h.state().settings.lighting, Lighting::File);
        assert!(h.state().view_error.is_none(), "{:?}", h.state().view_error);
        let picture = pixels(h.state());
        assert!(
            lit(&picture, channel) > picture.len() / 2,
            "the sky's colour"
        );
        for c in (0..3).filter(|&c| c != channel) {
            let worst = picture.iter().map(|v| v[c]).max().unwrap();
            assert!(
                worst <= 1,
                "{rgb:?} sky: channel {c} reaches {worst} (the studio's sun or sky leaks in)"
            );
        }
    }

    // A broken file: an error naming it; the lighting and the picture stay.
    let before = pixels(h.state());
    let kept = h.state().settings.environment.clone();
    let broken = dir.path().join("broken.exr");
    std::fs::write(&broken, b"not an OpenEXR file").unwrap();
    open(&mut h, "Environment file", "Open environment", &broken);
    let e = h.state().environment_error.clone().expect("an error");
    assert!(e.contains("broken.exr"), "{e}");
    assert!(h.query_by_label_contains("broken.exr:").is_some());
    assert_eq!(h.state().settings.environment, kept);
    assert_eq!(pixels(h.state()), before);
}

/// A 32 × 32 PNG of one RGB value.
fn uniform_png(path: &Path, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(32, 32, image::Rgb(rgb))
        .save(path)
        .unwrap();
}

/// A 32 × 32 greyscale PNG of one value.
fn grey_png(path: &Path, g: u8) {
    image::GrayImage::from_pixel(32, 32, image::Luma([g]))
        .save(path)
        .unwrap();
}

fn water(d_nm: f64, r_nm: f64) -> Film {
    let mut f = Film::new("water", d_nm);
    f.relative_nm = r_nm;
    f
}

#[test]
fn a_thickness_map_sets_each_films_thickness_by_its_channel() {
    let dir = tempfile::tempdir().unwrap();
    let doc = StackDoc {
        films: vec![water(300.0, 100.0)],
        ..StackDoc::default()
    };
    let mut s = studio(doc.clone());
    s.settings.technique = Technique::Stack;
    let mut h = harness(s);
    settle(&mut h);
    for (g, d_nm) in [(0u8, 200.0), (255, 400.0)] {
        let path = dir.path().join(format!("grey-{g}.png"));
        grey_png(&path, g);
        open(&mut h, "Thickness map", "Open thickness map", &path);
        assert!(
            h.state().thickness_map_error.is_none(),
            "{:?}",
            h.state().thickness_map_error
        );
        let want = predicted(&StackDoc {
            films: vec![Film::new("water", d_nm)],
            ..doc.clone()
        });
        let got = centre(h.state());
        assert!(
            distance(got, want) <= TOLERANCE,
            "g = {g}: centre {got:?}, nacre color at {d_nm} nm predicts {want:?}"
        );
    }

    // A colour map: R = 0 (film 1 at 200 nm), G = 255, B = 0; film 2 (an index-1.8 film
    // 100 ± 80 nm) follows R (20 nm) or G (180 nm).
    let two = StackDoc {
        films: vec![water(300.0, 100.0), {
            let mut f = Film::new("1.8", 100.0);
            f.relative_nm = 80.0;
            f
        }],
        ..StackDoc::default()
    };
    h.state_mut().set_doc(two.clone());
    let path = dir.path().join("colour.png");
    uniform_png(&path, [0, 255, 0]);
    open(&mut h, "Thickness map", "Open thickness map", &path);
    assert!(h.state().thickness_map_colour);
    assert!(h.query_by_label("Film 2 follows").is_some());
    let expect = |d2_nm: f64| {
        predicted(&StackDoc {
            films: vec![Film::new("water", 200.0), Film::new("1.8", d2_nm)],
            ..two.clone()
        })
    };
    let by_r = centre(h.state());
    assert!(
        distance(by_r, expect(20.0)) <= TOLERANCE,
        "film 2 on R: {by_r:?}, predicted {:?}",
        expect(20.0)
    );
    h.state_mut().settings.film_channels = vec![0, 1];
    settle(&mut h);
    let by_g = centre(h.state());
    assert!(
        distance(by_g, expect(180.0)) <= TOLERANCE,
        "film 2 on G: {by_g:?}, predicted {:?}",
        expect(180.0)
    );
    assert!(distance(by_r, by_g) > 4 * TOLERANCE, "the channel matters");

    // A file that is no picture: the error names it, the map stays.
    let before = pixels(h.state());
    let broken = dir.path().join("broken.png");
    std::fs::write(&broken, b"no picture").unwrap();
    open(&mut h, "Thickness map", "Open thickness map", &broken);
    let e = h.state().thickness_map_error.clone().expect("an error");
    assert!(e.contains("broken.png"), "{e}");
    assert_eq!(h.state().settings.thickness_map, Some(path));
    assert_eq!(pixels(h.state()), before);
    // Back to the procedural map.
    h.get_by_label("Procedural map").click();
    settle(&mut h);
    assert_eq!(h.state().settings.thickness_map, None);
    assert_ne!(pixels(h.state()), before);
}

/// Steps until `done` holds, at most `limit`.
fn until(h: &mut Harness<'_, Studio>, limit: Duration, what: &str, done: impl Fn(&Studio) -> bool) {
    let start = Instant::now();
    while !done(h.state()) {
        h.step();
        assert!(start.elapsed() < limit, "{what} within {limit:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
    settle(h);
}

fn notes(s: &Studio) -> String {
    s.frame
        .as_ref()
        .map(|f| f.notes.join("\n"))
        .unwrap_or_default()
}

/// An MgF₂-like film over TiO₂ on BK7: another base and a film under the top one, which
/// the bundled film-dielectric table does not hold.
fn coated_lens(d_nm: f64, base: &str) -> StackDoc {
    StackDoc {
        ambient: "1.0".into(),
        films: vec![Film::new("1.38", d_nm), Film::new("tio2", 40.0)],
        substrate: base.into(),
        base_dir: None,
    }
}

fn lut_studio(doc: StackDoc, cache: &Path) -> Studio {
    let mut s = studio(doc);
    s.settings.technique = Technique::Lut;
    s.live_lut = LiveLut::new(Some(cache.to_path_buf()));
    // A coarser table than the bundled one (16 × 256 × 16): a bake of seconds in the tests.
    let c = &mut s.live_lut.counts;
    [c.cos_theta_count, c.opd_count, c.film_ior_count] = [16, 256, 16];
    s
}

fn tables_in(cache: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(cache)
        .map(|d| d.filter_map(Result::ok).map(|e| e.path()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn lut_draws_any_stack_from_its_own_table_baked_in_the_background() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("luts");
    let mut s = lut_studio(coated_lens(120.0, "bk7"), &cache);
    // `stack` first, so that its pipeline is compiled before the bake starts.
    s.settings.technique = Technique::Stack;
    let mut h = harness(s);
    settle(&mut h);
    h.state_mut().settings.technique = Technique::Lut;
    let started = Instant::now();
    // At once (the next frame): the stack drawn exactly while its table bakes.
    h.step();
    assert!(
        h.state().live_lut.progress().is_some(),
        "a bake runs: {:?} {:?} {}",
        h.state().live_lut.error(),
        h.state().settings.lut_key,
        notes(h.state())
    );
    assert!(
        notes(h.state()).contains("is baking"),
        "{}",
        notes(h.state())
    );
    let exact = centre(h.state());
    assert!(
        distance(exact, predicted(&coated_lens(120.0, "bk7"))) <= TOLERANCE,
        "meanwhile the exact colour"
    );
    assert!(h.query_by_label("lut table of this stack").is_some());

    until(&mut h, Duration::from_secs(180), "the table bakes", |s| {
        s.live_lut.progress().is_none()
    });
    eprintln!(
        "16 × 256 × 16 table baked and drawn after {:.2} s",
        started.elapsed().as_secs_f64()
    );
    assert!(
        h.state().live_lut.error().is_none(),
        "{:?}",
        h.state().live_lut.error()
    );
    assert!(
        notes(h.state()).contains("own film-lut table"),
        "{}",
        notes(h.state())
    );
    let tables = tables_in(&cache);
    assert_eq!(tables.len(), 1, "{tables:?}");
    assert!(tables[0].join("studio-lut.json").is_file());
    // lut against the exact colour: the table's sampling alone.
    let lut = centre(h.state());
    assert!(
        distance(lut, exact) <= 2 * TOLERANCE,
        "lut {lut:?} against the exact {exact:?}"
    );

    // A thickness inside the table's axis: no bake, the next frame shows it from the table.
    h.get_by_label("Film 1 thickness (nm)")
        .set_text_value_accesskit("160");
    settle(&mut h);
    assert!(h.state().live_lut.progress().is_none(), "no new bake");
    assert!(notes(h.state()).contains("own film-lut table"));
    let moved = centre(h.state());
    assert!(
        distance(moved, predicted(&coated_lens(160.0, "bk7"))) <= 2 * TOLERANCE,
        "160 nm from the table: {moved:?}"
    );
    assert!(distance(moved, lut) > TOLERANCE, "the picture followed");

    // Another base: a new table; the stack meanwhile.
    h.get_by_label("Base").set_text_value_accesskit("1.6");
    h.step();
    assert_eq!(h.state().stack().0.substrate, "1.6");
    assert!(h.state().live_lut.progress().is_some(), "a new bake");
    assert!(notes(h.state()).contains("is baking"));
    until(
        &mut h,
        Duration::from_secs(180),
        "the second table bakes",
        |s| s.live_lut.progress().is_none(),
    );
    assert_eq!(tables_in(&cache).len(), 2);

    // A stack the bundled table holds: no table of its own.
    h.state_mut().set_doc(StackDoc {
        ambient: "1.0".into(),
        films: vec![Film::new("1.45", 300.0)],
        substrate: "1.5".into(),
        base_dir: None,
    });
    settle(&mut h);
    assert!(h.state().settings.lut_key.is_none());
    assert!(h.state().live_lut.progress().is_none());
    assert!(!notes(h.state()).contains("film-dielectric table's ambient"));
    drop(h);

    // A new studio finds the first table in the cache: lut at the first frame.
    let mut h = harness(lut_studio(coated_lens(120.0, "bk7"), &cache));
    settle(&mut h);
    assert!(h.state().live_lut.progress().is_none(), "no bake");
    assert!(notes(h.state()).contains("own film-lut table"));
    assert_eq!(centre(h.state()), lut);
}
