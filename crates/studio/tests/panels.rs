//! The studio's export, comparison and session features driven by their accessible labels
//! (`egui_kittest`, the view on whatever adapter wgpu finds: lavapipe in CI; a missing
//! adapter fails these tests).
//!
//! * Bake: "Bake tables" starts a bake on its own thread; while it runs the UI keeps
//!   drawing (harness frames counted) and the view follows a thickness edit; "Cancel bake"
//!   stops it and leaves no file behind; a finished bake's manifest reads back through
//!   `nacre info`'s reader ([`Manifest::read`]) and its texels are the stack's exact colours.
//! * ΔE2000: "ΔE2000 against spectral" shows a map that is 0 everywhere when the view's
//!   technique is spectral itself, and small but nonzero for lut (a film the table holds);
//!   the statistics are shown and the map reaches the screen on its colour scale.
//! * glTF: "Model file" + "Open model" (and a dropped file) draws Khronos' IridescenceSuzanne
//!   with the stack's film on its iridescent materials: a thickness edit changes the
//!   picture; "Film on every material" puts it on all; a bad path shows an error.
//! * Session: every committed change is written as a recipe; a new studio starts from it;
//!   an entry in error is not saved; a broken file is reported and left untouched.

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use nacre_format::film_lut::FilmLutAxes;
use nacre_format::manifest::{KindRecord, Manifest};
use nacre_runtime::{GpuContext, Technique};
use nacre_studio::compare::scale_colour;
use nacre_studio::curves::exact_colours;
use nacre_studio::doc::{Film, StackDoc};
use nacre_studio::view::{Lighting, film_on_model};
use nacre_studio::{Studio, View};
use std::path::PathBuf;
use std::time::{Duration, Instant};

mod support;

use support::{VIEW, harness, settle};

