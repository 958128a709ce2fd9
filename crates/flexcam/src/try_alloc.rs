//! Fallible allocation of the buffers whose size comes from the input: frames (image width x
//! height, times the samples per pixel where a renderer keeps a frame per sample), their
//! depth, id and surface layers, z-buffers, band buffers, caustic maps, environment-map faces,
//! and the image writers' sample buffers (8- and 16-bit bytes, EXR channels).
//!
//! The memory budget (`scene::budget`) refuses a scene whose estimate exceeds it before
//! anything is allocated, but memory taken by other processes meanwhile can still make an
//! allocation it allowed fail; `Vec`'s own allocation then aborts the process. Every such
//! buffer is allocated here instead, and a failure is an [`Error`] naming the bytes asked for
//! and what they were for: `out of memory: cannot allocate 5.8 MB for the 800 x 600 frame`
//! (the CLI adds the scene file). The cost is one comparison per buffer, none per pixel.
//!
//! Where the operating system overcommits memory (Linux by default), a large allocation
//! succeeds and the process may instead be killed when the pages are first touched; an
//! address-space limit (`ulimit -v`) or a cgroup without overcommit makes the failure
//! reach this module.
//!
//! Test hook: the environment variable `FLEXCAM_TEST_ALLOC_LIMIT` (bytes), read once per
//! process, makes every allocation here of more than that many bytes fail as if the
//! allocator had refused it, so that tests can show what a failed frame allocation does
//! without running a machine out of memory. It is not a user setting.

use std::sync::OnceLock;

use crate::error::{Error, Result};

/// The name of the test hook's environment variable (see the module documentation).
pub const TEST_LIMIT_VARIABLE: &str = "FLEXCAM_TEST_ALLOC_LIMIT";

/// What the message of every error of this module starts with.
const OUT_OF_MEMORY: &str = "out of memory: ";

/// Whether `error` is a failed allocation of this module (not the input's fault: a caller
/// that names an input file for its other errors names the scene's for this one).
pub fn is_out_of_memory(error: &Error) -> bool {
    error.location.is_none() && error.message.starts_with(OUT_OF_MEMORY)
}

/// `len` zero values (zero bits: black, depth 0, id 0), straight from the allocator's zeroed
/// memory (no clearing pass: fresh pages are zero until written). `what` names the buffer
/// for the error ("the 800 x 600 frame"); it is called only on failure.
pub fn zeroed<T: bytemuck::Zeroable>(len: usize, what: impl FnOnce() -> String) -> Result<Vec<T>> {
    allowed::<T, _>(len, what, || bytemuck::allocation::try_zeroed_vec(len).ok())
}

/// `len` copies of `value`.
pub fn filled<T: Clone>(len: usize, value: T, what: impl FnOnce() -> String) -> Result<Vec<T>> {
    let mut values = Vec::new();
    resize(&mut values, len, value, what)?;
    Ok(values)
}

/// A copy of `values`.
pub fn copied<T: Clone>(values: &[T], what: impl FnOnce() -> String) -> Result<Vec<T>> {
    let mut copy = Vec::new();
    reserve(&mut copy, values.len(), what)?;
    copy.extend_from_slice(values);
    Ok(copy)
}

/// The `len` items of `items` in a vector allocated fallibly (an image writer's samples, say).
/// `len` is the number of items: more would grow the vector by `Vec`'s own (aborting)
/// allocation, fewer leave spare capacity.
pub fn collected<T>(
    len: usize,
    items: impl IntoIterator<Item = T>,
    what: impl FnOnce() -> String,
) -> Result<Vec<T>> {
    let mut values = Vec::new();
    reserve(&mut values, len, what)?;
    values.extend(items);
    debug_assert_eq!(values.len(), len);
    Ok(values)
}

/// Makes room in `values` for `additional` more elements (exactly, as
/// [`Vec::try_reserve_exact`]).
pub fn reserve<T>(
    values: &mut Vec<T>,
    additional: usize,
    what: impl FnOnce() -> String,
) -> Result<()> {
    let len = values.len().saturating_add(additional);
    if len <= values.capacity() {
        return Ok(());
    }
    allowed::<T, _>(len, what, || values.try_reserve_exact(additional).ok())
}

