//! [`Cloth`]: the state of one simulated cloth, its model, and [`Cloth::step`].
//!
//! A step is atomic: it either advances to a sound state or returns an error and
//! leaves positions, velocities, pins, colliders and history exactly as they were.
//! "Sound" means every position and velocity is finite and no particle is faster
//! than [`ClothConfig::max_speed`] (an underwater cloth never moves at 100 m/s; a
//! state that does has exploded).

mod prepass;
mod snapshot;

pub use snapshot::SNAPSHOT_VERSION;

use crate::error::{check_finite_vec, check_non_negative, check_positive, Error};
use crate::forces::{self, Collider, ForceInput, ForceScratch, Plane, Sphere};
use crate::history::{History, Scheme};
use crate::integrate::{
    self, implicit_euler, ImplicitInput, ImplicitScratch, Integrator, SolverSettings, SolverStats,
};
use crate::model::Model;
use crate::parallel;
use crate::topology::Topology;
use crate::Vec3;
use std::sync::atomic::{AtomicBool, Ordering};

/// Everything that configures a cloth besides its topology.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothConfig {
    pub model: Model,
    /// How D^{1/2}x is evaluated. Ignored (no history kept) when the model has no fractional term.
    pub scheme: Scheme,
    pub integrator: Integrator,
    /// Speed (m/s) above which a step is declared unstable. Default 100.
    pub max_speed: f64,
    /// Longest substep (s) `Cloth::step` takes; 0 = one step per call. Default 0.
    pub max_substep: f64,
    /// Implicit solver settings.
    pub solver: SolverSettings,
    /// Accept an implicit step whose solver stopped at its iteration cap above its tolerance
    /// (the step then returns `Ok`; read [`Cloth::solver_stats`]). Default false: such a step
    /// is refused with [`crate::ErrorKind::NotConverged`] and changes nothing.
    pub accept_unconverged: bool,
}

/// Largest coordinate or speed a cloth may reach: beyond it a value no longer fits the
/// `float` the C ABI hands out. A step that would go past it is refused as unstable.
pub const MAX_COORDINATE: f64 = f32::MAX as f64;

/// A step that may move a particle farther than this (m: `dt * max_speed`) also checks every
/// position against [`MAX_COORDINATE`]. Shorter steps cannot get there: at 1 km a step it
/// would take 3e35 steps.
const FAR_STEP: f64 = 1.0e3;

/// Particles per tile of the pass before the forces (its arrays for a tile fit in L1).
const PASS_TILE: usize = 256;
// The history's pass needs ranges on its blocks (`History::begin_step`).
const _: () = assert!(PASS_TILE % crate::history::SOE_BLOCK == 0 && parallel::CHUNK % PASS_TILE == 0);

/// Most substeps one call may take.
pub const MAX_SUBSTEPS: u32 = 1_000_000;

fn check_dt(dt: f64) -> Result<(), Error> {
    if dt.is_finite() && dt > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "dt must be finite and > 0 seconds, got {dt}"
        )))
    }
}

fn check_solver(s: &SolverSettings) -> Result<(), Error> {
    if !(s.tolerance.is_finite() && s.tolerance > 0.0) || s.max_iterations == 0 {
        return Err(Error::invalid(format!(
            "solver tolerance must be finite and > 0 and max_iterations >= 1, got {} and {}",
            s.tolerance, s.max_iterations
        )));
    }
    Ok(())
}

impl Default for ClothConfig {
    fn default() -> Self {
        Self {
            model: Model::default(),
            scheme: Scheme::DEFAULT,
            integrator: Integrator::default(),
            max_speed: 100.0,
            accept_unconverged: false,
            max_substep: 0.0,
            solver: SolverSettings::default(),
        }
    }
}

#[derive(Clone, Debug, Default)]
struct Scratch {
    v_step: Vec<Vec3>,
    v_rel: Vec<Vec3>,
    half: Vec<Vec3>,
    force: Vec<Vec3>,
    x_new: Vec<Vec3>,
    v_new: Vec<Vec3>,
    goal: Vec<Vec3>,
    pin_start: Vec<Vec3>,
    hard_pins: Vec<u32>,
    forces: ForceScratch,
    implicit: ImplicitScratch,
}

