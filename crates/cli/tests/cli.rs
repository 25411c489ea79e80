//! End-to-end tests of the `nacre` binary: outputs, and bad input that must give exit
//! status 2, one clear message, no panic and no output (an existing file survives).

use std::path::Path;
use std::process::{Command, Output};

fn nacre(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run nacre")
}

/// The data rows (after the header) of CSV output as numbers, read as CSV.
fn csv_numbers(text: &str) -> Vec<Vec<f64>> {
    nacre_optics::csv_rows::rows("output", text)
        .unwrap()
        .into_iter()
        .skip(1)
        .map(|r| r.fields.iter().map(|x| x.parse().unwrap()).collect())
        .collect()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn default_spectrum_to_stdout() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(&["spectrum"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert_eq!(
        text.lines().next(),
        Some("angle_deg,wavelength_nm,R_s,R_p,R,T_s,T_p,T,A")
    );
    let rows = csv_numbers(&text);
    assert_eq!(rows.len(), 90 * 81);
    assert_eq!((rows[0][0], rows[0][1]), (0.0, 380.0));
    assert_eq!((rows[81][0], rows[81][1]), (1.0, 380.0));
    assert_eq!(
        (rows.last().unwrap()[0], rows.last().unwrap()[1]),
        (89.0, 780.0)
    );
    for r in &rows {
        // A lossless soap film: R + T = 1, R = (R_s + R_p)/2.
        assert!((r[4] + r[7] - 1.0).abs() < 1e-10 && (r[4] - 0.5 * (r[2] + r[3])).abs() < 1e-11);
    }
    assert!(nacre(&["spectrum", "--help"], dir.path()).status.success());
}

/// `--jacobian` appends dR/dd_j and dT/dd_j (unpolarised, per nm, films top first) after the
/// unchanged value columns; they match central differences of two runs.
#[test]
fn spectrum_jacobian_columns_match_finite_differences() {
    let dir = tempfile::tempdir().unwrap();
    let run = |d1: f64, d2: f64, jacobian: bool| {
        let (l1, l2) = (format!("2.3+0.02i@{d1}"), format!("1.38@{d2}"));
        let mut args = vec![
            "spectrum",
            "--layer",
            &l1,
            "--layer",
            &l2,
            "--substrate",
            "1.52",
            "--angles",
            "0:60:30",
            "--wavelengths",
            "400:700:50",
        ];
        if jacobian {
            args.push("--jacobian");
        }
        let o = nacre(&args, dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8(o.stdout).unwrap()
    };
    let (d1, d2) = (60.0, 100.0);
    let with = run(d1, d2, true);
    assert_eq!(
        with.lines().next(),
        Some("angle_deg,wavelength_nm,R_s,R_p,R,T_s,T_p,T,A,dR_dd1,dR_dd2,dT_dd1,dT_dd2")
    );
    let (rows, plain) = (csv_numbers(&with), csv_numbers(&run(d1, d2, false)));
    assert_eq!(rows.len(), plain.len());
    for (r, p) in rows.iter().zip(&plain) {
        assert_eq!(&r[..9], &p[..], "value columns unchanged");
    }
    let h = 0.01;
    for film in 0..2 {
        let shift = |s: f64| {
            let (a, b) = if film == 0 {
                (d1 + s, d2)
            } else {
                (d1, d2 + s)
            };
            csv_numbers(&run(a, b, false))
        };
        let (up, down) = (shift(h), shift(-h));
        for (k, r) in rows.iter().enumerate() {
            for (col, quantity) in [(4, 9), (7, 11)] {
                let fd = (up[k][col] - down[k][col]) / (2.0 * h);
                let exact = r[quantity + film];
                assert!(
                    (exact - fd).abs() < 1e-6,
                    "row {k} column {}: {exact} vs {fd}",
                    quantity + film
                );
            }
        }
    }
}

/// The defaults work at every wavelength (issue 16 §5): vacuum around a 1.33 film, not the
/// bundled `air` (230–1690 nm) and `water` (182–1129 nm); `--help` says what they are.
#[test]
fn defaults_work_at_every_wavelength_and_help_states_them() {
    let dir = tempfile::tempdir().unwrap();
    for wavelengths in ["100:200:50", "2000:20000:9000"] {
        let o = nacre(
            &["spectrum", "--angles", "0", "--wavelengths", wavelengths],
            dir.path(),
        );
        assert!(o.status.success(), "{wavelengths}: {}", stderr(&o));
        assert!(o.stderr.is_empty(), "{}", stderr(&o));
    }
    let help = String::from_utf8(nacre(&["spectrum", "--help"], dir.path()).stdout).unwrap();
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    for needle in ["[default: 1.0, vacuum", "1.33@400", "the table's own stack"] {
        assert!(help.contains(needle), "`{needle}` not in: {help}");
    }
}

/// A table method and no stack flags: the table's own stack (issue 16 §5).
#[test]
fn a_table_method_without_stack_flags_uses_the_tables_stack() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for method in ["lut:film-dielectric", "lut:soap-film", "lut:film-gold"] {
        let o = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args(["color", "--method", method, "--angles", "0:80:40"])
            .current_dir(&repo)
            .output()
            .unwrap();
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert_eq!(
            String::from_utf8_lossy(&o.stdout).lines().count(),
            4,
            "{method}"
        );
    }
}

#[test]
fn recipe_and_flags_agree_and_write_a_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("ar.toml"),
        "substrate = \"bk7\"\nangles = \"0:80:10\"\n[[layers]]\nmaterial = \"mgf2\"\nthickness_nm = 99.75\n",
    )
    .unwrap();
    let a = nacre(
        &["spectrum", "--recipe", "ar.toml", "-o", "a.csv"],
        dir.path(),
    );
    assert!(a.status.success(), "{}", stderr(&a));
    let b = nacre(
        &[
            "spectrum",
            "--layer",
            "mgf2@99.75nm",
            "--substrate",
            "bk7",
            "--angles",
            "0:80:10",
            "-o",
            "b.csv",
        ],
        dir.path(),
    );
    assert!(b.status.success(), "{}", stderr(&b));
    let a = std::fs::read(dir.path().join("a.csv")).unwrap();
    assert_eq!(a, std::fs::read(dir.path().join("b.csv")).unwrap());
    assert_eq!(String::from_utf8(a).unwrap().lines().count(), 1 + 9 * 81);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".nacre-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn bad_input_exits_2_with_a_message_and_keeps_existing_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("bad.yml"),
        "DATA:\n  - type: tabulated nk\n    data: |\n        0.4 1.5 0.1\n        0.5 oops 0.1\n",
    )
    .unwrap();
    std::fs::write(
        d.join("bad.csv"),
        "wavelength_nm,n,k\n400,1.5,0.1\n500,1.5\n",
    )
    .unwrap();
    std::fs::write(
        d.join("bad.toml"),
        "substrate = \"bk7\"\n[[layers]]\nmaterial = \"mgf2\"\nthickness = 5\n",
    )
    .unwrap();
    std::fs::write(d.join("unclosed.toml"), "substrate = \"bk7\n").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--angles", "0:95:1"], "--angles"),
        (&["--angles", "abc"], "--angles `abc`"),
        (&["--angles", "0:1e9:0.0001"], "exceed the limit"),
        (&["--wavelengths", "380:780:0"], "--wavelengths `380:780:0`"),
        (
            &["--wavelengths", "780:380:5"],
            "END must not be below START",
        ),
        (
            &["--substrate", "air", "--wavelengths", "100:200:1"],
            "--wavelengths: material `air` has no data at 100 nm: its data covers 230–1690 nm",
        ),
        (&["--wavelengths", "-5"], "--wavelengths"),
        (&["--layer", "water@-5"], "--layer `water@-5`"),
        (&["--layer", "water"], "MATERIAL@THICKNESS"),
        (&["--layer", "1.5-0.1i@100"], "κ"),
        (&["--layer", "1.5+0.1k@100"], "invalid refractive index"),
        (&["--ambient", "au"], "ambient medium `au` absorbs"),
        (&["--ambient", "1.5+0.1i"], "must be non-absorbing"),
        (
            &["--substrate", "unobtainium"],
            "unknown material `unobtainium`",
        ),
        (&["--substrate", "missing.yml"], "missing.yml"),
        (
            &["--substrate", "bad.yml"],
            "bad.yml:5: `oops` is not a finite number",
        ),
        (&["--substrate", "bad.csv"], "bad.csv:3: expected 3"),
        (
            &["--recipe", "bad.toml"],
            "bad.toml:4: unknown field `thickness`",
        ),
        (&["--recipe", "unclosed.toml"], "unclosed.toml:1:"),
        (&["--recipe", "nope.toml"], "nope.toml"),
        (
            &["--recipe", "bad.toml", "--substrate", "bk7"],
            "cannot be used with",
        ),
        (&["--frobnicate"], "--frobnicate"),
    ];
    for (args, needle) in cases {
        std::fs::write(d.join("out.csv"), "previous").unwrap();
        let mut full = vec!["spectrum"];
        full.extend_from_slice(args);
        full.extend_from_slice(&["-o", "out.csv"]);
        let o = nacre(&full, d);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(needle),
            "{args:?}: expected `{needle}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(
            std::fs::read_to_string(d.join("out.csv")).unwrap(),
            "previous",
            "{args:?}"
        );
        // and without an existing file, none is created
        std::fs::remove_file(d.join("out.csv")).unwrap();
        let o = nacre(&full, d);
        assert_eq!(o.status.code(), Some(2));
        assert!(!d.join("out.csv").exists(), "{args:?} created output");
    }
    let o = nacre(&["spectrum", "-o", "no/such/dir/out.csv"], d);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no/such/dir/out.csv"), "{}", stderr(&o));
}

