//! Linearised forces for implicit integration (Baraff & Witkin 1998).
//!
//! Around the state at t_n, with the fractional terms split as `D^{1/2}x = w0 v + H`:
//! - a spring contributes a stiffness block
//!   `K_s = k_s [l_hat l_hat^T + max(0, 1 - r/|l|) (I - l_hat l_hat^T)]` (the transverse part is
//!   clamped at zero for compressed springs so the system stays positive definite) and a
//!   damping `c_s l_hat l_hat^T`, with `c_s = k_d` for velocity damping and `c_s = k_d w0` for
//!   fractional springs (H enters as a known force);
//! - a particle contributes what each of its terms gives (`terms.rs`, each term's block beside
//!   its force; every block is checked against a central difference of its force by the tests
//!   here and in `terms.rs`);
//! - the water's inertia enters the mass matrix, not the forces ([`super::Inertia`]).
//!
//! Every block is symmetric positive semi-definite and enters `-df/dx` or `-df/dv`.

use nalgebra::Matrix3;

use super::terms::{self, Context, Particle};
use super::{body_acceleration, ForceInput};
use crate::math::Vec3;

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

/// Fills `out` for the state in `input` (its `weights` are the current-rate weights of each
/// memory's D^{1/2}); `normals` are the vertex normals (needed only with terms that read them or the water's
/// inertia), `projected` the patches' projected-area ratios (with normal added mass only).
pub fn linearise(input: &ForceInput<'_>, normals: &[Vec3], projected: &[f64], out: &mut Linearisation) {
    let m = input.model;
    let ns = input.topology.springs.len();
    let n = input.x.len();
    out.spring_stiffness.resize(ns, SpringBlock::default());
    out.spring_damping.resize(ns, 0.0);
    out.damping.resize(n, Matrix3::zeros());
    out.stiffness.resize(n, Matrix3::zeros());
    // Every pair element's damping, in the springs' blocks (`elements.rs`).
    let cd = super::spring_damping(m, &input.weights);
    let w0 = input.weights.of(super::Memory::Particles);
    for (k, s) in input.topology.springs.iter().enumerate() {
        let ks = m.stiffness(s.kind, input.topology.spacing);
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
        out.inertia.extend((0..n).map(|i| {
            let p = projected.get(i).copied().unwrap_or(1.0);
            super::Inertia::of(m, t.masses[i], t.areas[i], normals[i], p)
        }));
    }
}

#[cfg(test)]
mod tests {
    //! The springs' blocks against a central difference of the force pass, for each damping.
    use super::*;
    use crate::forces::{prior_forces, total_forces, ElementScratch, ForceScratch, Weights};
    use crate::model::{Model, SpringDamping};
    use crate::topology::{GridSpec, Topology};

    struct Case {
        model: Model,
        topology: Topology,
        x: Vec<Vec3>,
        v: Vec<Vec3>,
        past: Vec<Vec3>,
        w0: f64,
    }

    impl Case {
        fn new(mode: SpringDamping) -> Case {
            let topology = GridSpec {
                width: 4,
                height: 3,
                spacing: 0.01,
                total_mass: 0.01,
            }
            .build()
            .expect("a valid grid");
            let mut r = crate::testing::numbers(7);
            // Every spring stretched (the transverse part is exact there; compressed springs
            // clamp it to keep the system definite).
            let x = topology
                .rest_positions
                .iter()
                .map(|p| 1.1 * p + 1e-4 * Vec3::new(r(), r(), r()))
                .collect();
            let v = (0..topology.vertex_count())
                .map(|_| Vec3::new(r(), r(), r()))
                .collect();
            let past = (0..topology.vertex_count())
                .map(|_| 0.01 * Vec3::new(r(), r(), r()))
                .collect();
            let mut model = Model::fractional();
            // Springs only: no drag, no water (the weight is constant).
            model.viscous_drag = 0.0;
            model.history_drag = 0.0;
            model.spring_damping_mode = mode;
            model.spring_damping = 0.2;
            model.spring_damping_scale = [1.0, 0.5, 0.25];
            Case {
                model,
                topology,
                x,
                v,
                past,
                w0: 0.3,
            }
        }