/// State saved before a multi-substep call, restored if a substep fails.
#[derive(Clone, Debug, Default)]
struct Snapshot {
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    history: Option<History>,
    time: f64,
    steps: u64,
}

impl Snapshot {
    /// Copies the state, or fails with an out-of-memory error when the copy of a history
    /// that grew (the full history) cannot be allocated.
    fn save(&mut self, c: &Cloth) -> Result<(), Error> {
        use crate::history::HalfDerivative;
        let need = c.history.bytes_per_particle() as u64 * c.x.len() as u64;
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
        self.time = c.time;
        self.steps = c.steps;
        Ok(())
    }

    fn restore(&mut self, c: &mut Cloth) {
        std::mem::swap(&mut c.x, &mut self.x);
        std::mem::swap(&mut c.v, &mut self.v);
        if let Some(h) = &mut self.history {
            std::mem::swap(&mut c.history, h);
        }
        c.time = self.time;
        c.steps = self.steps;
    }
}

/// One cloth: topology, configuration and state.
#[derive(Clone, Debug)]
pub struct Cloth {
    topology: Topology,
    config: ClothConfig,
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    /// Fully pinned (weight 1): the solver treats these as prescribed.
    pinned: Vec<bool>,
    /// Pin weight of every vertex in [0, 1]; 0 = free.
    pin_weight: Vec<f64>,
    /// Vertices with a weight > 0, in the order they were pinned.
    pin_list: Vec<u32>,
    pin_target: Vec<Vec3>,
    /// Colliders by id, each with its friction coefficient.
    collider_slots: Vec<Option<(Collider, f64)>>,
    colliders: Vec<Collider>,
    friction: Vec<f64>,
    history: History,
    time: f64,
    steps: u64,
    scratch: Scratch,
    snapshot: Snapshot,
    solver_stats: SolverStats,
}

impl Cloth {
    /// Builds a cloth at rest in its rest positions.
    pub fn new(topology: Topology, config: ClothConfig) -> Result<Self, Error> {
        config.model.validate()?;
        check_positive("max_speed", config.max_speed)?;
        if config.max_speed >= MAX_COORDINATE {
            return Err(Error::invalid(format!(
                "max_speed must be below {MAX_COORDINATE:e} m/s (the float range), got {}",
                config.max_speed
            )));
        }
        config.scheme.validate()?;
        check_solver(&config.solver)?;
        if !(config.max_substep.is_finite() && config.max_substep >= 0.0) {
            return Err(Error::invalid(format!(
                "max_substep must be finite and >= 0, got {}",
                config.max_substep
            )));
        }
        let n = topology.vertex_count();
        let scheme = if config.model.uses_half_derivative() {
            config.scheme
        } else {
            Scheme::Off
        };
        // Room for the state, scratch and rollback copies and the history, checked up front.
        let history_bytes = match scheme {
            Scheme::Truncated { u } => 24 * u64::from(u),
            Scheme::Full => 0, // grows step by step, each step's room reserved fallibly
            Scheme::SumOfExponentials { .. } => 24 * 64,
            Scheme::Off => 0,
        };
        crate::memory::ensure_available(
            (n as u64).saturating_mul(crate::memory::STATE_BYTES_PER_PARTICLE + 2 * history_bytes),
            &format!("a cloth of {n} particles"),
        )?;
        let x = topology.rest_positions.clone();
        Ok(Self {
            v: vec![Vec3::zeros(); n],
            pinned: vec![false; n],
            pin_weight: vec![0.0; n],
            pin_list: Vec::new(),
            pin_target: x.clone(),
            x,
            collider_slots: Vec::new(),
            colliders: Vec::new(),
            friction: Vec::new(),
            history: History::new(scheme, n)?,
            time: 0.0,
            steps: 0,
            scratch: Scratch::default(),
            snapshot: Snapshot::default(),
            solver_stats: SolverStats::default(),
            topology,
            config,
        })
    }