/// `--method stack` (the GPU technique's CPU twin) against the exact reference on a
/// three-film stack with a 10 nm silver film, and a points file overriding the top film.
/// A coherent film whose fringes the wavelength grid cannot follow is named on stderr, once,
/// with a pointer to `:incoherent`; a normal film, or the same slab marked incoherent, gives
/// no warning (issue 31 §1).
#[test]
fn undersampled_coherent_films_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let warnings = |args: &[&str]| {
        let o = nacre(args, d);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        stderr(&o)
            .lines()
            .filter(|l| l.starts_with("nacre: warning: "))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    let slab = [
        "--layer",
        "mgf2@100nm",
        "--layer",
        "bk7@2mm",
        "--substrate",
        "air",
        "--angles",
        "0:30:10",
    ];
    let w = warnings(&[&["spectrum"][..], &slab].concat());
    assert_eq!(w.len(), 1, "{w:?}");
    for needle in [
        "layer 2 (`bk7`, 2000000 nm) is coherent",
        "2.385e-2 nm apart near 380 nm",
        "the 5 nm wavelength step",
        "mark it `:incoherent` (`bk7@2000000nm:incoherent`)",
    ] {
        assert!(w[0].contains(needle), "`{needle}` not in {}", w[0]);
    }
    let marked = [&["spectrum"][..], &slab].concat();
    let marked: Vec<&str> = marked
        .iter()
        .map(|a| {
            if *a == "bk7@2mm" {
                "bk7@2mm:incoherent"
            } else {
                a
            }
        })
        .collect();
    assert_eq!(warnings(&marked), Vec::<String>::new());
    assert_eq!(
        warnings(&["spectrum", "--angles", "0:30:10"]),
        Vec::<String>::new()
    );
    // `samples:N` samples 400–700 nm every 300/(N − 1) nm: a 20 µm film is too thick for 16.
    let color = |layer: &str, method: &str| {
        warnings(&[
            "color", "--layer", layer, "--angles", "0:60:30", "--method", method,
        ])
    };
    let w = color("1.33@20um", "samples:16");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("layer 1 (`1.33`, 20000 nm)") && w[0].contains("the 20 nm wavelength step"),
        "{}",
        w[0]
    );
    assert_eq!(color("1.33@400", "samples:16"), Vec::<String>::new());
    // `spectral` steps its rule by the fringes' phase: never undersampled.
    assert_eq!(color("1.33@20um", "spectral"), Vec::<String>::new());
}

