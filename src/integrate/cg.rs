//! Block-Jacobi preconditioned conjugate gradients with a constraint filter
//! (Baraff & Witkin's modified PCG): components marked fixed stay at zero.

use nalgebra::Matrix3;

use crate::math::Vec3;
use crate::parallel;

/// Tolerance and iteration cap of the solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Stop when `|r| <= tolerance |b|` (relative residual). Default 1e-6.
    pub tolerance: f64,
    /// Stop after this many iterations. Default 500.
    pub max_iterations: u32,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 500,
        }
    }
}

/// What the last solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolverStats {
    pub iterations: u32,
    /// Final relative residual `|r| / |b|`.
    pub residual: f64,
}

/// Work vectors, kept between steps so a step does not allocate.
#[derive(Clone, Debug, Default)]
pub struct CgScratch {
    r: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    q: Vec<Vec3>,
    partial: Vec<f64>,
}

/// `a . b`, summed chunk by chunk ([`parallel::CHUNK`]) and then over the chunks in order:
/// the same bits whether the chunks run on one thread or many.
fn dot(par: bool, partial: &mut [f64], a: &[Vec3], b: &[Vec3]) -> f64 {
    parallel::chunks(par, partial, 1, |k, s| {
        let lo = k * parallel::CHUNK;
        let hi = (lo + parallel::CHUNK).min(a.len());
        s[0] = a[lo..hi].iter().zip(&b[lo..hi]).map(|(x, y)| x.dot(y)).sum();
    });
    partial.iter().sum()
}

/// Solves `A x = b` for the free components (`fixed[i]` false); fixed components of `x`
/// are zero. `apply(p, out)` writes `A p`; `precond` holds the inverse diagonal blocks.
pub fn solve(
    mut apply: impl FnMut(&[Vec3], &mut [Vec3]),
    b: &[Vec3],
    precond: &[Matrix3<f64>],
    fixed: &[bool],
    settings: SolverSettings,
    scratch: &mut CgScratch,
    x: &mut [Vec3],
) -> SolverStats {
    let n = b.len();
    let par = parallel::worth_it(n);
    let CgScratch { r, z, p, q, partial } = scratch;
    for v in [&mut *r, &mut *z, &mut *p, &mut *q] {
        v.resize(n, Vec3::zeros());
    }
    partial.resize(n.div_ceil(parallel::CHUNK), 0.0);
    x.fill(Vec3::zeros());
    for i in 0..n {
        r[i] = if fixed[i] { Vec3::zeros() } else { b[i] };
        z[i] = precond[i] * r[i];
        p[i] = z[i];
    }
    let b_norm = dot(par, partial, r, r).sqrt();
    if b_norm == 0.0 {
        return SolverStats::default();
    }
    let mut rz = dot(par, partial, r, z);
    let mut stats = SolverStats {
        iterations: 0,
        residual: 1.0,
    };
    while stats.iterations < settings.max_iterations {
        apply(p, q);
        parallel::chunks(par, q, parallel::CHUNK, |first, q| {
            for (k, qi) in q.iter_mut().enumerate() {
                if fixed[first + k] {
                    *qi = Vec3::zeros();
                }
            }
        });
        let pq = dot(par, partial, p, q);
        if pq.is_nan() || pq <= 0.0 {
            break; // not positive definite along p (only on broken input): stop with what we have
        }
        let alpha = rz / pq;
        let (pp, qq) = (&*p, &*q);
        parallel::chunks2(par, (x, 1), (r, 1), parallel::CHUNK, |first, x, r| {
            for k in 0..x.len() {
                x[k] += alpha * pp[first + k];
                r[k] -= alpha * qq[first + k];
            }
        });
        stats.iterations += 1;
        stats.residual = dot(par, partial, r, r).sqrt() / b_norm;
        if stats.residual <= settings.tolerance {
            break;
        }
        let rr = &*r;
        parallel::chunks(par, z, parallel::CHUNK, |first, z| {
            for (k, zi) in z.iter_mut().enumerate() {
                *zi = precond[first + k] * rr[first + k];
            }
        });
        let rz_new = dot(par, partial, r, z);
        let beta = rz_new / rz;
        rz = rz_new;
        let zz = &*z;
        parallel::chunks(par, p, parallel::CHUNK, |first, p| {
            for (k, pi) in p.iter_mut().enumerate() {
                let i = first + k;
                *pi = if fixed[i] {
                    Vec3::zeros()
                } else {
                    zz[i] + beta * *pi
                };
            }
        });
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_spd_system_with_a_fixed_component() {
        // A = tridiagonal (4 on the diagonal, -1 off it) acting per component.
        let n = 6;
        let apply = |p: &[Vec3], out: &mut [Vec3]| {
            for i in 0..n {
                out[i] = 4.0 * p[i];
                if i > 0 {
                    out[i] -= p[i - 1];
                }
                if i + 1 < n {
                    out[i] -= p[i + 1];
                }
            }
        };
        let fixed = [false, false, true, false, false, false];
        let want: Vec<Vec3> = (0..n)
            .map(|i| {
                if fixed[i] {
                    Vec3::zeros()
                } else {
                    Vec3::new(i as f64, 1.0, -2.0)
                }
            })
            .collect();
        let mut b = vec![Vec3::zeros(); n];
        apply(&want, &mut b);
        let pre = vec![Matrix3::identity() * 0.25; n];
        let mut x = vec![Vec3::zeros(); n];
        let s = solve(
            apply,
            &b,
            &pre,
            &fixed,
            SolverSettings::default(),
            &mut CgScratch::default(),
            &mut x,
        );
        assert!(s.residual <= 1e-6 && s.iterations <= 6, "{s:?}");
        for i in 0..n {
            assert!((x[i] - want[i]).norm() < 1e-5, "{i}: {:?}", x[i]);
        }
    }
}
