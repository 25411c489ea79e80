//! Staged table commits: every file of a table is written into a hidden staging folder
//! and moved into place with the manifest last ([`StagedTable`]).

use crate::atomic::{STAGE_PREFIX, remove_stale, sync_dir, write_atomic};
use crate::error::{Error, Result};
use crate::ktx2::{self, Ktx2Format, Ktx2Image};
use crate::manifest::{Encoding, FileFormat, FileRecord};
use crate::table_io::{self, Precision, Table3};
use std::path::Path;

/// The files of one table, written into a hidden staging folder inside the output folder
/// (`.nacre-stage-*`, same file system) and then moved into place by [`StagedTable::commit`]
/// so that the table's manifest never describes files that are missing or differ from it,
/// even when the process is killed half-way:
///
/// 1. every file is written completely into the staging folder (and synced);
/// 2. an existing manifest of the same name that differs from the new one is removed
///    (from here until step 4 the table has no manifest: it is absent, not inconsistent);
/// 3. the data files are renamed over their targets, and stale files removed;
/// 4. the manifest is renamed into place, last.
///
/// A run killed before step 2 leaves the previous table untouched; one killed later leaves
/// no manifest, or the new complete table. Either way the next run succeeds. A staging
/// folder left by a killed run is hidden, never read, and removed by the next write into
/// the same folder ([`remove_stale`]).
pub struct StagedTable {
    out_dir: std::path::PathBuf,
    stage: tempfile::TempDir,
}

impl StagedTable {
    /// Creates `out_dir` (if needed) and a staging folder inside it.
    ///
    /// # Errors
    /// [`Error::Io`] when either folder cannot be created.
    pub fn new(out_dir: &Path) -> Result<Self> {
        let io = |source| Error::Io {
            path: out_dir.to_path_buf(),
            source,
        };
        if out_dir.exists() && !out_dir.is_dir() {
            return Err(Error::Invalid {
                context: out_dir.display().to_string().into(),
                message: "exists and is not a folder: expected the output folder".into(),
            });
        }
        std::fs::create_dir_all(out_dir).map_err(io)?;
        remove_stale(out_dir);
        let stage = tempfile::Builder::new()
            .prefix(&format!("{STAGE_PREFIX}{}-", std::process::id()))
            .tempdir_in(out_dir)
            .map_err(io)?;
        Ok(StagedTable {
            out_dir: out_dir.to_path_buf(),
            stage,
        })
    }

    /// The staging folder: write every file of the table here.
    pub fn path(&self) -> &Path {
        self.stage.path()
    }

    /// Writes `table` into the staging folder as the OpenEXR atlas `file` (channels R, G, B;
    /// width = `nx`, height = `ny · nz`) and returns its manifest record, checksum included.
    ///
    /// # Errors
    /// As [`table_io::write_exr`] and [`table_io::sha256_hex`].
    pub fn write_exr(
        &self,
        file: &str,
        quantity: &str,
        table: &Table3,
        precision: Precision,
    ) -> Result<FileRecord> {
        table_io::write_exr(&self.path().join(file), table, precision)?;
        self.record(
            file,
            quantity,
            FileFormat::Exr,
            precision.into(),
            3,
            table.nx,
            table.ny * table.nz,
        )
    }

    /// Writes `table` as the 16-bit PNG atlas `file` when every value is in [0, 1] and
    /// returns its record; `None` (and no file) otherwise.
    ///
    /// # Errors
    /// As [`table_io::write_png16`] and [`table_io::sha256_hex`].
    pub fn write_png16(
        &self,
        file: &str,
        quantity: &str,
        table: &Table3,
    ) -> Result<Option<FileRecord>> {
        if !table_io::write_png16(&self.path().join(file), table)? {
            return Ok(None);
        }
        let (width, height) = (table.nx, table.ny * table.nz);
        self.record(
            file,
            quantity,
            FileFormat::Png16,
            Encoding::Unorm16,
            3,
            width,
            height,
        )
        .map(Some)
    }

