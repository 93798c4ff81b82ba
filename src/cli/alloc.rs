//! The command line's global allocator: mimalloc for everything but the few arrays of tens of
//! megabytes (the triangulation's tets, the output mesh), which go to the system allocator.
//!
//! Why: refinement grows its tet array step by step, and mimalloc moves a grown block by
//! copying, so for a moment the old and the new array are both resident (a third more than the
//! array itself at the peak of a big run). glibc serves such blocks with `mmap` and grows them
//! with `mremap`, which moves pages instead of copying them: no second copy, no copying time.
//! mimalloc keeps the small, short-lived allocations (cavities, crossing lists, queues) that it
//! serves in fewer instructions than glibc's malloc.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks at least this large go to the system allocator. glibc's dynamic mmap threshold never
/// exceeds 32 MiB on 64-bit systems, so these are always `mmap`ed there.
const LARGE: usize = 32 << 20;

pub struct LargeToSystem;

fn large(size: usize) -> bool {
    size >= LARGE
}

// SAFETY: every block is freed and resized by the allocator that made it: which one is decided
// by the block's size, which `dealloc` and `realloc` receive as it was at allocation (or at the
// last `realloc`), and a resize across the threshold moves the block to the other allocator.
unsafe impl GlobalAlloc for LargeToSystem {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract (non-zero size) is passed on unchanged.
        unsafe {
            if large(layout.size()) {
                System.alloc(layout)
            } else {
                mimalloc::MiMalloc.alloc(layout)
            }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as `alloc`.
        unsafe {
            if large(layout.size()) {
                System.alloc_zeroed(layout)
            } else {
                mimalloc::MiMalloc.alloc_zeroed(layout)
            }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated with `layout`'s size, hence by the allocator chosen here.
        unsafe {
            if large(layout.size()) {
                System.dealloc(ptr, layout)
            } else {
                mimalloc::MiMalloc.dealloc(ptr, layout)
            }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        match (large(layout.size()), large(new_size)) {
            // SAFETY: `ptr` belongs to the allocator chosen by its size, which keeps it.
            (true, true) => unsafe { System.realloc(ptr, layout, new_size) },
            // SAFETY: as above.
            (false, false) => unsafe { mimalloc::MiMalloc.realloc(ptr, layout, new_size) },
            _ => {
                // SAFETY: `realloc`'s contract makes `new_size` with `layout`'s alignment a
                // valid layout; the new block is allocated before the old one is read and freed.
                unsafe {
                    let new_layout = Layout::from_size_align_unchecked(new_size, layout.align());
                    let new = self.alloc(new_layout);
                    if !new.is_null() {
                        std::ptr::copy_nonoverlapping(ptr, new, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                    new
                }
            }
        }
    }
}