/// Steps until the bake has ended, at most `limit`; returns the frames drawn meanwhile.
fn until_baked(h: &mut Harness<'_, Studio>, limit: Duration) -> u64 {
    let start = Instant::now();
    let frames = h.state().ui_frames;
    while h.state().baking() {
        h.step();
        assert!(
            start.elapsed() < limit,
            "the bake did not end within {limit:?}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    h.step();
    h.state().ui_frames - frames
}

/// An MgF₂-like film (constant index: the table's film-index axis) over TiO₂ on BK7: a
/// dispersive fixed layer and base, so every row is a full spectral sweep.
fn coated_lens() -> StackDoc {
    StackDoc {
        ambient: "1.0".into(),
        films: vec![Film::new("1.38", 120.0), Film::new("tio2", 40.0)],
        substrate: "bk7".into(),
        base_dir: None,
    }
}

fn set_bake(h: &mut Harness<'_, Studio>, folder: &std::path::Path, name: &str, counts: [usize; 3]) {
    h.get_by_label("Table folder")
        .set_text_value_accesskit(folder.to_str().unwrap());
    h.get_by_label("Table name").set_text_value_accesskit(name);
    h.step();
    let b = &mut h.state_mut().bake;
    [b.cos_theta_count, b.opd_count, b.film_ior_count] = counts;
    h.step();
}

#[test]
fn a_bake_keeps_the_ui_drawing_and_cancel_leaves_nothing() {
    let mut h = harness(coated_lens());
    settle(&mut h);
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("tables");
    // 64 × 1024 × 64: 4096 rows of 1024 thicknesses, minutes of work: still running when
    // cancelled below.
    set_bake(&mut h, &folder, "big", [64, 1024, 64]);
    h.get_by_label("Bake tables").click();
    h.step();
    assert!(h.state().baking(), "status: {:?}", h.state().bake_status);

    // Frames keep coming while the bake runs, and the view follows an edit.
    let frames = h.state().ui_frames;
    let view_frames = h.state().frames_drawn;
    h.get_by_label("Film 1 thickness (nm)")
        .set_text_value_accesskit("150");
    for _ in 0..40 {
        h.step();
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        h.state().baking(),
        "the bake ended early: {:?}",
        h.state().bake_status
    );
    assert!(h.state().ui_frames - frames >= 40);
    assert!(
        h.state().frames_drawn > view_frames,
        "the view did not redraw the edit while baking"
    );
    assert_eq!(h.state().stack().0.films[0].thickness_nm, 150.0);
    let (done, total) = h.state().bake_job.as_ref().unwrap().progress();
    assert_eq!(total, 64 * 64);
    assert!(done < total);
    assert!(
        h.query_by_label_contains("rows").is_some(),
        "a progress bar"
    );

    h.get_by_label("Cancel bake").click();
    let frames = until_baked(&mut h, Duration::from_secs(120));
    assert!(frames > 0);
    let status = h.state().bake_status.clone().unwrap();
    assert!(
        matches!(&status, Err(e) if e.contains("cancelled")),
        "{status:?}"
    );
    assert!(h.query_by_label_contains("cancelled").is_some());
    // Nothing written: not even the folder.
    assert!(
        !folder.exists(),
        "{:?}",
        std::fs::read_dir(&folder).map(|d| d.count())
    );
}

#[test]
fn a_finished_bake_reads_back_with_nacre_infos_reader_and_holds_the_stacks_colours() {
    let mut h = harness(coated_lens());
    settle(&mut h);
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("set");
    set_bake(&mut h, &folder, "lens", [6, 48, 5]);
    h.get_by_label("Bake tables").click();
    h.step();
    assert!(h.state().baking(), "status: {:?}", h.state().bake_status);
    until_baked(&mut h, Duration::from_secs(300));
    let manifest_path = folder.join("lens.json");
    assert_eq!(
        h.state().bake_status,
        Some(Ok(format!("baked {}", manifest_path.display())))
    );
    assert!(h.query_by_label_contains("baked").is_some());
    // `nacre info`'s reader.
    let manifest = Manifest::read(&manifest_path).unwrap();
    assert_eq!(manifest.name, "lens");
    assert_eq!(manifest.base, "bk7");
    assert_eq!(manifest.under, [("tio2".to_string(), 40.0)]);
    let KindRecord::FilmLut(axes) = &manifest.record else {
        panic!("a film-lut: {:?}", manifest.record)
    };
    let axes: FilmLutAxes = axes.clone();
    assert_eq!(
        (axes.cos_theta_count, axes.opd_count, axes.ior_count),
        (6, 48, 5)
    );
    assert!(axes.ior_min <= 1.38 && 1.38 <= axes.ior_max);
    // Every file the manifest lists is there, and no staging folder is left.
    for f in &manifest.files {
        assert!(folder.join(&f.path).is_file(), "{}", f.path);
    }
    let names: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| n.starts_with("lens.")), "{names:?}");

    // The texels are the stack's exact colours at their own (cos θ, d, n).
    let table = nacre_format::ktx2::read_film_lut_ktx2(
        &folder.join("lens.reflectance.ktx2"),
        axes.cos_theta_count,
        axes.opd_count,
        axes.ior_count,
    )
    .unwrap();
    let mut worst = 0.0f64;
    for (x, y, z) in [(5, 10, 2), (5, 30, 4), (3, 20, 1), (1, 47, 0)] {
        let (cos_theta, d_nm, n) = axes.texel_parameters(x, y, z);
        let mut doc = coated_lens();
        doc.films[0] = Film::new(&format!("{n}"), d_nm);
        let angle = cos_theta.clamp(0.0, 1.0).acos().to_degrees().min(89.999);
        let want = exact_colours(&doc.build().unwrap(), &[angle]).unwrap()[0];
        let got = table.texel(x, y, z);
        for c in 0..3 {
            worst = worst.max((f64::from(got[c]) - want[c]).abs());
        }
    }
    // Half-float storage: 2⁻¹¹ relative.
    assert!(worst < 2e-3, "worst texel error {worst}");
}

/// A film the film-dielectric table holds (index 1.45 in air on glass of index 1.5): `lut`
/// then differs from the exact colour by the table's sampling alone.
fn table_film() -> StackDoc {
    StackDoc {
        ambient: "1.0".into(),
        films: vec![Film::new("1.45", 300.0)],
        substrate: "1.5".into(),
        base_dir: None,
    }
}

