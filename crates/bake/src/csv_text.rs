//! CSV files read by the commands and kinds (points files, spectra, height fields), through
//! [`nacre_optics::csv_rows`]: `#` comment lines, blank lines, quoted fields, a UTF-8 BOM,
//! CRLF and spaces around fields are accepted, and every row knows its line. CSV written by
//! the commands goes through [`writer`]: numbers formatted by the commands themselves, LF
//! line ends, fields quoted only where CSV needs it.

use std::path::Path;

use crate::error::{Error, Result};
pub(crate) use nacre_optics::csv_rows::Row;

/// The rows of `text`, read from `path`, one at a time; malformed CSV is an
/// [`nacre_format::Error::Parse`] naming the file and line.
pub(crate) fn rows<'a>(path: &'a Path, text: &'a str) -> impl Iterator<Item = Result<Row>> + 'a {
    nacre_optics::csv_rows::Rows::new(&path.display().to_string(), text).map(move |row| {
        row.map_err(|e| match e {
            nacre_optics::Error::Parse { line, message, .. } => {
                Error::recipe(path.to_path_buf(), line, message)
            }
            other => Error::recipe(path.to_path_buf(), 0, other.to_string()),
        })
    })
}

/// The header of a table read with [`rows`]: its line and its trimmed column names. An
/// empty file is an error at line 0 saying `expected` (the header and rows it wants).
pub(crate) fn header(
    path: &Path,
    rows: &mut impl Iterator<Item = Result<Row>>,
    expected: &str,
) -> Result<(usize, Vec<String>)> {
    let header = rows.next().ok_or_else(|| {
        Error::recipe(
            path.to_path_buf(),
            0,
            format!("the file is empty: expected {expected}"),
        )
    })??;
    let names = header.fields.iter().map(|f| f.trim().to_string()).collect();
    Ok((header.line, names))
}

/// Line `line` (1-based) of `text` as written, trimmed (and without a leading BOM): the
/// row as error messages quote it.
pub(crate) fn line_text(text: &str, line: usize) -> &str {
    text.lines()
        .nth(line.saturating_sub(1))
        .unwrap_or("")
        .trim_start_matches('\u{feff}')
        .trim()
}

/// A CSV writer onto `w` with `\n` line ends (quotes only where a field needs them). Fields
/// are written as the strings given, so numbers keep the caller's formatting; flush it (or
/// drop it, ignoring errors) when done.
pub(crate) fn writer<W: std::io::Write>(w: W) -> csv::Writer<W> {
    csv::WriterBuilder::new()
        .has_headers(false)
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(w)
}
