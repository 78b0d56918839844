//! SHA-256 digests (FIPS 180-4, the `sha2` crate) of bytes and files, as
//! lower-case hex: what `manifest.json` records and `attsync verify`
//! checks. The same digest as coreutils' `sha256sum`.

use sha2::{Digest, Sha256};
use std::fs::File;
use std::io;
use std::path::Path;

/// Lower-case hex of `bytes`.
fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write;
    bytes.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

/// The SHA-256 of `bytes`, 64 lower-case hex digits.
///
/// ```
/// // FIPS 180-4's example "abc".
/// assert_eq!(
///     attsync::results::digest::sha256_hex(b"abc"),
///     "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
/// );
/// ```
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// The size of `file` in bytes and its SHA-256 (read in a stream, so a
/// large `states.bin` is not held in memory).
///
/// # Errors
/// The file cannot be opened or read.
pub fn sha256_file(file: &Path) -> io::Result<(u64, String)> {
    let mut hasher = Sha256::new();
    let size = io::copy(&mut File::open(file)?, &mut hasher)?;
    Ok((size, hex(&hasher.finalize())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_input_and_a_streamed_file_agree_with_the_standard() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("x");
        let data = vec![0x5a_u8; 100_000];
        std::fs::write(&file, &data).expect("write");
        assert_eq!(
            sha256_file(&file).expect("read"),
            (100_000, sha256_hex(&data))
        );
    }
}