#[test]
fn the_delta_e_map_is_zero_against_itself_and_small_for_lut() {
    let mut h = harness(table_film());
    h.state_mut().settings.technique = Technique::Spectral;
    settle(&mut h);
    assert!(h.state().delta_e.is_none());
    h.get_by_label("ΔE2000 against spectral").click();
    settle(&mut h);
    let d = h.state().delta_e.clone().expect("a ΔE map");
    assert_eq!((d.width, d.height), (VIEW[0], VIEW[1]));
    assert_eq!(d.differing, 0, "spectral against itself");
    assert_eq!((d.mean, d.p95, d.max), (0.0, 0.0, 0.0));
    assert!(h.query_by_label("ΔE2000 map").is_some());
    assert!(
        h.query_by_label_contains("mean 0.00, p95 0.00, max 0.00")
            .is_some()
    );

    h.state_mut().settings.technique = Technique::Lut;
    settle(&mut h);
    assert!(h.state().view_error.is_none(), "{:?}", h.state().view_error);
    let d = h.state().delta_e.clone().expect("a ΔE map");
    eprintln!(
        "lut against spectral: mean {:.3}, p95 {:.3}, max {:.3}; {} pixels differ (mean {:.3}, p95 {:.3})",
        d.mean, d.p95, d.max, d.differing, d.mean_differing, d.p95_differing
    );
    assert!(
        d.differing > 0 && d.max > 0.0,
        "lut equals spectral exactly?"
    );
    assert!(d.p95_differing < 2.0, "lut is far from spectral: {d:?}");
    assert!(
        h.query_by_label_contains("ΔE2000 lut against spectral")
            .is_some()
    );

    // The map reaches the screen painted on its scale: its centre pixel.
    let rect = h.get_by_label("ΔE2000 map").rect();
    let screen = h.render().expect("the UI renders");
    let (cx, cy) = (rect.center().x as u32, rect.center().y as u32);
    let p = screen.get_pixel(cx, cy).0;
    let (x, y) = (VIEW[0] as usize / 2, VIEW[1] as usize / 2);
    let want = scale_colour(d.values[y * VIEW[0] as usize + x], h.state().delta_e_max);
    assert!(
        (0..3).all(|c| p[c].abs_diff(want[c]) <= 2),
        "on screen {p:?}, the map's centre {want:?}"
    );
}

/// Khronos' IridescenceSuzanne (`../shared/gltf-samples`), or None (skipped) outside CI.
fn suzanne() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/gltf-samples");
    let dir = std::env::var_os("NACRE_GLTF_SAMPLES").map_or(dir, PathBuf::from);
    if !dir.is_dir() {
        assert!(
            std::env::var_os("CI").is_none(),
            "{} is missing: CI must provide the Khronos glTF samples (../shared/DATA.md)",
            dir.display()
        );
        eprintln!(
            "skipped: {} not found (the Khronos glTF samples of ../shared/DATA.md)",
            dir.display()
        );
        return None;
    }
    Some(dir.join("IridescenceSuzanne/glTF-Binary/IridescenceSuzanne.glb"))
}

fn pixel_difference(a: &[u8], b: &[u8]) -> u64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| u64::from(x.abs_diff(*y)))
        .sum()
}

