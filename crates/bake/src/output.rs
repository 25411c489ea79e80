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
    let tmp = tempfile::Builder::new()
        .prefix(".nacre-")
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
                context: target.display().to_string(),
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
    let staged = files
        .iter()
        .map(|(name, bytes)| {
            let target = dir.join(name);
            let tmp = tempfile::Builder::new()
                .prefix(".nacre-")
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

#[cfg(test)]
mod tests {
    use super::*;

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
