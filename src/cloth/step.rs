//! One step of a cloth, as a list of named passes ([`Cloth::advance`]).
//!
//! Read top to bottom, `advance` is the step. Each pass is a method below with a one-line doc;
//! the route from forces to the new state is chosen in one place, [`Route::of`]. Models of this
//! shape: NVIDIA NvCloth's `SwSolverKernel::iterateCloth` (a short list of named calls) and
//! avian's `schedule.rs` (the steps listed where they run).

use std::sync::atomic::{AtomicBool, Ordering};

use super::plan::StepPlan;
use super::{prepass, Cloth, FAR_STEP, MAX_COORDINATE};
use crate::error::Error;
use crate::forces::{self, ForceInput, ForceScratch, Memory, SpringInputs, Weights, TILE};
use crate::integrate::{self, implicit_euler, ImplicitInput, StepSoa};
use crate::math::Vec3;
use crate::parallel;

/// What [`Cloth::advance`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Advanced {
    /// The step is committed.
    Taken,
    /// Nothing is committed: a free vertex would move this many times the step limit
    /// ([`StepLimit::Refuse`] only). Self-collision's remembered pairs may have changed: the
    /// driver restores them.
    TooFar(f64),
}

/// How a step goes from forces to the new state, chosen by [`Route::of`]:
///
/// | integrator | forces reach the integrator as | state written |
/// |---|---|---|
/// | explicit or symplectic Euler | each tile's totals, in cache, from the force pass ([`forces::for_each_tile`]; a grid's tiles read a window of the step's arrays, any other topology's are gathered per tile) | tile by tile, checked as it is written |
/// | implicit Euler | one force array ([`forces::total_forces_with`]), then the linearised system solved by CG | whole arrays, checked after |
/// | XPBD | as symplectic Euler, without the constrained springs' forces; then the constraints projected (`constrained.rs`) | tile by tile, then whole arrays, checked after |
///
/// Friction, pins and the checks follow as passes of their own on every route.
#[derive(Clone, Copy)]
pub(super) enum Route {
    /// An explicit integrator's step on a tile's component arrays.
    ExplicitTiles(StepSoa),
    /// Linearised backward Euler on whole arrays.
    Implicit,
    /// An explicit step without the constrained springs, then their constraints projected.
    Constrained(StepSoa),
}

impl Route {
    pub(super) fn of(integrator: integrate::Integrator) -> Route {
        match integrator.explicit_step_soa() {
            Some(step) if integrator.is_constrained() => Route::Constrained(step),
            Some(step) => Route::ExplicitTiles(step),
            None => Route::Implicit,
        }
    }
}

/// What the force pass reads, from the cloth `$c` and its step scratch `$s` (borrowed apart,
/// so that the pass may write the scratch's other buffers).
macro_rules! force_input {
    ($c:ident, $s:ident, $weights:expr) => {
        force_input!($c, $s, $weights, &$c.config.model)
    };
    ($c:ident, $s:ident, $weights:expr, $model:expr) => {
        ForceInput {
            model: $model,
            topology: &$c.topology,
            x: &$c.state.x,
            v: &$s.v_step,
            half_derivative: &$s.half,
            colliders: &$c.colliders,
            prior_forces: &$s.prior_forces,
            weights: $weights,
            skin_mean: &$c.state.skin_mean,
        }
    };
}

/// The step's first pass (`prepass::FirstPass`) of cloth `$c` with scratch `$s`, for `$plan`,
/// its history `$past`, and the component arrays of positions and damping rates `$sx`, `$sq`
/// (each three slices, empty when the spring pass does not read them).
macro_rules! first_pass {
    ($c:ident, $s:ident, $plan:expr, $past:expr, $sx:expr, $sq:expr) => {
        prepass::FirstPass {
            x: &$c.state.x,
            v: &$c.state.v,
            goal: &$s.pins.goal,
            hard_pins: &$s.pins.hard,
            h: $plan.h,
            sampling: $plan.sampling,
            current: $c.config.model.current,
            rate: forces::spring_rate(&$c.config.model),
            past: $past.as_ref(),
            v_step: parallel::Disjoint::new(&mut $s.v_step),
            v_rel: parallel::Disjoint::new(&mut $s.v_rel),
            half: parallel::Disjoint::new(&mut $s.half),
            sx: $sx.map(parallel::Disjoint::new),
            sq: $sq.map(parallel::Disjoint::new),
        }
    };
}

