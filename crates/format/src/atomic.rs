//! Atomic output: everything is written to a temporary file beside the target and renamed
//! over it only once complete, so an existing file is never left half-written and a
//! failed run leaves no partial output.

use crate::error::{Error, Result};
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes `path` atomically with `fill`, or to standard output when `path` is `-`.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    if path.as_os_str() == "-" {
        let stdout = std::io::stdout();
        let mut w = BufWriter::new(stdout.lock());
        return fill(&mut w)
            .and_then(|()| w.flush())
            .map_err(|source| Error::Io {
                path: path.to_path_buf(),
                source,
            });
    }
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    remove_stale(dir);
    let tmp = tempfile::Builder::new()
        .prefix(&temp_prefix())
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io)?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w).and_then(|()| w.flush()).map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    // Temporary files are created private (0600); give the result ordinary permissions.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o644)).map_err(io)?;
    }
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Writes a set of files into `dir` as one unit. The names must be plain file names whose
/// targets are not folders (checked first). Every file is then written completely to a
/// temporary file in `dir` and synced; only when all of them are are they renamed over
/// their targets (renames within one folder). A failure before that point leaves `dir` as
/// it was (and removes `dir` again if this call created it); files in `dir` that are not in
/// `files` are kept.
pub fn write_files_atomic(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| Error::Io { path, source }
    };
    for (name, _) in files {
        let target = dir.join(name);
        if Path::new(name).file_name() != Some(std::ffi::OsStr::new(name)) || target.is_dir() {
            return Err(Error::Invalid {
                context: target.display().to_string().into(),
                message: "cannot be written: not a plain file name, or a folder is in the way"
                    .into(),
            });
        }
    }
    // The folders this call creates, outermost last, to remove again on failure.
    let mut created = Vec::new();
    let mut probe = Some(dir);
    while let Some(p) = probe {
        if p.as_os_str().is_empty() || p.exists() {
            break;
        }
        created.push(p.to_path_buf());
        probe = p.parent();
    }
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    remove_stale(dir);
    let staged = files
        .iter()
        .map(|(name, bytes)| {
            let target = dir.join(name);
            let tmp = tempfile::Builder::new()
                .prefix(&temp_prefix())
                .suffix(".tmp")
                .tempfile_in(dir)
                .map_err(io(&target))?;
            (|| {
                let mut w = BufWriter::new(tmp.as_file());
                w.write_all(bytes)?;
                w.flush()?;
                drop(w);
                tmp.as_file().sync_all()?;
                #[cfg(unix)]
                {
                    use std::os::unix::fs::PermissionsExt;
                    std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o644))?;
                }
                Ok(())
            })()
            .map_err(io(&target))?;
            Ok((tmp, target))
        })
        .collect::<Result<Vec<_>>>();
    let staged = match staged {
        Ok(s) => s,
        Err(e) => {
            // The temporary files are gone (dropped); remove the folders made above.
            for p in &created {
                let _ = std::fs::remove_dir(p);
            }
            return Err(e);
        }
    };
    for (tmp, target) in staged {
        tmp.persist(&target).map_err(|e| io(&target)(e.error))?;
    }
    Ok(())
}

/// Name prefix of temporary files: `.nacre-PID-` (then random characters and `.tmp`).
const TEMP_PREFIX: &str = ".nacre-";
/// Name prefix of staging folders: `.nacre-stage-PID-` (then random characters).
pub(crate) const STAGE_PREFIX: &str = ".nacre-stage-";

fn temp_prefix() -> String {
    format!("{TEMP_PREFIX}{}-", std::process::id())
}

/// The process id in a leftover's name: `.nacre-stage-PID-…` or `.nacre-PID-….tmp`.
fn owner_pid(name: &str) -> Option<u32> {
    let rest = match name.strip_prefix(STAGE_PREFIX) {
        Some(rest) => rest,
        None => name.strip_prefix(TEMP_PREFIX)?.strip_suffix(".tmp")?,
    };
    rest.split_once('-')?.0.parse().ok()
}

/// Whether process `pid` is running, where the system says (Linux's `/proc`); `None` where
/// it cannot be told.
fn process_alive(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    proc.join("self")
        .exists()
        .then(|| proc.join(pid.to_string()).exists())
}

/// Removes the temporary files and staging folders that killed runs left in `dir`: those
/// whose name carries the id of a process that is no longer running. Leftovers of running
/// processes (concurrent bakes into the same folder) are kept, as is everything where
/// liveness cannot be told (no `/proc`), and everything whose name nacre did not make.
/// Best effort: a leftover that cannot be removed stays hidden and unread. (A folder
/// shared between PID namespaces, e.g. containers, could hold a live bake's staging folder
/// under a pid this process cannot see; bake into such a folder from one namespace.)
pub fn remove_stale(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let own = std::process::id();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(owner_pid) else {
            continue;
        };
        if pid == own || process_alive(pid) != Some(false) {
            continue;
        }
        let path = entry.path();
        match entry.file_type() {
            Ok(t) if t.is_dir() => {
                let _ = std::fs::remove_dir_all(&path);
            }
            Ok(_) => {
                let _ = std::fs::remove_file(&path);
            }
            Err(_) => {}
        }
    }
}

