//! Faults (issue 9): `nacre bake` killed with SIGKILL at seeded random moments leaves its
//! output folder holding, for each table, either a complete table (the previous one or the
//! new one) or no manifest at all — never a partial file under a final name, and never a
//! manifest that names a missing file or one whose SHA-256 differs; the next bake succeeds.
//! And an output folder that cannot be written to gives exit status 2 and a clear message.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn nacre() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_nacre"));
    c.env_remove("NACRE_MATERIAL_DB");
    c
}

/// The two versions of the film-lut recipe `table.toml` and the fourier recipe
/// `fourier.toml` (different axes, so different files under the same names).
fn recipe(version: usize) -> String {
    let (cos, opd) = [(8, 48), (10, 40)][version];
    format!(
        "kind = \"film-lut\"\n[stack]\nambient = \"1.0\"\nbase = \"1.5\"\n[axes]\ncos_theta_count = {cos}\nthickness_nm = [0.0, 800.0]\nopd_count = {opd}\nfilm_ior = [1.0, 2.0]\nfilm_ior_count = 4\n"
    )
}

fn fourier(version: usize) -> String {
    let samples = [512, 256][version];
    format!(
        "kind = \"fourier\"\n[fourier]\nsamples = {samples}\nmax_opd_nm = 20000.0\nlevels = 3\n"
    )
}

fn bake(dir: &Path, version: usize, out: &Path) -> Command {
    let recipes = dir.join(format!("v{version}"));
    std::fs::create_dir_all(&recipes).unwrap();
    std::fs::write(recipes.join("table.toml"), recipe(version)).unwrap();
    std::fs::write(recipes.join("fourier.toml"), fourier(version)).unwrap();
    let mut c = nacre();
    c.arg("bake")
        .arg(recipes.join("table.toml"))
        .arg(recipes.join("fourier.toml"))
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

/// The non-hidden files of a folder with their bytes.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return BTreeMap::new();
    };
    entries
        .map(|e| e.unwrap().path())
        .filter(|p| !p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .map(|p| {
            assert!(p.is_file(), "{} is not a file", p.display());
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

/// Checks the invariant after a kill; returns, per manifest, which version it holds
/// (`None`: no manifest).
fn check(out: &Path, reference: &[BTreeMap<String, Vec<u8>>; 2]) -> Vec<Option<usize>> {
    let found = files(out);
    // Every file under a final name is complete: byte-identical to that file of one of
    // the two complete bakes.
    for (name, bytes) in &found {
        assert!(
            reference.iter().any(|r| r.get(name) == Some(bytes)),
            "{name} ({} bytes) is not a complete output of either bake",
            bytes.len()
        );
    }
    // Hidden leftovers are only nacre's temporary files and staging folders.
    for e in std::fs::read_dir(out).into_iter().flatten() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            !name.starts_with('.') || name.starts_with(".nacre-"),
            "unexpected hidden entry {name}"
        );
    }
    // Every manifest names files that exist with its SHA-256.
    ["table.json", "fourier.json"]
        .iter()
        .map(|manifest| {
            let bytes = found.get(*manifest)?;
            let m: serde_json::Value = serde_json::from_slice(bytes).unwrap();
            for f in m["files"].as_array().unwrap() {
                let path = out.join(f["path"].as_str().unwrap());
                let sha = nacre_format::table_io::sha256_hex(&path)
                    .unwrap_or_else(|e| panic!("{manifest} names {}: {e}", path.display()));
                assert_eq!(sha, f["sha256"].as_str().unwrap(), "{}", path.display());
            }
            reference
                .iter()
                .position(|r| r.get(*manifest) == Some(bytes))
        })
        .collect()
}

/// SplitMix64: deterministic kill delays.
fn next(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[test]
fn bake_killed_at_random_moments_leaves_complete_tables_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The two complete outputs, and how long a bake takes.
    let mut took = Duration::ZERO;
    let reference: [BTreeMap<String, Vec<u8>>; 2] = std::array::from_fn(|v| {
        let out = d.join(format!("ref{v}"));
        let start = Instant::now();
        assert!(bake(d, v, &out).status().unwrap().success());
        took = took.max(start.elapsed());
        files(&out)
    });
    assert_ne!(reference[0]["table.json"], reference[1]["table.json"]);
    assert_ne!(reference[0]["fourier.json"], reference[1]["fourier.json"]);

    let out = d.join("out");
    let mut seed = 0x6e61_6372_6520_u64;
    let (mut killed, mut states) = (0, BTreeMap::new());
    // Bake times vary with the machine's load: keep killing until 8 kills have landed
    // during a bake (16 rounds at least, 64 at most).
    let mut rounds = 0;
    for round in 0..64 {
        if round >= 16 && killed >= 8 {
            break;
        }
        rounds += 1;
        let version = round % 2;
        let delay = Duration::from_micros(next(&mut seed) % (took.as_micros() as u64 * 6 / 5 + 1));
        let mut child = bake(d, version, &out).spawn().unwrap();
        std::thread::sleep(delay);
        if child.try_wait().unwrap().is_none() {
            killed += 1;
        }
        child.kill().unwrap(); // SIGKILL
        child.wait().unwrap();
        let state = check(&out, &reference);
        *states.entry(format!("{state:?}")).or_insert(0) += 1;
    }
    eprintln!(
        "{killed} of {rounds} bakes killed while running (a bake takes {took:?}); states (table, fourier) seen: {states:?}"
    );
    assert!(
        killed >= 8,
        "only {killed} of {rounds} kills landed during a bake"
    );
    // The next bake succeeds and leaves the complete new tables.
    assert!(bake(d, 1, &out).status().unwrap().success());
    assert_eq!(check(&out, &reference), vec![Some(1), Some(1)]);
    assert_eq!(files(&out), reference[1]);
    // …and removes what the killed bakes left behind (their processes are gone).
    let left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".nacre-"))
        .collect();
    assert!(
        left.is_empty(),
        "leftovers of killed bakes remain: {left:?}"
    );
}