#[test]
fn color_stack_method_is_close_to_spectral() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |method: &str| {
        let o = nacre(
            &[
                "color",
                "--layer",
                "mgf2@110",
                "--layer",
                "ag@10",
                "--layer",
                "1.9@180",
                "--substrate",
                "ag",
                "--angles",
                "0:80:9",
                "--method",
                method,
            ],
            d,
        );
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        csv_numbers(&String::from_utf8(o.stdout).unwrap())
    };
    let exact = run("spectral");
    for method in ["stack", "stack:64"] {
        let got = run(method);
        assert_eq!(got.len(), exact.len());
        for (g, x) in got.iter().zip(&exact) {
            for c in 3..9 {
                assert!((g[c] - x[c]).abs() < 0.01, "{method}: {g:?} vs {x:?}");
            }
        }
    }
}

#[test]
fn color_methods_and_info() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let o = nacre(&["color", "--layer", "1.33@400", "--angles", "0:80:20"], d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B")
    );
    assert_eq!(lines.count(), 5);
    std::fs::write(
        d.join("p.csv"),
        "angle_deg,thickness_nm,film_ior\n0,400,1.33\n45,250.5,1.4\n",
    )
    .unwrap();
    for method in ["spectral", "rgb3", "samples:5", "lut:soap-film"] {
        // Run from the repository so that `lut:soap-film` finds the default set.
        let o = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args([
                "color",
                "--ambient",
                "1.0",
                "--layer",
                "1.33@400",
                "--substrate",
                "1.0",
                "--method",
                method,
                "-o",
            ])
            .arg(d.join("c.csv"))
            .arg("--points")
            .arg(d.join("p.csv"))
            .current_dir(&repo)
            .output()
            .unwrap();
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        let text = std::fs::read_to_string(d.join("c.csv")).unwrap();
        let rows = csv_numbers(&text);
        assert_eq!(rows.len(), 2, "{method}");
        assert_eq!((rows[1][0], rows[1][1], rows[1][2]), (45.0, 250.5, 1.4));
        assert!(rows.iter().all(|r| r[3..].iter().all(|v| v.is_finite())));
    }
    let o = Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(["info", "film-gold"])
        .current_dir(&repo)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(
        text.contains("\"kind\": \"film-lut\"") && text.contains("\"base\": \"au\""),
        "{text}"
    );
}

