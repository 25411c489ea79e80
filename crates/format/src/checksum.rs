//! SHA-256 checksums as 64 lowercase hexadecimal digits: of a file (table files, read in
//! 64 KiB pieces), of bytes in memory and of a text (recipes, for manifests). The one place
//! the workspace computes them (SHA-256 of FIPS 180-4, through the `sha2` crate).

use crate::error::{Error, Result};
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

/// The SHA-256 digest of the file at `path` as 64 lowercase hexadecimal digits, for
/// manifests.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read.
pub fn sha256_hex(path: &Path) -> Result<String> {
    let io_error = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io_error)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => hasher.update(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io_error(e)),
        }
    }
    Ok(hex(&hasher.finalize()))
}

/// The SHA-256 digest of `bytes` as 64 lowercase hexadecimal digits.
pub fn sha256_bytes(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// The SHA-256 digest of the UTF-8 bytes of `text` as 64 lowercase hexadecimal digits.
pub fn sha256_text(text: &str) -> String {
    sha256_bytes(text.as_bytes())
}

fn hex(digest: &[u8]) -> String {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut hex = String::with_capacity(2 * digest.len());
    for &b in digest {
        hex.push(char::from(HEX[usize::from(b >> 4)]));
        hex.push(char::from(HEX[usize::from(b & 0xf)]));
    }
    hex
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_text_and_file_digests_agree_with_the_fips_example() {
        // FIPS 180-4 / NIST CSRC example: SHA-256("abc").
        let abc = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";
        assert_eq!(sha256_bytes(b"abc"), abc);
        assert_eq!(sha256_text("abc"), abc);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("abc.txt");
        std::fs::write(&path, "abc").unwrap();
        assert_eq!(sha256_hex(&path).unwrap(), abc);
    }
}
