//! The CPU colours the three.js package's browser tests compare against
//! (`integrations/three/test/expected.json`, written by `node test/gen-expected.mjs`) are
//! still what `nacre color` gives: each case stores its command; this runs it again. And the
//! raw export the browser tests load (`test/export/`, served with the KTX2 file's level-0
//! bytes as the `.raw`) is what `nacre export` writes, and so are the multilayer stacks the
//! stack cases load (`test/export/NAME.stack.json`, each with its command in the fixture's
//! `stacks`).

use std::path::Path;
use std::process::Command;

#[test]
fn three_fixture_matches_nacre_color() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("integrations/three/test/expected.json");
    let text = std::fs::read_to_string(&path).expect("read integrations/three/test/expected.json");
    let fixture: serde_json::Value = serde_json::from_str(&text).expect("parse the fixture");
    let cases = fixture["cases"].as_array().expect("cases");
    assert!(!cases.is_empty());
    for case in cases {
        let command = case["command"].as_str().expect("command");
        let args: Vec<&str> = command
            .strip_prefix("nacre ")
            .expect("a nacre command")
            .split(' ')
            .collect();
        let out = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args(&args)
            .current_dir(&root)
            .output()
            .expect("run nacre");
        assert!(
            out.status.success(),
            "`{command}`: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let csv = String::from_utf8(out.stdout).expect("utf-8");
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().expect("header").split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
        let (r, g, b) = (col("R"), col("G"), col("B"));
        let rows: Vec<[f64; 3]> = lines
            .map(|l| {
                let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                [f[r], f[g], f[b]]
            })
            .collect();
        let expected = case["expected"].as_array().expect("expected");
        assert_eq!(rows.len(), expected.len(), "`{command}`: row count");
        for (i, (row, want)) in rows.iter().zip(expected).enumerate() {
            for (k, v) in row.iter().enumerate() {
                let w = want[k].as_f64().expect("number");
                assert!(
                    (v - w).abs() <= 1e-12,
                    "`{command}` row {i} channel {k}: nacre gives {v}, the fixture holds {w}; \
                     run `node test/gen-expected.mjs` in integrations/three"
                );
            }
        }
    }
}

#[test]
fn three_export_fixture_matches_nacre_export() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("three_export_fixture");
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let raw = dir.join("soap-film.reflectance.raw");
    let out = Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args([
            "export",
            "--table",
            "soap-film",
            "--quantity",
            "reflectance",
            "--out",
        ])
        .arg(&raw)
        .current_dir(&root)
        .output()
        .expect("run nacre");
    assert!(
        out.status.success(),
        "nacre export: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read_json = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).expect("read sidecar")).expect("json")
    };
    let fixture = root.join("integrations/three/test/export/soap-film.reflectance.json");
    assert_eq!(
        read_json(&dir.join("soap-film.reflectance.json")),
        read_json(&fixture),
        "{} is stale: copy the sidecar of `nacre export --table soap-film --quantity reflectance`",
        fixture.display()
    );
    // The KTX2 level index: level 0's byte offset and length at bytes 80 and 88.
    let ktx2 = std::fs::read(root.join("tables/baked/soap-film.reflectance.ktx2")).expect("ktx2");
    let word = |at: usize| u64::from_le_bytes(ktx2[at..at + 8].try_into().unwrap()) as usize;
    let (offset, length) = (word(80), word(88));
    let bytes = std::fs::read(&raw).expect("raw");
    assert!(
        bytes == ktx2[offset..offset + length],
        "the raw export differs from the KTX2 file's level 0 (the browser tests serve the latter)"
    );
}

#[test]
fn three_stack_fixtures_match_nacre_export() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("integrations/three/test/expected.json"))
        .expect("read integrations/three/test/expected.json");
    let fixture: serde_json::Value = serde_json::from_str(&text).expect("parse the fixture");
    let stacks = fixture["stacks"].as_array().expect("stacks");
    assert!(!stacks.is_empty());
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("three_stack_fixtures");
    std::fs::create_dir_all(&dir).expect("temporary folder");
    for stack in stacks {
        let command = stack["command"].as_str().expect("command");
        let mut args: Vec<&str> = command
            .strip_prefix("nacre ")
            .expect("a nacre command")
            .split(' ')
            .collect();
        // The last argument is the committed file (relative to integrations/three): write a
        // fresh one beside the test's scratch files and compare the bytes.
        let committed = root
            .join("integrations/three")
            .join(args.pop().expect("the --out path"));
        assert_eq!(
            args.last(),
            Some(&"--out"),
            "`{command}` ends with --out FILE"
        );
        let fresh = dir.join(committed.file_name().expect("a file name"));
        let out = Command::new(env!("CARGO_BIN_EXE_nacre"))
            .args(&args)
            .arg(&fresh)
            .current_dir(&root)
            .output()
            .expect("run nacre");
        assert!(
            out.status.success(),
            "`{command}`: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            std::fs::read(&fresh).expect("fresh stack")
                == std::fs::read(&committed).expect("committed stack"),
            "{} is stale: run `node test/gen-expected.mjs` in integrations/three",
            committed.display()
        );
    }
}
