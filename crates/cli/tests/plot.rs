//! End-to-end tests of `nacre plot`: every subcommand draws a non-trivial PNG and SVG on its
//! defaults, and bad input exits with status 2, one message, no output file and an
//! existing file untouched.

use std::collections::HashSet;
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

/// Decodes an 8-bit RGB PNG: (width, height, pixels).
fn decode(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let picture = image::ImageReader::open(path)
        .unwrap()
        .with_guessed_format()
        .unwrap()
        .decode()
        .unwrap();
    assert_eq!(picture.color(), image::ColorType::Rgb8);
    let rgb = picture.into_rgb8();
    let (w, h) = rgb.dimensions();
    (w, h, rgb.pixels().map(|p| p.0).collect())
}

/// Checks a PNG: at least `min_size` pixels each way, `min_colours` distinct colours and
/// `min_ink` of the pixels not white.
fn check_png(path: &Path, min_size: (u32, u32), min_colours: usize, min_ink: f64) {
    let (w, h, pixels) = decode(path);
    assert!(
        w >= min_size.0 && h >= min_size.1,
        "{}: {w}x{h}",
        path.display()
    );
    assert_eq!(pixels.len(), (w * h) as usize);
    let colours: HashSet<[u8; 3]> = pixels.iter().copied().collect();
    let ink = pixels.iter().filter(|p| **p != [255, 255, 255]).count() as f64 / pixels.len() as f64;
    assert!(
        colours.len() >= min_colours && ink >= min_ink,
        "{}: {} colours, {:.1} % ink",
        path.display(),
        colours.len(),
        100.0 * ink
    );
}

/// Checks an SVG: a document with at least `min_shapes` drawn elements and some text.
fn check_svg(path: &Path, min_shapes: usize) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("<svg") && text.trim_end().ends_with("</svg>"));
    let shapes: usize = [
        "<polyline",
        "<path",
        "<line",
        "<rect",
        "<polygon",
        "<circle",
    ]
    .iter()
    .map(|tag| text.matches(tag).count())
    .sum();
    assert!(shapes >= min_shapes, "{}: {shapes} shapes", path.display());
    assert!(
        text.matches("<text").count() >= 10,
        "{}: no labels",
        path.display()
    );
}

