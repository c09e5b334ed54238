//! A raw pointer that parallel tasks share to write disjoint parts of one buffer.
//!
//! The transfers partition particles into contiguous ranges and grid nodes into blocks of
//! which no two tasks running at the same time touch the same element; this wrapper lets
//! rayon tasks hold the buffer without locks or atomics. Every use states why its ranges are
//! disjoint.

/// Shared pointer to the start of a buffer of `T`.
#[derive(Clone, Copy)]
pub(crate) struct SyncPtr<T>(*mut T);

// SAFETY: the pointer is only dereferenced through `slice_mut`, whose callers
// guarantee that concurrent accesses are disjoint.
unsafe impl<T: Send> Send for SyncPtr<T> {}
unsafe impl<T: Send> Sync for SyncPtr<T> {}

impl<T> SyncPtr<T> {
    pub fn new(ptr: *mut T) -> Self {
        Self(ptr)
    }

    /// # Safety
    /// `start + len` must lie within the buffer and no other live reference may overlap
    /// `start..start + len`.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn slice_mut(&self, start: usize, len: usize) -> &mut [T] {
        std::slice::from_raw_parts_mut(self.0.add(start), len)
    }
}
