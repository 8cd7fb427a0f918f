//! Springs as compliant distance constraints (XPBD: Macklin, Mueller & Chentanez 2016,
//! "XPBD: position-based simulation of compliant constrained dynamics"; one projection a
//! substep as in Macklin et al. 2019, "Small steps in physics simulation").
//!
//! A spring of stiffness `k` (N/m), rest length `r` and velocity damping `c` (N s/m) between
//! particles `i` and `j` is the constraint `C = |x_i - x_j| - r` of compliance `alpha = 1/k`
//! with Rayleigh damping `c`. After an explicit step has predicted the positions without the
//! spring's force, one pass over the constraints moves each pair by
//!
//! `dl = (-kappa C - delta g . ((x_i - s_i) - (x_j - s_j))) / ((kappa + delta) g^T (W_i + W_j) g + 1)`,
//! `x_i += dl W_i g`, `x_j -= dl W_j g`,
//!
//! `g` the unit vector from `j` to `i`, `s` the positions where the substep began, `W` each
//! particle's inverse mass matrix, `kappa = k h^2` and `delta = c h`: XPBD's update
//! `(-C - gamma grad C . dx) / ((1 + gamma) grad C^T W grad C + alpha~)` with
//! `alpha~ = 1 / (k h^2)`, `gamma = c / (k h)` and the multiplier from 0, multiplied through by
//! `k h^2` so that a spring may carry damping alone (`k = 0`: its damping implicit, its
//! stiffness left to the forces). The stiffness no longer bounds the step: a stiff spring is a
//! small compliance. What one pass trades for its step: a spring alone rests exactly where
//! its stiffness holds it (a weight hangs at `m g / k`, tested below), but a chain of them is
//! held softer, because each link is projected on positions its neighbours' corrections have
//! not yet reached. A chain of springs `k` between particles of mass `m` rests stretched about
//! `1 + (omega h)^2` times as far as its springs hold it, `omega^2 = k / m` (measured below:
//! 1.01, 2.0 and 4.0 at `(omega h)^2` = 0.01, 1 and 3.1); the pass also damps what moves
//! faster than the step resolves. The underwater
//! preset's stretch springs at three substeps a 60 Hz frame have `(omega h)^2 = 3.1`
//! (`docs/realtime.md` says what that does to a tall cloth).
//!
//! The inverse mass carries the water along the normal ([`InverseMass`]): a particle moves
//! `1 - beta` as far along its normal as along the cloth for the same impulse, as the
//! explicit step's `M^{-1}` does (`forces/inertia.rs`).
//!
//! Two ways through the links, the same step for each (`link_update`): a grid's links come
//! as runs, projected in blocks on component arrays without gathers (`xpbd/runs.rs`); any other
//! mesh's are ordered into [`Batches`] and projected four at a time with AVX2 gathers.

use crate::math::Vec3;

#[cfg(target_arch = "x86_64")]
mod avx2;
pub mod runs;

/// One constraint: the pair, its rest length (m) and its family's index in the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    pub i: u32,
    pub j: u32,
    pub rest: f64,
    /// Which entry of the [`Compliance`] list it takes (the spring family).
    pub family: u8,
}

/// A family's parameters for a substep of `h` s (module docs): `kappa = k h^2` and
/// `delta = c h`, both in kg (times the inverse mass they are dimensionless). Both zero: the
/// family's links do not move anything.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Compliance {
    pub kappa: f64,
    pub delta: f64,
}

impl Compliance {
    /// The parameters of a spring of stiffness `k` (N/m, >= 0) and damping `c` (N s/m, >= 0)
    /// for a substep of `h` s. `k = 0`: damping alone (implicit), the stiffness left to forces.
    pub fn of(k: f64, c: f64, h: f64) -> Compliance {
        Compliance {
            kappa: k * h * h,
            delta: c * h,
        }
    }
}

/// A particle's inverse mass matrix `W = w I - u u^T`: `w` the inverse of its mass and the
/// water it carries in every direction, `u = sqrt(w beta) n` with `beta = m_a / (m + m_e + m_a)`
/// along the unit normal `n` (Sherman-Morrison of `M = (m + m_e) I + m_a n n^T`). All zero for
/// a pinned particle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct InverseMass {
    pub w: f64,
    pub u: Vec3,
}

