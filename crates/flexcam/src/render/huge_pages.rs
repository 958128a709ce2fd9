//! Transparent huge pages for large buffers such as new frames.
//!
//! The first write to each 4 KiB page of freshly allocated memory is a page fault: the kernel
//! maps a zeroed page and resumes the writer. A new 800 x 800 frame (12.8 MB) takes about
//! 3,100 of them; on the virtual machine we measure on each costs about 3 us of CPU, as much
//! as the trilinear renderer's whole work for the frame. A 2 MiB-aligned block mapped with
//! one transparent huge page costs one fault instead of 512 (where transparent huge pages are
//! enabled, `always` or `madvise`, as on Linux distributions by default). Two ways in:
//!
//! - [`HugePageAllocator`], a global allocator for programs (the `flexcam` binary installs it):
//!   every block of 2 MiB or more is its own 2 MiB-aligned anonymous mapping advised with
//!   `MADV_HUGEPAGE`, so all of it is mapped with huge pages, and it comes zeroed from the
//!   kernel (`alloc_zeroed` writes nothing); smaller blocks go to the system allocator.
//! - [`advise_huge_pages`], for a buffer from any allocator: only the 2 MiB-aligned blocks
//!   lying wholly inside it can be advised (about half of a frame's buffers).
//!
//! Measured in docs/trilinear.md, "A new frame without a clearing pass" and "A new frame on
//! huge pages only". Elsewhere than on Linux, or where a call fails, memory is mapped as
//! before: neither changes a byte, only the size of the pages memory not yet written is
//! mapped with.

/// Asks the kernel to map the 2 MiB-aligned blocks lying wholly inside `values` with huge
/// pages when they are first written; the contents are unchanged. Pages already mapped stay
/// as they are, so it only helps before the buffer's first write (a fresh allocation).
pub(crate) fn advise_huge_pages<T>(values: &mut [T]) {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: `sysconf` has no preconditions.
        let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
        let Ok(page) = usize::try_from(page) else {
            return;
        };
        if !page.is_power_of_two() {
            return;
        }
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

/// The size of an x86-64 transparent huge page (2 MiB): smaller ranges are not advised, and
/// [`HugePageAllocator`] maps blocks of at least this size.
#[cfg(target_os = "linux")]
const HUGE_PAGE: usize = 2 << 20;

/// A global allocator that maps every block of 2 MiB or more (alignment up to 2 MiB) as its
/// own anonymous mapping, 2 MiB-aligned, rounded up to whole 2 MiB, advised with
/// `MADV_HUGEPAGE` (so transparent huge pages cover all of it), and unmapped when freed; all
/// other blocks are the system allocator's. Fresh mappings read as zero, so `alloc_zeroed`
/// of a large block (`Frame::zeroed`) writes nothing: its pages are first touched by the
/// threads that fill them. Install it with
/// `#[global_allocator] static ALLOCATOR: HugePageAllocator = HugePageAllocator;`.
///
/// Costs: a large block always gets fresh memory from the kernel (a block freed is given
/// back at once, not reused), and up to 2 MiB at its end may be mapped without being used.
/// Off Linux it is the system allocator.
#[derive(Debug, Clone, Copy, Default)]
pub struct HugePageAllocator;

#[cfg(target_os = "linux")]
impl HugePageAllocator {
    /// The length of the mapping of a block of `layout`, or `None` for a block of the system
    /// allocator (smaller than a huge page, or aligned beyond one). `None` also where the
    /// rounded length overflows: such a size cannot be mapped anyway, and the system
    /// allocator then refuses it.
    fn mapping_len(layout: std::alloc::Layout) -> Option<usize> {
        (layout.size() >= HUGE_PAGE && layout.align() <= HUGE_PAGE)
            .then(|| layout.size().checked_next_multiple_of(HUGE_PAGE))
            .flatten()
            .filter(|len| len.checked_add(HUGE_PAGE).is_some())
    }

    /// Maps `len` bytes (a multiple of [`HUGE_PAGE`]) at a 2 MiB-aligned address, advised
    /// for huge pages; null where the mapping fails (out of memory).
    ///
    /// # Safety
    /// `len` must be a non-zero multiple of [`HUGE_PAGE`] that `HUGE_PAGE` can be added to.
    unsafe fn map(len: usize) -> *mut u8 {
        // One huge page more than needed, so that an aligned start lies inside; the slack
        // before and after it is unmapped again.
        let reserved = len + HUGE_PAGE;
        // SAFETY: a fresh private anonymous mapping; it overlaps nothing of ours.
        let base = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                reserved,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                -1,
                0,
            )
        };
        if base == libc::MAP_FAILED {
            return std::ptr::null_mut();
        }
        let base = base as usize;
        let start = base.next_multiple_of(HUGE_PAGE);
        let (head, tail) = (start - base, base + reserved - (start + len));
        // SAFETY: the head [base, start) and the tail [start + len, base + reserved) are
        // page-aligned parts of the mapping just made (mmap returns page-aligned addresses
        // and HUGE_PAGE is a multiple of the page size), used by nobody; MADV_HUGEPAGE
        // changes no byte, and its failure (no transparent huge pages) leaves small pages.
        unsafe {
            if head > 0 {
                libc::munmap(base as *mut libc::c_void, head);
            }
            if tail > 0 {
                libc::munmap((start + len) as *mut libc::c_void, tail);
            }
            libc::madvise(start as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
        }
        start as *mut u8
    }
}

