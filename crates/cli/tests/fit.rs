//! `nacre fit spectrum`: a fit of a synthetic measurement made by `nacre spectrum` finds the
//! thicknesses from the bounds alone and writes a recipe that `--recipe` reads back; and the
//! bad inputs of issue 33 (wavelengths out of order or repeated, NaN, fewer points than free
//! parameters, inverted bounds, a bound outside a material's data, an empty file), each
//! with exit status 2, one message naming the file and line or the flag, nothing on stdout
//! and no output file (the bad_input.rs style).

use std::path::Path;
use std::process::Command;

fn nacre(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(dir)
        .env_remove("NACRE_MATERIAL_DB")
        .output()
        .expect("run nacre")
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("nacre-fit-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `wavelength_nm,R` of `nacre spectrum`'s R at normal incidence for the stack `stack`,
/// 400–800 nm every `step` nm, with a deterministic ripple of ±0.002 as noise.
fn measured(dir: &Path, stack: &[&str], step: u32) -> String {
    let mut args = vec!["spectrum"];
    args.extend_from_slice(stack);
    let w = format!("400:800:{step}");
    args.extend_from_slice(&["--angles", "0", "--wavelengths", &w]);
    let out = nacre(dir, &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut csv = String::from("# synthetic\nwavelength_nm,R\n");
    for (i, line) in text.lines().skip(1).enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let noise = 0.002 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
        let r: f64 = f[4].parse().unwrap();
        csv.push_str(&format!("{},{}\n", f[1], r + noise));
    }
    csv
}

#[test]
fn fits_a_two_film_stack_and_reads_back() {
    let d = scratch("ok");
    let csv = measured(
        &d,
        &[
            "--layer",
            "tio2@143",
            "--layer",
            "sio2@523",
            "--substrate",
            "si",
        ],
        1,
    );
    std::fs::write(d.join("m.csv"), csv).unwrap();
    let out = nacre(
        &d,
        &[
            "fit",
            "spectrum",
            "m.csv",
            "--layer",
            "tio2@10:2000",
            "--layer",
            "sio2@10:2000",
            "--substrate",
            "si",
            "-o",
            "fit.toml",
            "--residuals",
            "res.csv",
            "--plot",
            "fit.png",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The picture: a PNG of the figure's size.
    let png = std::fs::read(d.join("fit.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&png[16..24], &[0, 0, 4, 176, 0, 0, 3, 12]);
    let toml = std::fs::read_to_string(d.join("fit.toml")).unwrap();
    let values: Vec<f64> = toml
        .lines()
        .filter_map(|l| l.strip_prefix("thickness_nm = "))
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(
        (values[0] - 143.0).abs() < 1.0 && (values[1] - 523.0).abs() < 1.0,
        "{toml}"
    );
    assert!(
        toml.contains("thickness_sigma_nm = ") && toml.contains("[fit]\npoints = 401"),
        "{toml}"
    );
    let res = std::fs::read_to_string(d.join("res.csv")).unwrap();
    assert!(res.starts_with("spectrum,angle_deg,wavelength_nm,measured,fitted,residual\n"));
    assert_eq!(res.lines().count(), 402);
    // The recipe goes back into the forward commands.
    let back = nacre(
        &d,
        &[
            "spectrum",
            "--recipe",
            "fit.toml",
            "--angles",
            "0",
            "--wavelengths",
            "500",
        ],
    );
    assert!(
        back.status.success(),
        "{}",
        String::from_utf8_lossy(&back.stderr)
    );
    // A wide file of two spectra: a thickness map, the same whatever the thread count.
    let one = measured(&d, &["--layer", "sio2@300", "--substrate", "si"], 2);
    let two = measured(&d, &["--layer", "sio2@1234", "--substrate", "si"], 2);
    let mut wide = String::from("wavelength_nm,a,b\n");
    for (l1, l2) in one.lines().skip(2).zip(two.lines().skip(2)) {
        wide.push_str(&format!("{l1},{}\n", l2.split(',').nth(1).unwrap()));
    }
    std::fs::write(d.join("wide.csv"), wide).unwrap();
    let map = |threads: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args([
                "fit",
                "spectrum",
                "wide.csv",
                "--layer",
                "sio2@10:2000",
                "--substrate",
                "si",
            ])
            .current_dir(&d)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    // An SVG of one spectrum; a plot of the two of a wide file is refused, nothing written.
    let svg = nacre(
        &d,
        &[
            "fit",
            "spectrum",
            "m.csv",
            "--layer",
            "tio2@143",
            "--layer",
            "sio2@10:2000",
            "--substrate",
            "si",
            "-o",
            "one.toml",
            "--plot",
            "fit.svg",
        ],
    );
    assert!(
        svg.status.success(),
        "{}",
        String::from_utf8_lossy(&svg.stderr)
    );
    let text = std::fs::read_to_string(d.join("fit.svg")).unwrap();
    assert!(
        text.starts_with("<svg") && text.contains("measured − fitted"),
        "{text:.200}"
    );
    let two = nacre(
        &d,
        &[
            "fit",
            "spectrum",
            "wide.csv",
            "--layer",
            "sio2@10:2000",
            "--substrate",
            "si",
            "-o",
            "map.csv",
            "--plot",
            "map.png",
        ],
    );
    let err = String::from_utf8_lossy(&two.stderr);
    assert_eq!(two.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--plot") && err.contains("wide.csv holds 2"),
        "{err}"
    );
    assert!(!d.join("map.csv").exists() && !d.join("map.png").exists());
    let m1 = map("1");
    assert_eq!(m1, map("2"));
    let rows: Vec<Vec<f64>> = m1
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(
        (rows[0][0] - 300.0).abs() < 1.0 && (rows[1][0] - 1234.0).abs() < 6.0,
        "{m1}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_input_is_refused_with_one_message() {
    let d = scratch("bad");
    let good = "wavelength_nm,R\n400,0.1\n410,0.2\n420,0.3\n430,0.2\n";
    std::fs::write(d.join("good.csv"), good).unwrap();
    std::fs::write(
        d.join("order.csv"),
        "wavelength_nm,R\n400,0.1\n410,0.2\n405,0.3\n",
    )
    .unwrap();
    std::fs::write(
        d.join("repeat.csv"),
        "wavelength_nm,R\n400,0.1\n410,0.2\n410,0.3\n",
    )
    .unwrap();
    std::fs::write(d.join("nan.csv"), "wavelength_nm,R\n400,0.1\n410,NaN\n").unwrap();
    std::fs::write(d.join("few.csv"), "wavelength_nm,R\n400,0.1\n410,0.2\n").unwrap();
    std::fs::write(d.join("empty.csv"), "").unwrap();
    std::fs::write(d.join("header.csv"), "# only a comment\nwavelength_nm,R\n").unwrap();
    std::fs::write(
        d.join("far.csv"),
        "wavelength_nm,R\n100,0.1\n110,0.2\n120,0.3\n130,0.2\n",
    )
    .unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["order.csv", "--layer", "sio2@10:500"],
            &["order.csv:4", "wavelength 405 nm", "must increase"],
        ),
        (
            &["repeat.csv", "--layer", "sio2@10:500"],
            &["repeat.csv:4", "repeats"],
        ),
        (
            &["nan.csv", "--layer", "sio2@10:500"],
            &["nan.csv:3", "R `NaN` is not a finite number"],
        ),
        (
            &[
                "few.csv",
                "--layer",
                "sio2@10:500",
                "--layer",
                "tio2@10:500",
            ],
            &["few.csv", "2 points cannot fix 2 free parameters"],
        ),
        (
            &["empty.csv", "--layer", "sio2@10:500"],
            &["empty.csv", "the file is empty"],
        ),
        (
            &["header.csv", "--layer", "sio2@10:500"],
            &["header.csv:2", "no rows"],
        ),
        (
            &["good.csv", "--layer", "sio2@500:10"],
            &["--layer `sio2@500:10`", "inverted"],
        ),
        (
            &["good.csv", "--layer", "2:1@100"],
            &["--layer `2:1@100`", "index bounds 2:1 are inverted"],
        ),
        (
            &["far.csv", "--layer", "sio2@10:500"],
            &["--layer", "no data at 100 nm"],
        ),
        (
            &["good.csv", "--layer", "sio2@10:500", "--scale", "poly:x"],
            &["--scale `poly:x`", "poly:N"],
        ),
        (
            &["good.csv", "--layer", "sio2@10:500", "--range", "700:400"],
            &["--range `700:400`", "START must be below END"],
        ),
        (&["missing.csv", "--layer", "sio2@10:500"], &["missing.csv"]),
        (
            &["good.csv", "--layer", "sio2@10:500", "--plot", "fit.jpg"],
            &["--plot `fit.jpg`", ".png or .svg"],
        ),
    ];
    for (args, needles) in cases {
        let mut all = vec!["fit", "spectrum"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", "out.toml", "--residuals", "res.csv"]);
        let out = nacre(&d, &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        for n in *needles {
            assert!(err.contains(n), "{args:?}: `{n}` not in: {err}");
        }
        assert!(
            !d.join("out.toml").exists()
                && !d.join("res.csv").exists()
                && !d.join("fit.jpg").exists(),
            "{args:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}