#[test]
fn color_and_bake_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("bad-points.csv"),
        "angle_deg,thickness_nm,film_ior\n0,400,1.33\n95,1,1\n",
    )
    .unwrap();
    std::fs::write(d.join("kind.toml"), "kind = \"cake\"\n").unwrap();
    std::fs::write(
        d.join("huge.toml"),
        "kind = \"film-lut\"\n[stack]\nambient = \"1.0\"\nbase = \"1.5\"\n[axes]\ncos_theta_count = 4096\nthickness_nm = [0.0, 100.0]\nopd_count = 4096\nfilm_ior = [1.0, 2.0]\nfilm_ior_count = 2\n",
    )
    .unwrap();
    std::fs::write(
        d.join("absorbing.toml"),
        "kind = \"film-lut\"\n[stack]\nambient = \"au\"\nbase = \"1.5\"\n[axes]\ncos_theta_count = 4\nthickness_nm = [0.0, 100.0]\nopd_count = 4\nfilm_ior = [1.0, 2.0]\nfilm_ior_count = 2\n",
    )
    .unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cases: &[(&[&str], &str)] = &[
        (&["color", "--method", "foo"], "--method `foo`"),
        (&["color", "--method", "samples:0"], "samples:N"),
        (&["color", "--method", "stack:0"], "stack:N"),
        (&["color", "--method", "lut:nope.json"], "nope.json"),
        (
            &[
                "color",
                "--ambient",
                "air",
                "--layer",
                "1.33@400",
                "--substrate",
                "1.5",
                "--method",
                "lut:soap-film",
            ],
            "baked for ambient `1.0`, this stack has `air`",
        ),
        (
            &[
                "color",
                "--ambient",
                "1.0",
                "--layer",
                "1.33@400",
                "--substrate",
                "1.5",
                "--method",
                "lut:soap-film",
            ],
            "baked for base",
        ),
        (
            &[
                "color",
                "--layer",
                "1.33@400",
                "--ambient",
                "1.0",
                "--substrate",
                "au",
                "--method",
                "lut:film-gold",
                "--quantity",
                "t",
            ],
            "no transmittance",
        ),
        (
            &[
                "color",
                "--layer",
                "1.33@400",
                "--ambient",
                "1.0",
                "--substrate",
                "au",
                "--method",
                "lut:film-gold",
                "--space",
                "rec2020",
            ],
            "--space",
        ),
        (&["color", "--space", "lab"], "--space `lab`"),
        (&["color", "--observer", "1900"], "--observer `1900`"),
        (&["color", "--illuminant", "d60"], "--illuminant `d60`"),
        (
            &["color", "--points", "BAD/bad-points.csv"],
            "bad-points.csv:3",
        ),
        (&["color", "--angles", "0:90:10"], "--angles"),
        (
            &["bake", "BAD/kind.toml", "--out", "BAD/out"],
            "kind.toml:1: unknown table kind `cake`",
        ),
        (
            &["bake", "BAD/huge.toml", "--out", "BAD/out"],
            "exceeds the limit",
        ),
        (
            &["bake", "BAD/absorbing.toml", "--out", "BAD/out"],
            "constant real index",
        ),
        (
            &["bake", "BAD/missing.toml", "--out", "BAD/out"],
            "missing.toml",
        ),
        (&["info", "no-such-table"], "no-such-table.json"),
    ];
    let bad = d.to_string_lossy().into_owned();
    for (args, needle) in cases {
        let args: Vec<String> = args.iter().map(|a| a.replace("BAD", &bad)).collect();
        let o = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args(&args)
            .current_dir(&repo)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(needle),
            "{args:?}: expected `{needle}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(!d.join("out").exists(), "a failed bake wrote output");
}