    pub fn vertex_count(&self) -> usize {
        self.x.len()
    }
    pub fn topology(&self) -> &Topology {
        &self.topology
    }
    pub fn config(&self) -> &ClothConfig {
        &self.config
    }
    pub fn model(&self) -> &Model {
        &self.config.model
    }
    /// Positions, m.
    pub fn positions(&self) -> &[Vec3] {
        &self.x
    }
    /// Velocities, m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.v
    }
    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.steps
    }
    /// The half-derivative history state.
    pub fn history(&self) -> &History {
        &self.history
    }
    /// Pinned vertex indices, in the order they were given.
    pub fn pinned(&self) -> &[u32] {
        &self.pin_list
    }

    fn check_index(&self, i: u32) -> Result<usize, Error> {
        let n = self.vertex_count();
        if (i as usize) < n {
            Ok(i as usize)
        } else {
            Err(Error::out_of_range(format!(
                "vertex index {i} out of range (cloth has {n} vertices)"
            )))
        }
    }

    /// Replaces the pinned set: the listed vertices are fully pinned (weight 1), every other
    /// vertex is free. Pins hold their current positions until moved.
    pub fn set_pinned(&mut self, indices: &[u32]) -> Result<(), Error> {
        for &i in indices {
            self.check_index(i)?;
        }
        self.clear_pins();
        for &i in indices {
            self.pin(i as usize, 1.0);
        }
        Ok(())
    }

    /// Replaces every vertex's pin weight (one per vertex, each in [0, 1]; 0 = free,
    /// 1 = fully pinned). A vertex of weight w in (0, 1) is pulled the fraction w of the way
    /// onto its target (and its velocity the fraction w onto the target's) at the end of
    /// every step: a soft pin, as a DCC's pin weight or goal strength.
    pub fn set_pin_weights(&mut self, weights: &[f64]) -> Result<(), Error> {
        if weights.len() != self.vertex_count() {
            return Err(Error::invalid(format!(
                "expected {} pin weights, got {}",
                self.vertex_count(),
                weights.len()
            )));
        }
        for (i, &w) in weights.iter().enumerate() {
            check_weight(i, w)?;
        }
        self.clear_pins();
        for (i, &w) in weights.iter().enumerate() {
            self.pin(i, w);
        }
        Ok(())
    }

    /// Sets the pin weight of a group of vertices (e.g. a DCC vertex group) to `weight` in
    /// [0, 1], leaving every other vertex as it is; 0 frees them.
    pub fn pin_group(&mut self, indices: &[u32], weight: f64) -> Result<(), Error> {
        for &i in indices {
            check_weight(self.check_index(i)?, weight)?;
        }
        for &i in indices {
            let i = i as usize;
            if self.pin_weight[i] > 0.0 {
                self.pin_weight[i] = 0.0;
                self.pinned[i] = false;
                self.pin_list.retain(|&p| p as usize != i);
            }
            self.pin(i, weight);
        }
        Ok(())
    }

    /// Pin weight of every vertex.
    pub fn pin_weights(&self) -> &[f64] {
        &self.pin_weight
    }

    fn clear_pins(&mut self) {
        self.pinned.fill(false);
        self.pin_weight.fill(0.0);
        self.pin_list.clear();
    }

    /// Pins free vertex `i` with weight `w` (nothing for w = 0) at its current position.
    fn pin(&mut self, i: usize, w: f64) {
        if w > 0.0 && self.pin_weight[i] == 0.0 {
            self.pin_weight[i] = w;
            self.pinned[i] = w == 1.0;
            self.pin_list.push(i as u32);
            self.pin_target[i] = self.x[i];
        }
    }

    /// Moves pinned vertices: at the end of the next step vertex `indices[k]` sits at
    /// `targets[k]`. Every index must be pinned.
    pub fn set_pin_targets(&mut self, indices: &[u32], targets: &[Vec3]) -> Result<(), Error> {
        if indices.len() != targets.len() {
            return Err(Error::invalid(format!(
                "{} indices but {} targets",
                indices.len(),
                targets.len()
            )));
        }
        for (&i, t) in indices.iter().zip(targets) {
            let i = self.check_index(i)?;
            if self.pin_weight[i] == 0.0 {
                return Err(Error::invalid(format!("vertex {i} is not pinned")));
            }
            check_finite_vec("pin target", t)?;
        }
        for (&i, t) in indices.iter().zip(targets) {
            self.pin_target[i as usize] = *t;
        }
        Ok(())
    }

    /// Teleports every vertex (velocities and history are kept); pins move with it.
    pub fn set_positions(&mut self, x: &[Vec3]) -> Result<(), Error> {
        self.check_all(x, "position")?;
        self.x.copy_from_slice(x);
        for &i in &self.pin_list {
            self.pin_target[i as usize] = x[i as usize];
        }
        Ok(())
    }

    /// Sets every velocity (m/s).
    pub fn set_velocities(&mut self, v: &[Vec3]) -> Result<(), Error> {
        self.check_all(v, "velocity")?;
        self.v.copy_from_slice(v);
        Ok(())
    }

    /// One finite vector per vertex.
    fn check_all(&self, values: &[Vec3], what: &str) -> Result<(), Error> {
        if values.len() != self.vertex_count() {
            return Err(Error::invalid(format!(
                "expected {} vertices, got {}",
                self.vertex_count(),
                values.len()
            )));
        }
        values.iter().try_for_each(|p| check_finite_vec(what, p))
    }

    /// Sets the uniform water current (m/s).
    pub fn set_current(&mut self, current: Vec3) -> Result<(), Error> {
        check_finite_vec("current", &current)?;
        self.config.model.current = current;
        Ok(())
    }

    /// Adds a sphere collider and returns its id.
    pub fn add_sphere(&mut self, sphere: Sphere) -> Result<u32, Error> {
        self.add_collider(Collider::Sphere(sphere))
    }

    /// Moves or resizes sphere `id`.
    pub fn set_sphere(&mut self, id: u32, sphere: Sphere) -> Result<(), Error> {
        self.set_collider(id, Collider::Sphere(sphere))
    }

    /// Adds any collider (friction 0) and returns its id, the smallest free one.
    pub fn add_collider(&mut self, collider: Collider) -> Result<u32, Error> {
        let collider = checked_collider(collider)?;
        let id = match self.collider_slots.iter().position(Option::is_none) {
            Some(free) => {
                self.collider_slots[free] = Some((collider, 0.0));
                free
            }
            None => {
                self.collider_slots.push(Some((collider, 0.0)));
                self.collider_slots.len() - 1
            }
        };
        self.rebuild_colliders();
        Ok(id as u32)
    }

    /// Replaces collider `id` (its shape may change; its friction is kept).
    pub fn set_collider(&mut self, id: u32, collider: Collider) -> Result<(), Error> {
        let collider = checked_collider(collider)?;
        let slot = self.collider_slot(id)?;
        let friction = slot.map_or(0.0, |s| s.1);
        *slot = Some((collider, friction));
        self.rebuild_colliders();
        Ok(())
    }

    /// Sets the Coulomb friction coefficient (>= 0) of collider `id`.
    pub fn set_collider_friction(&mut self, id: u32, friction: f64) -> Result<(), Error> {
        check_non_negative("friction", friction)?;
        if let Some((_, f)) = self.collider_slot(id)? {
            *f = friction;
        }
        self.rebuild_colliders();
        Ok(())
    }

    /// Removes collider `id`; its id may be reused.
    pub fn remove_collider(&mut self, id: u32) -> Result<(), Error> {
        *self.collider_slot(id)? = None;
        self.rebuild_colliders();
        Ok(())
    }

    /// Every collider present.
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// The collider with id `id`.
    pub fn collider(&self, id: u32) -> Option<&Collider> {
        self.collider_slots
            .get(id as usize)
            .and_then(Option::as_ref)
            .map(|s| &s.0)
    }

    /// Friction coefficient of collider `id`.
    pub fn collider_friction(&self, id: u32) -> Option<f64> {
        self.collider_slots
            .get(id as usize)
            .and_then(Option::as_ref)
            .map(|s| s.1)
    }

    fn collider_slot(&mut self, id: u32) -> Result<&mut Option<(Collider, f64)>, Error> {
        match self.collider_slots.get_mut(id as usize) {
            Some(slot @ Some(_)) => Ok(slot),
            _ => Err(Error::out_of_range(format!("no collider with id {id}"))),
        }
    }

    fn rebuild_colliders(&mut self) {
        self.colliders.clear();
        self.friction.clear();
        for (c, f) in self.collider_slots.iter().flatten() {
            self.colliders.push(*c);
            self.friction.push(*f);
        }
    }

    /// Advances by `dt` seconds with the configured integrator, split into
    /// `ceil(dt / max_substep)` equal substeps when `max_substep` is set. Atomic.
    pub fn step(&mut self, dt: f64) -> Result<(), Error> {
        check_dt(dt)?;
        let max = self.config.max_substep;
        let n = if max > 0.0 {
            (dt / max).ceil().max(1.0)
        } else {
            1.0
        };
        if n > MAX_SUBSTEPS as f64 {
            return Err(Error::invalid(format!(
                "dt / max_substep = {n} substeps exceeds the limit of {MAX_SUBSTEPS}"
            )));
        }
        self.step_substeps(dt, n as u32)
    }

    /// Advances by `dt` seconds in `substeps` equal substeps. Pins travel in a straight
    /// line to their targets over the whole call. Atomic over the whole call: if any
    /// substep fails, the cloth is restored to its state before the call.
    pub fn step_substeps(&mut self, dt: f64, substeps: u32) -> Result<(), Error> {
        check_dt(dt)?;
        if substeps == 0 || substeps > MAX_SUBSTEPS {
            return Err(Error::invalid(format!(
                "substeps must be in 1..={MAX_SUBSTEPS}, got {substeps}"
            )));
        }
        if substeps == 1 {
            return self.advance(dt, None);
        }
        let h = dt / f64::from(substeps);
        let mut snap = std::mem::take(&mut self.snapshot);
        if let Err(e) = snap.save(self) {
            self.snapshot = snap;
            return Err(e);
        }
        self.scratch.pin_start.clear();
        self.scratch
            .pin_start
            .extend(self.pin_list.iter().map(|&i| self.x[i as usize]));
        for k in 1..=substeps {
            let goal = (k < substeps).then_some(f64::from(k) / f64::from(substeps));
            if let Err(mut e) = self.advance(h, goal) {
                snap.restore(self);
                self.snapshot = snap;
                e.message = format!("substep {k} of {substeps}: {}", e.message);
                return Err(e);
            }
        }
        self.snapshot = snap;
        Ok(())
    }

    /// Statistics of the last implicit solve (zeros for explicit integrators).
    pub fn solver_stats(&self) -> SolverStats {
        self.solver_stats
    }

    /// Whether an implicit step whose solver stopped above its tolerance is accepted
    /// ([`ClothConfig::accept_unconverged`]).
    pub fn set_accept_unconverged(&mut self, accept: bool) {
        self.config.accept_unconverged = accept;
    }

    /// Sets the implicit solver's tolerance and iteration cap.
    pub fn set_solver(&mut self, settings: SolverSettings) -> Result<(), Error> {
        check_solver(&settings)?;
        self.config.solver = settings;
        Ok(())
    }

    /// One step of size `h`. Pins go to `pin_start + fraction (target - pin_start)`, or to
    /// their targets when `fraction` is None.
    fn advance(&mut self, h: f64, fraction: Option<f64>) -> Result<(), Error> {
        self.history.reserve_step()?;
        let n = self.vertex_count();
        let s = &mut self.scratch;
        for buf in [
            &mut s.v_step,
            &mut s.v_rel,
            &mut s.half,
            &mut s.force,
            &mut s.x_new,
            &mut s.v_new,
            &mut s.goal,
        ] {
            buf.resize(n, Vec3::zeros());
        }
        // Pins move in a straight line to their goals over the step; that is their velocity.
        for (k, &i) in self.pin_list.iter().enumerate() {
            let i = i as usize;
            s.goal[i] = match fraction {
                Some(f) => s.pin_start[k] + f * (self.pin_target[i] - s.pin_start[k]),
                None => self.pin_target[i],
            };
        }
        // One pass over the particles: the step's velocities (pins' from their goals), the
        // velocity relative to the water, D^{1/2}x_n = w0 v_n + H_n of it, and the component
        // arrays the spring pass reads (positions and damping rate).
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
        // A tile walk transposes its own spring inputs; only other topologies need them here.
        let arrays = !forces::tiled(&self.topology);
        let (sx, sq) = s.forces.spring_arrays(if arrays { n } else { 0 });
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
            for t0 in (0..len).step_by(PASS_TILE) {
                let t = t0..(t0 + PASS_TILE).min(len);
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
                    v_rel[k] = v_step[k] - current;
                }
                if let Some(past) = &past {
                    // SAFETY: every particle once; tiles start on multiples of PASS_TILE and
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
        let input = ForceInput {
            model: &self.config.model,
            topology: &self.topology,
            x: &self.x,
            v: &s.v_step,
            half_derivative: &s.half,
            colliders: &self.colliders,
        };
        let masses = &self.topology.masses;
        let explicit = self.config.integrator.explicit_step();
        let friction = forces::friction_active(&self.colliders, &self.friction);
        // Whether every particle the integrator wrote (before pins) was sound; None when the
        // check is left to `check_sound`.
        let mut integrated_sound = None;
        if let (Some(step), false) = (explicit, friction) {
            // Integrate each tile as soon as its forces are known, and check it there: no
            // force array is written and read back, no separate pass checks the result.
            let vmax2 = self.config.max_speed * self.config.max_speed;
            let all_sound = AtomicBool::new(true);
            let (x_new, v_new) = (
                parallel::Disjoint::new(&mut s.x_new),
                parallel::Disjoint::new(&mut s.v_new),
            );
            let v_step = &s.v_step;
            let soa_step = self.config.integrator.explicit_step_soa();
            if let (Some(step), true) = (soa_step, forces::soa_applies(&input)) {
                // The same, on the component arrays the tile walk has in cache.
                forces::accumulate_tiles_soa(&input, &mut s.forces, |tile| {
                    let r = tile.p0..tile.p0 + tile.force[0].len();
                    // SAFETY: each tile is handed over once and tiles are disjoint.
                    let (xn, vn) = unsafe { (x_new.range(r.clone()), v_new.range(r.clone())) };
                    let input = integrate::SoaStepInput {
                        h,
                        x: tile.x,
                        v: tile.v,
                        force: tile.force,
                        masses: &masses[r],
                        max_speed2: vmax2,
                    };
                    if !step(&input, xn, vn) {
                        all_sound.store(false, Ordering::Relaxed);
                    }
                });
            } else {
                forces::accumulate_tiles(&input, &mut s.forces, |p0, f| {
                    let r = p0..p0 + f.len();
                    // SAFETY: each tile is handed over once and tiles are disjoint.
                    let (xn, vn) = unsafe { (x_new.range(r.clone()), v_new.range(r.clone())) };
                    let input = integrate::StepInput {
                        h,
                        x: &x[r.clone()],
                        v: &v_step[r.clone()],
                        force: f,
                        masses: &masses[r],
                    };
                    step(&input, xn, vn);
                    if !integrate::sound(xn, vn, vmax2) {
                        all_sound.store(false, Ordering::Relaxed);
                    }
                });
            }
            integrated_sound = Some(all_sound.into_inner());
        } else {
            forces::accumulate_filled(&input, &mut s.forces, &mut s.force);
            match explicit {
                Some(step) => {
                    let input = integrate::StepInput {
                        h,
                        x: &self.x,
                        v: &s.v_step,
                        force: &s.force,
                        masses,
                    };
                    integrate::step_all(step, &input, &mut s.x_new, &mut s.v_new)
                }
                None => {
                    forces::linearise(&input, w0, s.forces.normals(), &mut s.implicit.lin);
                    let inp = ImplicitInput {
                        h,
                        x: &self.x,
                        v: &s.v_step,
                        force: &s.force,
                        masses,
                        topology: &self.topology,
                        pinned: &self.pinned,
                        settings: self.config.solver,
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
                }
            }
        }
        forces::apply_friction(
            &self.config.model,
            &self.colliders,
            &self.friction,
            h,
            &self.x,
            masses,
            &self.pinned,
            &mut s.v_new,
        );
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
        // Only pins changed particles after a sound integration: check just them then.
        let pins_sound = || self.pin_list.iter().all(|&i| !self.unsound(i as usize));
        if !(integrated_sound == Some(true) && pins_sound()) {
            self.check_sound(h)?;
        }
        if h * self.config.max_speed > FAR_STEP {
            self.check_in_range(h)?;
        }
        let s = &mut self.scratch;
        std::mem::swap(&mut self.x, &mut s.x_new);
        std::mem::swap(&mut self.v, &mut s.v_new);
        self.history.record(&mut s.v_rel, h);
        self.time += h;
        self.steps += 1;
        Ok(())
    }

    /// Whether the step's result for particle `i` is not finite or faster than `max_speed`.
    fn unsound(&self, i: usize) -> bool {
        let (x, v) = (&self.scratch.x_new[i], &self.scratch.v_new[i]);
        let vmax = self.config.max_speed;
        !x.iter().chain(v.iter()).all(|c| c.is_finite()) || v.norm_squared() > vmax * vmax
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
                "{} with dt = {dt} s is unstable at step {}: vertex {i} would reach speed {:.3e} m/s (limit {} m/s); state left unchanged, retry with a smaller dt",
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
                "{} with dt = {dt} s would move vertex {i} beyond the float range ({:.3e} m); state left unchanged, retry with a smaller dt",
                self.config.integrator.name(),
                self.scratch.x_new[i].amax()
            ))),
        }
    }

    /// Total mechanical energy (J): kinetic + spring + potential of the net weight in water.
    pub fn energy(&self) -> f64 {
        let m = &self.config.model;
        let mut e = 0.0;
        for ((x, v), &mass) in self.x.iter().zip(&self.v).zip(&self.topology.masses) {
            e += 0.5 * mass * v.norm_squared() - forces::body_force(m, mass).dot(x);
        }
        for s in &self.topology.springs {
            let k = m.stiffness(s.kind);
            let d = (self.x[s.i as usize] - self.x[s.j as usize]).norm() - s.rest;
            e += 0.5 * k * d * d;
        }
        e
    }
}