    /// Writes `image` as the KTX 2.0 file `file` (channels R, G, B, A; width and height of
    /// level 0) and returns its record.
    ///
    /// # Errors
    /// As [`ktx2::write_ktx2`] and [`table_io::sha256_hex`].
    pub fn write_ktx2(&self, file: &str, quantity: &str, image: &Ktx2Image) -> Result<FileRecord> {
        ktx2::write_ktx2(&self.path().join(file), image)?;
        let encoding = match image.format {
            Ktx2Format::Rgba16Float => Encoding::Half,
            Ktx2Format::Rgba32Float => Encoding::Float,
        };
        self.record(
            file,
            quantity,
            FileFormat::Ktx2,
            encoding,
            4,
            image.width as usize,
            image.height as usize,
        )
    }

    /// The record of the staged file `file`: its SHA-256 and the given description
    /// (`channels` of R, G, B, A in order).
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        file: &str,
        quantity: &str,
        format: FileFormat,
        encoding: Encoding,
        channels: usize,
        width: usize,
        height: usize,
    ) -> Result<FileRecord> {
        Ok(FileRecord {
            quantity: quantity.into(),
            format,
            path: file.into(),
            encoding,
            channels: ["R", "G", "B", "A"][..channels]
                .iter()
                .map(|c| c.to_string())
                .collect(),
            width,
            height,
            sha256: table_io::sha256_hex(&self.path().join(file))?,
        })
    }

    /// Writes `manifest` as `NAME.json` (pretty JSON and a newline) into the staging folder
    /// and [`StagedTable::commit`]s the table with it: the last step of every baker.
    ///
    /// # Errors
    /// As [`StagedTable::commit`]; [`Error::Io`] when the manifest cannot be written.
    pub fn commit_manifest(
        self,
        manifest: &crate::manifest::Manifest,
        stale: &[String],
    ) -> Result<std::path::PathBuf> {
        let name = format!("{}.json", manifest.name);
        let json = serde_json::to_string_pretty(manifest).expect("manifest serialises");
        write_atomic(&self.path().join(&name), |w| {
            w.write_all(json.as_bytes())?;
            w.write_all(b"\n")
        })?;
        self.commit(&name, stale)
    }

    /// Moves the staged files into the output folder, the manifest `manifest` (a file name
    /// in the staging folder) last, and removes the files named in `stale` (earlier outputs
    /// the new manifest no longer lists). Returns the manifest's final path.
    ///
    /// # Errors
    /// [`Error::Io`] when a file cannot be moved or removed.
    pub fn commit(self, manifest: &str, stale: &[String]) -> Result<std::path::PathBuf> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io { path, source }
        };
        let target = self.out_dir.join(manifest);
        let staged_manifest = self.stage.path().join(manifest);
        let new = std::fs::read(&staged_manifest).map_err(io(&staged_manifest))?;
        match std::fs::read(&target) {
            Ok(old) if old == new => {}
            Ok(_) => {
                std::fs::remove_file(&target).map_err(io(&target))?;
                sync_dir(&self.out_dir).map_err(io(&self.out_dir))?;
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io(&target)(e)),
        }
        let mut names: Vec<std::ffi::OsString> = std::fs::read_dir(self.stage.path())
            .map_err(io(self.stage.path()))?
            .map(|e| e.map(|e| e.file_name()))
            .collect::<std::io::Result<_>>()
            .map_err(io(self.stage.path()))?;
        names.sort();
        for name in names.iter().filter(|n| n.as_os_str() != manifest) {
            let to = self.out_dir.join(name);
            std::fs::rename(self.stage.path().join(name), &to).map_err(io(&to))?;
        }
        for name in stale {
            let path = self.out_dir.join(name);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io(&path)(e)),
                _ => {}
            }
        }
        sync_dir(&self.out_dir).map_err(io(&self.out_dir))?;
        std::fs::rename(&staged_manifest, &target).map_err(io(&target))?;
        sync_dir(&self.out_dir).map_err(io(&self.out_dir))?;
        Ok(target)
    }
}
