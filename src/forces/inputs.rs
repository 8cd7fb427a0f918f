//! What a tile walk ([`super::tiles`]) reads of the particles, as component arrays, for the
//! particles around the walk's current tile only: positions and the rate the spring damping
//! acts on (for the springs), and the velocities and half-derivatives a tile's drag and
//! integrator read (for the force pass's tiles, [`super::for_each_tile`]).
//!
//! The spring kernel reads each particle about sixteen times per step (two ends of eight runs on
//! a grid), and the drag and integrator loops are several times faster on component arrays than
//! on `Vec3`s, which they would have to shuffle apart. Copying a whole step's positions and rates
//! into cloth-sized component arrays in a pass of their own, and reading them back in the tile
//! walk, would stream 48 bytes per particle out to memory and back on a cloth larger than the
//! cache. Instead, each walk transposes the step's `Vec3` arrays into a window of its own just
//! ahead of the springs that read them: the window stays in cache.

use super::springs::{Params, SpringRate};
use crate::math::Vec3;

/// The step's arrays a window copies from: positions always, velocities and half-derivatives
/// when some reader needs them (all of one length), from particle `base` on.
#[derive(Clone, Copy)]
pub(super) struct Sources<'a> {
    pub x: &'a [Vec3],
    pub v: Option<&'a [Vec3]>,
    pub half: Option<&'a [Vec3]>,
    /// What the spring damping acts on: the velocities, the half-derivatives, or nothing.
    pub rate: SpringRate,
    /// The particle the slices start at (0: the whole arrays).
    pub base: usize,
}

