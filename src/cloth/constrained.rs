//! The XPBD route ([`crate::Integrator::Xpbd`]): symplectic Euler on every force but the stiff
//! in-plane springs, then those springs projected as compliant constraints
//! (`integrate/xpbd.rs`), each particle's inverse mass carrying the water along its normal.
//!
//! The bend springs stay forces: they are soft (0.5 N/m against the stretch springs' 10 in the
//! underwater preset) and carry the look's ripples, which the explicit step resolves as it
//! always did. The automatic step leaves the constrained families out of its bound
//! (`auto_step.rs`).

use super::Cloth;
use crate::error::Error;
use crate::forces::{Inertia, Weights};
use crate::integrate::xpbd::runs::{self, RunPlan};
use crate::integrate::xpbd::{self, Batches, Compliance, InverseMass, Link};
use crate::integrate::StepSoa;
use crate::math::Vec3;
use crate::model::{Model, SpringDamping};
use crate::topology::{SpringKind, Topology};

/// The spring families the XPBD route makes constraints: the stiff in-plane ones.
pub(super) const CONSTRAINED: [SpringKind; 2] = [SpringKind::Stretch, SpringKind::Shear];

/// Whether the XPBD route makes springs of `kind` constraints.
pub(super) fn constrained(kind: SpringKind) -> bool {
    CONSTRAINED.contains(&kind)
}

/// The model the XPBD route's force pass reads: the constrained families without stiffness
/// and, with velocity damping, every family without damping (the constraints carry it, the
/// bend springs' as damping alone). Any other damping (fractional) stays a force.
pub(super) fn forces_model(m: &Model) -> Model {
    let mut f = *m;
    for kind in CONSTRAINED {
        match kind {
            SpringKind::Stretch => f.stretch_stiffness = 0.0,
            SpringKind::Shear => f.shear_stiffness = 0.0,
            SpringKind::Bend => f.bend_stiffness = 0.0,
        }
    }
    if m.spring_damping_mode == SpringDamping::Velocity {
        f.spring_damping_scale = [0.0; 3];
    }
    f
}

/// The constraints' buffers: the links (built once for the families that are on) and each
/// particle's inverse mass.
#[derive(Clone, Debug, Default)]
pub(super) struct ConstraintScratch {
    links: Batches,
    /// On a grid, the links as runs of blocks (`xpbd/runs.rs`) instead, and the particles'
    /// component arrays they are projected on.
    runs: Option<RunPlan>,
    particles: runs::Particles,
    /// Which families the links were built for (`None`: not built yet).
    built_for: Option<[bool; 3]>,
    inverse: Vec<InverseMass>,
}

