//! The spring pass's inputs for a tile walk ([`super::tiles`]): the positions and the rate the
//! damping acts on, as component arrays, for the particles around the walk's current tile only.
//!
//! The spring kernel reads each particle about sixteen times per step (two ends of eight runs on
//! a grid), so it wants them as plain component arrays ([`crate::soa`]). Copying a whole step's
//! positions and rates into cloth-sized component arrays in a pass of their own, and reading them
//! back in the tile walk, streams 48 bytes per particle out to memory and back on a cloth larger
//! than the cache. Instead, each walk transposes the step's `Vec3` arrays into a window of its own
//! just ahead of the springs that read them: the window stays in cache, and the `Vec3` rows it
//! reads are the ones the walk's drag and integrator read a moment later.

use super::springs::Params;
use crate::Vec3;

/// A window of component arrays over particles `[origin, origin + cap)`, filled up to `filled`.
pub(super) struct InputWindow<'a> {
    x: &'a [Vec3],
    /// The damping rate, or None for undamped springs (then only positions are kept).
    q: Option<&'a [Vec3]>,
    /// Six component arrays of `cap` numbers each: x, y, z of the positions, then of the rate.
    buf: &'a mut [f64],
    cap: usize,
    origin: usize,
    filled: usize,
}

impl<'a> InputWindow<'a> {
    /// Numbers of scratch a window of `cap` particles needs.
    pub fn scratch(cap: usize) -> usize {
        6 * cap
    }

    /// An empty window at particle `start`; `buf` holds [`Self::scratch`] numbers.
    pub fn new(x: &'a [Vec3], q: Option<&'a [Vec3]>, buf: &'a mut [f64], start: usize) -> Self {
        let cap = buf.len() / 6;
        Self {
            x,
            q,
            buf,
            cap,
            origin: start,
            filled: start,
        }
    }

    /// Makes particles `[keep, upto)` (`upto` clamped to the cloth) available, dropping those
    /// before `keep` when the window has to slide. `keep` never decreases between calls, and
    /// `upto - keep` is at most the window's capacity.
    pub fn cover(&mut self, keep: usize, upto: usize) {
        let upto = upto.min(self.x.len());
        debug_assert!(keep >= self.origin && upto - keep.min(upto) <= self.cap);
        if upto <= self.filled {
            return;
        }
        let cap = self.cap;
        if upto - self.origin > cap {
            // Slide: keep [keep, filled) at the front.
            let (from, to) = (keep - self.origin, self.filled.max(keep) - self.origin);
            let comps = if self.q.is_some() { 6 } else { 3 };
            for c in 0..comps {
                self.buf[c * cap..(c + 1) * cap].copy_within(from..to, 0);
            }
            self.origin = keep;
            self.filled = self.filled.max(keep);
        }
        let (a, b) = (self.filled - self.origin, upto - self.origin);
        let (px, rest) = self.buf.split_at_mut(cap);
        let (py, rest) = rest.split_at_mut(cap);
        let (pz, rest) = rest.split_at_mut(cap);
        transpose_widest(
            &self.x[self.filled..upto],
            [&mut px[a..b], &mut py[a..b], &mut pz[a..b]],
        );
        if let Some(q) = self.q {
            let (qx, rest) = rest.split_at_mut(cap);
            let (qy, qz) = rest.split_at_mut(cap);
            transpose_widest(
                &q[self.filled..upto],
                [&mut qx[a..b], &mut qy[a..b], &mut qz[a..b]],
            );
        }
        self.filled = upto;
    }

    /// `p` reading its positions and rate from this window.
    pub fn params<'b>(&'b self, p: &Params<'b>) -> Params<'b> {
        let cap = self.cap;
        let comp = |c: usize| &self.buf[c * cap..(c + 1) * cap];
        let x = [comp(0), comp(1), comp(2)];
        Params {
            x,
            q: if self.q.is_some() {
                [comp(3), comp(4), comp(5)]
            } else {
                x
            },
            base: self.origin,
            ..*p
        }
    }
}

crate::simd_dispatch! { fn transpose_widest(src: &[Vec3], out: [&mut [f64]; 3]) => transpose }

/// `out[c][k] = src[k][c]`.
#[inline(always)]
fn transpose(src: &[Vec3], out: [&mut [f64]; 3]) {
    let [ox, oy, oz] = out;
    let n = src.len();
    let (ox, oy, oz) = (&mut ox[..n], &mut oy[..n], &mut oz[..n]);
    for (k, v) in src.iter().enumerate() {
        (ox[k], oy[k], oz[k]) = (v.x, v.y, v.z);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_holds_what_it_covers_across_slides() {
        let n = 1000;
        let x: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(i as f64, 2.0 * i as f64, -(i as f64)))
            .collect();
        let q: Vec<Vec3> = (0..n).map(|i| Vec3::new(0.5 * i as f64, 7.0, i as f64)).collect();
        for with_q in [false, true] {
            let mut buf = vec![f64::NAN; InputWindow::scratch(100)];
            let mut w = InputWindow::new(&x, with_q.then_some(&q[..]), &mut buf, 30);
            // Steps of 23 keeping the last 40: slides many times, ends clamped at n.
            let mut keep = 30;
            while keep < n {
                let upto = keep + 60;
                w.cover(keep, upto);
                let p = Params {
                    stiffness: [0.0; 3],
                    kd: 0.0,
                    x: [&[]; 3],
                    q: [&[]; 3],
                    base: 0,
                    rest: &[],
                    kinds: &[],
                };
                let p = w.params(&p);
                for i in keep..upto.min(n) {
                    let at = i - p.base;
                    assert_eq!([p.x[0][at], p.x[1][at], p.x[2][at]], [x[i].x, x[i].y, x[i].z]);
                    let r = if with_q { q[i] } else { x[i] };
                    assert_eq!([p.q[0][at], p.q[1][at], p.q[2][at]], [r.x, r.y, r.z]);
                }
                keep += 23;
            }
        }
    }
}