impl InverseMass {
    /// The inverse of `M = mass I + normal_mass n n^T` (kg; `n` unit).
    pub fn of(mass: f64, normal_mass: f64, n: Vec3) -> InverseMass {
        let w = 1.0 / mass;
        let beta = normal_mass / (mass + normal_mass);
        InverseMass {
            w,
            u: (w * beta).sqrt() * n,
        }
    }

    /// `W g`.
    #[inline(always)]
    pub fn times(&self, g: &Vec3) -> Vec3 {
        self.w * g - self.u.dot(g) * self.u
    }
}

/// The links in the order one pass projects them: batches in which no two links share a
/// particle (greedy colouring, in the given order), so a batch's links are independent and
/// are projected four at a time (as NvCloth and Jolt batch their constraints). The same order
/// on any thread count; the pass runs on one thread.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Batches {
    /// The particles the links were checked against.
    n: usize,
    links: Vec<Link>,
    /// Where each batch begins in `links`, and the end.
    starts: Vec<usize>,
}

/// Batches a colouring keeps apart at most (a particle touches fewer links in any cloth
/// this library builds; past it the links go to one last batch projected one by one).
const MAX_BATCHES: usize = 64;

impl Batches {
    /// Orders `links` of particles below `n` into batches; `None` when a link names a particle
    /// at or past `n`, or when the room cannot be had.
    pub fn of(links: &[Link], n: usize) -> Option<Batches> {
        let mut used = Vec::new();
        used.try_reserve_exact(n).ok()?;
        used.resize(n, 0u64);
        let mut colour = Vec::new();
        colour.try_reserve_exact(links.len()).ok()?;
        for l in links {
            let (i, j) = (l.i as usize, l.j as usize);
            if i >= n || j >= n {
                return None;
            }
            let free = !(used[i] | used[j]);
            let c = (free.trailing_zeros() as usize).min(MAX_BATCHES);
            if c < MAX_BATCHES {
                used[i] |= 1 << c;
                used[j] |= 1 << c;
            }
            colour.push(c);
        }
        let mut counts = [0usize; MAX_BATCHES + 1];
        for &c in &colour {
            counts[c] += 1;
        }
        let mut starts = Vec::with_capacity(MAX_BATCHES + 2);
        let mut at = 0;
        for &count in &counts {
            starts.push(at);
            at += count;
        }
        starts.push(at);
        let mut next = starts.clone();
        let mut ordered = Vec::new();
        ordered.try_reserve_exact(links.len()).ok()?;
        ordered.resize(
            links.len(),
            Link {
                i: 0,
                j: 0,
                rest: 0.0,
                family: 0,
            },
        );
        for (l, &c) in links.iter().zip(&colour) {
            ordered[next[c]] = *l;
            next[c] += 1;
        }
        Some(Batches {
            n,
            links: ordered,
            starts,
        })
    }

    /// How many links.
    pub fn len(&self) -> usize {
        self.links.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.links.is_empty()
    }
}

/// One pass over the constraints (`lambda` from 0: one pass a substep): moves `x` (the
/// predicted positions, one per particle) towards every link's rest length, `start` the
/// positions where the substep began (for the damping), `params` each family's
/// [`Compliance`], `inverse` each particle's. Panics if the slices are shorter than the
/// particles the batches were made for. A link of zero length or of two particles that cannot
/// move is left.
pub fn project(
    batches: &Batches,
    params: &[Compliance; 3],
    inverse: &[InverseMass],
    start: &[Vec3],
    x: &mut [Vec3],
) {
    let n = batches.n;
    let vector = cfg!(target_arch = "x86_64")
        && crate::simd_width() >= crate::SimdWidth::Avx2
        && inverse.len() >= n
        && start.len() >= n
        && x.len() >= n;
    let last = batches.starts.len() - 2;
    for (b, w) in batches.starts.windows(2).enumerate() {
        let links = &batches.links[w[0]..w[1]];
        let quads = if b < last { links.len() / 4 * 4 } else { 0 };
        let (whole, rest) = links.split_at(quads);
        if vector {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: AVX2 is there (`simd_width`), and every link's particles are below n
            // (`Batches::of`), which the three arrays reach.
            unsafe {
                avx2::project_quads(whole, params, inverse, start, x)
            };
        } else {
            for l in whole {
                project_one(l, params, inverse, start, x);
            }
        }
        for l in rest {
            project_one(l, params, inverse, start, x);
        }
    }
}

