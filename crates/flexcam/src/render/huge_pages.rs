//! Transparent huge pages for new frame buffers.
//!
//! The first write to each 4 KiB page of freshly allocated memory is a page fault: the kernel
//! maps a zeroed page and resumes the writer. A new 800 x 800 frame (12.8 MB) takes about
//! 3,100 of them; on the virtual machine we measure on each costs about 3 us of CPU, as much
//! as the trilinear renderer's whole work for the frame. `madvise(MADV_HUGEPAGE)` lets the
//! kernel map each 2 MiB-aligned block of the buffer with one 2 MiB page, one fault instead
//! of 512 (where transparent huge pages are enabled, `always` or `madvise`, as on Linux
//! distributions by default). Measured in docs/trilinear.md, "A new frame without a clearing
//! pass". Elsewhere, or where the call fails, nothing is done: it changes no byte, only the
//! size of the pages that memory not yet written is mapped with.

/// Asks the kernel to map the 2 MiB-aligned blocks lying wholly inside `values` with huge
/// pages when they are first written; the contents are unchanged. Pages already mapped stay
/// as they are, so it only helps before the buffer's first write (a fresh allocation).
pub(crate) fn advise_huge_pages<T>(values: &mut [T]) {
    #[cfg(target_os = "linux")]
    {
        let Some(page) = page_size() else {
            return;
        };
        let start = values.as_mut_ptr() as usize;
        let end = start + std::mem::size_of_val(values);
        let first = start.next_multiple_of(page);
        let last = end & !(page - 1);
        // Below one huge page nothing can be mapped with one.
        if last.saturating_sub(first) >= HUGE_PAGE {
            // SAFETY: [first, last) lies inside `values`, which we borrow mutably;
            // MADV_HUGEPAGE only sets how the kernel maps its pages and changes no byte
            // (anonymous memory not yet written reads as zero with either page size).
            // Failure (EINVAL without transparent huge pages) is harmless: the memory is
            // then mapped with small pages as before.
            unsafe {
                libc::madvise(
                    first as *mut libc::c_void,
                    last - first,
                    libc::MADV_HUGEPAGE,
                );
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = values;
}

/// Maps every page of `values` at once, as the first writes would, with one system call
/// (`madvise(MADV_POPULATE_WRITE)`, Linux 5.14) instead of one page fault per page: for a
/// buffer about to be written whole, such as a polygon batch allocated to its exact size.
/// Huge pages advised before ([`advise_huge_pages`]) are honoured. The pages holding the
/// ends of `values` are included whole (they belong to its allocation); pages already
/// mapped are left as they are. Elsewhere, or where the call fails (an older kernel), the
/// pages are mapped by the writes as before; no byte changes either way. A region under
/// [`POPULATE_MIN`] bytes is left to its page faults.
fn populate_for_writing<T>(values: &mut [T]) {
    #[cfg(target_os = "linux")]
    {
        let Some(page) = page_size() else {
            return;
        };
        let start = values.as_mut_ptr() as usize;
        let end = start + std::mem::size_of_val(values);
        if end - start < POPULATE_MIN {
            return;
        }
        let first = start & !(page - 1);
        let last = end.next_multiple_of(page);
        // SAFETY: [first, last) is the pages holding bytes of `values`, which we borrow
        // mutably, all inside its allocation's mapping; MADV_POPULATE_WRITE maps them as a
        // write would (zeroed where not yet mapped) and changes no byte. Failure (EINVAL
        // before Linux 5.14) is harmless: the writes then map the pages.
        unsafe {
            libc::madvise(
                first as *mut libc::c_void,
                last - first,
                libc::MADV_POPULATE_WRITE,
            );
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = values;
}

/// The least region [`populate_for_writing`] maps at once (16 pages of 4 KiB): the system
/// call costs about as much as a few page faults, and a growing buffer's first steps are
/// smaller than a page (74 calls a render of the fan example without the bound, most of
/// one page).
#[cfg(target_os = "linux")]
const POPULATE_MIN: usize = 64 << 10;

/// The page size, a power of two, or `None` where it cannot be had.
#[cfg(target_os = "linux")]
fn page_size() -> Option<usize> {
    // SAFETY: `sysconf` has no preconditions.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    usize::try_from(page).ok().filter(|p| p.is_power_of_two())
}

/// Makes room for `additional` more values in `values` as `Vec::reserve` does (amortised
/// doubling) and, when it grew, maps the fresh spare capacity at once: advised onto huge
/// pages ([`advise_huge_pages`]) and populated ([`populate_for_writing`]). For a buffer that
/// grows to megabytes while it is written once (the trilinear renderer's outline points):
/// one system call per growth instead of a page fault per 4 KiB of it, at the price of
/// mapping the room not yet used (at most what the last doubling added). The values are
/// unchanged.
pub(crate) fn reserve_mapped<T: Copy>(values: &mut Vec<T>, additional: usize) {
    if values.capacity() - values.len() < additional {
        // A new buffer, mapped before the values are copied in: growing in place
        // (`Vec::reserve`, a `realloc`) would copy them into fresh pages one page fault
        // at a time where the allocator cannot move the pages themselves.
        let wanted = values.len() + additional;
        let mut grown = Vec::with_capacity(wanted.max(2 * values.capacity()));
        map_spare_capacity(&mut grown);
        grown.extend_from_slice(values);
        *values = grown;
    }
}

/// Maps the spare capacity of `values`, about to be written once, at once: advised onto
/// huge pages ([`advise_huge_pages`]) and populated ([`populate_for_writing`]). The values
/// are unchanged.
pub(crate) fn map_spare_capacity<T>(values: &mut Vec<T>) {
    advise_huge_pages(values.spare_capacity_mut());
    populate_for_writing(values.spare_capacity_mut());
}

/// The size of an x86-64 transparent huge page (2 MiB): smaller ranges are not advised.
#[cfg(target_os = "linux")]
const HUGE_PAGE: usize = 2 << 20;

#[cfg(test)]
mod tests {
    use super::{advise_huge_pages, populate_for_writing, reserve_mapped};

    /// The contents are unchanged by either call, whatever the slice's alignment and length
    /// (empty, shorter than a page, spanning huge pages), in fresh zeroed memory, in written
    /// memory and in spare capacity written after it was populated.
    #[test]
    fn huge_page_advice_changes_no_value() {
        for n in [0, 1, 1023, 1024, 5000, 3 << 20] {
            let mut zeroed: Vec<u32> = bytemuck::zeroed_vec(n);
            for skip in [0, 1, 3].into_iter().filter(|&s| s <= n) {
                advise_huge_pages(&mut zeroed[skip..]);
                assert!(zeroed.iter().all(|&v| v == 0));
            }
            zeroed.iter_mut().step_by(997).for_each(|v| *v = 5);
            assert!(zeroed
                .iter()
                .enumerate()
                .all(|(i, &v)| v == if i % 997 == 0 { 5 } else { 0 }));
            let mut written: Vec<u32> = (0..n as u32)
                .map(|i| i.wrapping_mul(2_654_435_761))
                .collect();
            let copy = written.clone();
            advise_huge_pages(&mut written[..]);
            assert_eq!(written, copy);
            for skip in [0, 1, 3].into_iter().filter(|&s| s <= n) {
                populate_for_writing(&mut written[skip..]);
                populate_for_writing(&mut zeroed[skip..]);
            }
            assert_eq!(written, copy);
            assert!(zeroed
                .iter()
                .enumerate()
                .all(|(i, &v)| v == if i % 997 == 0 { 5 } else { 0 }));
            let mut fresh: Vec<u32> = Vec::with_capacity(n);
            populate_for_writing(fresh.spare_capacity_mut());
            fresh.extend(copy.iter().copied());
            assert_eq!(fresh, copy);
        }
    }

    /// Growing a buffer by [`reserve_mapped`] keeps its values and makes the room
    /// asked for, from empty, across the huge-page size, and when it already has room.
    #[test]
    fn reserving_mapped_room_keeps_the_values() {
        let mut values: Vec<u64> = Vec::new();
        let mut expected = Vec::new();
        for step in 0..40u64 {
            let run: Vec<u64> = (0..step * 997).map(|i| i ^ step).collect();
            let capacity = values.capacity();
            reserve_mapped(&mut values, run.len());
            assert!(values.capacity() - values.len() >= run.len());
            if capacity - expected.len() >= run.len() {
                assert_eq!(values.capacity(), capacity, "no growth when there is room");
            }
            values.extend_from_slice(&run);
            expected.extend_from_slice(&run);
            assert_eq!(values, expected);
        }
        assert!(std::mem::size_of_val(&values[..]) > 4 << 20);
    }
}
