//! Growable arrays whose first element starts a cache line (64 bytes), so that the vector
//! loops over them (AVX-512: one cache line per load) never split a load or a store across two
//! lines more than the element size makes them. `Vec<f64>` only promises 8-byte alignment, and
//! a large one from `malloc` starts 16 bytes into a page: every 64-byte access then touches two
//! lines. [`AlignedF64`] holds numbers (the SOE modes, the component arrays, the tile walks'
//! windows); [`AlignedVec3`] holds vectors (the state the step streams: positions, velocities
//! and their next values), which then also sit at the same offset within a line wherever the
//! allocator puts them, so the step's speed does not depend on the heap's layout.

use std::ops::{Deref, DerefMut};

/// One cache line of numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
struct Line([f64; 8]);

const PER_LINE: usize = 8;

/// An element of an [`Aligned`] array: `F64S` f64s with no padding, of alignment at most 64,
/// every bit pattern of which is a valid value (all zeros being zero).
///
/// # Safety
/// An implementation promises exactly that layout: [`Aligned`] reads its cache lines of f64s
/// as elements.
pub unsafe trait Element: Copy {
    /// f64s in one element.
    const F64S: usize;
}

// SAFETY: an f64 is one f64.
unsafe impl Element for f64 {
    const F64S: usize = 1;
}

// SAFETY: `Vec3` (nalgebra's `Matrix`, `repr(C)` over `[[f64; 3]; 1]`) is three f64s with no
// padding and alignment 8 (checked below); any three f64s are a vector.
unsafe impl Element for crate::Vec3 {
    const F64S: usize = 3;
}

const _: () = assert!(std::mem::size_of::<crate::Vec3>() == 24 && std::mem::align_of::<crate::Vec3>() == 8);

/// `len` elements in whole cache lines, starting on one. Compares and prints as the slice of
/// its `len` elements.
pub struct Aligned<T: Element> {
    lines: Vec<Line>,
    len: usize,
    _element: std::marker::PhantomData<T>,
}

/// Numbers on cache lines.
pub type AlignedF64 = Aligned<f64>;

/// Vectors on cache lines.
pub type AlignedVec3 = Aligned<crate::Vec3>;

/// Cache lines holding `len` elements of `f64s` numbers each.
fn lines_for(len: usize, f64s: usize) -> usize {
    (f64s * len).div_ceil(PER_LINE)
}

impl<T: Element> Default for Aligned<T> {
    fn default() -> Self {
        Self {
            lines: Vec::new(),
            len: 0,
            _element: std::marker::PhantomData,
        }
    }
}

impl<T: Element + PartialEq> PartialEq for Aligned<T> {
    fn eq(&self, other: &Self) -> bool {
        self[..] == other[..]
    }
}

impl<T: Element + std::fmt::Debug> std::fmt::Debug for Aligned<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self[..].fmt(f)
    }
}

impl<T: Element> Clone for Aligned<T> {
    fn clone(&self) -> Self {
        Self {
            lines: self.lines.clone(),
            len: self.len,
            _element: std::marker::PhantomData,
        }
    }

    /// Reuses the allocation when it is large enough (as `Vec::clone_from` does).
    fn clone_from(&mut self, source: &Self) {
        self.lines.clone_from(&source.lines);
        self.len = source.len;
    }
}

impl<T: Element> Aligned<T> {
    /// `len` zeros.
    pub fn zeros(len: usize) -> Self {
        Self {
            lines: vec![Line::default(); lines_for(len, T::F64S)],
            len,
            _element: std::marker::PhantomData,
        }
    }

    /// A copy of `a`.
    pub fn from_slice(a: &[T]) -> Self {
        let mut out = Self::zeros(a.len());
        out.copy_from_slice(a);
        out
    }

    /// Sets the length to `len`; new entries are zero.
    pub fn resize(&mut self, len: usize) {
        let old = self.len;
        self.lines.resize(lines_for(len, T::F64S), Line::default());
        self.len = len;
        if len > old {
            // Numbers after the old length in its last line may hold stale values.
            let numbers = self.lines.iter_mut().flat_map(|line| line.0.iter_mut());
            for x in numbers.skip(old * T::F64S).take((len - old) * T::F64S) {
                *x = 0.0;
            }
        }
    }
}

impl<T: Element> Deref for Aligned<T> {
    type Target = [T];

    fn deref(&self) -> &[T] {
        // SAFETY: `Line` is `repr(C)` around `[f64; 8]` with no padding (size 64 = 8 * 8), so
        // the lines are `8 * lines.len() >= F64S * len` contiguous, initialised f64s starting
        // at alignment 64; `T: Element` is `F64S` f64s with no padding, alignment at most 64,
        // valid for any bits.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<T>(), self.len) }
    }
}

impl<T: Element> DerefMut for Aligned<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as in `deref`, and `&mut self` borrows the lines exclusively.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<T>(), self.len) }
    }
}

impl<'a, T: Element> IntoIterator for &'a Aligned<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<'a, T: Element> IntoIterator for &'a mut Aligned<T> {
    type Item = &'a mut T;
    type IntoIter = std::slice::IterMut<'a, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter_mut()
    }
}

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
        a.resize(4);
        a.resize(7);
        let mut want = src[..4].to_vec();
        want.resize(7, Vec3::zeros());
        assert_eq!(&a[..], &want[..]);
        let mut b = AlignedVec3::default();
        b.clone_from(&a);
        assert_eq!(b, a);
        assert_eq!(b.as_ptr() as usize % 64, 0);
        assert_eq!(format!("{b:?}"), format!("{:?}", &want[..]));
    }
}
