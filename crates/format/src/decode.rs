//! The guard every decoder of an untrusted file runs under (table atlases here, height
//! fields in `nacre-bake`, pictures in `nacre-runtime`): a panic inside a decoder library
//! (a malformed file it did not anticipate) becomes the caller's error naming the file,
//! never a crash.

/// Runs `decode`; a panic inside it returns `on_panic()` instead (the caller's error, which
/// names the file and the format).
pub fn guarded<T, E>(
    decode: impl FnOnce() -> Result<T, E>,
    on_panic: impl FnOnce() -> E,
) -> Result<T, E> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode))
        .unwrap_or_else(|_| Err(on_panic()))
}

/// [`guarded`] for the table atlases: a panic is [`crate::Error::Table`] naming `path` and
/// `format` (`"malformed {format} data (the decoder failed)"`).
pub(crate) fn guarded_table<T>(
    path: &std::path::Path,
    format: &str,
    decode: impl FnOnce() -> crate::Result<T>,
) -> crate::Result<T> {
    guarded(decode, || crate::Error::Table {
        path: path.to_path_buf(),
        message: format!("malformed {format} data (the decoder failed)"),
    })
}