/// One link, scalar: the operations of the vector step (`avx2.rs`) in its order, so that
/// both give the same bits.
#[inline(always)]
fn project_one(
    link: &Link,
    params: &[Compliance; 3],
    inverse: &[InverseMass],
    start: &[Vec3],
    x: &mut [Vec3],
) {
    let (i, j) = (link.i as usize, link.j as usize);
    let v = |a: Vec3| [a.x, a.y, a.z];
    let (a, b) = (inverse[i], inverse[j]);
    let (ni, nj) = link_update(
        v(x[i]),
        v(x[j]),
        (v(start[i]), v(start[j])),
        (a.w, v(a.u)),
        (b.w, v(b.u)),
        params[link.family as usize],
        link.rest,
    );
    x[i] = Vec3::from(ni);
    x[j] = Vec3::from(nj);
}

/// The step of one link (module docs) from its ends' positions `xi`, `xj`, where they began
/// the substep, and their inverse masses (`w`, `u`): the ends' new positions. Every pass
/// (scalar, AVX2, runs) takes these operations in this order: the same bits.
#[inline(always)]
fn link_update(
    xi: [f64; 3],
    xj: [f64; 3],
    (si, sj): ([f64; 3], [f64; 3]),
    (wa, ua): (f64, [f64; 3]),
    (wb, ub): (f64, [f64; 3]),
    p: Compliance,
    rest: f64,
) -> ([f64; 3], [f64; 3]) {
    let d: [f64; 3] = std::array::from_fn(|c| xi[c] - xj[c]);
    let moved: [f64; 3] = std::array::from_fn(|c| (xi[c] - si[c]) - (xj[c] - sj[c]));
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let l2 = dot(d, d);
    // Zero length: no direction, no move.
    let l = l2.sqrt();
    let inv_l = if l2 > 0.0 { 1.0 / l } else { 0.0 };
    let g = d.map(|dc| dc * inv_l);
    let (ag, bg, along) = (dot(ua, g), dot(ub, g), dot(g, moved));
    // g^T W g for a unit g: w - (u . g)^2 for each end.
    let weight = (wa - ag * ag) + (wb - bg * bg);
    let step = (-p.kappa * (l - rest) - p.delta * along) / ((p.kappa + p.delta) * weight + 1.0);
    // No weight (both ends held) or no direction: no move (NaN fails the test too).
    let dl = if weight > 0.0 && l2 > 0.0 { step } else { 0.0 };
    let (a, b, aa, bb) = (dl * wa, dl * wb, dl * ag, dl * bg);
    (
        std::array::from_fn(|c| xi[c] + a * g[c] - aa * ua[c]),
        std::array::from_fn(|c| xj[c] - b * g[c] + bb * ub[c]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A particle of mass `m` hung from a fixed one by a spring of stiffness `k`, rest `r`,
    /// stepped `steps` times of `h` under gravity `g` (symplectic prediction, one projection).
    fn hang(m: f64, k: f64, c: f64, h: f64, steps: usize) -> (Vec3, Vec3) {
        let r = 0.1;
        let links = Batches::of(
            &[Link {
                i: 0,
                j: 1,
                rest: r,
                family: 0,
            }],
            2,
        )
        .unwrap();
        let params = [Compliance::of(k, c, h); 3];
        let inverse = [InverseMass::default(), InverseMass::of(m, 0.0, Vec3::z())];
        let g = Vec3::new(0.0, -9.81, 0.0);
        let (mut x, mut v) = (vec![Vec3::zeros(), Vec3::new(0.0, -r, 0.0)], Vec3::zeros());
        for _ in 0..steps {
            let start = x.clone();
            v += h * g;
            x[1] += h * v;
            project(&links, &params, &inverse, &start, &mut x);
            v = (x[1] - start[1]) / h;
        }
        (x[1], v)
    }

    #[test]
    fn a_weight_hangs_where_the_spring_holds_it() {
        // Static equilibrium is exact with one pass: extension m g / k.
        let (m, k) = (1e-3, 10.0);
        let (x, v) = hang(m, k, 0.05, 1.0 / 120.0, 4000);
        let want = -0.1 - m * 9.81 / k;
        assert!((x.y - want).abs() < 1e-9, "{} against {want}", x.y);
        assert!(v.norm() < 1e-9);
    }

    /// A chain of `links` particles of mass `m` hung from a held one by springs of stiffness
    /// `k` (rest 1 cm), stepped under gravity `h` at a time (symplectic prediction, one pass a
    /// substep) until it rests: its stretch over the stretch its springs hold (each link the
    /// weight of the particles below it).
    fn chain_stretch(links: usize, m: f64, k: f64, h: f64) -> f64 {
        let (n, r, g) = (links + 1, 0.01, 9.81);
        let chain: Vec<Link> = (0..links)
            .map(|i| Link {
                i: i as u32,
                j: i as u32 + 1,
                rest: r,
                family: 0,
            })
            .collect();
        let batches = Batches::of(&chain, n).unwrap();
        // Damping makes it rest (where it rests does not depend on it).
        let params = [Compliance::of(k, 0.05 * (k * m).sqrt(), h); 3];
        let mut inverse = vec![InverseMass::of(m, 0.0, Vec3::z()); n];
        inverse[0] = InverseMass::default();
        let mut x: Vec<Vec3> = (0..n).map(|i| Vec3::new(0.0, -r * i as f64, 0.0)).collect();
        let mut v = vec![Vec3::zeros(); n];
        for _ in 0..(40.0 / h) as usize {
            let start = x.clone();
            for i in 1..n {
                v[i].y -= h * g;
                x[i] += h * v[i];
            }
            project(&batches, &params, &inverse, &start, &mut x);
            for i in 1..n {
                v[i] = (x[i] - start[i]) / h;
            }
        }
        let stretch = -x[links].y - r * links as f64;
        let held: f64 = (0..links).map(|j| (links - j) as f64 * m * g / k).sum();
        stretch / held
    }

    #[test]
    fn one_pass_holds_a_chain_softer_than_its_springs_the_longer_the_step() {
        // The module docs' figures: a chain of 20 rests stretched about `1 + (omega h)^2` times
        // what its springs hold (measured 1.011, 1.995, 4.02), as springs that much softer
        // would hold it; one link alone rests exactly where its spring holds it.
        let (m, k): (f64, f64) = (1e-4, 10.0);
        let omega = (k / m).sqrt();
        let one = chain_stretch(1, m, k, 1.76 / omega);
        let fine = chain_stretch(20, m, k, 0.1 / omega);
        let unit = chain_stretch(20, m, k, 1.0 / omega);
        let coarse = chain_stretch(20, m, k, 1.76 / omega);
        assert!((one - 1.0).abs() < 1e-6, "one link: {one}");
        assert!((fine - 1.01).abs() < 0.01, "(omega h)^2 = 0.01: {fine}");
        assert!((unit - 2.0).abs() < 0.05, "(omega h)^2 = 1: {unit}");
        assert!((coarse - 4.1).abs() < 0.2, "(omega h)^2 = 3.1: {coarse}");
    }

    #[test]
    fn a_stiff_spring_does_not_bound_the_step() {
        // k / m = 1e6 s^-2: an explicit step would need h < 2 ms; XPBD at 8 ms stays bounded
        // and rings down to the same rest.
        let (m, k) = (1e-4, 100.0);
        let (x, _) = hang(m, k, 0.0, 8e-3, 2000);
        assert!(
            x.y.is_finite() && (x.y - (-0.1 - m * 9.81 / k)).abs() < 1e-6,
            "{}",
            x.y
        );
    }

    #[test]
    fn damping_takes_energy_and_none_keeps_the_swing() {
        // Dropped from rest length: the undamped spring keeps swinging, the damped one settles.
        let swing = |c: f64| {
            let (m, k, h) = (1e-3, 1.0, 2e-3);
            let (_, v) = hang(m, k, c, h, 1500);
            v.norm()
        };
        assert!(swing(0.0) > 1e-3, "{}", swing(0.0));
        assert!(swing(0.02) < 1e-3 * swing(0.0), "{} {}", swing(0.02), swing(0.0));
    }

    #[test]
    fn the_water_along_the_normal_slows_that_motion_alone() {
        let n = Vec3::new(0.0, 0.0, 1.0);
        let inv = InverseMass::of(1e-4, 8e-4, n);
        // Along the cloth: 1/m; along the normal: 1/(m + m_a).
        assert!((inv.times(&Vec3::x()) - 1e4 * Vec3::x()).norm() < 1e-9);
        assert!((inv.times(&n) - n / 9e-4).norm() < 1e-9);
        // A constraint along the normal moves the free particle 1/9 as far as the pinned pair's
        // would along the cloth for the same impulse: both close the gap fully when stiff.
        let links = Batches::of(
            &[Link {
                i: 0,
                j: 1,
                rest: 0.1,
                family: 0,
            }],
            2,
        )
        .unwrap();
        let params = [Compliance {
            kappa: 1e30,
            delta: 0.0,
        }; 3];
        for dir in [Vec3::x(), n] {
            let inverse = [InverseMass::default(), inv];
            let start = vec![Vec3::zeros(), 0.1 * dir];
            let mut x = vec![Vec3::zeros(), 0.12 * dir];
            project(&links, &params, &inverse, &start, &mut x);
            assert!(((x[1] - x[0]).norm() - 0.1).abs() < 1e-12);
        }
        // Two free particles, the gap along the normal: the one with less water moves more.
        let light = InverseMass::of(1e-4, 0.0, n);
        let mut x = vec![Vec3::zeros(), 0.12 * n];
        let start = x.clone();
        project(&links, &params, &[inv, light], &start, &mut x);
        let (moved0, moved1) = (x[0].norm(), (x[1] - 0.12 * n).norm());
        assert!((moved1 / moved0 - 9.0).abs() < 1e-9, "{moved0} {moved1}");
    }

    #[test]
    fn batches_hold_every_link_once_and_no_batch_touches_a_particle_twice() {
        // A 7 x 5 grid's stretch, shear and bend links, as a cloth's springs list them.
        let (w, h) = (7u32, 5u32);
        let mut links = Vec::new();
        for (di, dj, family) in [(1, 0, 0), (0, 1, 0), (1, 1, 1), (2, 0, 2), (0, 2, 2)] {
            for j in 0..h - dj {
                for i in 0..w - di {
                    links.push(Link {
                        i: j * w + i,
                        j: (j + dj) * w + i + di,
                        rest: 0.01,
                        family,
                    });
                }
            }
        }
        let b = Batches::of(&links, (w * h) as usize).unwrap();
        assert_eq!(b.len(), links.len());
        let sorted = |l: &[Link]| {
            let mut v: Vec<(u32, u32, u8)> = l.iter().map(|l| (l.i, l.j, l.family)).collect();
            v.sort();
            v
        };
        assert_eq!(sorted(&b.links), sorted(&links));
        for w in b.starts.windows(2).take(b.starts.len() - 2) {
            let mut seen = std::collections::HashSet::new();
            for l in &b.links[w[0]..w[1]] {
                assert!(
                    seen.insert(l.i) && seen.insert(l.j),
                    "a batch touches {} or {} twice",
                    l.i,
                    l.j
                );
            }
        }
        // The overflow batch is empty here: a grid's particle touches few links.
        assert_eq!(b.starts[b.starts.len() - 1], b.starts[b.starts.len() - 2]);
        assert!(Batches::of(
            &[Link {
                i: 0,
                j: 9,
                rest: 1.0,
                family: 0
            }],
            9
        )
        .is_none());
    }
}