impl ConstraintScratch {
    /// One pass over the links on the predicted positions `x` (`start`: where the substep
    /// began), as runs on a grid, as batches otherwise.
    fn project(&mut self, params: &[Compliance; 3], start: &[Vec3], x: &mut [Vec3]) {
        let Some(plan) = &self.runs else {
            xpbd::project(&self.links, params, &self.inverse, start, x);
            return;
        };
        let p = &mut self.particles;
        let each = self.inverse.iter().zip(x.iter().zip(start));
        for (i, (inv, (xi, si))) in each.enumerate() {
            for k in 0..3 {
                (p.x[k][i], p.start[k][i], p.u[k][i]) = (xi[k], si[k], inv.u[k]);
            }
            p.w[i] = inv.w;
        }
        runs::project(plan, params, p);
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = Vec3::new(p.x[0][i], p.x[1][i], p.x[2][i]);
        }
    }

    /// Builds the links of the families `on` (by [`SpringKind`] index) in the topology's spring
    /// order, unless they are built already; fails with out-of-memory when the room cannot be had.
    fn build(&mut self, t: &Topology, on: [bool; 3]) -> Result<(), Error> {
        if self.built_for == Some(on) {
            return Ok(());
        }
        self.built_for = None;
        let room = |what: &str| Error::out_of_memory(format!("XPBD: no room for the {what}"));
        let n = t.vertex_count();
        // A grid's links as runs of blocks (`xpbd/runs.rs`); any other mesh's as batches.
        (self.links, self.runs) = (Batches::default(), None);
        if t.grid_faces.is_some() {
            let on_runs = t.spring_runs.iter().filter(|r| on[usize::from(r.kind)]);
            let plan = RunPlan::of(
                on_runs.map(|r| runs::Run {
                    i0: r.first_vertex as usize,
                    offset: r.offset as usize,
                    rest: &t.spring_rest[r.first_spring as usize..(r.first_spring + r.len) as usize],
                    family: r.kind,
                }),
                n,
            )
            .ok_or_else(|| room("constraints' runs"))?;
            self.particles
                .ready(n)
                .ok_or_else(|| room("constraints' arrays"))?;
            self.runs = Some(plan);
        } else {
            let mut links = Vec::new();
            let count = t.springs.iter().filter(|s| on[s.kind as usize]).count();
            links.try_reserve_exact(count).map_err(|_| room("constraints"))?;
            links.extend(t.springs.iter().filter(|s| on[s.kind as usize]).map(|s| Link {
                i: s.i,
                j: s.j,
                rest: s.rest,
                family: s.kind as u8,
            }));
            self.links = Batches::of(&links, n).ok_or_else(|| room("constraints' batches"))?;
        }
        self.inverse
            .try_reserve_exact(n)
            .map_err(|_| room("inverse masses"))?;
        self.inverse.resize(n, InverseMass::default());
        self.built_for = Some(on);
        Ok(())
    }
}

impl Cloth {
    /// The XPBD route's step: the force pass without the constrained springs and symplectic
    /// Euler tile by tile, then the constraints. Returns false: the result is checked whole.
    pub(super) fn constrained_step(
        &mut self,
        h: f64,
        weights: Weights,
        step: StepSoa,
    ) -> Result<bool, Error> {
        let model = forces_model(&self.config.model);
        self.forces_and_explicit_step(h, weights, step, &model);
        self.project_constraints(h)?;
        Ok(false)
    }

    /// Projects the constrained springs once on the predicted positions (hard pins at their
    /// goals, not moved) and sets every free particle's velocity to its move over `h`.
    fn project_constraints(&mut self, h: f64) -> Result<(), Error> {
        let (m, t) = (&self.config.model, &self.topology);
        let stiffness = |kind: SpringKind| m.stiffness(kind, t.spacing);
        let kinds = [SpringKind::Stretch, SpringKind::Shear, SpringKind::Bend];
        let velocity = m.spring_damping_mode == SpringDamping::Velocity;
        let damping = |k: SpringKind| if velocity { m.spring_damping_of(k) } else { 0.0 };
        let held = |k: SpringKind| if constrained(k) { stiffness(k) } else { 0.0 };
        let on = kinds.map(|k| held(k) > 0.0 || damping(k) > 0.0);
        let s = &mut self.scratch;
        s.constraints.build(t, on)?;
        let params = kinds.map(|k| Compliance::of(held(k), damping(k), h));
        let water = crate::forces::carries_water(m);
        let normals = s.force_pass.normals();
        let c = &mut s.constraints;
        for (i, inv) in c.inverse.iter_mut().enumerate() {
            *inv = if self.pins.pinned[i] {
                InverseMass::default()
            } else if water {
                let p = s.projected.get(i).copied().unwrap_or(1.0);
                let inertia = Inertia::of(m, t.masses[i], t.areas[i], normals[i], p);
                InverseMass::of(inertia.isotropic(), inertia.normal_mass, inertia.normal)
            } else {
                InverseMass::of(t.masses[i], 0.0, Vec3::z())
            };
        }
        for &p in &self.pins.list {
            if self.pins.pinned[p as usize] {
                s.x_new[p as usize] = s.pins.goal[p as usize];
            }
        }
        c.project(&params, &self.state.x, &mut s.x_new);
        let x = &self.state.x;
        for (i, (v, xn)) in s.v_new.iter_mut().zip(s.x_new.iter()).enumerate() {
            if !self.pins.pinned[i] {
                *v = (xn - x[i]) / h;
            }
        }
        Ok(())
    }
}
