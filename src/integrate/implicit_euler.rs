//! Implicit (backward) Euler in the style of Baraff & Witkin (1998).
//!
//! `(M + h C + h^2 K) dv = h (f_n - h K v_n)`, `v_{n+1} = v_n + dv`, `x_{n+1} = x_n + h v_{n+1}`,
//! with `K = -df/dx` and `C = -df/dv` from [`crate::forces::linearise`] (one Newton step of
//! the backward Euler equations). The fractional terms use the split
//! `D^{1/2}x = w0 v + H`: `w0` enters `C` as damping, `H` (the past, lagged by one step)
//! stays in `f_n` as a known force. Pinned particles are filtered out of the solve (their
//! velocity is prescribed). The system is solved matrix-free by block-Jacobi
//! preconditioned CG ([`super::cg`]).
//!
//! Unconditionally stable for the linearised cloth; first order in time.

use nalgebra::Matrix3;

use super::cg::{self, CgScratch, SolverSettings, SolverStats};
use crate::forces::Linearisation;
use crate::topology::Spring;
use crate::Vec3;

/// Work memory of the implicit step.
#[derive(Clone, Debug, Default)]
pub struct ImplicitScratch {
    pub lin: Linearisation,
    rhs: Vec<Vec3>,
    dv: Vec<Vec3>,
    precond: Vec<Matrix3<f64>>,
    cg: CgScratch,
}

/// Everything one implicit step reads.
pub struct ImplicitInput<'a> {
    pub h: f64,
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub force: &'a [Vec3],
    pub masses: &'a [f64],
    pub springs: &'a [Spring],
    pub pinned: &'a [bool],
    pub settings: SolverSettings,
}

fn apply_system(inp: &ImplicitInput<'_>, lin: &Linearisation, p: &[Vec3], out: &mut [Vec3]) {
    let h = inp.h;
    for i in 0..p.len() {
        out[i] = inp.masses[i] * p[i] + h * (lin.damping[i] * p[i]) + h * h * (lin.stiffness[i] * p[i]);
    }
    for (k, s) in inp.springs.iter().enumerate() {
        let (i, j) = (s.i as usize, s.j as usize);
        let d = p[i] - p[j];
        let dir = lin.spring_dir[k];
        let f = h * lin.spring_damping[k] * dir.dot(&d) * dir + h * h * (lin.spring_stiffness[k] * d);
        out[i] += f;
        out[j] -= f;
    }
}

/// Solves for the new velocities of free particles into `v_new` (pinned entries keep `inp.v`).
pub fn implicit_euler(
    inp: &ImplicitInput<'_>,
    scratch: &mut ImplicitScratch,
    v_new: &mut [Vec3],
) -> SolverStats {
    let n = inp.x.len();
    let h = inp.h;
    let ImplicitScratch {
        lin,
        rhs,
        dv,
        precond,
        cg,
    } = scratch;
    rhs.resize(n, Vec3::zeros());
    dv.resize(n, Vec3::zeros());
    precond.resize(n, Matrix3::identity());
    // rhs = h f_n - h^2 K v_n
    for i in 0..n {
        rhs[i] = h * inp.force[i] - h * h * (lin.stiffness[i] * inp.v[i]);
    }
    for (k, s) in inp.springs.iter().enumerate() {
        let (i, j) = (s.i as usize, s.j as usize);
        let f = h * h * (lin.spring_stiffness[k] * (inp.v[i] - inp.v[j]));
        rhs[i] -= f;
        rhs[j] += f;
    }
    // Block-Jacobi preconditioner: inverse of each 3x3 diagonal block of the system.
    for i in 0..n {
        precond[i] = inp.masses[i] * Matrix3::identity() + h * lin.damping[i] + h * h * lin.stiffness[i];
    }
    for (k, s) in inp.springs.iter().enumerate() {
        let dir = lin.spring_dir[k];
        let b = h * lin.spring_damping[k] * dir * dir.transpose() + h * h * lin.spring_stiffness[k];
        precond[s.i as usize] += b;
        precond[s.j as usize] += b;
    }
    for (i, m) in precond.iter_mut().enumerate() {
        *m = m
            .try_inverse()
            .unwrap_or_else(|| Matrix3::identity() / inp.masses[i]);
    }
    let lin_ref: &Linearisation = lin;
    let stats = cg::solve(
        |p, out| apply_system(inp, lin_ref, p, out),
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
