//! One step of a cloth, as a list of named passes ([`Cloth::advance`]).
//!
//! Read top to bottom, `advance` is the step. Each pass is a method below with a one-line doc;
//! the route from forces to the new state is chosen in one place, [`Route::of`]. Models of this
//! shape: NVIDIA NvCloth's `SwSolverKernel::iterateCloth` (a short list of named calls) and
//! avian's `schedule.rs` (the steps listed where they run).

use std::sync::atomic::{AtomicBool, Ordering};

use super::{prepass, Cloth, FAR_STEP, MAX_COORDINATE};
use crate::error::Error;
use crate::forces::{self, ForceInput, ForceScratch, SpringInputs, TILE};
use crate::history::History;
use crate::integrate::{self, implicit_euler, ImplicitInput, ImplicitScratch, StepSoa};
use crate::math::Vec3;
use crate::parallel;

/// How a step goes from forces to the new state, chosen by [`Route::of`]:
///
/// | integrator | forces reach the integrator as | state written |
/// |---|---|---|
/// | explicit or symplectic Euler | each tile's totals, in cache, from the force pass ([`forces::for_each_tile`]; a grid's tiles read a window of the step's arrays, any other topology's are gathered per tile) | tile by tile, checked as it is written |
/// | implicit Euler | one force array ([`forces::total_forces_with`]), then the linearised system solved by CG | whole arrays, checked after |
///
/// Friction, pins and the checks follow as passes of their own on every route.
#[derive(Clone, Copy)]
pub(super) enum Route {
    /// An explicit integrator's step on a tile's component arrays.
    ExplicitTiles(StepSoa),
    /// Linearised backward Euler on whole arrays.
    Implicit,
}

impl Route {
    pub(super) fn of(integrator: integrate::Integrator) -> Route {
        match integrator.explicit_step_soa() {
            Some(step) => Route::ExplicitTiles(step),
            None => Route::Implicit,
        }
    }
}

/// Buffers a step reuses (no allocation in a step once they have grown).
#[derive(Clone, Debug, Default)]
pub(super) struct StepScratch {
    /// The step's velocity of every particle (pins' from their goals), m/s.
    pub v_step: Vec<Vec3>,
    /// Velocity relative to the water, m/s.
    pub v_rel: Vec<Vec3>,
    /// D^{1/2}x of the displacement relative to the water, m s^{-1/2}.
    pub half: Vec<Vec3>,
    /// Total forces as one array (the implicit route only), N.
    pub force_array: Vec<Vec3>,
    /// The state the step proposes; committed only if sound.
    pub x_new: Vec<Vec3>,
    pub v_new: Vec<Vec3>,
    /// Where every pin is at the end of the step.
    pub goal: Vec<Vec3>,
    /// Pin positions at the start of a multi-substep call.
    pub pin_start: Vec<Vec3>,
    /// Fully pinned particles, ascending.
    pub hard_pins: Vec<u32>,
    /// Goals of the pins (in `pin_list` order) for the first half step of an extrapolated
    /// step, used instead of `pin_goals`' when `mid_goal_set` (`extrapolate.rs`).
    pub mid_goal: Vec<Vec3>,
    pub mid_goal_set: bool,
    /// Rotation-invariant fractional springs only (`forces/strain.rs`): each spring's rate of
    /// elongation at the start of the step and the past part of its D^{1/2}, packed three
    /// springs to an entry.
    pub strain_rates: Vec<Vec3>,
    pub strain_past: Vec<Vec3>,
    /// Forces of the whole-cloth passes before the force pass (strain springs, the carried
    /// water's turning forces), one per particle; empty without them.
    pub prior_forces: Vec<Vec3>,
    /// The collision pass's contact elements (mesh colliders, self-collision).
    pub contacts: Vec<crate::collide::Contact>,
    pub turning: forces::TurningScratch,
    /// Each patch's projected-area ratio ([`forces::patch_normals`]), with normal added mass
    /// only (else empty).
    pub projected: Vec<f64>,
    pub force_pass: ForceScratch,
    pub implicit: ImplicitScratch,
}

