//! Reading input files whole, as every reader of user files here does: only regular files,
//! and at most a stated number of bytes. Opening a FIFO for reading blocks until a writer
//! comes, and `/dev/zero` never ends, so both are refused from their metadata before the
//! file is opened; the size cap bounds what a file that grows while it is read can cost.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// The largest scene file read: scene files are hand-written or generated tables of a few
/// thousand values; 64 MiB leaves room for long generated point lists.
pub const MAX_SCENE_FILE_BYTES: u64 = 64 << 20;

/// The largest model, texture, buffer or photo file read (4 GiB): what the formats address
/// with 32-bit offsets (glTF buffers, GLB chunks).
pub const MAX_DATA_FILE_BYTES: u64 = 4 << 30;

/// Fails unless `path` is a regular file (symbolic links followed) of at most `limit`
/// bytes; `what` names it in the message ("scene file", "photo").
pub fn check_regular(path: &Path, what: &str, limit: u64) -> Result<()> {
    let metadata = std::fs::metadata(path)
        .map_err(|e| Error::in_file(path, format!("cannot read {what}: {e}")))?;
    if !metadata.is_file() {
        let kind = if metadata.is_dir() {
            "a folder"
        } else {
            "not a regular file (a FIFO, socket or device)"
        };
        return Err(Error::in_file(path, format!("{what} is {kind}")));
    }
    too_large(path, what, metadata.len(), limit)
}

/// The bytes of the regular file `path`, at most `limit` of them (see [`check_regular`]).
pub fn read_regular(path: &Path, what: &str, limit: u64) -> Result<Vec<u8>> {
    check_regular(path, what, limit)?;
    let cannot = |e: std::io::Error| Error::in_file(path, format!("cannot read {what}: {e}"));
    let file = std::fs::File::open(path).map_err(cannot)?;
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    too_large(path, what, bytes.len() as u64, limit)?;
    Ok(bytes)
}

/// As [`read_regular`], as UTF-8 text.
pub fn read_regular_text(path: &Path, what: &str, limit: u64) -> Result<String> {
    String::from_utf8(read_regular(path, what, limit)?).map_err(|e| {
        Error::in_file(
            path,
            format!(
                "cannot read {what}: not UTF-8 text (byte {} is not valid)",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

fn too_large(path: &Path, what: &str, size: u64, limit: u64) -> Result<()> {
    if size > limit {
        return Err(Error::in_file(
            path,
            format!("{what} is larger than the {limit}-byte limit ({size} bytes or more)"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_devices_and_fifos_are_refused_before_opening() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_regular(dir.path(), "scene file", 10).unwrap_err();
        assert!(e.to_string().ends_with(": scene file is a folder"), "{e}");
        let e = read_regular(Path::new("/dev/zero"), "scene file", 10).unwrap_err();
        assert_eq!(
            e.to_string(),
            "/dev/zero: scene file is not a regular file (a FIFO, socket or device)"
        );
        let fifo = dir.path().join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            // Opening it would block forever: the check must come first.
            assert!(read_regular(&fifo, "photo", 10).is_err());
        }
    }

    #[test]
    fn size_is_capped() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.toml");
        std::fs::write(&path, "0123456789").unwrap();
        assert_eq!(read_regular(&path, "scene file", 10).unwrap().len(), 10);
        let e = read_regular(&path, "scene file", 9)
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("scene file is larger than the 9-byte limit (10 bytes or more)"));
        std::fs::write(&path, b"\xff\xfe").unwrap();
        let e = read_regular_text(&path, "scene file", 9).unwrap_err();
        assert!(e.to_string().contains("not UTF-8"), "{e}");
    }
}
