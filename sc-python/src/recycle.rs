//! The extension's allocator: large blocks that NumPy frees are kept for the next call.
//!
//! A mesh's arrays are handed to NumPy without a copy, so NumPy frees them when the user drops
//! them, through this crate's global allocator. Blocks of tens of megabytes are mapped fresh by
//! glibc for every call and unmapped on free, and the kernel zeroes each page again when the next
//! call first writes it, a sixth of a large mesh's call (docs/speed-log.md has the figures). So
//! blocks of [`LARGE`] bytes and more that are freed here wait in a small cache, up to [`CAP`]
//! bytes, and the next allocation they fit takes one instead of asking for fresh pages; so does a
//! vector that grows into one (a label atlas's arrays grow as the sweep goes), with its contents
//! copied.
//! [`release`] (`skelclimb.release_memory()`) gives them back at once.
//!
//! Every block comes from C's `malloc`, whose `free` and `realloc` need no size: a cached block
//! handed out for a smaller request is freed or resized correctly whatever layout it is later
//! given. Alignments above `malloc`'s go to [`System`], uncached.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;

/// Blocks from this size up are cached; smaller ones glibc keeps in its heap and reuses itself.
const LARGE: usize = 4 << 20;
/// The most bytes the cache holds: the arrays of a mesh of about ten million triangles.
const CAP: usize = 256 << 20;
/// The most blocks it holds: a mesh has four arrays, a call's scratch two more.
const SLOTS: usize = 8;
/// The alignment `malloc` guarantees: twice a pointer's size (16 bytes on 64-bit platforms), as
/// `System` assumes too.
const MALLOC_ALIGN: usize = 2 * core::mem::size_of::<usize>();

/// Freed blocks, as `(address, size)`; a size of 0 marks an empty slot. Allocations only try
/// the lock and go to `malloc` and `free` when another thread holds it: they never wait, not even
/// in a child forked while a thread of its parent held it.
static CACHE: Mutex<[(usize, usize); SLOTS]> = Mutex::new([(0, 0); SLOTS]);

/// The global allocator: C's `malloc`, with the cache of large freed blocks in front.
pub struct Recycling;

// SAFETY: every block comes from `malloc` (or, over-aligned, from `System`, which also frees it),
// and a cached block is handed out once, for a request no larger than it.
unsafe impl GlobalAlloc for Recycling {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.align() > MALLOC_ALIGN {
            // SAFETY: the caller's layout, passed on.
            return unsafe { System.alloc(layout) };
        }
        if layout.size() >= LARGE
            && let Some(block) = take(layout.size())
        {
            return block;
        }
        // SAFETY: `malloc` has no preconditions; a null result is passed on as the failure.
        unsafe { libc::malloc(layout.size()).cast() }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.align() > MALLOC_ALIGN {
            // SAFETY: the caller's layout, passed on.
            return unsafe { System.alloc_zeroed(layout) };
        }
        // Not from the cache: `calloc` gets fresh pages zeroed by the kernel as they are touched,
        // and a buffer the sweep only partly touches (its scratch) would pay for zeroing it all.
        // SAFETY: `calloc` has no preconditions.
        unsafe { libc::calloc(layout.size(), 1).cast() }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if layout.align() > MALLOC_ALIGN {
            // SAFETY: an over-aligned block came from `System` with this layout.
            return unsafe { System.dealloc(ptr, layout) };
        }
        if layout.size() >= LARGE && keep(ptr, layout.size()) {
            return;
        }
        // SAFETY: the block came from `malloc` or `calloc` and is freed once.
        unsafe { libc::free(ptr.cast()) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if layout.align() > MALLOC_ALIGN {
            // SAFETY: the caller's block and layout, passed on.
            return unsafe { System.realloc(ptr, layout, new_size) };
        }
        // A vector growing into a large block takes a cached one if one fits: copying what it
        // holds costs less than the fresh pages `realloc` would map, which the kernel zeroes as
        // the vector first writes them.
        if new_size >= LARGE
            && new_size > layout.size()
            && let Some(block) = take(new_size)
        {
            // SAFETY: `ptr` holds `layout.size()` bytes, the cached block at least `new_size`,
            // which is more, and they are different blocks; the old one is then freed once, with
            // the layout it was allocated with.
            unsafe {
                core::ptr::copy_nonoverlapping(ptr, block, layout.size());
                self.dealloc(ptr, layout);
            }
            return block;
        }
        // SAFETY: the block came from `malloc` or `calloc`; `realloc` knows its true size.
        unsafe { libc::realloc(ptr.cast(), new_size).cast() }
    }
}

/// A cached block of at least `size` bytes and at most twice that, the smallest there is: a
/// block much larger than the request would be held by an array that needs little of it.
fn take(size: usize) -> Option<*mut u8> {
    let mut cache = CACHE.try_lock().ok()?;
    let slot = cache
        .iter_mut()
        .filter(|(_, held)| *held >= size && *held / 2 <= size)
        .min_by_key(|(_, held)| *held)?;
    let (address, _) = core::mem::take(slot);
    Some(address as *mut u8)
}

/// Puts a freed block in the cache if it has room; false if it has not.
fn keep(ptr: *mut u8, size: usize) -> bool {
    let Ok(mut cache) = CACHE.try_lock() else {
        return false;
    };
    let held: usize = cache.iter().map(|&(_, held)| held).sum();
    if held + size > CAP {
        return false;
    }
    match cache.iter_mut().find(|(_, held)| *held == 0) {
        Some(slot) => {
            *slot = (ptr as usize, size);
            true
        }
        None => false,
    }
}

/// Frees every cached block; returns how many bytes they held.
pub fn release() -> usize {
    let Ok(mut cache) = CACHE.lock() else {
        return 0;
    };
    let mut freed = 0;
    for slot in cache.iter_mut() {
        let (address, held) = core::mem::take(slot);
        if held > 0 {
            // SAFETY: a cached block came from `malloc` and left every other owner when it was
            // cached; emptying its slot makes this the only free.
            unsafe { libc::free(address as *mut libc::c_void) };
            freed += held;
        }
    }
    freed
}