// SAFETY: a large block is a mapping of its own of at least `layout.size()` bytes at an
// address aligned to 2 MiB (so to `layout.align()`), freed by unmapping exactly the length
// it was mapped with, which `mapping_len` derives from the layout the caller passes back (the
// contract of `GlobalAlloc`: the same layout, or for `realloc`'s result the new size). Which
// allocator owns a block depends only on its layout, so each block is freed by the one that
// made it. Nothing here allocates or unwinds.
#[cfg(target_os = "linux")]
unsafe impl std::alloc::GlobalAlloc for HugePageAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        match Self::mapping_len(layout) {
            // SAFETY: `mapping_len`'s lengths are non-zero multiples of HUGE_PAGE with room.
            Some(len) => unsafe { Self::map(len) },
            // SAFETY: forwarded with the caller's guarantees.
            None => unsafe { std::alloc::System.alloc(layout) },
        }
    }

    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        match Self::mapping_len(layout) {
            // SAFETY: as in `alloc`; a fresh anonymous mapping reads as zero.
            Some(len) => unsafe { Self::map(len) },
            // SAFETY: forwarded with the caller's guarantees.
            None => unsafe { std::alloc::System.alloc_zeroed(layout) },
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        match Self::mapping_len(layout) {
            // SAFETY: `ptr` is the start of a mapping of `len` bytes made by `alloc` for
            // this layout (the caller's guarantee), no longer used.
            Some(len) => unsafe {
                libc::munmap(ptr as *mut libc::c_void, len);
            },
            // SAFETY: forwarded with the caller's guarantees.
            None => unsafe { std::alloc::System.dealloc(ptr, layout) },
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller guarantees that `new_size`, rounded up to `layout.align()`,
        // does not overflow `isize`.
        let new_layout =
            unsafe { std::alloc::Layout::from_size_align_unchecked(new_size, layout.align()) };
        match (Self::mapping_len(layout), Self::mapping_len(new_layout)) {
            // Both in the system allocator: its own realloc.
            // SAFETY: forwarded with the caller's guarantees.
            (None, None) => unsafe { std::alloc::System.realloc(ptr, layout, new_size) },
            // The same mapping still fits: nothing moves.
            (Some(old), Some(new)) if old == new => ptr,
            // Across allocators or mapping lengths: a new block, the common bytes copied.
            _ => {
                // SAFETY: `new_layout` is valid and non-zero-sized (the caller's guarantees).
                let moved = unsafe { self.alloc(new_layout) };
                if !moved.is_null() {
                    // SAFETY: both blocks hold at least the smaller size and are distinct;
                    // the old one is freed with the layout it was made with.
                    unsafe {
                        std::ptr::copy_nonoverlapping(ptr, moved, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                }
                moved
            }
        }
    }
}

// SAFETY: the system allocator's own functions.
#[cfg(not(target_os = "linux"))]
unsafe impl std::alloc::GlobalAlloc for HugePageAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { std::alloc::System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { std::alloc::System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { std::alloc::System.realloc(ptr, layout, new_size) }
    }
}

#[cfg(test)]
mod tests {
    use std::alloc::{GlobalAlloc, Layout};

    use super::{advise_huge_pages, HugePageAllocator};

    /// The byte at `i` of the test pattern.
    fn pattern(i: usize) -> u8 {
        (i.wrapping_mul(31) >> 3) as u8
    }

    /// Every block, small or large (either side of 2 MiB, alignments up to beyond 2 MiB),
    /// is aligned, zeroed where asked, writable over its whole size, and keeps its contents
    /// through `realloc` to a larger and a smaller size (across the 2 MiB threshold, within
    /// one mapping and between mappings); large blocks are 2 MiB-aligned mappings on Linux.
    #[test]
    fn the_allocator_keeps_every_block_aligned_zeroed_and_its_bytes() {
        let allocator = HugePageAllocator;
        let huge = 2 << 20;
        for size in [1, 4096, huge - 1, huge, huge + 1, 3 << 20, 5 << 20] {
            for align in [1, 8, 4096, huge, 2 * huge] {
                let layout = Layout::from_size_align(size, align).expect("layout");
                for zeroed in [false, true] {
                    // SAFETY: a non-zero-sized layout; the block is used within its size and
                    // freed (through realloc) with the layout it has at each point.
                    unsafe {
                        let ptr = if zeroed {
                            allocator.alloc_zeroed(layout)
                        } else {
                            allocator.alloc(layout)
                        };
                        assert!(!ptr.is_null(), "size {size} align {align}");
                        assert_eq!(ptr as usize % align, 0, "size {size} align {align}");
                        if cfg!(target_os = "linux") && size >= huge && align <= huge {
                            assert_eq!(ptr as usize % huge, 0, "size {size}");
                        }
                        let block = std::slice::from_raw_parts_mut(ptr, size);
                        if zeroed {
                            assert!(block.iter().all(|&b| b == 0), "size {size} align {align}");
                        }
                        block
                            .iter_mut()
                            .enumerate()
                            .for_each(|(i, b)| *b = pattern(i));
                        let mut ptr = ptr;
                        let mut layout = layout;
                        for new_size in [size + huge / 3, 2 * size + 1, size / 3 + 1, size] {
                            ptr = allocator.realloc(ptr, layout, new_size);
                            assert!(!ptr.is_null(), "{size} -> {new_size}");
                            assert_eq!(ptr as usize % align, 0, "{size} -> {new_size}");
                            let kept = layout.size().min(new_size);
                            let block = std::slice::from_raw_parts_mut(ptr, new_size);
                            assert!(
                                block[..kept]
                                    .iter()
                                    .enumerate()
                                    .all(|(i, &b)| b == pattern(i)),
                                "{size} -> {new_size}, align {align}"
                            );
                            block[kept..].iter_mut().enumerate().for_each(|(i, b)| {
                                *b = pattern(kept + i);
                            });
                            layout = Layout::from_size_align(new_size, align).expect("layout");
                        }
                        allocator.dealloc(ptr, layout);
                    }
                }
            }
        }
    }

    /// A `Vec` grown past 2 MiB a push at a time (realloc from the system allocator into a
    /// mapping, then from mapping to mapping) keeps its values.
    #[test]
    fn the_allocator_keeps_a_growing_vec() {
        let allocator = HugePageAllocator;
        let layout = |n: usize| Layout::array::<u32>(n).expect("layout");
        let (mut capacity, mut len) = (1024, 0);
        // SAFETY: the block is used within its capacity and freed with its layout.
        unsafe {
            let mut ptr = allocator.alloc(layout(capacity)) as *mut u32;
            while len < 3 << 20 {
                if len == capacity {
                    let grown = allocator.realloc(ptr as *mut u8, layout(capacity), 8 * capacity);
                    assert!(!grown.is_null());
                    ptr = grown as *mut u32;
                    capacity *= 2;
                }
                ptr.add(len).write(len as u32 ^ 0x5555);
                len += 1;
            }
            let values = std::slice::from_raw_parts(ptr, len);
            assert!(values
                .iter()
                .enumerate()
                .all(|(i, &v)| v == i as u32 ^ 0x5555));
            allocator.dealloc(ptr as *mut u8, layout(capacity));
        }
    }

    /// The contents are unchanged, whatever the slice's alignment and length (empty, shorter
    /// than a page, spanning huge pages), in fresh zeroed memory and in written memory.
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
        }
    }
}