/// A file dropped on the window, as the native integration hands it over.
#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &std::path::Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn a_gltf_model_opens_and_wears_the_stacks_film() {
    let Some(path) = suzanne() else { return };
    let mut h = harness(StackDoc::default());
    h.state_mut().settings.lighting = Lighting::Studio;
    h.state_mut().settings.technique = Technique::Fourier;
    settle(&mut h);
    let sphere = h.state().frame.as_ref().unwrap().image.pixels.clone();

    // A bad file: an error beside the field, the view unchanged.
    h.get_by_label("Model file")
        .set_text_value_accesskit("/no/such/model.glb");
    h.step();
    h.get_by_label("Open model").click();
    settle(&mut h);
    assert!(h.state().model_error.is_some());
    assert!(h.state().settings.model.is_none());
    assert!(h.query_by_label_contains("/no/such/model.glb").is_some());

    h.get_by_label("Model file")
        .set_text_value_accesskit(path.to_str().unwrap());
    h.step();
    h.get_by_label("Open model").click();
    settle(&mut h);
    assert!(
        h.state().model_error.is_none(),
        "{:?}",
        h.state().model_error
    );
    assert!(h.state().view_error.is_none(), "{:?}", h.state().view_error);
    assert_eq!(h.state().settings.model.as_deref(), Some(path.as_path()));
    let frame = h.state().frame.as_ref().unwrap();
    let notes = frame.notes.join("\n");
    assert!(notes.contains("film 1 (index 1.33"), "{notes}");
    let water_380 = frame.image.pixels.clone();
    assert!(pixel_difference(&sphere, &water_380) > 0);

    // The stack's thickness changes the model's colours.
    h.get_by_label("Film 1 thickness (nm)")
        .set_text_value_accesskit("650");
    settle(&mut h);
    let water_650 = h.state().frame.as_ref().unwrap().image.pixels.clone();
    let changed = pixel_difference(&water_380, &water_650);
    // The same model without any film, for scale.
    let doc = h.state().stack().0.clone();
    let scene = nacre_runtime::gltf_scene::GltfScene::load(&path).unwrap();
    let mut no_film = doc.clone();
    no_film.films.clear();
    let (bare, filmed) = film_on_model(&scene, &no_film, &no_film.build().unwrap(), false).unwrap();
    assert_eq!(filmed, 0);
    assert!(
        bare.materials
            .iter()
            .all(|m| m.iridescence.as_ref().is_none_or(|i| i.factor == 0.0))
    );
    let n = (VIEW[0] * VIEW[1]) as u64;
    eprintln!(
        "Suzanne: 380 → 650 nm changes the picture by {:.2} levels per pixel",
        changed as f64 / n as f64
    );
    assert!(changed > n, "the film's thickness barely shows: {changed}");

    // Film on every material: every material carries it (Suzanne's one material is
    // iridescent already, so the picture stays).
    h.get_by_label("Film on every material").click();
    settle(&mut h);
    let (_, all) = film_on_model(&scene, &doc, &doc.build().unwrap(), true).unwrap();
    assert_eq!(all, scene.materials.len());
    let notes = h.state().frame.as_ref().unwrap().notes.join("\n");
    assert!(
        notes.contains(&format!("on {all} of {all} materials (every material)")),
        "{notes}"
    );

    // Back to the sphere, then drop the file on the window.
    h.get_by_label("Close model").click();
    settle(&mut h);
    assert!(h.state().settings.model.is_none());
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(path.clone())));
    settle(&mut h);
    assert_eq!(h.state().settings.model.as_deref(), Some(path.as_path()));
}

#[test]
fn the_session_is_saved_on_change_and_restored_on_start() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("state/session.toml");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let make = |path: &std::path::Path| {
        let ctx = GpuContext::new_headless().expect("a wgpu adapter (lavapipe in CI)");
        let view = View::new(ctx).expect("the default tables load");
        Studio::with_session(Ok(view), StackDoc::default(), VIEW, path.to_path_buf())
    };
    let build = |s: Studio| {
        Harness::builder()
            .with_size([1400.0, 900.0])
            .wgpu()
            .build_ui_state(|ui, s: &mut Studio| s.ui(ui), s)
    };
    let mut h = build(make(&path));
    settle(&mut h);
    assert!(!path.exists(), "nothing written before a change");
    h.get_by_label("Film 1 thickness (nm)")
        .set_text_value_accesskit("275");
    settle(&mut h);
    h.get_by_label("Add film").click();
    settle(&mut h);
    h.get_by_label("Film 2 material")
        .set_text_value_accesskit("tio2");
    settle(&mut h);
    assert!(path.exists(), "{:?}", h.state().session_error);
    let saved = StackDoc::read_recipe(&path).unwrap();
    assert_eq!(saved.films.len(), 2);
    assert_eq!(saved.films[0].thickness_nm, 275.0);
    assert_eq!(saved.films[1].material, "tio2");
    // An entry in error is not saved: the file keeps the last stack that built.
    h.get_by_label("Film 2 material")
        .set_text_value_accesskit("unobtainium");
    settle(&mut h);
    assert_eq!(StackDoc::read_recipe(&path).unwrap(), saved);
    let design = h.state().stack().0.clone();
    drop(h);

    // A new studio starts from the session.
    let mut g = build(make(&path));
    settle(&mut g);
    assert_eq!(g.state().stack().0.films, design.films);
    assert_eq!(g.state().doc.films[1].material, "tio2");
    assert!(g.state().session_error.is_none());

    // A broken session file: the default stack, the error shown, the file untouched.
    std::fs::write(&path, "ambient = [").unwrap();
    let mut k = build(make(&path));
    settle(&mut k);
    assert_eq!(k.state().stack().0, StackDoc::default());
    assert!(k.query_by_label_contains("session not restored").is_some());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "ambient = [");
}