fn check_weight(i: usize, w: f64) -> Result<(), Error> {
    if (0.0..=1.0).contains(&w) {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "pin weight of vertex {i} must be in [0, 1], got {w}"
        )))
    }
}

/// Checks a collider's numbers; a plane's normal is normalised.
fn checked_collider(c: Collider) -> Result<Collider, Error> {
    Ok(match c {
        Collider::Sphere(s) => {
            check_finite_vec("sphere center", &s.center)?;
            check_finite_vec("sphere velocity", &s.velocity)?;
            check_positive("sphere radius", s.radius)?;
            c
        }
        Collider::Plane(p) => {
            check_finite_vec("plane point", &p.point)?;
            check_finite_vec("plane velocity", &p.velocity)?;
            check_finite_vec("plane normal", &p.normal)?;
            let len = p.normal.norm();
            if !(len > 0.0 && len.is_finite()) {
                return Err(Error::invalid("plane normal must not be zero"));
            }
            Collider::Plane(Plane {
                normal: p.normal / len,
                ..p
            })
        }
        Collider::Capsule(k) => {
            check_finite_vec("capsule end a", &k.a)?;
            check_finite_vec("capsule end b", &k.b)?;
            check_finite_vec("capsule velocity", &k.velocity)?;
            check_positive("capsule radius", k.radius)?;
            c
        }
    })
}
