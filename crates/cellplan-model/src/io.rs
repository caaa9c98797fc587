//! Reading inputs with a size limit, and writing outputs so that nothing is ever half-written.
use cellplan_geom::read::{LimitedReadError, read_limited, show_bytes, utf8_text};
use std::io::Write;
use std::path::Path;

/// Reads a UTF-8 text file of at most `limit` bytes. A larger file (or an endless one, such as
/// `/dev/zero`) is refused without reading more than `limit + 1` bytes, so no input can
/// exhaust memory (see [`cellplan_geom::read`]).
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<String> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidData, m);
    let bytes = read_limited(path, limit).map_err(|e| match e {
        LimitedReadError::Io(e) => e,
        LimitedReadError::TooLarge { size } => invalid(format!(
            "the file is {size}, larger than {}, the most cellplan reads",
            show_bytes(limit)
        )),
    })?;
    utf8_text(bytes).map_err(|e| invalid(format!("not UTF-8 text (line {}, byte {})", e.line, e.offset)))
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`. Parent
/// folders are created. On error the target is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes several files all or nothing: each goes to a temporary file beside its target, and
/// only when every one is complete are they renamed over their targets. If a write fails, no
/// target is touched.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> std::io::Result<()> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir)?;
        let mut tmp = tempfile::Builder::new().prefix(".cellplan-").tempfile_in(dir)?;
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        staged.push((tmp, *path));
    }
    for (tmp, path) in staged {
        tmp.persist(path).map_err(|e| e.error)?;
    }
    Ok(())
}

/// Checks, before any work, that `dir` can take the files of a run: creates it and writes and
/// removes a temporary file in it.
pub fn check_writable(dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    tempfile::Builder::new()
        .prefix(".cellplan-probe-")
        .tempfile_in(dir)?;
    Ok(())
}

/// Checks, before any work, that files can be made in `dir`, without making anything that
/// stays: where `dir` does not exist yet, in the nearest folder above it that does (writing
/// there will create it). An error where that is a file, or where a temporary file cannot be
/// written in it.
pub fn check_creatable(dir: &Path) -> std::io::Result<()> {
    let mut at = dir;
    while !at.exists() {
        match at.parent() {
            Some(p) if !p.as_os_str().is_empty() => at = p,
            _ => {
                at = Path::new(".");
                break;
            }
        }
    }
    if !at.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::NotADirectory,
            format!("{} is a file, not a folder", at.display()),
        ));
    }
    tempfile::Builder::new()
        .prefix(".cellplan-probe-")
        .tempfile_in(at)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn creatable_folders_are_checked_without_making_them() {
        let dir = tempfile::tempdir().unwrap();
        let deep = dir.path().join("a/b/c");
        check_creatable(&deep).unwrap();
        assert!(!dir.path().join("a").exists(), "nothing made");
        let file = dir.path().join("file");
        std::fs::write(&file, b"x").unwrap();
        let e = check_creatable(&file.join("below")).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::NotADirectory);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no probe left");
    }

    #[test]
    fn writes_whole_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("sub/out.txt");
        write_atomic(&target, b"hello").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "hello");
        let leftovers = std::fs::read_dir(target.parent().unwrap()).unwrap().count();
        assert_eq!(leftovers, 1);
    }

    #[test]
    fn all_or_nothing_when_one_target_cannot_be_written() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("plan.json");
        // A folder where the second file should go: its rename cannot succeed, but the first
        // target is only renamed if every temporary was written.
        let blocked = dir.path().join("missing-parent-is-a-file");
        std::fs::write(&blocked, b"x").unwrap();
        let bad = blocked.join("report.html");
        assert!(write_all_atomic(&[(&good, b"plan"), (&bad, b"report")]).is_err());
        assert!(
            !good.exists(),
            "the plan was written although the report could not be"
        );
    }

    #[test]
    fn endless_and_oversized_files_are_refused() {
        let e = read_bounded(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(e.to_string().contains("larger than 1 MiB"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("bin");
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        assert!(read_bounded(&f, 100).unwrap_err().to_string().contains("UTF-8"));
        assert!(check_writable(&f.join("sub")).is_err());
    }
}