/// A whole-cloth pass between the step's velocities and the force pass: what it is, when it
/// does anything (each reads the step's velocities), and how it runs (it handles its own off
/// state).
struct PriorPass {
    #[allow(dead_code)] // named for the reader and a debugger
    name: &'static str,
    on: fn(&Cloth) -> bool,
    run: fn(&mut Cloth, &StepPlan, &mut Weights) -> Result<(), Error>,
}

/// The whole-cloth passes before the force pass, in the order [`Cloth::advance`] runs them.
/// The step's first pass runs inside the force pass ([`Cloth::fused_route`]) only when none is
/// on, so a pass added here is both run and waited for.
const PRIOR_PASSES: [PriorPass; 4] = [
    PriorPass {
        name: "the pair elements' own passes",
        on: |c| forces::prior_elements_on(&c.config.model),
        run: |c, _, weights| {
            c.element_forces(weights);
            Ok(())
        },
    },
    PriorPass {
        name: "the carried water's turning forces",
        on: |c| c.config.model.water.normal_water(),
        run: |c, _, _| c.water_turning(),
    },
    PriorPass {
        name: "the wide form drag",
        on: |c| forces::wide_drag(&c.config.model),
        run: |c, _, _| {
            c.wide_form_drag();
            Ok(())
        },
    },
    PriorPass {
        name: "collisions (mesh colliders, self-collision)",
        on: |c| c.mesh_slots.iter().any(Option::is_some) || c.config.model.self_collision_on(),
        run: |c, plan, _| c.collisions(plan.fraction),
    },
];

impl Cloth {
    /// One step as `plan` says. Nothing is committed unless every pass succeeds and the step
    /// is [`Advanced::Taken`].
    pub(super) fn advance(&mut self, plan: StepPlan) -> Result<Advanced, Error> {
        let h = plan.h;
        self.prepare()?;
        self.pin_goals(&plan);
        // The first pass inside the force pass when nothing between them reads it.
        let fused = self.fused_route();
        let mut weights = match fused {
            Some(_) => Weights::default(),
            None => self.step_velocities(&plan),
        };
        for pass in &PRIOR_PASSES {
            (pass.run)(self, &plan, &mut weights)?;
        }
        let integrated_sound = match (fused, Route::of(self.config.integrator)) {
            (Some(step), _) => self.velocities_forces_and_explicit_step(&plan, weights, step),
            (None, Route::ExplicitTiles(step)) => {
                let model = self.config.model;
                self.forces_and_explicit_step(h, weights, step, &model)
            }
            (None, Route::Implicit) => self.forces_and_implicit_step(h, weights)?,
            (None, Route::Constrained(step)) => self.constrained_step(h, weights, step)?,
        };
        let friction = self.friction(h) | self.contact_friction(h);
        let limited = match self.limit_collision_step(&plan) {
            super::collisions::Limited::Over(ratio) => return Ok(Advanced::TooFar(ratio)),
            super::collisions::Limited::Slowed(count) => {
                self.splitter.stats.slowed += count as u64;
                count > 0
            }
        };
        self.pins(h);
        let carried = self.carry_through_meshes(h, plan.from, plan.fraction);
        self.mesh_carried += carried as u64;
        let carried = carried > 0;
        let zoned = self.impact_zones(h)? > 0;
        self.check(h, integrated_sound && !friction && !limited && !carried && !zoned)?;
        if zoned {
            self.learn_stopped_sides();
        }
        self.commit(h);
        Ok(Advanced::Taken)
    }