#[test]
fn compare_writes_csv_and_png() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(
        &[
            "compare",
            "--case",
            "dielectric",
            "--angles",
            "0:80:40",
            "--thicknesses",
            "100:500:200",
            "-o",
            "out",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    for m in [
        "rgb3",
        "samples:5",
        "gaussian",
        "fourier:1",
        "fourier:2",
        "fourier:3",
        "lut",
    ] {
        assert!(table.contains(&format!("| `{m}` |")), "{table}");
    }
    let csv = std::fs::read_to_string(dir.path().join("out/compare.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 7 * 3 * 3);
    let png = std::fs::read(dir.path().join("out/compare.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
    let o = nacre(&["compare", "--case", "nope", "-o", "out2"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--case `nope`"));
    assert!(!dir.path().join("out2").exists());
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    let be =
        |at: usize| u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    (be(16), be(20))
}

#[test]
fn render_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // With only -o: the sphere with the default tables (small here to keep the test quick).
    let o = nacre(
        &[
            "render",
            "--width",
            "64",
            "--height",
            "48",
            "-o",
            "sphere.png",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("adapter: "), "{}", stderr(&o));
    let png = std::fs::read(d.join("sphere.png")).unwrap();
    assert_eq!(png_size(&png), (64, 48));
    // Without a Wayland session, nothing on stderr says "error" (issue 16 §5: Mesa's Vulkan
    // device-select layer made libwayland print `error: XDG_RUNTIME_DIR is invalid or not
    // set in the environment.` twice on success).
    let o = Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(["render", "--width", "8", "--height", "8", "-o", "quiet.png"])
        .current_dir(d)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        !stderr(&o).to_lowercase().contains("error"),
        "{}",
        stderr(&o)
    );
    for (scene, technique, extra) in [
        ("bubble", "spectral", &["--wavelengths", "12"][..]),
        (
            "plane",
            "fourier",
            &["--harmonics", "0", "--exposure", "-0.5"][..],
        ),
    ] {
        let out = format!("{scene}.png");
        let mut args = vec![
            "render",
            "--scene",
            scene,
            "--technique",
            technique,
            "--width",
            "40",
            "--height",
            "30",
            "-o",
            &out,
        ];
        args.extend_from_slice(extra);
        let o = nacre(&args, d);
        assert!(o.status.success(), "{scene}: {}", stderr(&o));
        assert_eq!(png_size(&std::fs::read(d.join(&out)).unwrap()), (40, 30));
    }
    // Explicit tables: a film on gold.
    let o = nacre(
        &[
            "render",
            "--tables",
            "film-gold",
            "--tables",
            "fourier-srgb",
            "--technique",
            "lut",
            "--width",
            "32",
            "--height",
            "24",
            "-o",
            "gold.png",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let help = nacre(&["render", "--help"], d);
    assert!(help.status.success());
    assert!(String::from_utf8_lossy(&help.stdout).contains("Examples:"));
    let leftovers: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".nacre-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn render_bad_input_exits_2_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("junk.exr"), b"not an OpenEXR file").unwrap();
    std::fs::write(d.join("junk.png"), b"not a PNG file").unwrap();
    // A valid 2x2 8-bit RGB PNG: colour, not a greyscale thickness map.
    image::RgbImage::from_pixel(2, 2, image::Rgb([200, 100, 50]))
        .save(d.join("rgb.png"))
        .unwrap();
    let small = ["--width", "16", "--height", "12"];
    let cases: &[(&[&str], &str)] = &[
        (&["--scene", "cube"], "--scene"),
        (&["--technique", "raytrace"], "--technique"),
        (&["--width", "0"], "width"),
        (&["--height", "9000"], "8192"),
        (&["--width", "-3"], "-3"),
        (&["--env", "missing.exr"], "missing.exr"),
        (&["--env", "junk.exr"], "junk.exr"),
        (&["--thickness-map", "missing.png"], "missing.png"),
        (&["--thickness-map", "junk.png"], "junk.png"),
        (&["--thickness-map", "rgb.png"], "greyscale"),
        (&["--tables", "no-such-table"], "no-such-table"),
        (
            &["--technique", "fourier", "--tables", "film-dielectric"],
            "fourier",
        ),
        (
            &["--technique", "spectral", "--wavelengths", "0"],
            "wavelengths",
        ),
        (&["--exposure", "nan"], "exposure"),
        (
            &["--scene", "bubble", "--tables", "film-gold"],
            "transmittance",
        ),
    ];
    for (extra, expect) in cases {
        let mut args = vec!["render"];
        if !extra.iter().any(|a| *a == "--width" || *a == "--height") {
            args.extend_from_slice(&small);
        }
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", "out.png"]);
        let o = nacre(&args, d);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(
            err.contains(expect),
            "{extra:?}: expected `{expect}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
        assert!(!d.join("out.png").exists(), "{extra:?} wrote an output");
    }
    // -o is required.
    let o = nacre(&["render"], d);
    assert_eq!(o.status.code(), Some(2));
    // An existing output survives a failed render.
    std::fs::write(d.join("keep.png"), b"keep").unwrap();
    let o = nacre(&["render", "--env", "junk.exr", "-o", "keep.png"], d);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read(d.join("keep.png")).unwrap(), b"keep");
}

/// `nacre bench-gpu` times every pass on the adapter it finds (lavapipe in CI) and reports
/// ratios against the plain pass.
#[test]
fn bench_gpu_reports_every_pass() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let o = nacre(
        &[
            "bench-gpu",
            "--width",
            "64",
            "--height",
            "32",
            "--frames",
            "2",
        ],
        &repo,
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for pass in [
        "plain GGX + Schlick",
        "film_lut",
        "film_fourier",
        "film_spectral",
        "diffraction",
    ] {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(pass))
            .unwrap_or_else(|| panic!("no `{pass}` line in\n{stdout}"));
        let ms: f64 = line
            .split_whitespace()
            .rev()
            .nth(3)
            .unwrap()
            .parse()
            .unwrap();
        assert!(ms.is_finite() && ms >= 0.0, "{line}");
    }
    assert!(
        stdout.contains("diffraction cd-tracks at a 10 nm step"),
        "{stdout}"
    );
    // The diffraction pass on the integrated table of the same surface (the fast path).
    let o = nacre(
        &[
            "bench-gpu",
            "--width",
            "64",
            "--height",
            "32",
            "--frames",
            "2",
            "--diffraction",
            "cd-tracks-fast",
        ],
        &repo,
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        stdout.contains("diffraction cd-tracks-fast (layout integrated)"),
        "{stdout}"
    );
    assert!(
        stdout.lines().any(|l| l.starts_with("diffraction ")),
        "{stdout}"
    );
    let bad = nacre(
        &[
            "bench-gpu",
            "--frames",
            "0",
            "--width",
            "8",
            "--height",
            "8",
        ],
        &repo,
    );
    assert_eq!(bad.status.code(), Some(2));
}

/// `nacre render --scene cd-disc | snake-skin --tables cd-tracks-fast`: the diffraction
/// scenes draw from an integrated table (the fast path) as from a terms table.
#[test]
fn render_diffraction_scenes_take_an_integrated_table() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for scene in ["cd-disc", "snake-skin"] {
        let out = format!("{scene}.png");
        let o = nacre(
            &[
                "render",
                "--scene",
                scene,
                "--tables",
                "cd-tracks-fast",
                "--width",
                "40",
                "--height",
                "30",
                "-o",
                &out,
            ],
            d,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!(
                "rendered {scene} (diffraction, cd-tracks-fast, integrated)"
            )),
            "{}",
            stderr(&o)
        );
        assert_eq!(png_size(&std::fs::read(d.join(&out)).unwrap()), (40, 30));
    }
}

/// `nacre render --gltf`: a committed sweep renders; bad glTF files exit 2 with one message
/// and no output.
#[test]
fn render_gltf_writes_a_png_and_refuses_bad_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let sweep = repo.join("tests/golden/gltf/sweep-base-ior.glb");
    let sweep = sweep.to_str().unwrap();
    let o = nacre(
        &[
            "render", "--gltf", sweep, "--width", "100", "--height", "28", "-o", "s.png",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        png_size(&std::fs::read(d.join("s.png")).unwrap()),
        (100, 28)
    );
    // lut with film-dielectric: bases other than 1.5 fall back to fourier, with a note.
    assert!(
        stderr(&o).contains("drawn with fourier instead of lut"),
        "{}",
        stderr(&o)
    );
    let o = nacre(
        &[
            "render",
            "--gltf",
            sweep,
            "--technique",
            "fourier",
            "--width",
            "50",
            "--height",
            "14",
            "-o",
            "f.png",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));

    let good = std::fs::read(repo.join("tests/golden/gltf/sweep-thickness.glb")).unwrap();
    std::fs::write(d.join("truncated.glb"), &good[..good.len() - 100]).unwrap();
    std::fs::write(d.join("junk.gltf"), b"{\"asset\": 3}").unwrap();
    // A line-list primitive: mesh 0's `"material":0` becomes `"material":0,"mode":1` in the
    // JSON chunk, re-packed as GLB.
    let json_len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let json = String::from_utf8(good[20..20 + json_len].to_vec()).unwrap();
    let json = json.replacen("\"material\":0", "\"material\":0,\"mode\":1", 1);
    let bin = &good[20 + json_len + 8..];
    let mut json = json.trim_end().as_bytes().to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut lines = Vec::new();
    lines.extend_from_slice(b"glTF");
    lines.extend_from_slice(&2u32.to_le_bytes());
    lines.extend_from_slice(&(total as u32).to_le_bytes());
    lines.extend_from_slice(&(json.len() as u32).to_le_bytes());
    lines.extend_from_slice(b"JSON");
    lines.extend_from_slice(&json);
    lines.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    lines.extend_from_slice(b"BIN\0");
    lines.extend_from_slice(bin);
    std::fs::write(d.join("lines.glb"), lines).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--gltf", "missing.glb"], "missing.glb"),
        (&["--gltf", "truncated.glb"], "truncated.glb"),
        (&["--gltf", "junk.gltf"], "junk.gltf"),
        (&["--gltf", sweep, "--width", "0"], "width"),
        (&["--gltf", sweep, "--height", "100000"], "8192"),
    ];
    for (extra, expect) in cases {
        let mut args = vec!["render"];
        if !extra.iter().any(|a| *a == "--width" || *a == "--height") {
            args.extend_from_slice(&["--width", "16", "--height", "12"]);
        }
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", "out.png"]);
        let o = nacre(&args, d);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(
            err.contains(expect),
            "{extra:?}: expected `{expect}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
        assert!(!d.join("out.png").exists(), "{extra:?} wrote an output");
    }
    // A line primitive is drawn (as lines: the sphere's wireframe), with no note; the
    // picture differs from the one of the same file with triangles.
    std::fs::write(d.join("triangles.glb"), &good).unwrap();
    let mut pictures = Vec::new();
    for name in ["lines", "triangles"] {
        let (glb, png) = (format!("{name}.glb"), format!("{name}.png"));
        let o = nacre(
            &[
                "render", "--width", "100", "--height", "28", "--gltf", &glb, "-o", &png,
            ],
            d,
        );
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(0), "{err}");
        assert!(!err.contains("skipped"), "{err}");
        pictures.push(image::open(d.join(&png)).unwrap().to_rgb8());
    }
    let differing = pictures[0]
        .pixels()
        .zip(pictures[1].pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(differing > 20, "{differing} pixels differ");
}

/// `nacre color --method rough-lut:NAME --roughness A` (issue 6) agrees with the Monte Carlo
/// reference `rough-mc` at the same points (reflected and transmitted), reports the
/// reference's noise, and refuses missing, misplaced or out-of-range roughness.
#[test]
fn color_rough_methods() {
    let dir = tempfile::tempdir().unwrap();
    let stack = [
        "color",
        "--ambient",
        "1.0",
        "--layer",
        "1.4@350",
        "--substrate",
        "1.5",
        "--angles",
        "0:80:40",
    ];
    let run = |extra: &[&str]| {
        let mut args = stack.to_vec();
        args.extend_from_slice(extra);
        nacre(&args, dir.path())
    };
    let rows = |o: &Output| -> Vec<Vec<f64>> {
        let text = String::from_utf8(o.stdout.clone()).unwrap();
        assert_eq!(
            text.lines().next(),
            Some("angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B")
        );
        csv_numbers(&text)
    };
    for quantity in ["r", "t"] {
        let lut = run(&[
            "--method",
            "rough-lut:rough-film-dielectric",
            "--roughness",
            "0.4",
            "--quantity",
            quantity,
        ]);
        assert!(lut.status.success(), "{}", stderr(&lut));
        let mc = run(&[
            "--method",
            "rough-mc:65536",
            "--roughness",
            "0.4",
            "--quantity",
            quantity,
        ]);
        assert!(mc.status.success(), "{}", stderr(&mc));
        assert!(
            stderr(&mc).contains("largest standard error"),
            "{}",
            stderr(&mc)
        );
        let (a, b) = (rows(&lut), rows(&mc));
        assert_eq!(a.len(), 3);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x[..3], y[..3]);
            for c in 6..9 {
                // A few per cent reflected, most transmitted: agree within 3 % + 1e-3.
                assert!(
                    (x[c] - y[c]).abs() <= 0.03 * y[c] + 1e-3,
                    "{quantity}: {x:?} vs {y:?}"
                );
            }
        }
    }
    for (extra, needle) in [
        (vec!["--method", "rough-mc"], "--roughness"),
        (
            vec!["--method", "spectral", "--roughness", "0.3"],
            "--roughness",
        ),
        (
            vec![
                "--method",
                "rough-lut:rough-film-dielectric",
                "--roughness",
                "0.01",
            ],
            "covers GGX",
        ),
        (vec!["--method", "rough-mc", "--roughness", "1.5"], "(0, 1]"),
        (
            vec!["--method", "rough-lut:", "--roughness", "0.3"],
            "rough-lut:NAME",
        ),
        (
            vec!["--method", "rough-mc:0", "--roughness", "0.3"],
            "rough-mc:N",
        ),
    ] {
        let o = run(&extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
        assert!(o.stdout.is_empty());
    }
    // A table baked for another base is refused.
    let o = nacre(
        &[
            "color",
            "--ambient",
            "1.0",
            "--layer",
            "1.4@350",
            "--substrate",
            "1.33",
            "--method",
            "rough-lut:rough-film-dielectric",
            "--roughness",
            "0.3",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("base"), "{}", stderr(&o));
}

/// `nacre export` writes a raw RGBA16F 3-D texture and its sidecar that read back as the
/// table's texels; bad input exits 2 naming the flag or file and writes nothing.
#[test]
fn export_writes_a_raw_texture_and_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let table = nacre_format::set::default_baked_dir().join("soap-film.json");
    let table_arg = table.to_str().unwrap();
    let o = nacre(
        &[
            "export",
            "--table",
            table_arg,
            "--quantity",
            "transmittance",
            "--out",
            "t.raw",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(dir.path().join("t.raw")).unwrap();
    let sidecar: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("t.json")).unwrap()).unwrap();
    let m = nacre_format::Manifest::read(&table).unwrap();
    let t = m.load_table(&table, "transmittance").unwrap().unwrap();
    assert_eq!(sidecar["width"], t.nx);
    assert_eq!(sidecar["height"], t.ny);
    assert_eq!(sidecar["depth"], t.nz);
    assert_eq!(sidecar["format"], "rgba16f-le");
    assert_eq!(bytes.len(), t.nx * t.ny * t.nz * 8);
    for z in 0..t.nz {
        for y in (0..t.ny).step_by(7) {
            for x in 0..t.nx {
                let o = 8 * ((z * t.ny + y) * t.nx + x);
                let want = t.texel(x, y, z);
                for c in 0..3 {
                    let h = half::f16::from_le_bytes([bytes[o + 2 * c], bytes[o + 2 * c + 1]]);
                    assert_eq!(
                        h,
                        half::f16::from_f32(want[c]),
                        "texel ({x}, {y}, {z}) channel {c}"
                    );
                }
            }
        }
    }
    for (args, names) in [
        (
            vec!["export", "--table", "no-such-table", "--out", "x.raw"],
            "no-such-table",
        ),
        (
            vec![
                "export",
                "--table",
                table_arg,
                "--quantity",
                "albedo",
                "--out",
                "x.raw",
            ],
            "--quantity",
        ),
        (
            vec!["export", "--table", "fourier-srgb", "--out", "x.raw"],
            "--table",
        ),
        (
            vec!["export", "--table", table_arg, "--out", "x.json"],
            "--out",
        ),
    ] {
        let o = nacre(&args, dir.path());
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(names), "{args:?}: {}", stderr(&o));
        assert!(!dir.path().join("x.raw").exists() && !dir.path().join("x.json").exists());
    }
}

/// `nacre export --layer …` writes the stack JSON of the engine libraries' `film_stack`:
/// the numbers `StackGpu` prepares from the same stack (read back exactly), the stack
/// described under `about`; bad input exits 2 naming the flag and writes nothing.
#[test]
fn export_writes_a_stack_json() {
    use nacre_optics::few_wavelengths::StackEvaluation;
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(
        &[
            "export",
            "--layer",
            "1.38@100",
            "--layer",
            "2.3@60",
            "--substrate",
            "1.5",
            "--relative",
            "0",
            "--relative",
            "20",
            "--layer-channel",
            "r",
            "--layer-channel",
            "g",
            "--out",
            "stack.json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("2 films"), "{}", stderr(&o));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("stack.json")).unwrap()).unwrap();
    let read = nacre_format::export::read_stack_json(&json, "stack.json").unwrap();
    let constant = |n: f64| {
        nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0)).unwrap()
    };
    let layer = |n: f64, d: f64| nacre_optics::Layer {
        material: constant(n),
        thickness_nm: d,
    };
    let stack = nacre_optics::Stack::new(
        constant(1.0),
        vec![layer(1.38, 100.0), layer(2.3, 60.0)],
        constant(1.5),
    )
    .unwrap();
    let colorimeter = nacre_optics::colour::Colorimeter::new(
        "1931".parse().unwrap(),
        "d65".parse().unwrap(),
        "srgb".parse().unwrap(),
    );
    let eval = StackEvaluation::new(&colorimeter, &stack, &[0.0, 20.0], None)
        .unwrap()
        .with_channels(&[0, 1])
        .unwrap();
    assert_eq!(read, nacre_format::gpu_params::StackGpu::new(&eval));
    assert_eq!(json["about"]["films"][1]["channel"], "g");
    assert_eq!(json["about"]["films"][1]["relative_nm"], 20.0);
    assert_eq!(json["texture"]["width"], 6);
    assert_eq!(json["texture"]["height"], json["node_count"]);
    let wrong = |args: &[&str], names: &[&str]| {
        let o = nacre(args, dir.path());
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        for name in names {
            assert!(stderr(&o).contains(name), "{args:?}: {}", stderr(&o));
        }
        assert!(!dir.path().join("x.json").exists());
    };
    wrong(
        &[
            "export",
            "--layer",
            "1.38@100",
            "--relative",
            "1",
            "--relative",
            "2",
            "--out",
            "x.json",
        ],
        &["--relative", "one per film"],
    );
    wrong(
        &[
            "export",
            "--layer",
            "1.38@100",
            "--relative",
            "-5",
            "--out",
            "x.json",
        ],
        &["--relative"],
    );
    wrong(
        &[
            "export",
            "--layer",
            "1.38@100",
            "--layer",
            "1.5@10",
            "--layer-channel",
            "g",
            "--layer-channel",
            "r",
            "--out",
            "x.json",
        ],
        &["--layer-channel", "top film"],
    );
    wrong(
        &[
            "export",
            "--layer",
            "1.38@100",
            "--wavelengths",
            "0",
            "--out",
            "x.json",
        ],
        &["--wavelengths"],
    );
    let nine: Vec<&str> = std::iter::once("export")
        .chain((0..9).flat_map(|_| ["--layer", "1.4@50"]))
        .chain(["--out", "x.json"])
        .collect();
    wrong(&nine, &["--layer", "1 to 8"]);
    wrong(
        &["export", "--layer", "nosuchmaterial@100", "--out", "x.json"],
        &["nosuchmaterial"],
    );
    wrong(
        &[
            "export", "--layer", "1.38@100", "--space", "cmyk", "--out", "x.json",
        ],
        &["--space"],
    );
    // --table and a stack, or neither: usage errors.
    wrong(
        &[
            "export",
            "--table",
            "soap-film",
            "--layer",
            "1.38@100",
            "--out",
            "x.json",
        ],
        &["--table"],
    );
    wrong(&["export", "--out", "x.json"], &["--table"]);
}

/// `nacre spectrum | head`: a reader that closes the pipe early ends the command quietly
/// (status 0, nothing on stderr), as Unix tools do.
#[test]
fn a_closed_pipe_ends_quietly() {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args([
            "spectrum",
            "--angles",
            "0:89:0.05",
            "--wavelengths",
            "380:780:1",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 64];
    child
        .stdout
        .as_mut()
        .unwrap()
        .read_exact(&mut first)
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}: {}", out.status, stderr(&out));
    assert!(out.stderr.is_empty(), "{}", stderr(&out));
}

#[test]
fn fit_gltf_writes_a_material_and_prints_both_errors() {
    let dir = tempfile::tempdir().unwrap();
    let o = nacre(
        &[
            "fit",
            "gltf",
            "--layer",
            "tio2@100",
            "--substrate",
            "bk7",
            "-o",
            "material.json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stdout.is_empty());
    let text = std::fs::read_to_string(dir.path().join("material.json")).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let irid = &j["extensions"]["KHR_materials_iridescence"];
    for key in [
        "iridescenceFactor",
        "iridescenceIor",
        "iridescenceThicknessMinimum",
        "iridescenceThicknessMaximum",
    ] {
        assert!(irid[key].is_number(), "{key} in {text}");
    }
    assert!(
        j["extensions"]["KHR_materials_ior"]["ior"].is_number(),
        "{text}"
    );
    // stderr: `fitted: ΔE2000 mean M, max X (…)` then `naive:  ΔE2000 mean M, max X (…)`.
    let err = stderr(&o);
    let mean = |prefix: &str| -> f64 {
        let line = err.lines().find(|l| l.starts_with(prefix)).unwrap();
        let rest = line.split("mean ").nth(1).unwrap();
        rest.split(',').next().unwrap().parse().unwrap()
    };
    assert!(mean("fitted:") <= mean("naive:"), "{err}");
    // To standard output: the same material.
    let o = nacre(
        &["fit", "gltf", "--layer", "tio2@100", "--substrate", "bk7"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(String::from_utf8(o.stdout).unwrap(), text);
}
