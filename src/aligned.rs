//! Arrays the step kernels stream: each starts on a cache line (64 bytes), and a large one
//! asks Linux for transparent huge pages.
//!
//! With `Vec`, where an array starts within its cache line depends on the allocator's history:
//! glibc takes large arrays from the heap once a large block has been freed, at whatever
//! 16-byte offset is free. At an offset of 16 or 48 bytes, half of the kernels' 32-byte AVX
//! loads and stores straddle two cache lines, and which arrays are hit changes with any change
//! in what the program allocated before. On a cache line every vector access stays in one
//! line and the layout no longer depends on that history.
//!
//! The kernels gather neighbours from arrays of 10–100 MB at 10^6 particles, more than the
//! TLB covers with 4 KiB pages. Where the kernel's huge-page mode is `madvise` (the default of
//! many distributions), an array only gets 2 MiB pages if it asks, so [`filled`], [`copied`]
//! and [`CollectAligned::collect_aligned`] advise `MADV_HUGEPAGE` for the 2 MiB-aligned part of
//! any array of at least 2 MiB before they first touch it (benchmarks/RESULTS.md, "Aligned
//! arrays and huge pages"). It is a hint: where it is refused, nothing changes but speed. The
//! contents and every result are the same as with `Vec`.

/// A growable array whose first element is on a 64-byte boundary; it dereferences to a slice.
/// A clone is aligned too but not advised for huge pages: build the kernels' arrays with the
/// functions below.
pub type Aligned<T> = aligned_vec::AVec<T, aligned_vec::ConstAlign<64>>;

/// Huge-page size on x86-64 Linux; smaller arrays are not advised.
#[cfg(target_os = "linux")]
const HUGE: usize = 2 << 20;

/// Room for n elements, not yet touched, advised for huge pages where it is large enough.
fn with_capacity<T>(n: usize) -> Aligned<T> {
    let v = Aligned::with_capacity(64, n);
    advise_huge_pages(v.as_ptr() as usize, n * std::mem::size_of::<T>());
    v
}

/// `MADV_HUGEPAGE` for the whole 2 MiB pages inside [start, start + bytes).
#[cfg(target_os = "linux")]
fn advise_huge_pages(start: usize, bytes: usize) {
    let first = start.next_multiple_of(HUGE);
    let end = (start + bytes) / HUGE * HUGE;
    if end > first {
        // SAFETY: the range lies inside one live allocation of ours; MADV_HUGEPAGE changes
        // only how the kernel backs it, never its contents. A refusal (THP off) is harmless.
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages(_start: usize, _bytes: usize) {}

/// n copies of `value`.
pub fn filled<T: Clone>(value: T, n: usize) -> Aligned<T> {
    let mut v = with_capacity(n);
    v.resize(n, value);
    v
}

/// A copy of a slice.
pub fn copied<T: Clone>(s: &[T]) -> Aligned<T> {
    let mut v = with_capacity(s.len());
    v.extend_from_slice(s);
    v
}

/// `collect` into an [`Aligned`] array.
pub trait CollectAligned: Iterator + Sized {
    fn collect_aligned(self) -> Aligned<Self::Item> {
        let mut v = with_capacity(self.size_hint().0);
        for x in self {
            v.push(x);
        }
        v
    }
}

impl<I: Iterator> CollectAligned for I {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_constructor_starts_on_a_cache_line() {
        // the last two are advised for huge pages
        for n in [1, 3, 1000, 100_003, 300_001, 1 << 20] {
            let a = filled(0.5f64, n);
            let b = copied(&a);
            let c = (0..n as u32).map(|i| [i; 6]).collect_aligned();
            assert_eq!(a.as_ptr() as usize % 64, 0);
            assert_eq!(b.as_ptr() as usize % 64, 0);
            assert_eq!(c.as_ptr() as usize % 64, 0);
            assert_eq!((a.len(), b.len(), c.len()), (n, n, n));
            assert!(b.iter().all(|&v| v == 0.5));
            assert_eq!(c[n - 1], [n as u32 - 1; 6]);
        }
    }
}