fn no_temporaries(dir: &Path) {
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".nacre-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn plot_spectrum_default_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(&["plot", "spectrum"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    check_png(&dir.path().join("spectrum.png"), (1000, 800), 20, 0.03);
    let o = nacre(&["plot", "spectrum", "-o", "s.svg"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    check_svg(&dir.path().join("s.svg"), 30);
    no_temporaries(dir.path());
}

#[test]
fn plot_spectrum_from_a_csv_and_with_polarisations() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(
        &[
            "spectrum",
            "--layer",
            "au@30",
            "--substrate",
            "1.52",
            "-o",
            "gold.csv",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // 90 angles in the file: six are drawn, and a note says so.
    let o = nacre(
        &["plot", "spectrum", "--csv", "gold.csv", "-o", "a.png"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("plotting 6 of them"), "{}", stderr(&o));
    check_png(&dir.path().join("a.png"), (1000, 800), 20, 0.03);
    let o = nacre(
        &[
            "plot",
            "spectrum",
            "--csv",
            "gold.csv",
            "--angles",
            "0,45,70",
            "--quantities",
            "R,R_s,R_p,T,A",
            "-o",
            "b.svg",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    check_svg(&dir.path().join("b.svg"), 30);
    // An angle the file does not have.
    let o = nacre(
        &[
            "plot", "spectrum", "--csv", "gold.csv", "--angles", "12.5", "-o", "c.png",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--angles `12.5`: angle 12.5 is not in gold.csv"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("c.png").exists());
}

#[test]
fn plot_chromaticity_default_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(&["plot", "chromaticity"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    // The painted locus gives thousands of colours.
    check_png(&dir.path().join("chromaticity.png"), (900, 900), 2000, 0.3);
    let o = nacre(
        &[
            "plot",
            "chromaticity",
            "--case",
            "soap",
            "--angles",
            "0:85:5",
            "--gamut",
            "srgb,p3,rec2020",
            "-o",
            "c.svg",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    check_svg(&dir.path().join("c.svg"), 500);
    no_temporaries(dir.path());
}

#[test]
fn plot_chart_default_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(&["plot", "chart"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    check_png(&dir.path().join("chart.png"), (600, 800), 100, 0.5);
    let o = nacre(
        &[
            "plot",
            "chart",
            "--case",
            "dielectric",
            "--film-iors",
            "1.2,1.5:2.4:0.3",
            "--exposure",
            "4",
            "-o",
            "c.svg",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    check_svg(&dir.path().join("c.svg"), 31 * 5);
}

#[test]
fn plot_table_film_lut_and_fourier() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(&["plot", "table"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    check_png(&dir.path().join("table.png"), (1000, 900), 2000, 0.5);
    let o = nacre(&["plot", "table", "-o", "t.svg"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    check_svg(&dir.path().join("t.svg"), 4 * 32 * 100);
    let o = nacre(
        &["plot", "table", "fourier-srgb", "-o", "f.png"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    check_png(&dir.path().join("f.png"), (1200, 1000), 8, 0.02);
    let o = nacre(
        &["plot", "table", "fourier-srgb", "-o", "f.svg"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    check_svg(&dir.path().join("f.svg"), 6 * 8);
}

#[test]
fn plot_bad_input_exits_2_and_leaves_files_alone() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.csv"),
        "angle_deg,wavelength_nm,R_s,R_p,R,T_s,T_p,T,A\n0,400,0.1,0.1,0.1,0.9,0.9,0.9,0\n0,405,0.1,oops,0.1,0.9,0.9,0.9,0\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("keep.png"), b"precious").unwrap();
    std::fs::write(dir.path().join("keep.jpg"), b"precious").unwrap();
    for (args, expect) in [
        (
            &["plot", "spectrum", "-o", "keep.jpg"][..],
            "-o/--output `keep.jpg`: the image format follows the extension",
        ),
        (
            &["plot", "chart", "-o", "out.gif"][..],
            "expected a file name ending in .png or .svg",
        ),
        (
            &["plot", "spectrum", "--csv", "bad.csv", "-o", "keep.png"][..],
            "bad.csv:3: R_p `oops` is not a finite number",
        ),
        (
            &["plot", "spectrum", "--csv", "missing.csv", "-o", "keep.png"][..],
            "missing.csv",
        ),
        (
            &["plot", "table", "no-such-table", "-o", "keep.png"][..],
            "TABLE `no-such-table`: no such table",
        ),
        (
            &["plot", "table", "--film-iors", "3.5", "-o", "keep.png"][..],
            "--film-iors `3.5`: outside the table's film index range",
        ),
        (
            &[
                "plot",
                "chromaticity",
                "--methods",
                "spectral,bogus",
                "-o",
                "keep.png",
            ][..],
            "--methods `bogus`",
        ),
        (
            // The Fig. 7 base (1.09) is not the table's (1.5).
            &[
                "plot",
                "chromaticity",
                "--methods",
                "lut:film-dielectric",
                "-o",
                "keep.png",
            ][..],
            "the table was baked for base",
        ),
        (
            &[
                "plot",
                "chromaticity",
                "--gamut",
                "srgb,cmyk",
                "-o",
                "keep.png",
            ][..],
            "--gamut `srgb,cmyk`: unknown gamut `cmyk`",
        ),
        (
            &["plot", "chart", "--case", "nope", "-o", "keep.png"][..],
            "--case `nope`: expected one of",
        ),
        (
            &["plot", "spectrum", "--quantities", "R,X", "-o", "keep.png"][..],
            "--quantities `R,X`: unknown quantity `X`",
        ),
        (
            &["plot", "spectrum", "--angles", "0:90:10", "-o", "keep.png"][..],
            "--angles `0:90:10`: angle 90 must lie strictly between",
        ),
        (
            &["plot", "spectrum", "--angles", "0:88:8", "-o", "keep.png"][..],
            "12 angles: a spectrum plot shows at most 10",
        ),
    ] {
        let o = nacre(args, dir.path());
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.starts_with("nacre: error: "), "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert_eq!(
        std::fs::read(dir.path().join("keep.png")).unwrap(),
        b"precious"
    );
    assert_eq!(
        std::fs::read(dir.path().join("keep.jpg")).unwrap(),
        b"precious"
    );
    assert!(!dir.path().join("out.gif").exists());
    no_temporaries(dir.path());
    // Usage errors (clap) also exit 2.
    let o = nacre(
        &["plot", "chart", "--angles", "0", "--film-iors", "1.5"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(nacre(&["plot", "--help"], dir.path()).status.success());
}