    /// Sizes the step's buffers and lets the histories make room for the step.
    fn prepare(&mut self) -> Result<(), Error> {
        self.state.histories.reserve_step()?;
        let n = self.vertex_count();
        let s = &mut self.scratch;
        for buf in [&mut s.v_step, &mut s.half, &mut s.x_new, &mut s.v_new] {
            buf.resize(n);
        }
        for buf in [&mut s.v_rel, &mut s.pins.goal] {
            buf.resize(n, Vec3::zeros());
        }
        Ok(())
    }

    /// One pass over the particles: the step's velocities (pins' from their goals), the
    /// velocity relative to the water, D^{1/2}x = w0 v + H of it (the history folds the last
    /// accepted step in here), and, for an untiled topology, the component arrays the spring
    /// pass reads. Returns the memories' weights, the particles' w0 filled in.
    fn step_velocities(&mut self, plan: &StepPlan) -> Weights {
        let n = self.vertex_count();
        let s = &mut self.scratch;
        let history = self.state.histories.get_mut(Memory::Particles);
        let with_history = !history.is_off();
        // The history folds the last accepted step in during this pass (SOE).
        let past = with_history.then(|| history.begin_step());
        // A tile walk transposes its own spring inputs; only other topologies need them here.
        let arrays = self.topology.tiled.is_none();
        let (sx, sq) = s.force_pass.spring_arrays(if arrays { n } else { 0 });
        let first = first_pass!(self, s, plan, past, sx.slices_mut(), sq.slices_mut());
        let w0 = first.w0();
        parallel::for_chunks(parallel::worth_it(n), n, parallel::CHUNK, |lo, len| {
            // SAFETY: every particle once, in chunks (which start on multiples of TILE).
            unsafe { first.run(lo..lo + len) };
        });
        if with_history {
            self.state.histories.get_mut(Memory::Particles).end_step();
        }
        let mut weights = Weights::default();
        weights.0[Memory::Particles.index()] = w0;
        weights
    }

    /// The explicit step whose first pass over the particles ([`Self::step_velocities`]) runs
    /// inside the force pass, when nothing between the two reads what it writes: a tiled
    /// topology, no water carried along the normal, no wide form drag, no pair element with a
    /// pass of its own, no mesh collider and no self-collision. `FRACCLOTH_FUSE=0` (read once)
    /// turns it off, for measuring. The same operations in the same order for each particle as
    /// the two passes one after the other: the same bits.
    fn fused_route(&self) -> Option<StepSoa> {
        let Route::ExplicitTiles(step) = Route::of(self.config.integrator) else {
            return None;
        };
        let fusable = self.topology.tiled.is_some()
            && !PRIOR_PASSES.iter().any(|pass| (pass.on)(self))
            && fuse_enabled();
        fusable.then_some(step)
    }

    /// [`Self::step_velocities`] and [`Self::forces_and_explicit_step`] in one pass over
    /// memory ([`Self::fused_route`]); returns whether every result it wrote was sound.
    fn velocities_forces_and_explicit_step(
        &mut self,
        plan: &StepPlan,
        mut weights: Weights,
        step: StepSoa,
    ) -> bool {
        let s = &mut self.scratch;
        let history = self.state.histories.get_mut(Memory::Particles);
        let with_history = !history.is_off();
        let past = with_history.then(|| history.begin_step());
        // A tiled topology: the walk transposes its own spring inputs.
        let none = || -> [&mut [f64]; 3] { [&mut [], &mut [], &mut []] };
        let first = first_pass!(self, s, plan, past, none(), none());
        weights.0[Memory::Particles.index()] = first.w0();
        // SAFETY: the force pass runs every particle once, in ranges that start on multiples
        // of TILE, and reads none while it runs (`forces::Ahead`).
        let run = |r: std::ops::Range<usize>, v: &mut [Vec3], half: &mut [Vec3]| unsafe {
            first.run_into(r, v, half)
        };
        let ahead = forces::Ahead { run: &run };
        let input = ForceInput {
            model: &self.config.model,
            topology: &self.topology,
            x: &self.state.x,
            v: &[],
            half_derivative: &[],
            colliders: &self.colliders,
            prior_forces: &s.prior_forces,
            weights,
            skin_mean: &self.state.skin_mean,
        };
        let sound = explicit_tiles(
            &input,
            &mut s.force_pass,
            Some(&ahead),
            (&mut s.x_new, &mut s.v_new),
            &s.projected,
            self.config.max_speed,
            plan.h,
            step,
        );
        if with_history {
            self.state.histories.get_mut(Memory::Particles).end_step();
        }
        sound
    }

