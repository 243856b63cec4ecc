//! Reading a user's input file with bounds: it must be a regular file (not a device such as
//! `/dev/zero`, a FIFO that would block, or a directory), no larger than a limit, and text
//! must be UTF-8 — an error names the line and column of the first invalid byte.
//!
//! [`MAX_COORD`] is the plausible magnitude of a coordinate, for the checks of surfaces,
//! sheets and programs.
//!
//! Choices: the errors are `std::io::Error`s with a message of their own, so every reader
//! keeps its own error variant (which names the file); the type is checked on the path before
//! it is opened (opening a FIFO blocks) and again on the open handle; the read takes at most
//! `limit + 1` bytes, so a file that grows while it is read is still refused.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// Largest coordinate (mm, either sign) of a surface, sheet or program flatcut works with:
/// 1 km. Checked before any stage allocates by a coordinate (grids, pictures, rulers).
pub const MAX_COORD: f64 = 1e6;

/// Largest text input (spec, profile, CSV loop, ESICUP instance): 16 MiB.
pub const TEXT_LIMIT: u64 = 16 << 20;
/// Largest mesh or device program: 256 MiB.
pub const DATA_LIMIT: u64 = 256 << 20;

fn kind_of(ft: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if ft.is_char_device() || ft.is_block_device() {
            return "a device";
        }
        if ft.is_socket() {
            return "a socket";
        }
    }
    if ft.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

fn too_large(size: u64, limit: u64) -> Error {
    Error::new(
        ErrorKind::InvalidInput,
        format!(
            "the file is {} MiB, over the {} MiB limit for this kind of input",
            size.div_ceil(1 << 20),
            limit >> 20
        ),
    )
}

/// The bytes of a regular file of at most `limit` bytes.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>, Error> {
    let meta = std::fs::metadata(path)?;
    let ft = meta.file_type();
    if !ft.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{} — give a regular file", kind_of(&ft)),
        ));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len(), limit));
    }
    let f = std::fs::File::open(path)?;
    let ft = f.metadata()?.file_type();
    if !ft.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{} — give a regular file", kind_of(&ft)),
        ));
    }
    let mut out = Vec::with_capacity(meta.len() as usize);
    f.take(limit + 1).read_to_end(&mut out)?;
    if out.len() as u64 > limit {
        return Err(too_large(out.len() as u64, limit));
    }
    Ok(out)
}

/// Where byte `at` of `bytes` is: 1-based line and column (columns count characters).
pub fn line_col(bytes: &[u8], at: usize) -> (usize, usize) {
    let at = at.min(bytes.len());
    let before = &bytes[..at];
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let col = 1 + String::from_utf8_lossy(&before[start..]).chars().count();
    (line, col)
}

/// Bytes as UTF-8 text, or an error naming where the first invalid byte is.
pub fn utf8(bytes: Vec<u8>) -> Result<String, Error> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let (line, col) = line_col(e.as_bytes(), at);
        Error::new(
            ErrorKind::InvalidData,
            format!(
                "invalid UTF-8 at line {line}, column {col} (byte {})",
                at + 1
            ),
        )
    })
}

/// The text of a regular UTF-8 file of at most `limit` bytes.
pub fn read_text(path: &Path, limit: u64) -> Result<String, Error> {
    utf8(read_bytes(path, limit)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_and_directories_are_refused() {
        let e = read_bytes(Path::new("/dev/zero"), TEXT_LIMIT).unwrap_err();
        assert!(e.to_string().contains("a device"), "{e}");
        let e = read_bytes(Path::new("/"), TEXT_LIMIT).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
    }

    #[test]
    fn invalid_utf8_names_line_and_column() {
        let e = utf8(b"ab\ncd\xffe".to_vec()).unwrap_err();
        assert_eq!(e.to_string(), "invalid UTF-8 at line 2, column 3 (byte 6)");
    }

    #[test]
    fn over_the_limit_is_refused() {
        let dir = std::env::temp_dir().join(format!("flatcut-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("big.txt");
        std::fs::write(&f, vec![b'a'; 3 << 20]).unwrap();
        let e = read_bytes(&f, 1 << 20).unwrap_err();
        assert!(e.to_string().contains("over the 1 MiB limit"), "{e}");
        assert_eq!(read_bytes(&f, 4 << 20).unwrap().len(), 3 << 20);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
