//! The limits every front end enforces, in the same words: the command line, the Python package
//! and the Dask driver refuse the same inputs the same way. Each check returns the reason as
//! text; the caller adds what it was checking (an option, an argument, a file).

/// Threads beyond this are a mistake, not a machine: each costs a stack and a chunk of layers.
pub const MAX_THREADS: usize = 1024;

/// Spacings, origins and affine entries must stay below this in magnitude: vertices are `f32`
/// (largest finite value about 3.4e38), and a coordinate times an index must stay finite.
pub const MAX_COORDINATE: f64 = 1e30;

/// What [`triple`] asks for, in words.
pub const THREE_COORDINATES: &str =
    "expected three finite numbers X,Y,Z (below 1e30: vertices are f32)";

/// A thread count, 0 meaning every core.
pub fn threads(n: u64) -> Result<usize, String> {
    match usize::try_from(n) {
        Ok(n) if n <= MAX_THREADS => Ok(n),
        _ => Err(too_many_threads(n)),
    }
}

/// Why `n` threads are refused, for a count of any size (Python's integers have no bound).
pub fn too_many_threads(n: impl std::fmt::Display) -> String {
    format!("at most {MAX_THREADS} threads (0 uses every core), not {n}")
}

/// Whether `v` can be a coordinate, a spacing or an origin component.
pub fn coordinate(v: f64) -> bool {
    v.is_finite() && v.abs() < MAX_COORDINATE
}

/// Three coordinates (a spacing or an origin), each finite and below [`MAX_COORDINATE`].
pub fn triple(v: [f64; 3]) -> Result<[f64; 3], String> {
    if v.iter().all(|&c| coordinate(c)) {
        Ok(v)
    } else {
        Err(THREE_COORDINATES.into())
    }
}

/// The bytes of `count` items of `item_bytes` each, refused when that is more than this process
/// may allocate ([`memory`]): the allocation would abort the process, not fail.
pub fn bytes(count: u128, item_bytes: usize, what: &str) -> Result<usize, String> {
    let total = count.checked_mul(item_bytes as u128);
    let limit = memory();
    match total {
        Some(total) if total <= limit as u128 => Ok(total as usize),
        _ => Err(format!(
            "{what} would need {} of memory, more than the {} this process may use",
            size(total),
            size(Some(limit as u128))
        )),
    }
}

/// The bytes of a grid of `dims` samples of `sample_bytes` each (see [`bytes`]).
pub fn grid(dims: [u64; 3], sample_bytes: usize, what: &str) -> Result<usize, String> {
    let count = dims.iter().fold(1u128, |n, &d| n.saturating_mul(d as u128));
    bytes(count, sample_bytes, what)
}

/// What this process may allocate at most: the machine's physical memory, or less where an
/// address-space or data limit (`ulimit -v`, `ulimit -d`) says so. Without a way to ask,
/// `isize::MAX`, the most a Rust allocation can be.
pub fn memory() -> usize {
    #[cfg(target_os = "linux")]
    {
        let physical = {
            // SAFETY: sysconf reads two constants of the running system; no memory is passed.
            let (pages, page) = unsafe {
                (
                    libc::sysconf(libc::_SC_PHYS_PAGES),
                    libc::sysconf(libc::_SC_PAGESIZE),
                )
            };
            match (u64::try_from(pages), u64::try_from(page)) {
                (Ok(pages), Ok(page)) if pages > 0 && page > 0 => pages.saturating_mul(page),
                _ => u64::MAX,
            }
        };
        let limit = |resource| {
            let mut r = libc::rlimit {
                rlim_cur: 0,
                rlim_max: 0,
            };
            // SAFETY: getrlimit writes one rlimit into `r`, which lives for the call.
            match unsafe { libc::getrlimit(resource, &mut r) } {
                0 if r.rlim_cur != libc::RLIM_INFINITY => r.rlim_cur,
                _ => u64::MAX,
            }
        };
        let least = physical
            .min(limit(libc::RLIMIT_AS))
            .min(limit(libc::RLIMIT_DATA));
        usize::try_from(least)
            .unwrap_or(usize::MAX)
            .min(isize::MAX as usize)
    }
    #[cfg(not(target_os = "linux"))]
    {
        isize::MAX as usize
    }
}

/// `bytes` in words, or "more than 2^128 bytes" when it did not fit in a number.
fn size(bytes: Option<u128>) -> String {
    let Some(bytes) = bytes else {
        return "more than 2^128 bytes".into();
    };
    let units = [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)];
    let b = bytes as f64;
    match units.iter().find(|(_, u)| b >= *u) {
        Some((name, u)) => format!("{:.1} {name}", b / u),
        None => format!("{bytes} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_counts_up_to_the_limit_pass_and_none_beyond() {
        assert_eq!(threads(0), Ok(0));
        assert_eq!(threads(MAX_THREADS as u64), Ok(MAX_THREADS));
        for n in [MAX_THREADS as u64 + 1, 1 << 31, u64::MAX] {
            let e = threads(n).unwrap_err();
            assert!(e.contains("at most 1024 threads"), "{e}");
            assert!(e.ends_with(&format!("not {n}")), "{e}");
        }
        let huge = too_many_threads("1267650600228229401496703205376");
        assert!(
            huge.ends_with("not 1267650600228229401496703205376"),
            "{huge}"
        );
    }

    #[test]
    fn coordinates_must_be_finite_and_below_1e30() {
        assert_eq!(triple([-1.5, 0.0, 2e3]), Ok([-1.5, 0.0, 2e3]));
        for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY, 1e30, -1e30, 1e308] {
            assert!(triple([1.0, bad, 1.0]).is_err(), "{bad}");
        }
    }

    /// Sizes beyond what `u128` holds, beyond the process's memory and within it.
    #[test]
    fn sizes_are_refused_beyond_this_process_s_memory() {
        let m = memory() as u128;
        assert!(m > 0);
        assert_eq!(bytes(m, 1, "x"), Ok(m as usize));
        let e = bytes(m + 1, 1, "a volume").unwrap_err();
        assert!(e.starts_with("a volume would need"), "{e}");
        let e = grid([u64::MAX; 3], 8, "a store").unwrap_err();
        assert!(e.contains("more than 2^128 bytes"), "{e}");
        let e = grid([1_000_000; 3], 2, "a store").unwrap_err();
        assert!(e.contains("would need 2000000.0 TB of memory"), "{e}");
        assert_eq!(grid([10, 20, 30], 4, "x"), Ok(24_000));
    }
}