    /// The pair elements with a pass of their own (`forces::elements`): each memory's rates
    /// from the step's velocities, its past, and their forces, into the prior forces; fills in
    /// those memories' weights.
    fn element_forces(&mut self, weights: &mut Weights) {
        let (s, histories) = (&mut self.scratch, &mut self.state.histories);
        let memory_past = |memory: Memory, out: &mut [Vec3]| {
            let history = histories.get_mut(memory);
            let past = history.begin_step();
            let w0 = past.current_weight();
            // SAFETY: one call covers every entry once.
            unsafe { past.past_range(0, out) };
            history.end_step();
            weights.0[memory.index()] = w0;
            w0
        };
        forces::prior_forces(
            &self.config.model,
            &self.topology,
            &self.state.x,
            &s.v_step,
            &mut s.elements,
            memory_past,
            &mut s.prior_forces,
        );
    }

    /// The carried water's forces as the normals turn (`dT/dx - (dM/dt) v`,
    /// [`forces::turning_forces`]), added to the forces before the pass; nothing without
    /// normal added mass.
    fn water_turning(&mut self) -> Result<(), Error> {
        let (s, t) = (&mut self.scratch, &self.topology);
        let w = &self.config.model.water;
        if !w.normal_water() {
            s.projected.clear();
            s.coarse = None;
            return Ok(());
        }
        if s.prior_forces.is_empty() {
            s.prior_forces.resize(self.state.x.len(), Vec3::zeros());
        }
        s.projected.resize(self.state.x.len(), 0.0);
        let m = &self.config.model;
        let wanted = (w.coarse_added_mass, w.coarse_length);
        if wanted.0 == 0.0 {
            s.coarse = None;
        } else if s
            .coarse
            .as_ref()
            .is_none_or(|c| !c.built_for(wanted.0, wanted.1, &self.pins.pinned))
        {
            s.coarse = Some(forces::coarse_water::CoarseWater::new(
                t,
                wanted.0,
                wanted.1,
                &self.pins.pinned,
            )?);
        }
        let normals = s.force_pass.normals_to_write(self.state.x.len());
        forces::turning_forces(
            m,
            t,
            &self.state.x,
            &s.v_rel,
            &mut s.turning,
            &mut s.projected,
            normals,
            &mut s.prior_forces,
            s.coarse.as_mut(),
        );
        Ok(())
    }

    /// Form drag on the smoothed normal velocity ([`forces::add_wide_form_drag`]), added to
    /// the forces before the pass; nothing unless the model gives it a length.
    fn wide_form_drag(&mut self) {
        let m = &self.config.model;
        if !forces::wide_drag(m) {
            return;
        }
        let (s, t) = (&mut self.scratch, &self.topology);
        if s.prior_forces.is_empty() {
            s.prior_forces.resize(self.state.x.len(), Vec3::zeros());
        }
        let normals = s.force_pass.normals_ahead(&self.state.x, t);
        forces::add_wide_form_drag(m, t, normals, &s.v_rel, &mut s.wide_drag, &mut s.prior_forces);
    }