        /// The force on every particle; D^{1/2}x = w0 v + past, and every other memory's
        /// D^{1/2} (the elements' own passes) likewise with a past of zero.
        fn forces(&self, x: &[Vec3], v: &[Vec3], past: &[Vec3]) -> Vec<Vec3> {
            let n = x.len();
            let half: Vec<Vec3> = v.iter().zip(past).map(|(v, p)| self.w0 * v + p).collect();
            let mut prior = Vec::new();
            let memory_past = |_, _: &mut [Vec3]| self.w0;
            let mut scratch = ElementScratch::default();
            prior_forces(
                &self.model,
                &self.topology,
                x,
                v,
                &mut scratch,
                memory_past,
                &mut prior,
            );
            let input = ForceInput {
                model: &self.model,
                topology: &self.topology,
                x,
                v,
                half_derivative: &half,
                colliders: &[],
                prior_forces: &prior,
                weights: Weights([self.w0; 2]),
                skin_mean: &[],
            };
            let mut f = vec![Vec3::zeros(); n];
            total_forces(&input, &mut ForceScratch::default(), &mut f);
            f
        }

        fn linearisation(&self) -> Linearisation {
            let half: Vec<Vec3> = self
                .v
                .iter()
                .zip(&self.past)
                .map(|(v, p)| self.w0 * v + p)
                .collect();
            let input = ForceInput {
                model: &self.model,
                topology: &self.topology,
                x: &self.x,
                v: &self.v,
                half_derivative: &half,
                colliders: &[],
                prior_forces: &[],
                weights: Weights([self.w0; 2]),
                skin_mean: &[],
            };
            let mut out = Linearisation::default();
            linearise(&input, &[], &[], &mut out);
            out
        }
    }

    /// `sum_k blocks_k` applied to a unit displacement of particle `a` along `e`, as the
    /// implicit solver applies them (springs on `u_i - u_j`, particles on `u_i`).
    fn apply(
        t: &Topology,
        springs: impl Fn(usize) -> Matrix3<f64>,
        particle: &[Matrix3<f64>],
        u: &[Vec3],
    ) -> Vec<Vec3> {
        let mut out: Vec<Vec3> = (0..u.len())
            .map(|i| particle.get(i).map_or(Vec3::zeros(), |b| b * u[i]))
            .collect();
        for (k, s) in t.springs.iter().enumerate() {
            let (i, j) = (s.i as usize, s.j as usize);
            let g = springs(k) * (u[i] - u[j]);
            out[i] += g;
            out[j] -= g;
        }
        out
    }

    #[test]
    fn spring_blocks_match_a_central_difference_of_the_force_pass() {
        for mode in [
            SpringDamping::None,
            SpringDamping::Velocity,
            SpringDamping::Fractional,
            SpringDamping::FractionalStrain,
        ] {
            let c = Case::new(mode);
            let lin = c.linearisation();
            let n = c.x.len();
            let eps = 1e-7;
            for a in [0, 5, n - 1] {
                for axis in 0..3 {
                    let mut u = vec![Vec3::zeros(); n];
                    u[a][axis] = 1.0;
                    // The stiffness blocks leave out how the damping forces turn with the
                    // springs (Baraff & Witkin's simplification), so -df/dx is taken at rest
                    // (v = 0, no past), where those forces vanish; -df/dv anywhere.
                    let zeros = vec![Vec3::zeros(); n];
                    let shifted = |s: f64, by_v: bool| {
                        let moved: Vec<Vec3> = (0..n).map(|i| s * eps * u[i]).collect();
                        if by_v {
                            let v: Vec<Vec3> = c.v.iter().zip(&moved).map(|(v, d)| v + d).collect();
                            c.forces(&c.x, &v, &c.past)
                        } else {
                            let x: Vec<Vec3> = c.x.iter().zip(&moved).map(|(x, d)| x + d).collect();
                            c.forces(&x, &zeros, &zeros)
                        }
                    };
                    let check = |by_v: bool, want: Vec<Vec3>, what: &str| {
                        let (p, m) = (shifted(1.0, by_v), shifted(-1.0, by_v));
                        for i in 0..n {
                            let fd = -(p[i] - m[i]) / (2.0 * eps);
                            let tol = 1e-6 * (1.0 + want[i].norm());
                            assert!(
                                (fd - want[i]).norm() < tol,
                                "{mode:?}, {what}, particle {a} axis {axis}, at {i}: difference {fd} against blocks {}",
                                want[i]
                            );
                        }
                    };
                    let kx = apply(
                        &c.topology,
                        |k| lin.spring_stiffness[k].matrix(),
                        &lin.stiffness,
                        &u,
                    );
                    check(false, kx, "-df/dx");
                    // The strain springs' damping depends on x through their rate too; its
                    // block is checked in velocity only, like every damping block.
                    let cv = apply(
                        &c.topology,
                        |k| {
                            lin.spring_damping[k]
                                * lin.spring_stiffness[k].dir
                                * lin.spring_stiffness[k].dir.transpose()
                        },
                        &lin.damping,
                        &u,
                    );
                    check(true, cv, "-df/dv");
                }
            }
        }
    }
}