/// Component arrays of a tile's particles: positions, and velocities and half-derivatives
/// when the window keeps them.
pub(super) struct TileState<'b> {
    pub x: [&'b [f64]; 3],
    pub v: Option<[&'b [f64]; 3]>,
    pub half: Option<[&'b [f64]; 3]>,
}

/// A window of component arrays over particles `[origin, origin + cap)`, filled up to `filled`.
pub(super) struct InputWindow<'a> {
    /// Positions, velocities, half-derivatives: groups 0, 1, 2 of `buf`; from particle
    /// `base` on.
    sources: [Option<&'a [Vec3]>; 3],
    base: usize,
    rate: SpringRate,
    /// Three groups of three component arrays of `cap` numbers each (x, y, z per group); a
    /// group without a source is not written.
    buf: &'a mut [f64],
    cap: usize,
    origin: usize,
    filled: usize,
}

impl<'a> InputWindow<'a> {
    /// Numbers of scratch a window of `cap` particles needs.
    pub fn scratch(cap: usize) -> usize {
        9 * cap
    }

    /// An empty window at particle `start`; `buf` holds [`Self::scratch`] numbers. The rate's
    /// source must be present.
    pub fn new(s: Sources<'a>, buf: &'a mut [f64], start: usize) -> Self {
        debug_assert!(match s.rate {
            SpringRate::None => true,
            SpringRate::Velocity => s.v.is_some(),
            SpringRate::HalfDerivative => s.half.is_some(),
        });
        let cap = buf.len() / 9;
        debug_assert!(start >= s.base);
        Self {
            sources: [Some(s.x), s.v, s.half],
            base: s.base,
            rate: s.rate,
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
        let n = self.base + self.sources[0].map_or(0, <[Vec3]>::len);
        let upto = upto.min(n);
        debug_assert!(keep >= self.origin && upto - keep.min(upto) <= self.cap);
        if upto <= self.filled {
            return;
        }
        let cap = self.cap;
        if upto - self.origin > cap {
            // Slide: keep [keep, filled) at the front.
            let (from, to) = (keep - self.origin, self.filled.max(keep) - self.origin);
            for (g, src) in self.sources.iter().enumerate() {
                if src.is_some() {
                    for c in 3 * g..3 * g + 3 {
                        self.buf[c * cap..(c + 1) * cap].copy_within(from..to, 0);
                    }
                }
            }
            self.origin = keep;
            self.filled = self.filled.max(keep);
        }
        let (a, b) = (self.filled - self.origin, upto - self.origin);
        for (g, src) in self.sources.iter().enumerate() {
            if let Some(src) = src {
                let group = &mut self.buf[3 * g * cap..3 * (g + 1) * cap];
                let (px, rest) = group.split_at_mut(cap);
                let (py, pz) = rest.split_at_mut(cap);
                transpose_widest(
                    &src[self.filled - self.base..upto - self.base],
                    [&mut px[a..b], &mut py[a..b], &mut pz[a..b]],
                );
            }
        }
        self.filled = upto;
    }

    /// Group `g`'s component arrays over the whole window.
    fn group(&self, g: usize) -> [&[f64]; 3] {
        let cap = self.cap;
        std::array::from_fn(|c| &self.buf[(3 * g + c) * cap..(3 * g + c + 1) * cap])
    }

    /// `p` reading its positions and rate from this window.
    pub fn params<'b>(&'b self, p: &Params<'b>) -> Params<'b> {
        let x = self.group(0);
        Params {
            x,
            q: match self.rate {
                SpringRate::None => x,
                SpringRate::Velocity => self.group(1),
                SpringRate::HalfDerivative => self.group(2),
            },
            base: self.origin,
            ..*p
        }
    }

    /// The component arrays of particles `[from, to)`, which must be covered.
    pub fn tile(&self, from: usize, to: usize) -> TileState<'_> {
        debug_assert!(from >= self.origin && to <= self.filled);
        let (a, b) = (from - self.origin, to - self.origin);
        let part = |g: usize| {
            let [x, y, z] = self.group(g);
            [&x[a..b], &y[a..b], &z[a..b]]
        };
        TileState {
            x: part(0),
            v: self.sources[1].map(|_| part(1)),
            half: self.sources[2].map(|_| part(2)),
        }
    }
}

crate::simd_dispatch! { pub(super) fn transpose_widest(src: &[Vec3], out: [&mut [f64]; 3]) => transpose }

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
        let make = |a: f64, b: f64| -> Vec<Vec3> {
            (0..n).map(|i| Vec3::new(a * i as f64, b, -(i as f64))).collect()
        };
        let (x, v, h) = (make(1.0, 2.0), make(0.5, 7.0), make(-3.0, 0.25));
        let cases = [
            (None, None, SpringRate::None),
            (Some(&v[..]), None, SpringRate::Velocity),
            (None, Some(&h[..]), SpringRate::HalfDerivative),
            (Some(&v[..]), Some(&h[..]), SpringRate::HalfDerivative),
            (Some(&v[..]), Some(&h[..]), SpringRate::Velocity),
        ];
        for (vs, hs, rate) in cases {
            let mut buf = vec![f64::NAN; InputWindow::scratch(100)];
            let sources = Sources {
                x: &x,
                v: vs,
                half: hs,
                rate,
                base: 0,
            };
            let mut w = InputWindow::new(sources, &mut buf, 30);
            // Steps of 23 keeping the last 40: slides many times, ends clamped at n.
            let mut keep = 30;
            while keep < n {
                let upto = keep + 60;
                w.cover(keep, upto);
                let p = Params {
                    stiffness: [0.0; 3],
                    kd: [0.0; 3],
                    x: [&[]; 3],
                    q: [&[]; 3],
                    base: 0,
                    rest: &[],
                };
                let p = w.params(&p);
                let end = upto.min(n);
                let tile = w.tile(keep, end);
                let at = |a: [&[f64]; 3], k: usize| [a[0][k], a[1][k], a[2][k]];
                let expect = |src: &[Vec3], i: usize| [src[i].x, src[i].y, src[i].z];
                for i in keep..end {
                    let (j, k) = (i - p.base, i - keep);
                    assert_eq!(at(p.x, j), expect(&x, i));
                    let r = match rate {
                        SpringRate::None => &x,
                        SpringRate::Velocity => &v,
                        SpringRate::HalfDerivative => &h,
                    };
                    assert_eq!(at(p.q, j), expect(r, i));
                    assert_eq!(at(tile.x, k), expect(&x, i));
                    assert_eq!(tile.v.map(|a| at(a, k)), vs.map(|s| expect(s, i)));
                    assert_eq!(tile.half.map(|a| at(a, k)), hs.map(|s| expect(s, i)));
                }
                keep += 23;
            }
        }
    }
}
