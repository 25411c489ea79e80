//! `nacre color` on coated glass with an incoherent slab (issue 31), each `--method`: the
//! methods whose physics takes a slab give the whole pane's colour, reflected and
//! transmitted; the others refuse it with exit 2 and say why.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn nacre(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run nacre")
}

/// The lens of `tables/recipes/extra/film-spectacle-lens.toml`: MgF₂ on the front of 2 mm
/// of BK7 (incoherent), MgF₂ on the back, air around.
const LENS: [&str; 10] = [
    "--ambient",
    "1.0",
    "--layer",
    "1.38@99",
    "--layer",
    "bk7@2mm:incoherent",
    "--layer",
    "mgf2@99",
    "--substrate",
    "1.0",
];

/// Y of each CSV row (`angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B`).
fn luminances(o: &Output) -> Vec<f64> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
        .collect()
}

fn color(method: &str, quantity: &str, extra: &[&str], dir: &Path) -> Output {
    let mut args = vec!["color"];
    args.extend(LENS);
    args.extend([
        "--method",
        method,
        "--quantity",
        quantity,
        "--angles",
        "0:80:20",
    ]);
    args.extend(extra);
    nacre(&args, dir)
}

#[test]
fn spectral_rgb3_samples_and_stack_give_the_whole_panes_reflected_and_transmitted_colour() {
    let dir = tempfile::tempdir().unwrap();
    for method in ["spectral", "rgb3", "samples:16", "stack"] {
        let r = color(method, "r", &[], dir.path());
        let t = color(method, "t", &[], dir.path());
        for o in [&r, &t] {
            assert!(
                o.status.success(),
                "{method}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let (r, t) = (luminances(&r), luminances(&t));
        assert_eq!(r.len(), 5, "{method}");
        for (a, (r, t)) in r.iter().zip(&t).enumerate() {
            // BK7 absorbs a little over 2 mm; nothing else does.
            let sum = r + t;
            assert!(
                (0.97..=1.0 + 1e-9).contains(&sum),
                "{method} at {}°: R {r} + T {t} = {sum}",
                20 * a
            );
            // Both faces reflect: more than one coated face alone (≈ 1.3 % at 0°).
            assert!(*r > 0.012, "{method} at {}°: R {r}", 20 * a);
        }
    }
}

#[test]
fn methods_without_slab_physics_refuse_it_with_exit_2() {
    for (method, extra, why) in [
        ("fourier", &[][..], "Fourier series"),
        ("fourier-exact:3", &[][..], "Fourier series"),
        ("gaussian", &[][..], "Gaussian fit"),
        (
            "rough-lut:rough-film-dielectric",
            &["--roughness", "0.3"][..],
            "rough-film-lut",
        ),
        ("rough-mc:64", &["--roughness", "0.3"][..], "microfacet"),
    ] {
        let o = color(method, "r", extra, &repo());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{method}: {err}");
        assert!(o.stdout.is_empty(), "{method}: partial output");
        for needle in ["--method", "layer 2 is incoherent", why, "spectral"] {
            assert!(err.contains(needle), "{method}: `{needle}` not in {err}");
        }
    }
    // A film-lut baked without the slab is not this lens's table.
    let o = color("lut:film-dielectric", "r", &[], &repo());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("baked for"), "{err}");
}

#[test]
fn a_film_lut_baked_over_the_lens_looks_up_its_colour() {
    let dir = tempfile::tempdir().unwrap();
    let recipe = repo().join("tables/recipes/extra/film-spectacle-lens.toml");
    let bake = nacre(
        &["bake", recipe.to_str().unwrap(), "--out", "tables"],
        dir.path(),
    );
    assert!(
        bake.status.success(),
        "{}",
        String::from_utf8_lossy(&bake.stderr)
    );
    let lut = "lut:tables/film-spectacle-lens.json";
    for q in ["r", "t"] {
        let looked_up = color(lut, q, &[], dir.path());
        assert!(
            looked_up.status.success(),
            "{}",
            String::from_utf8_lossy(&looked_up.stderr)
        );
        let exact = luminances(&color("spectral", q, &[], dir.path()));
        for (a, b) in luminances(&looked_up).iter().zip(&exact) {
            assert!(
                (a - b).abs() < 2e-3,
                "--quantity {q}: lut {a}, spectral {b}"
            );
        }
    }
    // The table's own stack: no stack flags.
    let o = nacre(
        &["color", "--method", lut, "--angles", "0:80:40"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
