//! Asking for memory before a pass reads it, for the passes that would otherwise wait on it: the
//! classification of each slice (the sweep's slice ahead) and the survey's scattered rows.
//! A prefetch is only a hint: it reads nothing the program sees and changes no result.

use core::ops::Range;

/// Bytes per cache line, the step between prefetches.
pub(crate) const LINE: usize = 64;

/// Asks for the line holding `p` to be brought into L2 (`_MM_HINT_T1`: the data is read a pass
/// or some rows later, and L1 could not hold a slice). Elsewhere than on x86-64, nothing.
#[inline(always)]
pub(crate) fn line(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_MM_HINT_T1, _mm_prefetch};
        // SAFETY: a prefetch does not access memory in the language's sense: it cannot fault,
        // and reads nothing the program sees, whatever the address.
        unsafe { _mm_prefetch::<_MM_HINT_T1>(p.cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// [`line`] for every line of the bytes `bytes` from `start`.
#[inline(always)]
pub(crate) fn lines(start: *const u8, bytes: Range<usize>) {
    for offset in bytes.step_by(LINE) {
        line(start.wrapping_add(offset));
    }
}

/// [`lines`] for all of `data`.
#[cfg(feature = "alloc")]
#[inline(always)]
pub(crate) fn all<T>(data: &[T]) {
    lines(data.as_ptr().cast(), 0..size_of_val(data));
}
