//! Implicit (backward) Euler in the style of Baraff & Witkin (1998).
//!
//! `(M + h C + h^2 K) dv = h (f_n - h K v_n)`, `v_{n+1} = v_n + dv`, `x_{n+1} = x_n + h v_{n+1}`,
//! with `K = -df/dx` and `C = -df/dv` from [`crate::forces::linearise`] (one Newton step of
//! the backward Euler equations). The fractional terms use the split
//! `D^{1/2}x = w0 v + H`: `w0` enters `C` as damping, `H` (the past, lagged by one step)
//! stays in `f_n` as a known force. Pinned particles are filtered out of the solve (their
//! velocity is prescribed). The system is solved matrix-free by block-Jacobi
//! preconditioned CG ([`super::cg`]). The water's inertia enters `M` per particle
//! ([`crate::forces::Inertia`]), in the product and the preconditioner.
//!
//! Unconditionally stable for the linearised cloth; first order in time.

use nalgebra::Matrix3;

use super::cg::{self, CgScratch, SolverSettings, SolverStats};
use crate::collide::{contact, Contact};
use crate::forces::add_spring_values;
use crate::forces::coarse_water::CoarseWater;
use crate::forces::{Linearisation, SpringBlock};
use crate::math::Vec3;
use crate::parallel;
use crate::topology::{for_each_piece, Topology};

/// Work memory of the implicit step.
#[derive(Clone, Debug, Default)]
pub struct ImplicitScratch {
    pub lin: Linearisation,
    rhs: Vec<Vec3>,
    dv: Vec<Vec3>,
    precond: Vec<Matrix3<f64>>,
    /// Per-spring blocks of the system, the same as matrices (for the preconditioner), and
    /// per-spring vectors of the product.
    spring_blocks: Vec<SpringBlock>,
    spring_matrices: Vec<Matrix3<f64>>,
    spring_values: Vec<Vec3>,
    /// Each contact element's weight in the system (`collide/contact.rs`).
    contact_weights: Vec<f64>,
    cg: CgScratch,
}

/// Everything one implicit step reads.
pub struct ImplicitInput<'a> {
    pub h: f64,
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub force: &'a [Vec3],
    pub masses: &'a [f64],
    pub topology: &'a Topology,
    pub pinned: &'a [bool],
    pub settings: SolverSettings,
    /// Contact elements (`collide/contact.rs`): their blocks join the system.
    pub contacts: &'a [Contact],
    pub contact_stiffness: f64,
    pub contact_damping: f64,
    /// The carried water's coarse level with the step's unit normals and projected-area
    /// ratios (`forces::coarse_water`), when the model has one: its `W'^T K W'` joins `M`.
    pub coarse: Option<(&'a CoarseWater, &'a [Vec3], &'a [f64])>,
}

/// Writes `out[k] = blocks[k] (p_i - p_j)` for every spring k.
fn spring_products(par: bool, t: &Topology, blocks: &[SpringBlock], p: &[Vec3], out: &mut [Vec3]) {
    // Run by run: a run's end points are contiguous slices of `p` (no index loads).
    parallel::chunks(par, out, parallel::CHUNK, |first, chunk| {
        for_each_piece(&t.spring_runs, first, first + chunk.len(), |run, lo, hi| {
            let n = hi - lo;
            let i0 = run.first_vertex as usize + (lo - run.first_spring as usize);
            let j0 = i0 + run.offset as usize;
            let (pi, pj, bl) = (&p[i0..i0 + n], &p[j0..j0 + n], &blocks[lo..hi]);
            for (k, o) in chunk[lo - first..hi - first].iter_mut().enumerate() {
                *o = bl[k].apply(&(pi[k] - pj[k]));
            }
        });
    });
}

/// `out = A p` with `A = M + h C + h^2 K`: per-particle blocks, then the springs' blocks
/// (`S_k (p_i - p_j)` added at i and subtracted at j).
fn apply_system(
    inp: &ImplicitInput<'_>,
    lin: &Linearisation,
    blocks: &[SpringBlock],
    contact_weights: &[f64],
    values: &mut [Vec3],
    p: &[Vec3],
    out: &mut [Vec3],
) {
    let h = inp.h;
    let par = parallel::worth_it(p.len());
    spring_products(par, inp.topology, blocks, p, values);
    let values = &*values;
    parallel::chunks(par, out, parallel::CHUNK, |first, chunk| {
        for (k, o) in chunk.iter_mut().enumerate() {
            let i = first + k;
            *o = inp.masses[i] * p[i] + h * (lin.damping[i] * p[i]) + h * h * (lin.stiffness[i] * p[i]);
            if let Some(inertia) = lin.inertia.get(i) {
                *o += inertia.water_times(&p[i]);
            }
        }
        add_spring_values(inp.topology, first, values, -1.0, chunk);
    });
    if let Some((coarse, normals, projected)) = inp.coarse {
        coarse.add_product(normals, projected, p, out);
    }
    contact::add_system_product(inp.contacts, contact_weights, p, out);
}