    /// The force pass with an explicit integrator stepping each tile in cache; returns whether
    /// every result it wrote was sound.
    /// `model`: the cloth's, or the one its forces come from beside constraints.
    pub(super) fn forces_and_explicit_step(
        &mut self,
        h: f64,
        weights: Weights,
        step: StepSoa,
        model: &crate::Model,
    ) -> bool {
        if self.scratch.coarse.is_some() {
            return self.forces_coarse_and_explicit_step(h, weights, step, model);
        }
        let s = &mut self.scratch;
        let input = force_input!(self, s, weights, model);
        explicit_tiles(
            &input,
            &mut s.force_pass,
            None,
            (&mut s.x_new, &mut s.v_new),
            &s.projected,
            self.config.max_speed,
            h,
            step,
        )
    }

    /// The force pass of `model` into the one force array (`scratch.force_array`).
    fn forces_into_array(&mut self, weights: Weights, model: &crate::Model) {
        let n = self.vertex_count();
        let s = &mut self.scratch;
        s.force_array.resize(n, Vec3::zeros());
        let input = force_input!(self, s, weights, model);
        forces::total_forces_with(
            &input,
            &mut s.force_pass,
            SpringInputs::Filled,
            &mut s.force_array,
        );
    }

    /// The force pass into one array, the coarse water's Woodbury solve, then the explicit
    /// step tile by tile.
    fn forces_coarse_and_explicit_step(
        &mut self,
        h: f64,
        weights: Weights,
        step: StepSoa,
        model: &crate::Model,
    ) -> bool {
        self.forces_into_array(weights, model);
        let n = self.vertex_count();
        let s = &mut self.scratch;
        let t = &self.topology;
        let Some(coarse) = s.coarse.as_mut() else {
            return false;
        };
        coarse.effective_forces(
            &self.config.model,
            t,
            s.force_pass.normals(),
            &s.projected,
            &mut s.force_array,
        );
        let max_speed2 = self.config.max_speed * self.config.max_speed;
        let mut ok = true;
        let mut lo = 0;
        while lo < n {
            let hi = (lo + TILE).min(n);
            let len = hi - lo;
            let mut a = [[0.0; TILE]; 9];
            for k in 0..len {
                let (xk, vk, fk) = (self.state.x[lo + k], s.v_step[lo + k], s.force_array[lo + k]);
                for c in 0..3 {
                    a[c][k] = xk[c];
                    a[3 + c][k] = vk[c];
                    a[6 + c][k] = fk[c];
                }
            }
            let input = integrate::StepInput {
                h,
                x: [&a[0][..len], &a[1][..len], &a[2][..len]],
                v: [&a[3][..len], &a[4][..len], &a[5][..len]],
                force: [&a[6][..len], &a[7][..len], &a[8][..len]],
                masses: &t.masses[lo..hi],
                max_speed2,
            };
            ok &= step(&input, &mut s.x_new[lo..hi], &mut s.v_new[lo..hi]);
            lo = hi;
        }
        ok
    }

    /// The force pass into one array, then linearised backward Euler solved by CG; refused
    /// when the solver stops above its tolerance (unless accepted). The result is checked by
    /// [`Self::check`], so this returns false (not checked here).
    fn forces_and_implicit_step(&mut self, h: f64, weights: Weights) -> Result<bool, Error> {
        let model = self.config.model;
        self.forces_into_array(weights, &model);
        let n = self.vertex_count();
        let s = &mut self.scratch;
        let input = force_input!(self, s, weights);
        forces::linearise(&input, s.force_pass.normals(), &s.projected, &mut s.implicit.lin);
        let inp = ImplicitInput {
            h,
            x: &self.state.x,
            v: &s.v_step,
            force: &s.force_array,
            masses: &self.topology.masses,
            topology: &self.topology,
            pinned: &self.pins.pinned,
            settings: self.config.solver,
            contacts: &s.contacts,
            contact_stiffness: self.config.model.collision_stiffness,
            contact_damping: self.config.model.collision_damping,
            coarse: s
                .coarse
                .as_ref()
                .map(|c| (c, s.force_pass.normals(), &s.projected[..])),
        };
        self.solver_stats = implicit_euler(&inp, &mut s.implicit, &mut s.v_new);
        let st = self.solver_stats;
        if st.residual > self.config.solver.tolerance && !self.config.accept_unconverged {
            return Err(Error::not_converged(format!(
                "the implicit solver stopped after {} iterations at relative residual {:.3e}, above its tolerance {:e}; state left unchanged: raise solver_max_iterations, loosen solver_tolerance, shorten dt, or accept such steps",
                st.iterations, st.residual, self.config.solver.tolerance
            )));
        }
        for i in 0..n {
            s.x_new[i] = self.state.x[i] + h * s.v_new[i];
        }
        Ok(false)
    }