/// State saved before a multi-substep call, restored if a substep fails (and around the whole
/// step of an extrapolated integrator).
#[derive(Clone, Debug, Default)]
pub(super) struct Rollback {
    pub(super) x: Vec<Vec3>,
    pub(super) v: Vec<Vec3>,
    history: Option<History>,
    strain_history: Option<History>,
    /// Self-collision's remembered pairs and sides (state: a snapshot carries them).
    self_collision: crate::collide::self_collision::SavedMemory,
    time: f64,
    steps: u64,
}

impl Rollback {
    /// Copies the state, or fails with an out-of-memory error when the copy of a history
    /// that grew (the full history) cannot be allocated.
    pub(super) fn save(&mut self, c: &Cloth) -> Result<(), Error> {
        use crate::history::HalfDerivative;
        let need = c.history.bytes_per_particle() as u64 * c.x.len() as u64
            + c.strain_history.bytes_per_particle() as u64
                * forces::strain::entries(c.topology.springs.len()) as u64;
        let have = self
            .history
            .as_ref()
            .map_or(0, |h| h.bytes_per_particle() as u64 * c.x.len() as u64);
        if need > have {
            crate::memory::ensure_available(
                2 * (need - have),
                "the copy that makes a multi-substep call atomic",
            )?;
        }
        self.x.clone_from(&c.x);
        self.v.clone_from(&c.v);
        match &mut self.history {
            Some(h) => h.clone_from(&c.history),
            None => self.history = Some(c.history.clone()),
        }
        match &mut self.strain_history {
            Some(h) => h.clone_from(&c.strain_history),
            None => self.strain_history = Some(c.strain_history.clone()),
        }
        c.self_collision.save_memory(&mut self.self_collision);
        self.time = c.time;
        self.steps = c.steps;
        Ok(())
    }

    pub(super) fn restore(&mut self, c: &mut Cloth) {
        std::mem::swap(&mut c.x, &mut self.x);
        std::mem::swap(&mut c.v, &mut self.v);
        if let Some(h) = &mut self.history {
            std::mem::swap(&mut c.history, h);
        }
        if let Some(h) = &mut self.strain_history {
            std::mem::swap(&mut c.strain_history, h);
        }
        c.self_collision.swap_memory(&mut self.self_collision);
        c.time = self.time;
        c.steps = self.steps;
    }
}

impl Cloth {
    /// One step of size `h`. Pins go to `pin_start + fraction (target - pin_start)`, or to
    /// their targets when `fraction` is None. Nothing is committed unless every pass succeeds.
    pub(super) fn advance(&mut self, h: f64, fraction: Option<f64>) -> Result<(), Error> {
        self.prepare()?;
        self.pin_goals(fraction);
        let w0 = self.step_velocities(h);
        let strain_w0 = self.strain_damping();
        self.water_turning();
        self.collisions(fraction);
        let integrated_sound = match Route::of(self.config.integrator) {
            Route::ExplicitTiles(step) => self.forces_and_explicit_step(h, strain_w0, step),
            Route::Implicit => self.forces_and_implicit_step(h, w0, strain_w0)?,
        };
        let friction = self.friction(h) | self.contact_friction(h);
        let limited = self.limit_collision_step() > 0;
        self.pins(h);
        self.check(h, integrated_sound && !friction && !limited)?;
        self.commit(h);
        Ok(())
    }

    /// Sizes the step's buffers and lets the histories make room for the step.
    fn prepare(&mut self) -> Result<(), Error> {
        self.history.reserve_step()?;
        self.strain_history.reserve_step()?;
        let n = self.vertex_count();
        let s = &mut self.scratch;
        for buf in [
            &mut s.v_step,
            &mut s.v_rel,
            &mut s.half,
            &mut s.x_new,
            &mut s.v_new,
            &mut s.goal,
        ] {
            buf.resize(n, Vec3::zeros());
        }
        Ok(())
    }

    /// Where every pin is at the end of the step: its target, or the `fraction` of the way
    /// there from where a multi-substep call started.
    fn pin_goals(&mut self, fraction: Option<f64>) {
        let s = &mut self.scratch;
        if s.mid_goal_set {
            for (k, &i) in self.pin_list.iter().enumerate() {
                s.goal[i as usize] = s.mid_goal[k];
            }
            return;
        }
        for (k, &i) in self.pin_list.iter().enumerate() {
            let i = i as usize;
            s.goal[i] = match fraction {
                Some(f) => s.pin_start[k] + f * (self.pin_target[i] - s.pin_start[k]),
                None => self.pin_target[i],
            };
        }
    }

