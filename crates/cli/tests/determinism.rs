//! Determinism and reproducibility (issue 9). `default_set.rs` re-bakes the committed
//! default set on 1 and 2 threads and compares it byte for byte; here: the committed
//! manifests list every committed file with its SHA-256, and recipes off the defaults'
//! paths (float precision, a fixed layer under the film, other observers, illuminants and
//! spaces, every table kind) bake to identical bytes on 1 and 2 threads and run after run.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

#[test]
fn committed_manifests_list_every_committed_file_with_its_sha256() {
    let baked = repo().join("tables/baked");
    let all = files(&baked);
    let mut listed = std::collections::BTreeSet::new();
    for (name, bytes) in all.iter().filter(|(n, _)| n.ends_with(".json")) {
        let m: serde_json::Value = serde_json::from_slice(bytes).unwrap();
        for f in m["files"].as_array().unwrap() {
            let path = f["path"].as_str().unwrap();
            let sha = nacre_format::table_io::sha256_hex(&baked.join(path))
                .unwrap_or_else(|e| panic!("{name} lists {path}: {e}"));
            assert_eq!(sha, f["sha256"].as_str().unwrap(), "{name}: {path}");
            listed.insert(path.to_string());
        }
    }
    for name in all.keys().filter(|n| !n.ends_with(".json")) {
        assert!(
            listed.contains(name),
            "{name} is in tables/baked but no manifest lists it"
        );
    }
}

/// Small recipes of every kind, each off the default set's settings.
fn recipes() -> Vec<(&'static str, String)> {
    let mut v = vec![
        (
            "lut-float",
            "kind = \"film-lut\"\n[colour]\nobserver = \"1964\"\nilluminant = \"a\"\nspace = \"acescg\"\n[stack]\nambient = \"1.33\"\nbase = \"au\"\nunder = [ { material = \"tio2\", thickness_nm = 40.0 } ]\n[axes]\ncos_theta_count = 9\nthickness_nm = [20.0, 900.0]\nopd_count = 33\nfilm_ior = [1.4, 2.2]\nfilm_ior_count = 5\n[output]\nprecision = \"float\"\ntransmittance = true\n"
                .to_string(),
        ),
        (
            "lut-half",
            "kind = \"film-lut\"\n[colour]\nspace = \"rec2020\"\n[stack]\nambient = \"1.0\"\nbase = \"water\"\n[axes]\ncos_theta_count = 7\nthickness_nm = [0.0, 2000.0]\nopd_count = 40\nfilm_ior = [1.0, 1.6]\nfilm_ior_count = 3\n[output]\npng = true\n"
                .to_string(),
        ),
        (
            "fourier",
            "kind = \"fourier\"\n[colour]\nobserver = \"1964\"\nilluminant = \"d50\"\nspace = \"p3\"\n[fourier]\nsamples = 512\nmax_opd_nm = 40000.0\nlevels = 4\n"
                .to_string(),
        ),
    ];
    // A diffraction table of layout "integrated" (rows of texels in parallel), on a
    // 2-D field so that the window's y factor is exercised; coarse, hence the loose
    // tolerance.
    v.push((
        "diffraction-integrated",
        "kind = \"diffraction\"\n[colour]\nspace = \"rec2020\"\n[height_field]\nsynthetic = \"cd:3\"\nsamples = 64\npitch_um = 0.125\n[diffraction]\nlayout = \"integrated\"\ncoherence_diameter_um = 8.0\nwavelengths = \"380:780:20\"\ntaylor_tolerance = 1e-3\nintegrated_samples = 32\nintegrated_tolerance = 1.0\n"
            .to_string(),
    ));
    // Kinds added later: their default recipe with small counts, when the default set has
    // one.
    let rough = repo().join("tables/recipes/rough-film-dielectric.toml");
    if let Ok(text) = std::fs::read_to_string(rough) {
        let mut small = String::new();
        for line in text.lines() {
            let key = line.split('=').next().unwrap_or("").trim();
            let value = match key {
                "cos_theta_count" => Some("5"),
                "opd_count" => Some("24"),
                "film_ior_count" => Some("3"),
                "alpha_count" => Some("3"),
                _ => None,
            };
            match value {
                Some(v) => small.push_str(&format!("{key} = {v}\n")),
                None => {
                    small.push_str(line);
                    small.push('\n');
                }
            }
        }
        v.push(("rough", small));
    }
    v
}

#[test]
fn every_kind_bakes_identically_on_1_and_2_threads_and_run_after_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut paths = Vec::new();
    for (name, text) in recipes() {
        let p = d.join(format!("{name}.toml"));
        std::fs::write(&p, text).unwrap();
        paths.push(p);
    }
    let bake = |threads: &str, out: &str| {
        let o = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .arg("bake")
            .args(&paths)
            .arg("--out")
            .arg(d.join(out))
            .env("RAYON_NUM_THREADS", threads)
            .env_remove("NACRE_MATERIAL_DB")
            .current_dir(repo())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        files(&d.join(out))
    };
    let first = bake("1", "a");
    assert!(first.len() >= 3 * paths.len(), "{:?}", first.keys());
    for (threads, out) in [("2", "b"), ("2", "c"), ("1", "d")] {
        let again = bake(threads, out);
        assert_eq!(
            again.keys().collect::<Vec<_>>(),
            first.keys().collect::<Vec<_>>()
        );
        for (name, bytes) in &first {
            assert!(
                again[name] == *bytes,
                "{name} differs between RAYON_NUM_THREADS=1 and {threads} (run {out})"
            );
        }
    }
}