    /// Coulomb friction with the colliders, as a velocity correction; says whether any applied.
    fn friction(&mut self, h: f64) -> bool {
        let on = forces::friction_active(&self.colliders, &self.friction);
        forces::apply_friction(
            &self.config.model,
            &self.colliders,
            &self.friction,
            h,
            &self.state.x,
            &self.topology.masses,
            &self.pins.pinned,
            &mut self.scratch.v_new,
        );
        on
    }

    /// Refuses a proposed state that is not finite, too fast, or beyond the float range.
    /// `integrated_sound`: every particle the integrator wrote was checked and sound, so only
    /// what the pins changed is checked again.
    fn check(&self, h: f64, integrated_sound: bool) -> Result<(), Error> {
        let pins_sound = || self.pins.list.iter().all(|&i| !self.unsound(i as usize));
        if !(integrated_sound && pins_sound()) {
            self.check_sound(h)?;
        }
        if h * self.config.max_speed > FAR_STEP {
            self.check_in_range(h)?;
        }
        Ok(())
    }

    /// Makes the proposed state the cloth's and records the step in every memory: the
    /// particles' displacements by their velocities relative to the water, the others by the
    /// rates their elements' passes wrote.
    fn commit(&mut self, h: f64) {
        let s = &mut self.scratch;
        std::mem::swap(&mut self.state.x, &mut s.x_new);
        std::mem::swap(&mut self.state.v, &mut s.v_new);
        if !self.state.skin_mean.is_empty() {
            let (m, v) = (&self.config.model, &self.state.v[..]);
            if parallel::worth_it(v.len()) {
                use rayon::prelude::*;
                self.state
                    .skin_mean
                    .par_chunks_mut(parallel::CHUNK)
                    .zip(v.par_chunks(parallel::CHUNK))
                    .for_each(|(mean, v)| forces::follow_skin_mean(m, v, h, mean));
            } else {
                forces::follow_skin_mean(m, v, h, &mut self.state.skin_mean);
            }
        }
        for memory in Memory::ALL {
            let history = self.state.histories.get_mut(memory);
            if history.is_off() {
                continue;
            }
            let rates = match memory {
                Memory::Particles => &mut s.v_rel,
                Memory::Springs => &mut s.elements.rates,
            };
            history.record(rates, h);
        }
        self.state.time += h;
        self.state.steps += 1;
    }

    /// Whether the proposed state of particle `i` is not finite or faster than `max_speed`.
    fn unsound(&self, i: usize) -> bool {
        let (x, v) = (&self.scratch.x_new[i], &self.scratch.v_new[i]);
        !integrate::sound_particle(
            [x.x, x.y, x.z],
            [v.x, v.y, v.z],
            self.config.max_speed * self.config.max_speed,
        )
    }