    /// One pass over the particles: the step's velocities (pins' from their goals), the
    /// velocity relative to the water, D^{1/2}x = w0 v + H of it (the history folds the last
    /// accepted step in here), and, for an untiled topology, the component arrays the spring
    /// pass reads. Returns w0, the current-velocity weight of D^{1/2}.
    fn step_velocities(&mut self, h: f64) -> f64 {
        let n = self.vertex_count();
        let s = &mut self.scratch;
        let par = parallel::worth_it(n);
        let with_history = !self.history.is_off();
        // The history folds the last accepted step in during this pass (SOE).
        let past = with_history.then(|| self.history.begin_step());
        let w0 = past.as_ref().map_or(0.0, |p| p.current_weight());
        // Fully pinned particles, ascending, to find those of a tile by bisection.
        s.hard_pins.clear();
        s.hard_pins
            .extend(self.pin_list.iter().filter(|&&i| self.pinned[i as usize]));
        s.hard_pins.sort_unstable();
        let hard_pins = &s.hard_pins;
        let rate = forces::spring_rate(&self.config.model);
        let current = self.config.model.current;
        // A hard pin's step velocity is its goal's secant, the velocity half a step ahead. The
        // second-order integrators give the history (and this step's D^{1/2}) the slope of the
        // pin's path at the start of the (half) step instead: the history keeps every sample, so
        // a first-order error in them would never be extrapolated away. Its stored velocity is
        // read as the last secant, half a step back (what extrapolated symplectic Euler leaves
        // it; extrapolated implicit Euler extrapolates it and measured best so), giving the mean
        // of it and this secant; in the first half step, whose secant reaches only a quarter
        // step ahead, `(S_prev + 2 S_1) / 3`. The first-order integrators keep the secant.
        let integrator = self.config.integrator;
        let central_pins = integrator.is_extrapolated();
        let start_pins = central_pins && !integrator.is_implicit();
        let first_half = s.mid_goal_set;
        // A tile walk transposes its own spring inputs; only other topologies need them here.
        let arrays = self.topology.tiled.is_none();
        let (sx, sq) = s.force_pass.spring_arrays(if arrays { n } else { 0 });
        // This chunk's part of a component array, or nothing when the arrays are not kept.
        fn part<'a>(a: &parallel::Disjoint<'a, f64>, r: std::ops::Range<usize>) -> &'a mut [f64] {
            if a.is_empty() {
                return &mut [];
            }
            // SAFETY: every task borrows only its own chunk `r` of each array.
            unsafe { a.range(r) }
        }
        let (x, v, goal) = (&self.x, &self.v, &s.goal);
        let (v_step, v_rel, half) = (
            parallel::Disjoint::new(&mut s.v_step),
            parallel::Disjoint::new(&mut s.v_rel),
            parallel::Disjoint::new(&mut s.half),
        );
        let [sx, sy, sz] = sx.slices_mut().map(parallel::Disjoint::new);
        let [qx, qy, qz] = sq.slices_mut().map(parallel::Disjoint::new);
        parallel::for_chunks(par, n, parallel::CHUNK, |first, len| {
            let r = first..first + len;
            // SAFETY: every task borrows only its own chunk `r` of each array.
            let (v_step, v_rel, half) = unsafe {
                (
                    v_step.range(r.clone()),
                    v_rel.range(r.clone()),
                    half.range(r.clone()),
                )
            };
            let (sx, sy, sz) = (part(&sx, r.clone()), part(&sy, r.clone()), part(&sz, r.clone()));
            let (qx, qy, qz) = (part(&qx, r.clone()), part(&qy, r.clone()), part(&qz, r.clone()));
            let (x, v) = (&x[r.clone()], &v[r.clone()]);
            // Tile by tile, so that the loops below find the tile's numbers in L1.
            for t0 in (0..len).step_by(TILE) {
                let t = t0..(t0 + TILE).min(len);
                // The tile in the component arrays: nothing when they are not kept.
                let ts = if arrays { t.clone() } else { 0..0 };
                prepass::velocities_and_positions(
                    &x[t.clone()],
                    &v[t.clone()],
                    current,
                    &mut v_step[t.clone()],
                    &mut v_rel[t.clone()],
                    [&mut sx[ts.clone()], &mut sy[ts.clone()], &mut sz[ts.clone()]],
                );
                // Fully pinned particles move to their goals: that is their velocity.
                let (lo, hi) = (first + t.start, first + t.end);
                let pins = &hard_pins[hard_pins.partition_point(|&i| (i as usize) < lo)..];
                for &i in pins.iter().take_while(|&&i| (i as usize) < hi) {
                    let (p, k) = (i as usize, i as usize - first);
                    v_step[k] = (goal[p] - x[k]) / h;
                    v_rel[k] = if start_pins && first_half {
                        // The slope at the start from the last whole secant (a step back) and
                        // this half step's: p'(0) = S_prev / 3 + 2 S_1 / 3 on a parabola.
                        (v[k] + 2.0 * v_step[k]) / 3.0 - current
                    } else if central_pins {
                        0.5 * (v[k] + v_step[k]) - current
                    } else {
                        v_step[k] - current
                    };
                }
                if let Some(past) = &past {
                    // SAFETY: every particle once; tiles start on multiples of TILE and
                    // end on one or at the last particle, so on blocks of 16.
                    unsafe { past.past_range(lo, &mut half[t.clone()]) };
                }
                // The damping rate's component arrays: none for undamped springs.
                let (rate, q): (Option<&[Vec3]>, [&mut [f64]; 3]) = match rate {
                    forces::SpringRate::None if !with_history => continue,
                    forces::SpringRate::None => (None, [&mut [], &mut [], &mut []]),
                    forces::SpringRate::HalfDerivative => (
                        None,
                        [&mut qx[ts.clone()], &mut qy[ts.clone()], &mut qz[ts.clone()]],
                    ),
                    forces::SpringRate::Velocity => (
                        Some(&v_step[t.clone()]),
                        [&mut qx[ts.clone()], &mut qy[ts.clone()], &mut qz[ts.clone()]],
                    ),
                };
                prepass::add_current_and_split(
                    with_history.then_some(w0),
                    &v_rel[t.clone()],
                    &mut half[t.clone()],
                    rate,
                    q,
                );
            }
        });
        if with_history {
            self.history.end_step();
        }
        w0
    }

    /// The rotation-invariant fractional springs' forces at the start of the step, from each
    /// spring's rate of elongation and its history (nothing without them). Returns their w0.
    fn strain_damping(&mut self) -> f64 {
        if self.strain_history.is_off() {
            self.scratch.prior_forces.clear();
            return 0.0;
        }
        let s = &mut self.scratch;
        forces::strain::elongation_rates(&self.topology, &self.x, &s.v_step, &mut s.strain_rates);
        s.strain_past.resize(s.strain_rates.len(), Vec3::zeros());
        let past = self.strain_history.begin_step();
        let w0 = past.current_weight();
        // SAFETY: one call covers every entry once.
        unsafe { past.past_range(0, &mut s.strain_past) };
        self.strain_history.end_step();
        s.prior_forces.resize(self.x.len(), Vec3::zeros());
        forces::strain::forces(
            &self.config.model,
            &self.topology,
            &self.x,
            w0,
            &s.strain_rates,
            &s.strain_past,
            &mut s.prior_forces,
        );
        w0
    }

    /// The carried water's forces as the normals turn (`dT/dx - (dM/dt) v`,
    /// [`forces::turning_forces`]), added to the forces before the pass; nothing without
    /// normal added mass.
    fn water_turning(&mut self) {
        let (s, t) = (&mut self.scratch, &self.topology);
        if self.config.model.water.added_mass == 0.0 {
            s.projected.clear();
            return;
        }
        if s.prior_forces.is_empty() {
            s.prior_forces.resize(self.x.len(), Vec3::zeros());
        }
        s.projected.resize(self.x.len(), 0.0);
        let m = &self.config.model;
        forces::turning_forces(
            m,
            t,
            &self.x,
            &s.v_rel,
            &mut s.turning,
            &mut s.projected,
            &mut s.prior_forces,
        );
    }

    /// The force pass with an explicit integrator stepping each tile in cache; returns whether
    /// every result it wrote was sound.
    fn forces_and_explicit_step(&mut self, h: f64, strain_w0: f64, step: StepSoa) -> bool {
        let s = &mut self.scratch;
        let input = ForceInput {
            model: &self.config.model,
            topology: &self.topology,
            x: &self.x,
            v: &s.v_step,
            half_derivative: &s.half,
            colliders: &self.colliders,
            prior_forces: &s.prior_forces,
            strain_w0,
        };
        let (masses, areas) = (&self.topology.masses, &self.topology.areas);
        let projected = &s.projected;
        let model = &self.config.model;
        let max_speed2 = self.config.max_speed * self.config.max_speed;
        let all_sound = AtomicBool::new(true);
        let (x_new, v_new) = (
            parallel::Disjoint::new(&mut s.x_new),
            parallel::Disjoint::new(&mut s.v_new),
        );
        forces::for_each_tile(&input, &mut s.force_pass, SpringInputs::Filled, |tile| {
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

    /// The force pass into one array, then linearised backward Euler solved by CG; refused
    /// when the solver stops above its tolerance (unless accepted). The result is checked by
    /// [`Self::check`], so this returns false (not checked here).
    fn forces_and_implicit_step(&mut self, h: f64, w0: f64, strain_w0: f64) -> Result<bool, Error> {
        let n = self.vertex_count();
        let s = &mut self.scratch;
        s.force_array.resize(n, Vec3::zeros());
        let input = ForceInput {
            model: &self.config.model,
            topology: &self.topology,
            x: &self.x,
            v: &s.v_step,
            half_derivative: &s.half,
            colliders: &self.colliders,
            prior_forces: &s.prior_forces,
            strain_w0,
        };
        forces::total_forces_with(
            &input,
            &mut s.force_pass,
            SpringInputs::Filled,
            &mut s.force_array,
        );
        forces::linearise(
            &input,
            w0,
            s.force_pass.normals(),
            &s.projected,
            &mut s.implicit.lin,
        );
        let inp = ImplicitInput {
            h,
            x: &self.x,
            v: &s.v_step,
            force: &s.force_array,
            masses: &self.topology.masses,
            topology: &self.topology,
            pinned: &self.pinned,
            settings: self.config.solver,
            contacts: &s.contacts,
            contact_stiffness: self.config.model.collision_stiffness,
            contact_damping: self.config.model.collision_damping,
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
            s.x_new[i] = self.x[i] + h * s.v_new[i];
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
            &self.x,
            &self.topology.masses,
            &self.pinned,
            &mut self.scratch.v_new,
        );
        on
    }

    /// Pinned particles onto their goals (moving with their step velocity); soft pins pulled
    /// the fraction of their weight of the way there.
    fn pins(&mut self, h: f64) {
        let s = &mut self.scratch;
        for &i in &self.pin_list {
            let i = i as usize;
            let w = self.pin_weight[i];
            if self.pinned[i] {
                s.x_new[i] = s.goal[i];
                s.v_new[i] = s.v_step[i];
            } else {
                // Soft pin: the fraction w of the way onto the target and its velocity.
                let v_goal = (s.goal[i] - self.x[i]) / h;
                let (x_free, v_free) = (s.x_new[i], s.v_new[i]);
                s.x_new[i] = x_free + w * (s.goal[i] - x_free);
                s.v_new[i] = v_free + w * (v_goal - v_free);
            }
        }
    }

    /// Refuses a proposed state that is not finite, too fast, or beyond the float range.
    /// `integrated_sound`: every particle the integrator wrote was checked and sound, so only
    /// what the pins changed is checked again.
    fn check(&self, h: f64, integrated_sound: bool) -> Result<(), Error> {
        let pins_sound = || self.pin_list.iter().all(|&i| !self.unsound(i as usize));
        if !(integrated_sound && pins_sound()) {
            self.check_sound(h)?;
        }
        if h * self.config.max_speed > FAR_STEP {
            self.check_in_range(h)?;
        }
        Ok(())
    }

    /// Makes the proposed state the cloth's and records the step in the history.
    fn commit(&mut self, h: f64) {
        let s = &mut self.scratch;
        std::mem::swap(&mut self.x, &mut s.x_new);
        std::mem::swap(&mut self.v, &mut s.v_new);
        self.history.record(&mut s.v_rel, h);
        if !self.strain_history.is_off() {
            self.strain_history.record(&mut s.strain_rates, h);
        }
        self.time += h;
        self.steps += 1;
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
                self.steps,
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
