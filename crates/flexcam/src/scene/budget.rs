//! The memory budget: a scene whose estimated memory (its triangles and frame) exceeds it
//! is refused before the memory is allocated, with the estimate in the message, instead of
//! running the machine out of memory (an abort, or the OOM killer) part way through.
//!
//! The budget is process-wide: by default three quarters of the memory this process may
//! use (the least of physical memory, the cgroup limit `memory.max`, and half the address
//! space limit `RLIMIT_AS`, which also holds code, stacks and allocator slack); the CLI's
//! `--max-memory` sets it ([`set_max_memory`]). The estimates are deliberately round
//! upper bounds measured on this code base (a teapot of 4.2 million triangles takes about
//! 0.9 GB through loading, the acceleration structure and the prepared scene), not exact
//! accounting.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};
use crate::try_alloc::format_bytes;

/// Estimated bytes per scene triangle, everything a render holds for it: vertices,
/// indices, the world-space copy, the acceleration structure.
pub const BYTES_PER_TRIANGLE: u64 = 220;

/// Estimated bytes per byte of a model file before it is parsed (its triangles are not
/// known yet): a binary mesh stores about 30 bytes a triangle, a text one more.
pub const BYTES_PER_MODEL_FILE_BYTE: u64 = 8;

/// Estimated bytes per image pixel: the frame's colour, depth and id buffers, the encoded
/// output, and a second frame for `compare`.
pub const BYTES_PER_PIXEL: u64 = 64;

/// Estimated bytes per texel of a decoded texture or photo while it is converted: the
/// decoded image, its f32 copy and the linear texels.
pub const BYTES_PER_TEXEL: u64 = 32;

/// The budget set by [`set_max_memory`]; 0 while unset.
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// Sets the budget, in bytes, for the rest of the process.
pub fn set_max_memory(bytes: u64) {
    MAX_MEMORY.store(bytes.max(1), Ordering::Relaxed);
}

/// The budget in bytes: as set, or [`machine_budget`].
pub fn max_memory() -> u64 {
    match MAX_MEMORY.load(Ordering::Relaxed) {
        0 => machine_budget(),
        set => set,
    }
}

/// Three quarters of the memory this process may use (see the module documentation).
pub fn machine_budget() -> u64 {
    let physical = meminfo_total().unwrap_or(u64::MAX);
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .unwrap_or(u64::MAX);
    let address_space = address_space_limit().map_or(u64::MAX, |l| l / 2);
    let usable = physical.min(cgroup).min(address_space);
    if usable == u64::MAX {
        // Nothing known (not Linux): assume a modest machine.
        return 8 << 30;
    }
    usable / 4 * 3
}

fn meminfo_total() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

fn address_space_limit() -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes one rlimit into the struct it is given.
    let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } == 0;
    (ok && limit.rlim_cur != libc::RLIM_INFINITY).then_some(limit.rlim_cur)
}

/// Fails when `estimate` bytes (for `what`, e.g. "12,582,912 triangles") exceed the
/// budget; the message gives both, and the flag that changes the budget.
pub fn check(estimate: u64, what: &str) -> Result<()> {
    let budget = max_memory();
    if estimate <= budget {
        return Ok(());
    }
    Err(Error::new(format!(
        "needs about {} of memory ({what}), more than the memory budget of {} \
         (--max-memory changes it)",
        format_bytes(estimate),
        format_bytes(budget)
    )))
}

/// Fails when parsing the model file `path`, whose size suggests its memory before it is
/// parsed ([`BYTES_PER_MODEL_FILE_BYTE`]), would exceed the budget with the `reserved`
/// bytes already held.
pub fn check_model_file(path: &Path, reserved: u64) -> Result<()> {
    let size = std::fs::metadata(path).map_or(0, |m| m.len());
    let estimate = size.saturating_mul(BYTES_PER_MODEL_FILE_BYTE);
    check(
        reserved.saturating_add(estimate),
        &format!("model file {} of {size} bytes", path.display()),
    )
}

/// Fails when decoding a `width` x `height` image (a texture, a photo) would exceed the
/// budget on its own: checked from the image's header, before it is decoded.
pub fn check_image(width: u32, height: u32) -> Result<()> {
    let texels = u64::from(width) * u64::from(height);
    check(
        texels.saturating_mul(BYTES_PER_TEXEL),
        &format!("a {width} x {height} image"),
    )
}

/// Parses a size as `--max-memory` takes it: a number of bytes, optionally with a decimal
/// (k, M, G, T) or binary (KiB, MiB, GiB, TiB) unit, case-insensitive, `B` optional:
/// `8G`, `512MiB`, `1.5GB`, `1000000`.
pub fn parse_size(text: &str) -> std::result::Result<u64, String> {
    let text = text.trim();
    let split = text
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let number: f64 = number
        .parse()
        .map_err(|_| format!("\"{text}\" is not a size (e.g. 8G, 512MiB, 1000000)"))?;
    let unit = unit.trim().to_ascii_lowercase();
    let scale: f64 = match unit.trim_end_matches('b') {
        "" => 1.0,
        "k" => 1e3,
        "m" => 1e6,
        "g" => 1e9,
        "t" => 1e12,
        "ki" => 1024.0,
        "mi" => 1024.0 * 1024.0,
        "gi" => 1024.0 * 1024.0 * 1024.0,
        "ti" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "unknown unit \"{unit}\" in \"{text}\" (k, M, G, T, KiB, MiB, GiB, TiB)"
            ))
        }
    };
    let bytes = number * scale;
    if !(1.0..=u64::MAX as f64).contains(&bytes) {
        return Err(format!("\"{text}\" is out of range (at least 1 byte)"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units() {
        assert_eq!(parse_size("1000000"), Ok(1_000_000));
        assert_eq!(parse_size("8G"), Ok(8_000_000_000));
        assert_eq!(parse_size("1.5GB"), Ok(1_500_000_000));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("2 gib"), Ok(2 << 30));
        assert!(parse_size("-1G").is_err());
        assert!(parse_size("0").is_err());
        assert!(parse_size("8X").unwrap_err().contains("unknown unit"));
        assert!(parse_size("G").is_err());
    }

    #[test]
    fn the_machine_budget_is_some_memory() {
        let budget = machine_budget();
        assert!(budget > 1 << 20, "{budget}");
    }
}