    fn check_sound(&self, dt: f64) -> Result<(), Error> {
        let s = &self.scratch;
        let vmax2 = self.config.max_speed * self.config.max_speed;
        let (x, v) = (&s.x_new, &s.v_new);
        let bad = |i: usize| self.unsound(i);
        let clean = |r: std::ops::Range<usize>| integrate::sound(&x[r.clone()], &v[r], vmax2);
        match parallel::first_failing(parallel::worth_it(x.len()), x.len(), clean, bad) {
            None => Ok(()),
            Some(i) => Err(Error::unstable(format!(
                "{} with dt = {dt} s is unstable at step {}: vertex {i} would reach speed {:.3e} m/s (limit {} m/s); state left unchanged, retry with a smaller dt (max_substep = FC_MAX_SUBSTEP_AUTO lets the library choose the substeps; or set max_substep, or call fc_cloth_step_substeps)",
                self.config.integrator.name(),
                self.state.steps,
                v[i].norm(),
                self.config.max_speed
            ))),
        }
    }

    /// Refuses a step whose positions leave the float range (see [`FAR_STEP`]).
    fn check_in_range(&self, dt: f64) -> Result<(), Error> {
        match self.scratch.x_new.iter().position(|x| x.amax() >= MAX_COORDINATE) {
            None => Ok(()),
            Some(i) => Err(Error::unstable(format!(
                "{} with dt = {dt} s would move vertex {i} beyond the float range ({:.3e} m); state left unchanged, retry with a smaller dt (max_substep = FC_MAX_SUBSTEP_AUTO lets the library choose the substeps; or set max_substep, or call fc_cloth_step_substeps)",
                self.config.integrator.name(),
                self.scratch.x_new[i].amax()
            ))),
        }
    }
}

/// Whether the first pass may run inside the force pass (`FRACCLOTH_FUSE`, read once: `0`
/// turns it off).
fn fuse_enabled() -> bool {
    #[cfg(test)]
    if tests::UNFUSED.load(Ordering::Relaxed) {
        return false;
    }
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| std::env::var("FRACCLOTH_FUSE").map_or(true, |v| v.trim() != "0"))
}

