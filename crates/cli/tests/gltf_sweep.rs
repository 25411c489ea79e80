//! The glTF sweep: every `.gltf` / `.glb` under `../shared/gltf-samples` and
//! `../shared/gltf-core-samples` (Khronos sample assets, not part of this repository; see
//! `../shared/DATA.md`) either renders with `nacre render --gltf FILE` at 64 × 48 (exit 0, the
//! PNG written) or is refused with exit status 2 and one `nacre: error:` line naming the file,
//! and no output file. A panic, a crash (a signal, another status) or a hang (a file taking
//! more than [`PER_FILE_LIMIT`]) fails. Each file runs in its own child process, on the
//! backend wgpu picks, or the one `WGPU_BACKEND` names (inherited by the child).
//!
//! The directories missing is a failure when the `CI` environment variable is set, a skip
//! (with a message) elsewhere. The per-file outcomes are printed and written to
//! `gltf-sweep.txt` under the test's temporary directory.
//!
//! Run: `cargo test -p nacre-cli --test gltf_sweep -- --nocapture`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The longest one file may take (load, render at 64 × 48, write).
const PER_FILE_LIMIT: Duration = Duration::from_secs(180);

/// The sample directories, relative to the repository root.
const SAMPLE_DIRS: [&str; 2] = ["../shared/gltf-samples", "../shared/gltf-core-samples"];

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every `.gltf` / `.glb` under `dir`, sorted.
fn gltf_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            gltf_files(&path, out);
        } else if matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("gltf" | "glb")
        ) {
            out.push(path);
        }
    }
}

/// What one file did.
enum Outcome {
    Rendered,
    Refused(String),
}

/// Runs `nacre render --gltf file` in a child process with a time bound; `Err` names what
/// went wrong (panic, crash, hang, a refusal without its one line, output left behind).
fn sweep_one(file: &Path, work: &Path) -> Result<Outcome, String> {
    let out = work.join("out.png");
    let _ = std::fs::remove_file(&out);
    let stderr_path = work.join("stderr.txt");
    let mut child = Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(["render", "--width", "64", "--height", "48", "--gltf"])
        .arg(file)
        .arg("-o")
        .arg(&out)
        .current_dir(work)
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&stderr_path).unwrap())
        .spawn()
        .expect("the nacre binary starts");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > PER_FILE_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("hung: no exit after {PER_FILE_LIMIT:?}"));
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    let name = file.file_name().unwrap().to_string_lossy().into_owned();
    match status.code() {
        Some(0) if out.is_file() => Ok(Outcome::Rendered),
        Some(0) => Err("exit 0 but no picture written".into()),
        Some(2) => {
            let errors: Vec<&str> = stderr
                .lines()
                .filter(|l| l.starts_with("nacre: error:"))
                .collect();
            if out.exists() {
                Err(format!("refused but wrote {}: {stderr}", out.display()))
            } else if errors.len() != 1 {
                Err(format!(
                    "refused with {} error lines (expected one): {stderr}",
                    errors.len()
                ))
            } else if !errors[0].contains(&name) {
                Err(format!("the refusal does not name {name}: {}", errors[0]))
            } else {
                Ok(Outcome::Refused(errors[0].to_string()))
            }
        }
        code => Err(format!(
            "{} (status {code:?}): {}",
            if stderr.contains("panicked") {
                "panicked"
            } else {
                "crashed"
            },
            stderr.lines().take(8).collect::<Vec<_>>().join(" | ")
        )),
    }
}

#[test]
fn every_sample_renders_or_is_refused_with_one_line() {
    let root = repo_root();
    let mut files = Vec::new();
    for dir in SAMPLE_DIRS.map(|d| root.join(d)) {
        if dir.is_dir() {
            gltf_files(&dir, &mut files);
        } else if std::env::var_os("CI").is_some() {
            panic!(
                "{} is missing: CI must provide the Khronos glTF samples (../shared/DATA.md)",
                dir.display()
            );
        } else {
            eprintln!(
                "skipped {}: not found (the Khronos glTF samples of ../shared/DATA.md)",
                dir.display()
            );
        }
    }
    if files.is_empty() {
        return;
    }
    let backend = std::env::var("WGPU_BACKEND").unwrap_or_else(|_| "default".into());
    let work = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let (mut rendered, mut refused, mut failures) = (0, 0, Vec::new());
    let mut report = format!("backend: {backend}\n");
    for file in &files {
        let shown = file
            .strip_prefix(&root)
            .unwrap_or(file)
            .display()
            .to_string();
        let t = Instant::now();
        let line = match sweep_one(file, work.path()) {
            Ok(Outcome::Rendered) => {
                rendered += 1;
                format!("rendered {shown}")
            }
            Ok(Outcome::Refused(why)) => {
                refused += 1;
                format!("refused  {shown}: {why}")
            }
            Err(why) => {
                failures.push(format!("{shown}: {why}"));
                format!("FAILED   {shown}: {why}")
            }
        };
        let line = format!("{line} ({:.1} s)", t.elapsed().as_secs_f64());
        eprintln!("{line}");
        report.push_str(&line);
        report.push('\n');
    }
    let summary = format!(
        "{} files on backend {backend}: {rendered} rendered, {refused} refused, {} failed, in {:.0} s",
        files.len(),
        failures.len(),
        start.elapsed().as_secs_f64()
    );
    eprintln!("{summary}");
    report.push_str(&summary);
    report.push('\n');
    let _ = std::fs::write(
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gltf-sweep.txt"),
        &report,
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
