//! Reading input files with a size limit, so that no input can exhaust memory: a regular file
//! larger than the limit is refused before reading, anything else (a pipe, `/dev/zero`) is read
//! up to one byte past the limit and refused if it has more. Shared by the mesh loaders, the
//! URDF loader and the cell loader.
use std::io::Read as _;
use std::path::Path;

/// Why [`read_limited`] gave no bytes.
#[derive(Debug)]
pub enum LimitedReadError {
    /// The file could not be opened or read.
    Io(std::io::Error),
    /// The file is larger than the limit; `size` says by how much as people read it
    /// (`"1073741825 bytes"`, or `"more than 4096 bytes"` when its size was not stated).
    TooLarge {
        /// The size found.
        size: String,
    },
}

/// The bytes of `path`, at most `limit` of them; never allocates more than `limit + 1` bytes.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, LimitedReadError> {
    let file = std::fs::File::open(path).map_err(LimitedReadError::Io)?;
    let stated = file.metadata().ok().filter(|m| m.is_file()).map(|m| m.len());
    if let Some(len) = stated
        && len > limit
    {
        return Err(LimitedReadError::TooLarge {
            size: format!("{len} bytes"),
        });
    }
    // `stated <= limit` here, so the reservation is bounded.
    let mut bytes = Vec::with_capacity(stated.map_or(0, |l| l as usize + 1));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(LimitedReadError::Io)?;
    if bytes.len() as u64 > limit {
        return Err(LimitedReadError::TooLarge {
            size: format!("more than {limit} bytes"),
        });
    }
    Ok(bytes)
}

/// `limit` as people read it: whole MiB when it is some, else bytes.
pub fn show_bytes(limit: u64) -> String {
    if limit >= 1 << 20 && limit.is_multiple_of(1 << 20) {
        format!("{} MiB", limit >> 20)
    } else {
        format!("{limit} bytes")
    }
}

/// Where bytes stop being UTF-8 text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotUtf8 {
    /// 1-based line of the first bad byte.
    pub line: usize,
    /// Its offset.
    pub offset: usize,
    /// Its value.
    pub byte: u8,
}

/// The bytes as text, or where they stop being UTF-8.
pub fn utf8_text(bytes: Vec<u8>) -> Result<String, NotUtf8> {
    String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        NotUtf8 {
            line: bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1,
            offset,
            byte: bytes[offset],
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endless_and_oversized_inputs_are_refused() {
        match read_limited(Path::new("/dev/zero"), 4096) {
            Err(LimitedReadError::TooLarge { size }) => assert_eq!(size, "more than 4096 bytes"),
            other => panic!("{other:?}"),
        }
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("big");
        std::fs::File::create(&f).unwrap().set_len(5000).unwrap();
        match read_limited(&f, 4096) {
            Err(LimitedReadError::TooLarge { size }) => assert_eq!(size, "5000 bytes"),
            other => panic!("{other:?}"),
        }
        assert_eq!(read_limited(&f, 5000).unwrap().len(), 5000);
        assert!(matches!(
            read_limited(&dir.path().join("none"), 1),
            Err(LimitedReadError::Io(_))
        ));
        assert_eq!(show_bytes(1 << 30), "1024 MiB");
        assert_eq!(show_bytes(4096), "4096 bytes");
    }

    #[test]
    fn non_utf8_names_line_and_byte() {
        let e = utf8_text(b"ok\nal\xe9".to_vec()).unwrap_err();
        assert_eq!(
            e,
            NotUtf8 {
                line: 2,
                offset: 5,
                byte: 0xe9
            }
        );
        assert_eq!(utf8_text(b"fine".to_vec()).unwrap(), "fine");
    }
}
