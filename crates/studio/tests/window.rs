//! `nacre-studio` in a real window under Xvfb (`xvfb-run`, as the Bevy viewer's test runs
//! its window): `--recipe FILE --screenshot PATH --frames N` starts, draws and saves the
//! window's picture; the test checks its colours: the egui panels, the uniform sky behind
//! the sphere, and the sphere's centre in the colour `nacre color` gives for the recipe's
//! film. Without `xvfb-run` the test fails (it never skips): `scripts/test.sh` installs it.
//! Bad flags exit with status 2 before any window opens.

use nacre_studio::StackDoc;
use nacre_studio::curves::exact_colours;
use nacre_studio::view::uniform_sky_pixel;
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_nacre-studio");

fn xvfb_run() -> &'static str {
    let found = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join("xvfb-run").is_file()))
        .unwrap_or(false);
    assert!(
        found,
        "xvfb-run is not installed (apt-get install xvfb xauth; scripts/test.sh installs it)"
    );
    "xvfb-run"
}

/// Pixels of `img` within `tol` levels (per channel) of `rgb`.
fn count_near(img: &image::RgbaImage, rgb: [u8; 3], tol: i32) -> usize {
    img.pixels()
        .filter(|p| (0..3).all(|k| (i32::from(p.0[k]) - i32::from(rgb[k])).abs() <= tol))
        .count()
}

#[test]
fn screenshot_under_xvfb_shows_the_recipes_colour() {
    let xvfb = xvfb_run();
    let dir = tempfile::tempdir().unwrap();
    let recipe = dir.path().join("film.toml");
    std::fs::write(
        &recipe,
        "ambient = \"1.0\"\nsubstrate = \"1.5\"\n[[layers]]\nmaterial = \"2.0\"\nthickness_nm = 190\n",
    )
    .unwrap();
    let shot = dir.path().join("studio.png");
    let out = Command::new(xvfb)
        .args(["-a", "-s", "-screen 0 1280x800x24", BIN])
        .arg("--recipe")
        .arg(&recipe)
        .arg("--screenshot")
        .arg(&shot)
        .args([
            "--frames",
            "3",
            "--window",
            "1200x760",
            "--view-size",
            "360x300",
            "--lighting",
            "uniform",
        ])
        .env("XDG_RUNTIME_DIR", dir.path())
        .output()
        .expect("xvfb-run starts");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "nacre-studio failed: {stderr}");
    assert!(stderr.contains("first picture after"), "{stderr}");
    let img = image::open(&shot)
        .unwrap_or_else(|e| panic!("{}: {e}\n{stderr}", shot.display()))
        .to_rgba8();
    assert_eq!(img.dimensions(), (1200, 760), "the window's size");
    let total = (img.width() * img.height()) as usize;
    // The egui dark theme's panels (27, 27, 27) cover much of the window.
    let panels = count_near(&img, [27, 27, 27], 3);
    assert!(panels > total / 5, "{panels} panel pixels of {total}");
    // The uniform sky of radiance 1 around the sphere: PBR Neutral of 1.0, sRGB.
    let sky = uniform_sky_pixel([1.0; 3], 0.0);
    let sky_pixels = count_near(&img, sky, 3);
    assert!(sky_pixels > 5_000, "{sky_pixels} sky pixels {sky:?}");
    // The sphere's centre: the film's colour at normal incidence, as `nacre color` gives.
    let doc = StackDoc::read_recipe(&recipe).unwrap();
    let rgb = exact_colours(&doc.build().unwrap(), &[0.0]).unwrap()[0];
    let film = uniform_sky_pixel(rgb, 0.06);
    let near = count_near(&img, film, 4);
    assert!(
        near > 100,
        "{near} pixels near the film's colour {film:?} (sky {sky:?})"
    );
    assert!(
        (0..3).any(|k| film[k].abs_diff(sky[k]) > 30),
        "the film's colour {film:?} must differ from the sky's"
    );
}

fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(BIN).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_flags_exit_2_naming_the_flag_before_any_window() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let bad_recipe = dir.path().join("bad.toml");
    std::fs::write(
        &bad_recipe,
        "[[layers]]\nmaterial = \"unobtainium\"\nthickness_nm = 100\n",
    )
    .unwrap();
    let shot = dir.path().join("never.png");
    let no_sky = dir.path().join("sky.exr");
    std::fs::write(&no_sky, b"not an OpenEXR file").unwrap();
    let no_map = dir.path().join("missing-map.png");
    for (args, flag, text) in [
        (vec!["--env", no_sky.to_str().unwrap()], "--env", "sky.exr"),
        (
            vec!["--thickness-map", no_map.to_str().unwrap()],
            "--thickness-map",
            "missing-map.png",
        ),
        (
            vec!["--lut-cache", bad_recipe.to_str().unwrap()],
            "--lut-cache",
            "is a file",
        ),
        (
            vec!["--recipe", missing.to_str().unwrap()],
            "--recipe",
            "missing.toml",
        ),
        (
            vec!["--recipe", bad_recipe.to_str().unwrap()],
            "--recipe",
            "unobtainium",
        ),
        (vec!["--frames", "0"], "--frames", "0"),
        (vec!["--window", "big"], "--window", "big"),
        (vec!["--technique", "raytrace"], "--technique", "raytrace"),
        (vec!["--lighting", "dusk"], "--lighting", "dusk"),
    ] {
        let mut all = args.clone();
        all.extend(["--screenshot", shot.to_str().unwrap()]);
        let (code, stderr) = run(&all);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains(flag) && stderr.contains(text),
            "{args:?}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
        assert!(!Path::new(&shot).exists(), "no output");
    }
}