/// Solves for the new velocities of free particles into `v_new` (pinned entries keep `inp.v`).
pub fn implicit_euler(
    inp: &ImplicitInput<'_>,
    scratch: &mut ImplicitScratch,
    v_new: &mut [Vec3],
) -> SolverStats {
    let n = inp.x.len();
    let h = inp.h;
    let t = inp.topology;
    let par = parallel::worth_it(n);
    let ImplicitScratch {
        lin,
        rhs,
        dv,
        precond,
        spring_blocks,
        spring_matrices,
        spring_values,
        contact_weights,
        cg,
    } = scratch;
    rhs.resize(n, Vec3::zeros());
    dv.resize(n, Vec3::zeros());
    precond.resize(n, Matrix3::identity());
    spring_blocks.resize(t.springs.len(), SpringBlock::default());
    spring_matrices.resize(t.springs.len(), Matrix3::zeros());
    spring_values.resize(t.springs.len(), Vec3::zeros());
    // Each spring's block of the system: h c_s dir dir^T + h^2 K_s.
    parallel::chunks(par, spring_blocks, parallel::CHUNK, |first, chunk| {
        for (k, b) in chunk.iter_mut().enumerate() {
            // h c_s dir dir^T + h^2 K_s, K_s = along dir dir^T + across I.
            let ks = &lin.spring_stiffness[first + k];
            *b = SpringBlock {
                dir: ks.dir,
                along: h * lin.spring_damping[first + k] + h * h * ks.along,
                across: h * h * ks.across,
            };
        }
    });
    // rhs = h f_n - h^2 K v_n (the springs' K acting on v_i - v_j).
    parallel::chunks(par, spring_values, parallel::CHUNK, |first, chunk| {
        for (k, o) in chunk.iter_mut().enumerate() {
            let s = &t.springs[first + k];
            *o = -(h * h)
                * lin.spring_stiffness[first + k].apply(&(inp.v[s.i as usize] - inp.v[s.j as usize]));
        }
    });
    let values = &*spring_values;
    parallel::chunks(par, rhs, parallel::CHUNK, |first, chunk| {
        for (k, r) in chunk.iter_mut().enumerate() {
            let i = first + k;
            *r = h * inp.force[i] - h * h * (lin.stiffness[i] * inp.v[i]);
        }
        add_spring_values(t, first, values, -1.0, chunk);
    });
    let (kc, cc) = (inp.contact_stiffness, inp.contact_damping);
    contact::add_rhs(inp.contacts, kc, h, inp.v, rhs);
    contact::system_weights(inp.contacts, kc, cc, h, inp.v, contact_weights);
    let contact_weights = &*contact_weights;
    // Block-Jacobi preconditioner: inverse of each 3x3 diagonal block of the system.
    let blocks = &*spring_blocks;
    parallel::chunks(par, spring_matrices, parallel::CHUNK, |first, chunk| {
        for (k, m) in chunk.iter_mut().enumerate() {
            *m = blocks[first + k].matrix();
        }
    });
    let matrices = &*spring_matrices;
    parallel::chunks(par, precond, parallel::CHUNK, |first, chunk| {
        for (k, m) in chunk.iter_mut().enumerate() {
            let i = first + k;
            *m = inp.masses[i] * Matrix3::identity() + h * lin.damping[i] + h * h * lin.stiffness[i];
            if let Some(inertia) = lin.inertia.get(i) {
                *m += inertia.water_matrix();
            }
        }
        add_spring_values(t, first, matrices, 1.0, chunk);
    });
    contact::add_system_diagonal(inp.contacts, contact_weights, precond);
    parallel::chunks(par, precond, parallel::CHUNK, |first, chunk| {
        for (k, m) in chunk.iter_mut().enumerate() {
            *m = m
                .try_inverse()
                .unwrap_or_else(|| Matrix3::identity() / inp.masses[first + k]);
        }
    });
    let lin_ref: &Linearisation = lin;
    let stats = cg::solve(
        |p, out| apply_system(inp, lin_ref, blocks, contact_weights, spring_values, p, out),
        rhs,
        precond,
        inp.pinned,
        inp.settings,
        cg,
        dv,
    );
    for i in 0..n {
        v_new[i] = inp.v[i] + dv[i];
    }
    stats
}
