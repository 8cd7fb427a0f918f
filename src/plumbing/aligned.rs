//! A growable array of f64 whose first number starts a cache line (64 bytes), so that the
//! vector loops over it (AVX-512: one cache line per load) never split a load or a store across
//! two lines. `Vec<f64>` only promises 8-byte alignment, and a large one from `malloc` starts
//! 16 bytes into a page: every 64-byte access then touches two lines.

use std::ops::{Deref, DerefMut};

/// One cache line of numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
struct Line([f64; 8]);

const PER_LINE: usize = 8;

/// `len` numbers in whole cache lines. Compares and prints as the slice of its `len` numbers.
#[derive(Default)]
pub struct AlignedF64 {
    lines: Vec<Line>,
    len: usize,
}

impl PartialEq for AlignedF64 {
    fn eq(&self, other: &Self) -> bool {
        self[..] == other[..]
    }
}

impl std::fmt::Debug for AlignedF64 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self[..].fmt(f)
    }
}

impl Clone for AlignedF64 {
    fn clone(&self) -> Self {
        Self {
            lines: self.lines.clone(),
            len: self.len,
        }
    }

    /// Reuses the allocation when it is large enough (as `Vec::clone_from` does).
    fn clone_from(&mut self, source: &Self) {
        self.lines.clone_from(&source.lines);
        self.len = source.len;
    }
}

impl AlignedF64 {
    /// `len` zeros.
    pub fn zeros(len: usize) -> Self {
        Self {
            lines: vec![Line::default(); len.div_ceil(PER_LINE)],
            len,
        }
    }

    /// Sets the length to `len`; new entries are zero.
    pub fn resize(&mut self, len: usize) {
        let old = self.len;
        self.lines.resize(len.div_ceil(PER_LINE), Line::default());
        self.len = len;
        if len > old {
            // Entries after the old length in its last line may hold stale numbers.
            self[old..].fill(0.0);
        }
    }
}

impl Deref for AlignedF64 {
    type Target = [f64];

    fn deref(&self) -> &[f64] {
        // SAFETY: `Line` is `repr(C)` around `[f64; 8]` with no padding (size 64 = 8 * 8), so
        // the lines are `8 * lines.len() >= len` contiguous, initialised f64s.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<f64>(), self.len) }
    }
}

impl DerefMut for AlignedF64 {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as in `deref`, and `&mut self` borrows the lines exclusively.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<f64>(), self.len) }
    }
}

/// A growable array of [`crate::Vec3`] whose first vector starts a cache line, as
/// [`AlignedF64`]: the state arrays the step streams (positions, velocities and their next
/// values) then sit at the same offset within a line wherever the allocator puts them, so the
/// step's speed does not depend on the heap's layout (a `Vec<Vec3>` from `malloc` starts 16
/// bytes into a line or a page, wherever the allocations before it left it).
#[derive(Default)]
pub struct AlignedVec3 {
    lines: Vec<Line>,
    len: usize,
}

/// Cache lines holding `len` vectors of three numbers.
fn lines_for(len: usize) -> usize {
    (3 * len).div_ceil(PER_LINE)
}

impl AlignedVec3 {
    /// A copy of `a`.
    pub fn from_slice(a: &[crate::Vec3]) -> Self {
        let mut out = Self {
            lines: vec![Line::default(); lines_for(a.len())],
            len: a.len(),
        };
        out.copy_from_slice(a);
        out
    }

    /// Sets the length to `len`; new entries are `value`.
    pub fn resize(&mut self, len: usize, value: crate::Vec3) {
        let old = self.len;
        self.lines.resize(lines_for(len), Line::default());
        self.len = len;
        if len > old {
            self[old..].fill(value);
        }
    }
}

impl Clone for AlignedVec3 {
    fn clone(&self) -> Self {
        Self {
            lines: self.lines.clone(),
            len: self.len,
        }
    }

    /// Reuses the allocation when it is large enough (as `Vec::clone_from` does).
    fn clone_from(&mut self, source: &Self) {
        self.lines.clone_from(&source.lines);
        self.len = source.len;
    }
}

impl PartialEq for AlignedVec3 {
    fn eq(&self, other: &Self) -> bool {
        self[..] == other[..]
    }
}

