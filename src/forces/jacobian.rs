//! Linearised forces for implicit integration (Baraff & Witkin 1998).
//!
//! Around the state at t_n, with the fractional terms split as `D^{1/2}x = w0 v + H`:
//! - a spring contributes a stiffness block
//!   `K_s = k_s [l_hat l_hat^T + max(0, 1 - r/|l|) (I - l_hat l_hat^T)]` (the transverse part is
//!   clamped at zero for compressed springs so the system stays positive definite) and a
//!   damping `c_s l_hat l_hat^T`, with `c_s = k_d` for velocity damping and `c_s = k_d w0` for
//!   fractional springs (H enters as a known force);
//! - a particle contributes what each of its terms gives (`terms.rs`): damping
//!   `k_vd I + k_hd w0 v_hat v_hat^T + k_nd n n^T` (+ contact damping) and contact stiffness
//!   `k_c n n^T`.
//!
//! Every block is symmetric positive semi-definite and enters `-df/dx` or `-df/dv`.

use nalgebra::Matrix3;

use super::terms::{self, Context, Particle};
use super::{body_acceleration, ForceInput};
use crate::model::SpringDamping;
use crate::Vec3;

/// A spring's 3x3 block in the form every spring block has: `along dir dir^T + across I`
/// (40 bytes instead of a matrix's 72; applying it is two dot-product-sized operations).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpringBlock {
    /// Unit direction of the spring (zero for a collapsed spring).
    pub dir: Vec3,
    pub along: f64,
    pub across: f64,
}

impl SpringBlock {
    /// The block times `u`.
    #[inline]
    pub fn apply(&self, u: &Vec3) -> Vec3 {
        (self.along * self.dir.dot(u)) * self.dir + self.across * u
    }

    /// The block as a matrix.
    pub fn matrix(&self) -> Matrix3<f64> {
        self.along * outer(&self.dir) + self.across * Matrix3::identity()
    }
}

/// Per-spring and per-particle blocks of `-df/dx` and `-df/dv`.
#[derive(Clone, Debug, Default)]
pub struct Linearisation {
    /// `-df_i/dx_i` of each spring (acts on x_i - x_j).
    pub spring_stiffness: Vec<SpringBlock>,
    /// Damping coefficient c_s of each spring (block `c_s dir dir^T`, dir as in
    /// `spring_stiffness`).
    pub spring_damping: Vec<f64>,
    /// Per-particle `-df/dv`.
    pub damping: Vec<Matrix3<f64>>,
    /// Per-particle `-df/dx`.
    pub stiffness: Vec<Matrix3<f64>>,
    /// Per-particle inertia at the start of the step (empty when the model carries no water:
    /// the mass matrix is then `m I`).
    pub inertia: Vec<super::Inertia>,
}

fn outer(a: &Vec3) -> Matrix3<f64> {
    a * a.transpose()
}

/// Fills `out` for the state in `input`; `w0` is the current-velocity weight of D^{1/2};
/// `normals` are the vertex normals (needed only with normal drag).
pub fn linearise(input: &ForceInput<'_>, w0: f64, normals: &[Vec3], out: &mut Linearisation) {
    let m = input.model;
    let ns = input.topology.springs.len();
    let n = input.x.len();
    out.spring_stiffness.resize(ns, SpringBlock::default());
    out.spring_damping.resize(ns, 0.0);
    out.damping.resize(n, Matrix3::zeros());
    out.stiffness.resize(n, Matrix3::zeros());
    let cd = match m.spring_damping_mode {
        SpringDamping::None => 0.0,
        SpringDamping::Velocity => m.spring_damping,
        SpringDamping::Fractional => m.spring_damping * w0,
        SpringDamping::FractionalStrain => m.spring_damping * input.strain_w0,
    };
    for (k, s) in input.topology.springs.iter().enumerate() {
        let ks = m.stiffness(s.kind);
        let l = input.x[s.i as usize] - input.x[s.j as usize];
        let len = l.norm();
        if len == 0.0 {
            out.spring_stiffness[k] = SpringBlock::default();
            out.spring_damping[k] = 0.0;
            continue;
        }
        // k_s [l l^T + t (I - l l^T)] = k_s (1 - t) l l^T + k_s t I.
        let transverse = (1.0 - s.rest / len).max(0.0);
        out.spring_stiffness[k] = SpringBlock {
            dir: l / len,
            along: ks * (1.0 - transverse),
            across: ks * transverse,
        };
        out.spring_damping[k] = cd * m.spring_damping_scale[s.kind as usize];
    }
    // Every per-particle term's blocks, in the order of the list (`terms.rs`).
    let context = Context {
        model: m,
        gravity: body_acceleration(m),
        colliders: input.colliders,
    };
    let zero = Vec3::zeros();
    for i in 0..n {
        let p = Particle {
            x: &input.x[i],
            v: &input.v[i],
            normal: normals.get(i).unwrap_or(&zero),
            w0,
            area: input.topology.areas[i],
        };
        let b = terms::linearise_all(&context, &p);
        out.damping[i] = b.damping;
        out.stiffness[i] = b.stiffness;
    }
    out.inertia.clear();
    if super::carries_water(m) {
        let t = input.topology;
        out.inertia
            .extend((0..n).map(|i| super::Inertia::of(m, t.masses[i], t.areas[i], normals[i])));
    }
}