/// Whether `dir` can be written to by this process (root ignores permission bits).
fn writable(dir: &Path) -> bool {
    let probe = dir.join("probe");
    let ok = std::fs::write(&probe, "x").is_ok();
    let _ = std::fs::remove_file(&probe);
    ok
}

#[test]
fn an_unwritable_output_folder_is_reported_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.toml"), recipe(0)).unwrap();
    let locked = d.join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::write(locked.join("t.json"), "previous\n").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    }
    // Running as root, permission bits do not stop writes: use a folder of a read-only
    // file system (/sys) instead, where there is one.
    // (folder for `nacre bake --out`, folder for `nacre spectrum -o`)
    let (bake_out, csv_dir): (PathBuf, PathBuf) = if writable(&locked) {
        if !Path::new("/sys").is_dir() || writable(Path::new("/sys")) {
            eprintln!("skipped: no folder here refuses writes to this user");
            return;
        }
        ("/sys/nacre-test-out".into(), "/sys".into())
    } else {
        (locked.clone(), locked.clone())
    };
    for args in [
        vec![
            "bake".to_string(),
            "t.toml".into(),
            "--out".into(),
            bake_out.display().to_string(),
        ],
        vec![
            "spectrum".to_string(),
            "--angles".into(),
            "0".into(),
            "-o".into(),
            csv_dir.join("s.csv").display().to_string(),
        ],
    ] {
        let o = nacre().args(&args).current_dir(d).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            (err.contains(&*bake_out.display().to_string())
                || err.contains(&*csv_dir.display().to_string()))
                && [
                    "Permission denied",
                    "Operation not permitted",
                    "Read-only file system"
                ]
                .iter()
                .any(|m| err.contains(m)),
            "{args:?}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    assert_eq!(std::fs::read(locked.join("t.json")).unwrap(), b"previous\n");
    assert_eq!(std::fs::read_dir(&locked).unwrap().count(), 1);
}