/// [`Vec::resize`] that fails instead of aborting when the memory for `len` elements cannot
/// be had; `values` is then unchanged.
pub fn resize<T: Clone>(
    values: &mut Vec<T>,
    len: usize,
    value: T,
    what: impl FnOnce() -> String,
) -> Result<()> {
    reserve(values, len.saturating_sub(values.len()), what)?;
    values.resize(len, value);
    Ok(())
}

/// `bytes` for people: "9.1 GB", "512.0 MB", "900 bytes" (decimal units).
pub fn format_bytes(bytes: u64) -> String {
    let units = [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)];
    match units.iter().find(|(_, size)| bytes as f64 >= *size) {
        Some((unit, size)) => format!("{:.1} {unit}", bytes as f64 / size),
        None => format!("{bytes} bytes"),
    }
}

/// Runs `allocate` for a buffer of `len` elements of `T` unless the test hook's limit forbids
/// it; the error names the bytes and `what`.
fn allowed<T, R>(
    len: usize,
    what: impl FnOnce() -> String,
    allocate: impl FnOnce() -> Option<R>,
) -> Result<R> {
    let bytes = len.checked_mul(std::mem::size_of::<T>());
    let refused = bytes.is_none_or(|b| test_limit().is_some_and(|limit| b > limit));
    match (!refused).then(allocate).flatten() {
        Some(buffer) => Ok(buffer),
        None => Err(Error::new(format!(
            "{OUT_OF_MEMORY}cannot allocate {} for {}",
            bytes.map_or_else(
                || format!("{len} elements of {} bytes", std::mem::size_of::<T>()),
                |b| format_bytes(b as u64)
            ),
            what()
        ))),
    }
}

/// The test hook's limit in bytes, read once; `None` when unset or not a number.
fn test_limit() -> Option<usize> {
    static LIMIT: OnceLock<Option<usize>> = OnceLock::new();
    *LIMIT.get_or_init(|| std::env::var(TEST_LIMIT_VARIABLE).ok()?.trim().parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_format_in_decimal_units() {
        assert_eq!(format_bytes(9_100_000_000), "9.1 GB");
        assert_eq!(format_bytes(900), "900 bytes");
        assert_eq!(format_bytes(1_500_000), "1.5 MB");
    }

    #[test]
    fn buffers_are_what_was_asked() {
        let what = || "a test buffer".to_string();
        assert_eq!(zeroed::<u32>(5, what).unwrap(), vec![0; 5]);
        assert_eq!(filled(3, 7u8, what).unwrap(), vec![7; 3]);
        assert_eq!(copied(&[4, 5], what).unwrap(), [4, 5]);
        let mut values = vec![1, 2];
        resize(&mut values, 4, 9, what).unwrap();
        assert_eq!(values, [1, 2, 9, 9]);
        resize(&mut values, 1, 9, what).unwrap();
        assert_eq!(values, [1]);
        reserve(&mut values, 100, what).unwrap();
        assert!(values.capacity() >= 101);
        assert!(zeroed::<u8>(0, what).unwrap().is_empty());
        assert_eq!(collected(3, [1u16, 2, 3], what).unwrap(), [1, 2, 3]);
    }

    /// More than the address space can hold fails with the bytes and the buffer named,
    /// whatever the test hook says; `values` is left as it was.
    #[test]
    fn impossible_sizes_are_errors_not_aborts() {
        let e = zeroed::<u64>(usize::MAX / 4, || "the 9 x 9 frame".into()).unwrap_err();
        assert!(
            e.message.starts_with(
                "out of memory: cannot allocate 4611686018427387903 elements of 8 bytes"
            ),
            "{e}"
        );
        let mut values = vec![1u64, 2];
        let e = resize(&mut values, usize::MAX / 16, 0, || "the z-buffer".into()).unwrap_err();
        assert!(e.message.ends_with("for the z-buffer"), "{e}");
        // An image writer's samples: the iterator is never started.
        let e = collected(usize::MAX / 4, std::iter::repeat(0u32), || {
            "the 8-bit RGB bytes of the 9 x 9 image".into()
        })
        .unwrap_err();
        assert!(
            e.message
                .ends_with("for the 8-bit RGB bytes of the 9 x 9 image"),
            "{e}"
        );
        assert_eq!(values, [1, 2]);
        let e = filled(usize::MAX / 2, 0u32, || "ids".into()).unwrap_err();
        assert!(is_out_of_memory(&e), "{e}");
        assert!(!is_out_of_memory(&e.or_in_file("scene.toml")));
    }
}
