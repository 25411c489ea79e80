//! The rows of CSV text handed to a parser (material files, the bundled CIE tables), read
//! with the [`csv`] crate.
//!
//! Accepted: a UTF-8 byte-order mark at the start, LF or CRLF line ends, `#` comment lines,
//! blank (or all-space) lines anywhere, RFC 4180 quoted fields (`"1.5"`, `""` for a quote
//! inside), and spaces around every field. A field that opens with spaces before its quote
//! (` "1.5"`) is not a quoted field to `csv` (a quote only opens a field), so after trimming
//! one pair of enclosing quotes is removed from it. A line whose first non-space character
//! is `#` is a comment too, as before `csv` was used.
//!
//! Every row carries the 1-based line it starts on, for `file:line` errors.
//!
//! Public so that the other crates of the workspace read their CSV files (points files,
//! spectra, height fields) the same way; `csv` alone stamps a record with the line *before*
//! the comment and blank lines it skipped.

use crate::error::{Error, Result};

/// One row that is neither blank nor a comment.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// 1-based line of the text on which the row starts.
    pub line: usize,
    /// The fields, trimmed and unquoted.
    pub fields: Vec<String>,
}

impl Row {
    /// The fields joined by commas: the row as error messages quote it.
    pub fn text(&self) -> String {
        self.fields.join(",")
    }
}

/// Reads every row of `text`; `source_name` labels errors (`file:line`).
///
/// # Errors
///
/// [`Error::Parse`] naming `source_name` and the line for malformed CSV.
pub fn rows(source_name: &str, text: &str) -> Result<Vec<Row>> {
    Rows::new(source_name, text).collect()
}

/// The rows of a text one at a time (for files too long to hold as rows): the iterator
/// behind [`rows`]. It ends after the first error.
pub struct Rows<'a> {
    source_name: String,
    text: &'a str,
    reader: csv::Reader<&'a [u8]>,
    record: csv::StringRecord,
    done: bool,
}

impl<'a> Rows<'a> {
    /// The rows of `text`; `source_name` labels errors (`file:line`).
    pub fn new(source_name: &str, text: &'a str) -> Self {
        // Untrimmed reading: the newlines inside a record's raw fields locate its first line
        // (see `start_line`); `StringRecord::trim` then trims as `csv::Trim::All` would.
        let reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .trim(csv::Trim::None)
            .from_reader(text.as_bytes());
        Rows {
            source_name: source_name.to_string(),
            text,
            reader,
            record: csv::StringRecord::new(),
            done: false,
        }
    }
}

impl Iterator for Rows<'_> {
    type Item = Result<Row>;

    fn next(&mut self) -> Option<Result<Row>> {
        while !self.done {
            match self.reader.read_record(&mut self.record) {
                Ok(true) => {}
                Ok(false) => {
                    self.done = true;
                    break;
                }
                Err(e) => {
                    self.done = true;
                    let line = e
                        .position()
                        .map_or(self.reader.position().line(), |p| p.line());
                    return Some(Err(Error::Parse {
                        source_name: self.source_name.clone(),
                        line: line as usize,
                        message: format!("malformed CSV: {e}"),
                    }));
                }
            }
            let line = start_line(self.text, self.reader.position(), &self.record);
            self.record.trim();
            let fields: Vec<String> = self.record.iter().map(unquote).collect();
            let blank = fields.iter().all(String::is_empty);
            if blank || fields[0].starts_with('#') {
                continue;
            }
            return Some(Ok(Row { line, fields }));
        }
        None
    }
}

/// The line on which the record just read (untrimmed) starts.
///
/// `csv` stamps a record with the reader's position *before* the comment and blank lines
/// that it skips ahead of the record, so the line is found from the position *after* it
/// instead: that is on the record's last line, unless the record's `\n` terminator was
/// consumed (then it is the next line; a CRLF record stops before its `\n`). A record
/// spans one line more than its fields hold newlines (only quoted fields hold them).
fn start_line(text: &str, after: &csv::Position, record: &csv::StringRecord) -> usize {
    let consumed = usize::try_from(after.byte()).unwrap_or(usize::MAX);
    let ends_in_newline =
        consumed.checked_sub(1).and_then(|i| text.as_bytes().get(i)) == Some(&b'\n');
    let last_line = after.line() as usize - usize::from(ends_in_newline);
    let inner_newlines: usize = record.iter().map(|f| f.matches('\n').count()).sum();
    last_line.saturating_sub(inner_newlines).max(1)
}

/// Removes one pair of enclosing double quotes (and undoubles `""` inside) from a trimmed
/// field that `csv` did not read as quoted because spaces came before its opening quote.
fn unquote(field: &str) -> String {
    match field.strip_prefix('"').and_then(|f| f.strip_suffix('"')) {
        Some(inner) => inner.replace("\"\"", "\""),
        None => field.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines_and_fields(text: &str) -> Vec<(usize, Vec<&'static str>)> {
        rows("t.csv", text)
            .unwrap()
            .into_iter()
            .map(|r| {
                let fields = r
                    .fields
                    .into_iter()
                    .map(|f| &*Box::leak(f.into_boxed_str()))
                    .collect();
                (r.line, fields)
            })
            .collect()
    }

    #[test]
    fn rows_know_their_lines_past_comments_blanks_and_crlf() {
        let text = "\u{feff}# c\r\nwavelength_nm,n,k\r\n\r\n# x\n  # y\n400, \"1.5\" ,0\n   \n\"5\n00\",1.6,0";
        assert_eq!(
            lines_and_fields(text),
            vec![
                (2, vec!["wavelength_nm", "n", "k"]),
                (6, vec!["400", "1.5", "0"]),
                (8, vec!["5\n00", "1.6", "0"]),
            ]
        );
        // LF only, a trailing newline, a row on line 1.
        assert_eq!(
            lines_and_fields("a,b\n#\n\nc , d\n"),
            vec![(1, vec!["a", "b"]), (4, vec!["c", "d"])]
        );
        assert_eq!(lines_and_fields(""), vec![]);
        assert_eq!(lines_and_fields("# only\n\n"), vec![]);
    }

    #[test]
    fn quotes_are_read_as_csv_quotes() {
        assert_eq!(
            lines_and_fields("\"a,b\",\"say \"\"hi\"\"\", \"c\"\"\" ,\"d\""),
            vec![(1, vec!["a,b", "say \"hi\"", "c\"", "d"])]
        );
    }
}
