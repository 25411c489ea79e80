//! `nacre fit color`: a look made by `nacre color` from a two-film stack is designed back
//! from the bounds alone (ΔE2000 ≤ 1 at every angle), the recipe reads back into `nacre
//! color`, the output is the same whatever the thread count; the bad inputs each stop with
//! exit status 2, one message naming the file and line or the flag, nothing on stdout and no
//! output file (the bad_input.rs style). And the one syntax of the fit commands: in `fit
//! gltf`, a range on the top film (`--layer oil@200:800`) is `--thicknesses 200:800`.

use std::path::Path;
use std::process::Command;

fn nacre_env(dir: &Path, args: &[&str], threads: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(dir)
        .env_remove("NACRE_MATERIAL_DB")
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .expect("run nacre")
}

fn nacre(dir: &Path, args: &[&str]) -> std::process::Output {
    nacre_env(dir, args, "2")
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("nacre-fit-color-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ok(out: &std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

const TEMPLATE: [&str; 6] = [
    "--layer",
    "tio2@20:300",
    "--layer",
    "sio2@20:300",
    "--substrate",
    "bk7",
];

#[test]
fn designs_a_two_film_look_and_reads_back() {
    let d = scratch("ok");
    let look = ok(&nacre(
        &d,
        &[
            "color",
            "--layer",
            "tio2@137",
            "--layer",
            "sio2@211",
            "--substrate",
            "bk7",
            "--angles",
            "0:60:20",
        ],
    ));
    std::fs::write(d.join("look.csv"), &look).unwrap();
    let mut args = vec!["fit", "color", "look.csv"];
    args.extend_from_slice(&TEMPLATE);
    args.extend_from_slice(&[
        "--solutions",
        "2",
        "-o",
        "fit.toml",
        "--report",
        "report.csv",
        "--plot",
        "design.png",
    ]);
    let out = nacre_env(&d, &args, "1");
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("solution 1: layer 1 137.0 nm, layer 2 211.0 nm"),
        "{err}"
    );
    assert!(err.contains("reached"), "{err}");
    let toml = std::fs::read_to_string(d.join("fit.toml")).unwrap();
    assert!(toml.contains("reached = true"), "{toml}");
    let report = std::fs::read_to_string(d.join("report.csv")).unwrap();
    assert!(report.starts_with(
        "solution,angle_deg,weight,target_L,target_a,target_b,L,a,b,R,G,B,delta_e_2000\n"
    ));
    for line in report.lines().skip(1).filter(|l| l.starts_with("1,")) {
        let de: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
        assert!(de <= 1.0, "{line}");
    }
    let png = std::fs::read(d.join("design.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // The same bytes with two threads.
    let first = (toml.clone(), report.clone());
    ok(&nacre_env(&d, &args, "2"));
    assert_eq!(
        first,
        (
            std::fs::read_to_string(d.join("fit.toml")).unwrap(),
            std::fs::read_to_string(d.join("report.csv")).unwrap()
        )
    );
    // The recipe goes back into nacre color and gives the reported colour.
    let back = ok(&nacre(
        &d,
        &["color", "--recipe", "fit.toml", "--angles", "0"],
    ));
    let g: f64 = back
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(7)
        .unwrap()
        .parse()
        .unwrap();
    let reported: f64 = report
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(10)
        .unwrap()
        .parse()
        .unwrap();
    assert!((g - reported).abs() < 1e-5, "{back} vs {report}");
    // L,a,b targets give the same design.
    let mut lab = String::from("angle_deg,L,a,b\n");
    for line in report.lines().skip(1).filter(|l| l.starts_with("1,")) {
        let f: Vec<&str> = line.split(',').collect();
        lab.push_str(&format!("{},{},{},{}\n", f[1], f[3], f[4], f[5]));
    }
    std::fs::write(d.join("lab.csv"), lab).unwrap();
    let mut args = vec!["fit", "color", "lab.csv"];
    args.extend_from_slice(&TEMPLATE);
    let out = nacre(&d, &args);
    let recipe = ok(&out);
    assert!(recipe.contains("reached = true"), "{recipe}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_input_is_refused_with_one_message() {
    let d = scratch("bad");
    std::fs::write(d.join("good.csv"), "angle_deg,R,G,B\n0,0.1,0.2,0.3\n").unwrap();
    std::fs::write(d.join("empty.csv"), "").unwrap();
    std::fs::write(
        d.join("nan.csv"),
        "angle_deg,R,G,B\n0,0.1,0.2,0.3\n30,NaN,0.2,0.3\n",
    )
    .unwrap();
    std::fs::write(d.join("noangle.csv"), "R,G,B\n0.1,0.2,0.3\n").unwrap();
    std::fs::write(d.join("hue.csv"), "angle_deg,hue\n0,1\n").unwrap();
    std::fs::write(
        d.join("weight.csv"),
        "angle_deg,L,a,b,weight\n0,50,0,0,-1\n",
    )
    .unwrap();
    std::fs::write(d.join("grazing.csv"), "angle_deg,R,G,B\n95,0.1,0.2,0.3\n").unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["empty.csv", "--layer", "sio2@10:500"],
            &["empty.csv", "the file is empty"],
        ),
        (
            &["nan.csv", "--layer", "sio2@10:500"],
            &["nan.csv:3", "R `NaN` is not a finite number"],
        ),
        (
            &["noangle.csv", "--layer", "sio2@10:500"],
            &["noangle.csv:1", "no `angle_deg`"],
        ),
        (
            &["hue.csv", "--layer", "sio2@10:500"],
            &["hue.csv:1", "unknown column `hue`"],
        ),
        (
            &["weight.csv", "--layer", "sio2@10:500"],
            &["weight.csv:2", "weight -1 must be positive"],
        ),
        (
            &["grazing.csv", "--layer", "sio2@10:500"],
            &["grazing.csv:2", "angle_deg 95"],
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
            &["good.csv", "--layer", "sio2@10:500", "--solutions", "0"],
            &["--solutions `0`"],
        ),
        (
            &["good.csv", "--layer", "sio2@10:500", "--distinct=-1"],
            &["--distinct `-1`"],
        ),
        (
            &["good.csv", "--layer", "sio2@10:500", "--quantity", "x"],
            &["--quantity `x`", "r or t"],
        ),
        (
            &["good.csv", "--layer", "sio2@10:500", "--space", "cmyk"],
            &["--space `cmyk`"],
        ),
        (
            &["good.csv", "--layer", "sio2@10:500", "--plot", "p.jpg"],
            &["--plot `p.jpg`", ".png or .svg"],
        ),
        (&["missing.csv", "--layer", "sio2@10:500"], &["missing.csv"]),
    ];
    for (args, needles) in cases {
        let mut all = vec!["fit", "color"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", "out.toml", "--report", "rep.csv"]);
        let out = nacre(&d, &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        for n in *needles {
            assert!(err.contains(n), "{args:?}: `{n}` not in: {err}");
        }
        assert!(
            !d.join("out.toml").exists() && !d.join("rep.csv").exists(),
            "{args:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn fit_gltf_takes_the_range_on_the_layer() {
    let d = scratch("gltf");
    let on_layer = nacre(
        &d,
        &[
            "fit",
            "gltf",
            "--layer",
            "oil@200:800",
            "--substrate",
            "water",
        ],
    );
    let flag = nacre(
        &d,
        &[
            "fit",
            "gltf",
            "--layer",
            "oil@500",
            "--substrate",
            "water",
            "--thicknesses",
            "200:800",
        ],
    );
    assert_eq!(ok(&on_layer), ok(&flag));
    assert_eq!(on_layer.stderr, flag.stderr);
    for (args, needle) in [
        (
            &[
                "fit",
                "gltf",
                "--layer",
                "oil@200:800",
                "--thicknesses",
                "200:800",
            ][..],
            "give the range once",
        ),
        (
            &[
                "fit",
                "gltf",
                "--layer",
                "oil@500",
                "--layer",
                "sio2@10:100",
            ][..],
            "--layer sio2@10:100: fit gltf takes a range only on the top film",
        ),
    ] {
        let out = nacre(&d, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{err}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