impl std::fmt::Debug for AlignedVec3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self[..].fmt(f)
    }
}

impl Deref for AlignedVec3 {
    type Target = [crate::Vec3];

    fn deref(&self) -> &[crate::Vec3] {
        // SAFETY: `Vec3` (nalgebra's `Matrix`, `repr(C)` over `[[f64; 3]; 1]`) is three f64s
        // with no padding and alignment 8; the lines are `8 * lines.len() >= 3 * len`
        // contiguous, initialised f64s starting at alignment 64, and any f64 bits are valid.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<crate::Vec3>(), self.len) }
    }
}

impl DerefMut for AlignedVec3 {
    fn deref_mut(&mut self) -> &mut [crate::Vec3] {
        // SAFETY: as in `deref`, and `&mut self` borrows the lines exclusively.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<crate::Vec3>(), self.len) }
    }
}

impl<'a> IntoIterator for &'a AlignedVec3 {
    type Item = &'a crate::Vec3;
    type IntoIter = std::slice::Iter<'a, crate::Vec3>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<'a> IntoIterator for &'a mut AlignedVec3 {
    type Item = &'a mut crate::Vec3;
    type IntoIter = std::slice::IterMut<'a, crate::Vec3>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter_mut()
    }
}

const _: () = assert!(std::mem::size_of::<crate::Vec3>() == 24 && std::mem::align_of::<crate::Vec3>() <= 64);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_on_a_cache_line_and_holds_its_length() {
        for len in [0, 1, 7, 8, 9, 1000, 123_457] {
            let mut a = AlignedF64::zeros(len);
            assert_eq!(a.len(), len);
            assert!(a.iter().all(|&x| x == 0.0));
            assert_eq!(a.as_ptr() as usize % 64, 0);
            if len > 0 {
                a[len - 1] = 2.5;
            }
            let b = a.clone();
            assert_eq!(b.as_ptr() as usize % 64, 0);
            assert_eq!(&b[..], &a[..]);
            let mut c = AlignedF64::zeros(3);
            c.clone_from(&a);
            assert_eq!(&c[..], &a[..]);
            assert_eq!(c.as_ptr() as usize % 64, 0);
        }
    }

    #[test]
    fn resizing_keeps_the_numbers_and_zeroes_new_ones() {
        let mut a = AlignedF64::zeros(13);
        a.iter_mut().enumerate().for_each(|(k, x)| *x = k as f64 + 1.0);
        a.resize(10);
        assert_eq!(a[9], 10.0);
        // Growing again within the same lines: the old numbers past 10 do not come back.
        a.resize(20);
        assert_eq!(a.len(), 20);
        assert_eq!(a[9], 10.0);
        assert!(a[10..].iter().all(|&x| x == 0.0));
        assert_eq!(a.as_ptr() as usize % 64, 0);
        // Equal as slices, whatever the unused end of the last line holds.
        let mut b = AlignedF64::zeros(20);
        b[..10].copy_from_slice(&a[..10]);
        let mut c = b.clone();
        c.resize(21);
        c[20] = 7.0;
        c.resize(20);
        assert_eq!(b, c);
        assert_eq!(format!("{b:?}"), format!("{:?}", &b[..]));
    }

    #[test]
    fn vectors_start_on_a_cache_line_and_resize_like_a_vec() {
        use crate::Vec3;
        let src: Vec<Vec3> = (0..11).map(|k| Vec3::new(k as f64, -(k as f64), 0.5)).collect();
        let mut a = AlignedVec3::from_slice(&src);
        assert_eq!(&a[..], &src[..]);
        assert_eq!(a.as_ptr() as usize % 64, 0);
        a.resize(4, Vec3::zeros());
        a.resize(7, Vec3::new(1.0, 2.0, 3.0));
        let mut want = src[..4].to_vec();
        want.resize(7, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(&a[..], &want[..]);
        let mut b = AlignedVec3::default();
        b.clone_from(&a);
        assert_eq!(b, a);
        assert_eq!(b.as_ptr() as usize % 64, 0);
        assert_eq!(format!("{b:?}"), format!("{:?}", &want[..]));
    }
}
