//! The CPU colours the three.js package's browser tests compare against
//! (`integrations/three/test/expected.json`, written by `node test/gen-expected.mjs`) are
//! still what `nacre color` gives: each case stores its command; this runs it again.

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
