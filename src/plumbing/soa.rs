//! Structure-of-arrays copies of 3-vectors for the hot loops.
//!
//! The state is stored as arrays of `Vec3` (x, y, z interleaved), which is what hosts read and
//! what the per-particle code wants. The spring pass touches every particle about six times per
//! step, and on interleaved data each vector load has to be shuffled into x, y and z registers;
//! that shuffling, not the arithmetic, bounded the pass. So the positions (and the rate the
//! spring damping acts on) are copied once per step into three plain arrays, one per component,
//! and the spring pass reads and writes those: one shuffle per particle instead of one per
//! spring end. (Tiled topologies, grids among them, copy into a window per tile walk instead:
//! [`crate::forces`]' `inputs` module.)

use crate::aligned::AlignedF64;
use crate::math::Vec3;
use crate::parallel;

/// Three component arrays of equal length, each starting on a cache line.
#[derive(Clone, Debug, Default)]
pub struct Soa3 {
    pub c: [AlignedF64; 3],
}

impl Soa3 {
    /// Sets the length of every component array (new entries are zero).
    pub fn resize(&mut self, n: usize) {
        for a in &mut self.c {
            a.resize(n);
        }
    }

    /// The three component arrays.
    pub fn slices(&self) -> [&[f64]; 3] {
        [&self.c[0], &self.c[1], &self.c[2]]
    }

    /// The three component arrays, mutable.
    pub fn slices_mut(&mut self) -> [&mut [f64]; 3] {
        let [a, b, c] = &mut self.c;
        [a, b, c]
    }

    /// Component-wise copy of `src` (resizing to its length), in parallel chunks when `par`.
    pub fn fill_from(&mut self, par: bool, src: &[Vec3]) {
        self.resize(src.len());
        parallel::chunks3(par, self.slices_mut(), parallel::CHUNK, |first, [x, y, z]| {
            for (k, v) in src[first..first + x.len()].iter().enumerate() {
                x[k] = v.x;
                y[k] = v.y;
                z[k] = v.z;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_from_copies_each_component() {
        for par in [false, true] {
            let n = 2 * parallel::CHUNK + 3;
            let src: Vec<Vec3> = (0..n)
                .map(|i| Vec3::new(i as f64, -(i as f64), 0.5 * i as f64))
                .collect();
            let mut s = Soa3::default();
            s.fill_from(par, &src);
            assert_eq!(s.slices()[0].len(), n);
            for (i, v) in src.iter().enumerate() {
                assert_eq!([s.c[0][i], s.c[1][i], s.c[2][i]], [v.x, v.y, v.z]);
            }
        }
    }
}