/// Makes renames and removals in `dir` durable (a no-op where folders cannot be synced).
pub(crate) fn sync_dir(dir: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    std::fs::File::open(dir)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stage::StagedTable;

    /// Leftovers of dead processes go; those of running ones (this one, pid 1), foreign
    /// hidden files and unparsable names stay.
    #[test]
    fn stale_leftovers_of_dead_processes_are_removed() {
        if process_alive(1).is_none() {
            eprintln!("skipped: no /proc here, so nothing is removed (documented)");
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let dead = 4_000_000_000u32; // above any pid_max (2^22)
        let own = std::process::id();
        let stage = |pid: u32| d.join(format!(".nacre-stage-{pid}-Ab3xYz"));
        let tmp = |pid: u32| d.join(format!(".nacre-{pid}-Qw9e.tmp"));
        for pid in [dead, own, 1] {
            std::fs::create_dir(stage(pid)).unwrap();
            std::fs::write(stage(pid).join("table.exr"), "x").unwrap();
            std::fs::write(tmp(pid), "x").unwrap();
        }
        let keep = [".nacre-stage-Ab3xYz", ".nacre-x-1.tmp", ".other", "t.json"];
        for name in keep {
            std::fs::write(d.join(name), "x").unwrap();
        }
        assert_eq!(
            owner_pid(&format!(".nacre-stage-{dead}-Ab3xYz")),
            Some(dead)
        );
        assert_eq!(owner_pid(&format!(".nacre-{own}-Qw9e.tmp")), Some(own));
        assert_eq!(owner_pid(".nacre-stage-Ab3xYz"), None);
        remove_stale(d);
        assert!(!stage(dead).exists() && !tmp(dead).exists());
        for pid in [own, 1] {
            assert!(stage(pid).join("table.exr").exists() && tmp(pid).exists());
        }
        for name in keep {
            assert!(d.join(name).exists(), "{name}");
        }
    }

    /// A disk that fills up (ENOSPC) or any other write error half-way: the error names
    /// the target, an existing file is untouched and no temporary file is left.
    #[test]
    fn a_failing_writer_leaves_the_existing_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, "previous\n").unwrap();
        let e = write_atomic(&path, |w| {
            w.write_all(b"half a row,")?;
            Err(std::io::Error::from_raw_os_error(28)) // ENOSPC
        })
        .unwrap_err()
        .to_string();
        assert!(e.starts_with(&format!("{}: ", path.display())), "{e}");
        assert!(e.contains("No space left on device"), "{e}");
        assert_eq!(std::fs::read(&path).unwrap(), b"previous\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// A table staged and committed over an older one; staging that fails half-way (the
    /// stage dropped without a commit) leaves the older table and no staging folder.
    #[test]
    fn staged_tables_replace_the_manifest_last() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("t");
        let stage = StagedTable::new(&out).unwrap();
        std::fs::write(stage.path().join("a.exr"), "1").unwrap();
        std::fs::write(stage.path().join("a.png"), "1").unwrap();
        std::fs::write(stage.path().join("a.json"), "m1").unwrap();
        assert_eq!(stage.commit("a.json", &[]).unwrap(), out.join("a.json"));
        let stage = StagedTable::new(&out).unwrap();
        std::fs::write(stage.path().join("a.exr"), "2").unwrap();
        drop(stage);
        assert_eq!(std::fs::read(out.join("a.exr")).unwrap(), b"1");
        let stage = StagedTable::new(&out).unwrap();
        std::fs::write(stage.path().join("a.exr"), "2").unwrap();
        std::fs::write(stage.path().join("a.json"), "m2").unwrap();
        stage.commit("a.json", &["a.png".into()]).unwrap();
        assert_eq!(std::fs::read(out.join("a.exr")).unwrap(), b"2");
        assert_eq!(std::fs::read(out.join("a.json")).unwrap(), b"m2");
        let mut names: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["a.exr", "a.json"]);
        // A file where the folder should be.
        let e = StagedTable::new(&out.join("a.exr"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("not a folder"), "{e}");
    }

    #[test]
    fn file_sets_replace_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a/b");
        write_files_atomic(&out, &[("x.txt".into(), b"1".to_vec())]).unwrap();
        std::fs::write(out.join("keep.txt"), "k").unwrap();
        write_files_atomic(
            &out,
            &[
                ("x.txt".into(), b"2".to_vec()),
                ("y.txt".into(), b"3".to_vec()),
            ],
        )
        .unwrap();
        assert_eq!(std::fs::read(out.join("x.txt")).unwrap(), b"2");
        assert_eq!(std::fs::read(out.join("y.txt")).unwrap(), b"3");
        assert_eq!(std::fs::read(out.join("keep.txt")).unwrap(), b"k");
        // A name that is not a plain file, or a folder in the way: nothing is replaced.
        std::fs::create_dir(out.join("z.txt")).unwrap();
        for bad in ["no/such/dir.txt", "z.txt", ".."] {
            let e = write_files_atomic(
                &out,
                &[("x.txt".into(), b"4".to_vec()), (bad.into(), b"5".to_vec())],
            );
            assert!(e.is_err(), "{bad}");
            assert_eq!(std::fs::read(out.join("x.txt")).unwrap(), b"2");
        }
        let names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(names.iter().all(|n| !n.starts_with(".nacre-")), "{names:?}");
        // A folder that cannot be created is not left half-made.
        let blocker = dir.path().join("file");
        std::fs::write(&blocker, "").unwrap();
        assert!(write_files_atomic(&blocker.join("sub"), &[("x".into(), vec![])]).is_err());
    }
}
