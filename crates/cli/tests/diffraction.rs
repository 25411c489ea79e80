//! End-to-end tests of `nacre diffraction`: output columns and values, the baked default
//! table, and bad input (exit status 2, a message naming the flag, no output written).

use std::path::Path;
use std::process::{Command, Output};

fn nacre(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run nacre")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn rows(o: &Output) -> (String, Vec<Vec<f64>>) {
    let text = String::from_utf8(o.stdout.clone()).unwrap();
    let header = text.lines().next().unwrap().to_string();
    let rows = nacre_optics::csv_rows::rows("stdout", &text)
        .unwrap()
        .into_iter()
        .skip(1)
        .map(|r| r.fields.iter().map(|x| x.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn spectra_of_a_sinusoidal_grating() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(
        &[
            "diffraction",
            "sine:1.6:0.05",
            "--incidence",
            "30",
            "--views",
            "-10:40:0.05",
            "--wavelengths",
            "500:600:50",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = rows(&o);
    assert_eq!(header, "view_deg,wavelength_nm,reflectance");
    assert_eq!(rows.len(), 1001 * 3);
    assert_eq!((rows[0][0], rows[0][1]), (-10.0, 500.0));
    assert_eq!((rows[1][0], rows[1][1]), (-10.0, 550.0));
    // Specular: G/w² = 1 and |P_0|² = J_0(k w a)² (0.592752 at 550 nm, w = −2 cos 30°).
    let spec = rows.iter().find(|r| r[0] == 30.0 && r[1] == 550.0).unwrap();
    assert!((spec[2] - 0.592_752).abs() < 1e-4, "{spec:?}");
    // The first order on the −x side of the specular: sin θ = sin 30° − 0.55/1.6.
    let theory = (0.5f64 - 0.55 / 1.6).asin().to_degrees();
    let peak = rows
        .iter()
        .filter(|r| r[1] == 550.0 && r[0] < 20.0)
        .max_by(|a, b| a[2].total_cmp(&b[2]))
        .unwrap();
    assert!((peak[0] - theory).abs() < 0.1, "{peak:?} vs {theory}");
}

#[test]
fn colours_and_files() {
    let dir = tempfile::tempdir().unwrap();
    // A flat CSV height field (any constant: the mean is removed) is a mirror; one row is
    // a surface invariant along y.
    let line = vec!["0.2"; 512].join(",");
    std::fs::write(dir.path().join("flat.csv"), format!("# flat\n{line}\n")).unwrap();
    let o = nacre(
        &[
            "diffraction",
            "flat.csv",
            "--pitch",
            "0.25",
            "--incidence",
            "-20",
            "--views",
            "-25:-15:5",
            "--wavelengths",
            "400:700:10",
            "--color",
            "-o",
            "c.csv",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.path().join("c.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("view_deg,X,Y,Z,R,G,B"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    // The specular row is the illuminant white: Y = 1, RGB = (1, 1, 1).
    let spec = &rows[1];
    assert_eq!(spec[0], -20.0);
    for v in &spec[4..7] {
        assert!((v - 1.0).abs() < 1e-9, "{spec:?}");
    }
    assert!((spec[2] - 1.0).abs() < 1e-9);
    assert!(rows[0][2] < 1e-6 && rows[2][2] < 1e-6, "{rows:?}");
}

#[test]
fn the_default_table_evaluates_like_its_height_field() {
    let dir = tempfile::tempdir().unwrap();
    let common = [
        "--incidence",
        "10",
        "--views",
        "-40:40:2",
        "--wavelengths",
        "380:780:20",
    ];
    let mut a = vec!["diffraction", "--table", "cd-tracks"];
    a.extend(common);
    let from_table = nacre(&a, dir.path());
    assert!(from_table.status.success(), "{}", stderr(&from_table));
    let mut b = vec![
        "diffraction",
        "cd",
        "--samples",
        "256",
        "--pitch",
        "0.125",
        "--coherence",
        "32",
    ];
    b.extend(common);
    let direct = nacre(&b, dir.path());
    assert!(direct.status.success(), "{}", stderr(&direct));
    let (h1, r1) = rows(&from_table);
    let (h2, r2) = rows(&direct);
    assert_eq!(h1, h2);
    assert_eq!(r1.len(), 41 * 21);
    // f32 terms and the table's Taylor order (bound 4.5e-4 at the worst point) against f64
    // terms at order N for 1e-6: 4.8e-5 at most when recorded, against a peak ρ of 0.76.
    let worst = r1
        .iter()
        .zip(&r2)
        .map(|(a, b)| (a[2] - b[2]).abs())
        .fold(0.0, f64::max);
    assert!(worst < 2e-4, "{worst}");
    assert!(r1.iter().any(|r| r[2] > 1e-3));
}

/// `view_deg,X,Y,Z,R,G,B` rows of a `--color` run.
fn colour_rows(o: &Output) -> Vec<Vec<f64>> {
    let (header, rows) = rows(o);
    assert_eq!(header, "view_deg,X,Y,Z,R,G,B");
    rows
}

/// The largest |ΔR|, |ΔG|, |ΔB| between two colour runs over the same views.
fn max_rgb_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let mut worst = (0.0, 0.0);
    for (a, b) in a.iter().zip(b) {
        assert_eq!(a[0], b[0]);
        for c in 4..7 {
            let d = (a[c] - b[c]).abs();
            if d > worst.0 {
                worst = (d, a[0]);
            }
        }
    }
    worst
}

#[test]
fn the_integrated_default_table_gives_the_colours_of_the_terms_table() {
    // cd-tracks-fast is cd-tracks summed over wavelengths with Stam's k² as (555 nm/λ)²
    // (issue 37): the colours of the terms table's spectra weighted the same way, within the
    // integrated_tolerance its bake measured (0.01 of the specular white with the same weight,
    // Σ_λ (555/λ)² u(λ)), read as a shader reads the table.
    let dir = tempfile::tempdir().unwrap();
    let path = nacre_format::set::resolve_table("cd-tracks-fast");
    let manifest = nacre_format::Manifest::read(&path).unwrap();
    let reference = manifest
        .diffraction()
        .unwrap()
        .integrated
        .as_ref()
        .unwrap()
        .k_squared_reference_nm;
    assert_eq!(reference, Some(555.0));
    let colorimeter = manifest.colorimeter(&path).unwrap();
    let wavelengths: Vec<f64> = (0..=80).map(|i| 380.0 + 5.0 * f64::from(i)).collect();
    let grid = nacre_optics::diffraction::SpectralGrid::new(&colorimeter, &wavelengths).unwrap();
    let weights: Vec<f64> = wavelengths.iter().map(|l| (555.0 / l).powi(2)).collect();
    let white = colorimeter.output_from_xyz(grid.xyz(&weights));
    for incidence in ["0", "10", "-30"] {
        let common = ["--incidence", incidence, "--views", "-44:44:0.25"];
        let mut a = vec!["diffraction", "--table", "cd-tracks-fast", "--color"];
        a.extend(common);
        let fast = nacre(&a, dir.path());
        assert!(fast.status.success(), "{}", stderr(&fast));
        assert!(stderr(&fast).contains("Stam's k^2"), "{}", stderr(&fast));
        let mut b = vec![
            "diffraction",
            "--table",
            "cd-tracks",
            "--wavelengths",
            "380:780:5",
        ];
        b.extend(common);
        let spectra = nacre(&b, dir.path());
        assert!(spectra.status.success(), "{}", stderr(&spectra));
        let (header, spectra) = rows(&spectra);
        assert_eq!(header, "view_deg,wavelength_nm,reflectance");
        // The terms table's colours with the k² weight: view_deg, R, G, B.
        let terms: Vec<Vec<f64>> = spectra
            .chunks_exact(wavelengths.len())
            .map(|views| {
                let rho: Vec<f64> = views
                    .iter()
                    .zip(&wavelengths)
                    .map(|(r, &l)| {
                        assert_eq!(r[1], l);
                        (555.0 / l).powi(2) * r[2]
                    })
                    .collect();
                let rgb = colorimeter.output_from_xyz(grid.xyz(&rho));
                vec![views[0][0], 0.0, 0.0, 0.0, rgb[0], rgb[1], rgb[2]]
            })
            .collect();
        // In units of the white with the same weight (the baker's metric).
        let fast: Vec<Vec<f64>> = colour_rows(&fast)
            .into_iter()
            .map(|mut r| {
                for c in 4..7 {
                    r[c] /= white[c - 4];
                }
                r
            })
            .collect();
        let terms: Vec<Vec<f64>> = terms
            .into_iter()
            .map(|mut r| {
                for c in 4..7 {
                    r[c] /= white[c - 4];
                }
                r
            })
            .collect();
        let (worst, at) = max_rgb_difference(&fast, &terms);
        eprintln!(
            "incidence {incidence}°: max |ΔRGB| {worst:.2e} of the k²-weighted white at view {at}°"
        );
        assert!(worst < 0.01, "incidence {incidence}: {worst} at {at}");
        // The specular highlight and the orders are there, not just agreement near zero.
        assert!(terms.iter().any(|r| r[5] > 0.1));
    }
}

#[test]
fn an_in_memory_integrated_table_evaluates_a_height_field() {
    let dir = tempfile::tempdir().unwrap();
    let common = [
        "sine:1.6:0.05",
        "--coherence",
        "16",
        "--incidence",
        "10",
        "--views",
        "-30:30:0.25",
        "--wavelengths",
        "380:780:10",
        "--color",
    ];
    let mut a = vec!["diffraction"];
    a.extend(common);
    a.extend(["--layout", "integrated"]);
    let fast = nacre(&a, dir.path());
    assert!(fast.status.success(), "{}", stderr(&fast));
    assert!(stderr(&fast).contains("integrated table of 128 x 256 texels"));
    let mut b = vec!["diffraction"];
    b.extend(common);
    let terms = nacre(&b, dir.path());
    assert!(terms.status.success(), "{}", stderr(&terms));
    let (worst, at) = max_rgb_difference(&colour_rows(&fast), &colour_rows(&terms));
    eprintln!("sine grating, --layout integrated: max |ΔRGB| {worst:.2e} at view {at}°");
    assert!(worst < 0.01, "{worst} at {at}");
}

#[test]
fn bad_input_exits_2_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("keep.csv"), "old").unwrap();
    std::fs::write(dir.path().join("h.csv"), "0,1\n2\n").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["sine:1.6:0.05", "--incidence", "95"], "--incidence"),
        (&["sine:1.6:0.05", "--incidence", "abc"], "--incidence"),
        (&["sine:1.6:0.05", "--views", "10:0:1"], "--views"),
        (&["sine:1.6:0.05", "--views", "0:90:1"], "--views"),
        (
            &["sine:1.6:0.05", "--wavelengths", "300:400:5"],
            "--wavelengths",
        ),
        (&["sine:0:0.05"], "sine:0:0.05"),
        (&["blazed:2"], "blazed:2"),
        (&["sine:1.6:0.05", "--pitch", "0.3"], "Nyquist"),
        (&["sine:1.6:0.05", "--pitch", "0"], "--pitch"),
        (&["cd", "--coherence", "0"], "--coherence"),
        (&["h.csv", "--pitch", "0.1"], "h.csv:2"),
        (&["h.csv"], "--pitch"),
        (&["missing.png", "--pitch", "0.1"], "missing.png"),
        (&["sine:1.6:0.05", "--space", "cmyk"], "--space"),
        (&["sine:1.6:0.05", "--fresnel", "x"], "--fresnel"),
        (&["--table", "cd-tracks", "--views", "-80:80:1"], "45"),
        (
            &["--table", "cd-tracks", "--wavelengths", "360:700:5"],
            "--wavelengths",
        ),
        (&["--table", "no-such-table"], "no-such-table"),
        // The integrated layout holds colours, summed over its own grid and colour space.
        (
            &["--table", "cd-tracks-fast", "--views", "-40:40:1"],
            "--color",
        ),
        (
            &[
                "--table",
                "cd-tracks-fast",
                "--color",
                "--wavelengths",
                "400:700:10",
            ],
            "380:780:5",
        ),
        (
            &[
                "--table",
                "cd-tracks-fast",
                "--color",
                "--space",
                "rec2020",
                "--views",
                "0:10:1",
            ],
            "--space",
        ),
        (
            &["--table", "cd-tracks", "--layout", "integrated", "--color"],
            "--layout",
        ),
        (&["sine:1.6:0.05", "--layout", "integrated"], "--color"),
        (
            &["sine:1.6:0.05", "--layout", "fast", "--color"],
            "--layout",
        ),
        (
            &["sine:1.6:0.05", "--integrated-samples", "64", "--color"],
            "--integrated-samples",
        ),
        (
            &[
                "sine:1.6:0.05",
                "--layout",
                "integrated",
                "--integrated-samples",
                "7",
                "--color",
            ],
            "--integrated-samples",
        ),
    ];
    for (args, needle) in cases {
        let mut a = vec!["diffraction"];
        a.extend_from_slice(args);
        a.extend(["-o", "keep.csv"]);
        let o = nacre(&a, dir.path());
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(needle), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{args:?}: {e}");
        assert_eq!(
            std::fs::read_to_string(dir.path().join("keep.csv")).unwrap(),
            "old"
        );
    }
    let o = nacre(&["diffraction"], dir.path());
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn diffraction_map_png() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(
        &[
            "plot",
            "diffraction",
            "sine:1.6:0.05",
            "--incidence",
            "30",
            "--max-view",
            "70",
            "--cells",
            "40",
            "--wavelengths",
            "400:700:50",
            "-o",
            "map.png",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(dir.path().join("map.png")).unwrap();
    let map = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).unwrap();
    assert_eq!((map.width(), map.height()), (760, 800));
    for (args, needle) in [
        (&["sine:1.6:0.05", "-o", "map.jpg"][..], "-o/--output"),
        (
            &["sine:1.6:0.05", "--cells", "4", "-o", "m.png"][..],
            "--cells",
        ),
        (
            &["sine:1.6:0.05", "--max-view", "90", "-o", "m.png"][..],
            "--max-view",
        ),
        (
            &["sine:1.6:0.05", "--exposure", "0", "-o", "m.png"][..],
            "--exposure",
        ),
        (
            &[
                "--table",
                "cd-tracks-fast",
                "--max-view",
                "60",
                "-o",
                "m.png",
            ][..],
            "45",
        ),
    ] {
        let mut a = vec!["plot", "diffraction"];
        a.extend_from_slice(args);
        let o = nacre(&a, dir.path());
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
    }
    assert!(!dir.path().join("m.png").exists());
    // A map from the integrated default table.
    let o = nacre(
        &[
            "plot",
            "diffraction",
            "--table",
            "cd-tracks-fast",
            "--incidence",
            "10",
            "--max-view",
            "35",
            "--cells",
            "40",
            "-o",
            "fast.png",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("fast.png").exists());
}
