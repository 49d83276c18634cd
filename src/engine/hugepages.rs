//! The allocator of the `demx` binary: the system's, asking the kernel to
//! back every large allocation with 2 MB pages (Linux transparent huge
//! pages, `madvise(MADV_HUGEPAGE)`; most distributions enable them only on
//! request).
//!
//! On a bed of 10^6 spheres the pair pass reads each partner's state where
//! its id puts it, scattered over tens of MB: with 4 kB pages, most of those
//! reads also miss the TLB and wait for a page walk. A hint only: where the
//! kernel has no huge pages to give, nothing changes, and no result does.

use std::alloc::{GlobalAlloc, Layout, System};

/// Allocations from this size up are advised (smaller ones fit a few
/// pages, which the TLB holds anyway).
const ADVISE_FROM: usize = 4 << 20;
/// The huge page size of x86-64 and of most arm64 kernels.
const HUGE: usize = 2 << 20;

/// The system allocator, advising huge pages for allocations of
/// [`ADVISE_FROM`] bytes or more.
pub struct HugePages;

/// Advise the whole 2 MB pages inside `len` bytes at `p`.
fn advise(p: *mut u8, len: usize) {
    #[cfg(target_os = "linux")]
    {
        let (start, end) = (((p as usize) + HUGE - 1) & !(HUGE - 1), (p as usize + len) & !(HUGE - 1));
        if !p.is_null() && end > start {
            // SAFETY: the range lies inside an allocation this process owns;
            // the advice changes how it is backed, never its contents
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (p, len);
}

// SAFETY: every call is the system allocator's; the advice only follows it
unsafe impl GlobalAlloc for HugePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if layout.size() >= ADVISE_FROM {
            advise(p, layout.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if layout.size() >= ADVISE_FROM {
            advise(p, layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        unsafe { System.dealloc(p, layout) }
    }
    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, layout, new_size) };
        if new_size >= ADVISE_FROM {
            advise(q, new_size);
        }
        q
    }
}
