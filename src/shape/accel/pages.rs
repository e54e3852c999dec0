//! The BVH's large read-only arrays (nodes, leaf packets, lane records) in memory that Linux may
//! back with 2 MiB pages: an array of at least 2 MiB is copied, once built, into an allocation
//! aligned to 2 MiB and marked `MADV_HUGEPAGE` (the hint transparent huge pages need in their
//! default `madvise` mode). A traversal step touches a node, a packet and lane records scattered
//! over megabytes; with 4 KiB pages most of those accesses also miss the TLB (the statue's 17.5 MB
//! span 4,300 pages against Zen 4's 3,072 second-level TLB entries), with 2 MiB pages ten entries
//! cover them. Measured on the statue (`bench_traversal --groups`, five interleaved runs): closest
//! rays from the mesh +6 to +8 % (medians), the render −2 %.
//!
//! Smaller arrays, other systems, a refused allocation and `SNEE_HUGE_PAGES=off` keep the `Vec`.
//! The contents and so every query's result are the same either way.

use std::alloc::Layout;
use std::ops::Deref;
use std::ptr::NonNull;

/// Page size of the hint, and the smallest array that gets its own allocation.
const HUGE: usize = 2 << 20;

/// A read-only array: in its `Vec`, or copied into a 2 MiB-aligned allocation with the huge-page hint.
pub struct Pages<T: Copy> {
    ptr: NonNull<T>,
    len: usize,
    owner: Owner<T>,
}

enum Owner<T> {
    /// The elements are the `Vec`'s (`ptr` points at its buffer, which does not move with it).
    Vec(#[allow(dead_code)] Vec<T>),
    /// The elements are in an allocation of this layout at `ptr`.
    Alloc(Layout),
}

// SAFETY: `Pages` owns its elements like a `Vec` and hands out only shared references to them.
unsafe impl<T: Copy + Send> Send for Pages<T> {}
// SAFETY: as above; no interior mutability.
unsafe impl<T: Copy + Sync> Sync for Pages<T> {}

impl<T: Copy> Pages<T> {
    /// `v` as it is (small, not Linux, or `SNEE_HUGE_PAGES=off`), or copied into huge-page memory.
    pub fn new(v: Vec<T>) -> Pages<T> {
        let bytes = std::mem::size_of_val(v.as_slice());
        if bytes >= HUGE && cfg!(target_os = "linux") && std::env::var("SNEE_HUGE_PAGES").as_deref() != Ok("off") {
            if let Some(p) = Self::huge_copy(&v) {
                return p;
            }
        }
        Self::keep(v)
    }

    /// The array in its `Vec`.
    fn keep(mut v: Vec<T>) -> Pages<T> {
        // A `Vec`'s pointer is never null (dangling but aligned when empty).
        let ptr = NonNull::new(v.as_mut_ptr()).expect("a Vec's pointer is never null");
        Pages { ptr, len: v.len(), owner: Owner::Vec(v) }
    }

    /// Whether the elements are in huge-page memory.
    pub fn is_huge(&self) -> bool {
        matches!(self.owner, Owner::Alloc(_))
    }

    fn huge_copy(v: &[T]) -> Option<Pages<T>> {
        let bytes = std::mem::size_of_val(v);
        let layout = Layout::from_size_align(bytes.div_ceil(HUGE) * HUGE, HUGE.max(std::mem::align_of::<T>())).ok()?;
        // SAFETY: the layout has a non-zero size (at least `HUGE`).
        let raw = unsafe { std::alloc::alloc(layout) };
        let ptr = NonNull::new(raw)?;
        advise_huge(raw, layout.size());
        // SAFETY: `raw` holds `layout.size() ≥ bytes` bytes, is aligned for `T` and does not overlap
        // `v`; `T: Copy`, so a byte copy makes valid elements.
        unsafe { std::ptr::copy_nonoverlapping(v.as_ptr().cast::<u8>(), raw, bytes) };
        Some(Pages { ptr: ptr.cast(), len: v.len(), owner: Owner::Alloc(layout) })
    }
}

/// `madvise(MADV_HUGEPAGE)` on the range (before its first touch, so that its page faults can map
/// 2 MiB pages); a refusal only leaves 4 KiB pages.
#[cfg(target_os = "linux")]
fn advise_huge(addr: *mut u8, len: usize) {
    extern "C" {
        fn madvise(addr: *mut std::ffi::c_void, len: usize, advice: i32) -> i32;
    }
    const MADV_HUGEPAGE: i32 = 14;
    // SAFETY: the range is one live allocation of `len` bytes; the hint changes no contents.
    let _ = unsafe { madvise(addr.cast(), len, MADV_HUGEPAGE) };
}

#[cfg(not(target_os = "linux"))]
fn advise_huge(_addr: *mut u8, _len: usize) {}

impl<T: Copy> Deref for Pages<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        // SAFETY: `ptr` points at `len` initialised elements owned by `self` (the `Vec`'s buffer or
        // the copy).
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr(), self.len) }
    }
}

impl<'a, T: Copy> IntoIterator for &'a Pages<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<T: Copy> Drop for Pages<T> {
    fn drop(&mut self) {
        if let Owner::Alloc(layout) = self.owner {
            // SAFETY: allocated in `huge_copy` with this layout; `T: Copy` needs no drop.
            unsafe { std::alloc::dealloc(self.ptr.as_ptr().cast(), layout) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small arrays stay in their `Vec`; a large one is copied whole (same elements) into 2 MiB
    /// aligned memory, and dropping it frees that.
    #[test]
    fn large_arrays_move_to_aligned_memory_with_the_same_contents() {
        let small: Vec<u64> = (0..1000).collect();
        let p = Pages::new(small.clone());
        assert!(!p.is_huge());
        assert_eq!(&*p, small.as_slice());
        let large: Vec<[f32; 7]> = (0..200_000).map(|i| [i as f32; 7]).collect();
        let p = Pages::new(large.clone());
        assert_eq!(p.is_huge(), cfg!(target_os = "linux") && std::env::var("SNEE_HUGE_PAGES").as_deref() != Ok("off"));
        if p.is_huge() {
            assert_eq!(p.as_ptr() as usize % HUGE, 0);
        }
        assert_eq!(&*p, large.as_slice());
        assert_eq!(p.iter().count(), large.len());
        let empty: Pages<u8> = Pages::new(Vec::new());
        assert!(empty.is_empty());
    }
}