/// The force pass with an explicit integrator stepping each tile in cache into `x_new`,
/// `v_new` (`ahead`: the first pass run as it goes); returns whether every result it wrote
/// was sound.
#[allow(clippy::too_many_arguments)] // the step's arrays, borrowed apart
fn explicit_tiles(
    input: &ForceInput<'_>,
    force_pass: &mut ForceScratch,
    ahead: Option<&forces::Ahead<'_>>,
    (x_new, v_new): (&mut [Vec3], &mut [Vec3]),
    projected: &[f64],
    max_speed: f64,
    h: f64,
    step: StepSoa,
) -> bool {
    let model = input.model;
    let (masses, areas) = (&input.topology.masses, &input.topology.areas);
    let max_speed2 = max_speed * max_speed;
    let all_sound = AtomicBool::new(true);
    let (x_new, v_new) = (parallel::Disjoint::new(x_new), parallel::Disjoint::new(v_new));
    forces::for_each_tile_ahead(input, force_pass, SpringInputs::Filled, ahead, |tile| {
        let r = tile.p0..tile.p0 + tile.force[0].len();
        // SAFETY: each tile is handed over once and tiles are disjoint.
        let (xn, vn) = unsafe { (x_new.range(r.clone()), v_new.range(r.clone())) };
        // With the water's inertia the step needs M^{-1} f (`forces/inertia.rs`).
        let mut effective;
        let force = match (forces::carries_water(model), tile.normals) {
            (true, Some(n)) => {
                let len = r.len();
                effective = [[0.0; TILE]; 3];
                forces::effective_forces(
                    model,
                    &masses[r.clone()],
                    &areas[r.clone()],
                    n,
                    projected.get(r.clone()).unwrap_or(&[]),
                    tile.force,
                    &mut effective,
                );
                let [a, b, c] = &effective;
                [&a[..len], &b[..len], &c[..len]]
            }
            _ => tile.force,
        };
        let input = integrate::StepInput {
            h,
            x: tile.x,
            v: tile.v,
            force,
            masses: &masses[r],
            max_speed2,
        };
        if !step(&input, xn, vn) {
            all_sound.store(false, Ordering::Relaxed);
        }
    });
    all_sound.into_inner()
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicBool, Ordering};

    use crate::forces::{Collider, Sphere};
    use crate::history::Scheme;
    use crate::model::{Model, SpringDamping};
    use crate::{Cloth, ClothConfig, GridSpec, Integrator, Vec3};

    /// Set by the test below: steps run their two passes apart (on whichever thread a cloth
    /// steps; other tests stepping meanwhile take the same bits either way).
    pub(super) static UNFUSED: AtomicBool = AtomicBool::new(false);

    /// A `w` x `h` cloth of `model` with a pinned top row moving sideways, a half-weight pin,
    /// a current and a sphere, stepped `steps` times on `threads` threads with the first pass
    /// inside the force pass or apart; its positions and velocities.
    fn stepped(
        w: usize,
        h: usize,
        model: &Model,
        scheme: Scheme,
        threads: u32,
        steps: usize,
        unfused: bool,
    ) -> Vec<Vec3> {
        let t = GridSpec {
            width: w as u32,
            height: h as u32,
            spacing: 0.01,
            total_mass: 1e-4 * (w * h) as f64,
        }
        .build()
        .unwrap();
        let config = ClothConfig {
            model: *model,
            scheme,
            integrator: Integrator::SymplecticEuler,
            ..ClothConfig::default()
        };
        let mut c = Cloth::new(t, config).unwrap();
        c.set_threads(threads).unwrap();
        let top: Vec<u32> = (0..w as u32).collect();
        c.set_pinned(&top).unwrap();
        c.pin_group(&[(w + 3) as u32], 0.5).unwrap();
        c.set_current(Vec3::new(0.02, 0.0, 0.05)).unwrap();
        c.add_collider(Collider::Sphere(Sphere {
            center: Vec3::new(0.05, -0.04, 0.02),
            radius: 0.03,
            velocity: Vec3::zeros(),
        }))
        .unwrap();
        UNFUSED.store(unfused, Ordering::Relaxed);
        for k in 0..steps {
            let targets: Vec<Vec3> = top
                .iter()
                .map(|&i| c.positions()[i as usize] + Vec3::new(1e-4 * k as f64, 0.0, 0.0))
                .collect();
            c.set_pin_targets(&top, &targets).unwrap();
            c.step(2e-4).unwrap();
        }
        UNFUSED.store(false, Ordering::Relaxed);
        c.positions().iter().chain(c.velocities()).copied().collect()
    }

    /// The first pass run inside the force pass gives the bits of the two passes apart: a
    /// 211 x 211 cloth (whose SOE history defers its folds) on one, two and three threads
    /// (the walk's tasks meet in bands the first pass runs before them), and small cloths with
    /// velocity damping and a truncated history.
    #[test]
    fn the_first_pass_inside_the_force_pass_gives_the_bits_of_the_two_apart() {
        let fractional = Model::fractional();
        for threads in [1, 2, 3] {
            let fused = stepped(211, 211, &fractional, Scheme::DEFAULT, threads, 5, false);
            let apart = stepped(211, 211, &fractional, Scheme::DEFAULT, threads, 5, true);
            assert!(fused.iter().all(|p| p.iter().all(|c| c.is_finite())));
            assert!(fused == apart, "211 x 211 on {threads} threads");
        }
        let velocity = Model {
            spring_damping_mode: SpringDamping::Velocity,
            spring_damping: 0.01,
            ..Model::fractional()
        };
        for (model, scheme) in [
            (&velocity, Scheme::PAPER),
            (&fractional, Scheme::Off),
            (&fractional, Scheme::PAPER),
        ] {
            let fused = stepped(31, 21, model, scheme, 1, 30, false);
            let apart = stepped(31, 21, model, scheme, 1, 30, true);
            assert!(fused == apart, "31 x 21, {}", scheme.name());
        }
    }
}
