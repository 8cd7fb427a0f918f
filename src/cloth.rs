//! [`Cloth`]: the state of one simulated cloth, its model, and [`Cloth::step`].
//!
//! A step is atomic: it either advances to a sound state or returns an error and
//! leaves positions, velocities, pins, colliders and history exactly as they were.
//! "Sound" means every position and velocity is finite and no particle is faster
//! than [`ClothConfig::max_speed`] (an underwater cloth never moves at 100 m/s; a
//! state that does has exploded).

mod auto_step;
mod colliders;
mod collisions;
mod constrained;
mod extrapolate;
mod histories;
mod motion;
mod pins;
mod plan;
mod prepass;
mod rollback;
mod scratch;
mod snapshot;
mod split;
mod state;
mod step;

use colliders::{checked_collider, ColliderSlot};
use histories::Histories;
use pins::check_weight;
use rollback::Rollback;
use scratch::StepScratch;

pub use auto_step::{safety, StepStats, AUTO, MAX_RETRIES, SAFETY, SAFETY_SYMPLECTIC};
pub use snapshot::SNAPSHOT_VERSION;
pub use split::StepLimitStats;

use crate::collide::{MeshCollider, SelfCollision};
use crate::error::{check_finite_vec, check_non_negative, check_positive, Error};
use crate::forces::{self, Collider};
use crate::history::{History, Scheme};
use crate::integrate::{Integrator, SolverSettings, SolverStats};
use crate::math::Vec3;
use crate::model::Model;
use crate::parallel::Threads;
use crate::topology::Topology;

/// Everything that configures a cloth besides its topology.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothConfig {
    pub model: Model,
    /// How D^{1/2}x is evaluated. Ignored (no history kept) when the model has no fractional term.
    pub scheme: Scheme,
    pub integrator: Integrator,
    /// Speed (m/s) above which a step is declared unstable. Default 100.
    pub max_speed: f64,
    /// Longest substep (s) `Cloth::step` takes; 0 = one step per call; negative ([`AUTO`]) =
    /// the automatic step (`cloth/auto_step.rs`). Default 0.
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

// The history's pass needs ranges on its blocks (`History::begin_step`).
const _: () = assert!(crate::parallel::TILE % crate::history::SOE_BLOCK == 0);

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

/// Checks every setting of `config` for the cloth `topology` and resolves, once, an added mass
/// given as a coefficient into kg/m^2 ([`crate::model::Water::added_mass_coefficient`], by the
/// cloth's width) and a self-collision thickness given in spacings into metres
/// ([`crate::model::Model::self_collision_relative`], by the cloth's spacing).
fn checked_config(mut config: ClothConfig, topology: &Topology) -> Result<ClothConfig, Error> {
    config.model.validate()?;
    let water = &mut config.model.water;
    water.added_mass = water.added_mass_for(config.model.water_density, topology.width());
    water.added_mass_coefficient = 0.0;
    check_non_negative("added_mass (with added_mass_coefficient)", water.added_mass)?;
    let m = &mut config.model;
    if m.self_collision_relative != 0.0 {
        m.self_collision_thickness += m.self_collision_relative * topology.spacing;
        m.self_collision_relative = 0.0;
        check_non_negative(
            "self_collision_thickness (with self_collision_relative)",
            m.self_collision_thickness,
        )?;
    }
    check_positive("max_speed", config.max_speed)?;
    if config.max_speed >= MAX_COORDINATE {
        return Err(Error::invalid(format!(
            "max_speed must be below {MAX_COORDINATE:e} m/s (the float range), got {}",
            config.max_speed
        )));
    }
    config.scheme.validate()?;
    check_solver(&config.solver)?;
    if !config.max_substep.is_finite() {
        return Err(Error::invalid(format!(
            "max_substep must be finite (> 0 a longest substep, 0 one step per call, negative the automatic step), got {}",
            config.max_substep
        )));
    }
    Ok(config)
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

/// One cloth: topology, configuration and state.
#[derive(Clone, Debug)]
pub struct Cloth {
    topology: Topology,
    config: ClothConfig,
    /// Positions, velocities, time, steps and the memories (`state.rs`).
    state: state::State,
    /// The pins as the host set them (`pins.rs`).
    pins: pins::Pins,
    /// Colliders by id, each with its friction coefficient.
    collider_slots: Vec<Option<ColliderSlot>>,
    colliders: Vec<Collider>,
    friction: Vec<f64>,
    /// Triangle-mesh colliders by id (ids shared with `collider_slots`: an id is in at most
    /// one of the two).
    mesh_slots: Vec<Option<MeshCollider>>,
    /// Self-collision's search and remembered sides (`collide/self_collision.rs`).
    self_collision: SelfCollision,
    /// Cloth vertices the mesh colliders carried (kept from passing through them), summed
    /// over the steps since the cloth was made.
    mesh_carried: u64,
    /// Self-collision's step limit's splitter: what it did and when it next tries a
    /// substep whole (`split.rs`).
    splitter: split::Splitter,
    scratch: StepScratch,
    rollback: Rollback,
    /// The whole step of an extrapolated integrator, beside its two half steps.
    probe: Rollback,
    /// An extrapolated step's start, kept while its half steps may be refused for
    /// self-collision's step limit (`cloth/extrapolate.rs`).
    probe_start: Rollback,
    solver_stats: SolverStats,
    /// What the last call to `step` did.
    step_stats: StepStats,
    /// Where the step runs (`plumbing/parallel.rs`).
    threads: Threads,
}

impl Cloth {
    /// Builds a cloth at rest in its rest positions.
    pub fn new(topology: Topology, config: ClothConfig) -> Result<Self, Error> {
        let config = checked_config(config, &topology)?;
        let n = topology.vertex_count();
        let memories = forces::memories(&config.model);
        let scheme = if memories.particles {
            config.scheme
        } else {
            Scheme::Off
        };
        // Room for the state, scratch and rollback copies and the history, checked up front.
        let history_bytes = match scheme {
            Scheme::Truncated { u } => 24 * u64::from(u),
            Scheme::Full => 0, // grows step by step, each step's room reserved fallibly
            // Up to 64 modes, and two more samples when folds are deferred.
            Scheme::SumOfExponentials { .. } => 24 * (64 + 2),
            Scheme::Off => 0,
        };
        let self_collision_bytes = if config.model.self_collision_on() {
            crate::memory::SELF_COLLISION_BYTES_PER_PARTICLE
        } else {
            0
        };
        crate::memory::ensure_available(
            (n as u64).saturating_mul(
                crate::memory::STATE_BYTES_PER_PARTICLE
                    + 2 * history_bytes
                    + self_collision_bytes
                    // The unsteady skin drag's running mean and its rollback copy.
                    + if config.model.water.unsteady_skin() { 48 } else { 0 },
            ),
            &format!(
                "a cloth of {n} particles{}",
                if self_collision_bytes > 0 {
                    " with self-collision"
                } else {
                    ""
                }
            ),
        )?;
        forces::coarse_water::check(&topology, &config.model)?;
        let mut self_collision = SelfCollision::new(&topology.triangles);
        self_collision.prepare(
            &topology.rest_positions,
            &topology.triangles,
            config.model.self_collision_thickness,
        )?;
        Ok(Self {
            pins: pins::Pins {
                pinned: vec![false; n],
                weight: vec![0.0; n],
                list: Vec::new(),
                target: topology.rest_positions.clone(),
            },
            collider_slots: Vec::new(),
            colliders: Vec::new(),
            friction: Vec::new(),
            mesh_slots: Vec::new(),
            self_collision,
            mesh_carried: 0,
            splitter: split::Splitter::default(),
            scratch: StepScratch::default(),
            rollback: Rollback::default(),
            probe: Rollback::default(),
            probe_start: Rollback::default(),
            solver_stats: SolverStats::default(),
            step_stats: StepStats::default(),
            state: state::State::at_rest(
                &topology.rest_positions,
                Histories::new(&config.model, config.scheme, &topology)?,
                &config.model,
            ),
            threads: Threads::default(),
            topology,
            config,
        })
    }

    pub fn vertex_count(&self) -> usize {
        self.state.x.len()
    }

    /// Changes the cloth's coefficients, integrator, speed limit, substep and solver settings
    /// between steps; the state (positions, velocities, pins, colliders, history, time) is kept.
    /// The history cannot change: `config.scheme` must be the cloth's, and a model that needs a
    /// history (fractional terms; rotation-invariant fractional springs) must need the same
    /// histories as the one the cloth was built with. All or nothing: on an error nothing changes.
    pub fn reconfigure(&mut self, config: ClothConfig) -> Result<(), Error> {
        let config = checked_config(config, &self.topology)?;
        let old = &self.config;
        if config.scheme != old.scheme {
            return Err(Error::invalid(format!(
                "the history scheme cannot change after creation ({} -> {}); create a new cloth",
                old.scheme.name(),
                config.scheme.name()
            )));
        }
        if forces::memories(&config.model) != forces::memories(&old.model) {
            return Err(Error::invalid(
                "the model's fractional terms (history drag, fractional springs) must be on or off as when the cloth was created: the history it keeps was sized then; create a new cloth, or set a coefficient to a tiny value instead of 0",
            ));
        }
        forces::coarse_water::check(&self.topology, &config.model)?;
        // A memory the new model keeps starts from the state as it is, its room asked for
        // before anything changes (`state.rs`).
        let memories = self.state.memories_for(&config.model)?;
        let thickness = config.model.self_collision_thickness;
        let old_thickness = old.model.self_collision_thickness;
        // On the cloth's threads (its lists are made on the pool for a large cloth): a cloth
        // told to stay on the calling thread touches no other.
        let (threads, topology) = (self.threads.clone(), &self.topology);
        let self_collision = &mut self.self_collision;
        threads.run(|| self_collision.prepare(&topology.rest_positions, &topology.triangles, thickness))?;
        if thickness != old_thickness {
            // The pair list was found for the old reach.
            self.self_collision.look_again();
        }
        self.state.change_memories(memories);
        self.config = config;
        Ok(())
    }

    pub fn topology(&self) -> &Topology {
        &self.topology
    }
    pub fn config(&self) -> &ClothConfig {
        &self.config
    }
    /// The model this cloth steps with: the one it was built from, its added mass given as a
    /// coefficient resolved into [`crate::model::Water::added_mass`] (kg/m^2).
    pub fn model(&self) -> &Model {
        &self.config.model
    }
    /// Positions, m.
    pub fn positions(&self) -> &[Vec3] {
        &self.state.x
    }
    /// Writes the unit vertex normal of every vertex at the current positions into `out` (one
    /// per vertex): the area-weighted sum of its triangles' normals, on the side the triangles
    /// wind counter-clockwise; zero for a vertex whose triangles have no area. Fails with
    /// out-of-memory (nothing written) when the per-triangle buffer cannot be allocated.
    pub fn vertex_normals(&self, out: &mut [Vec3]) -> Result<(), Error> {
        self.vertex_normals_in(out, &mut Vec::new())
    }

    /// [`Self::vertex_normals`] with the triangles' normals summed in `faces` (its contents
    /// replaced; in its room when it has enough): a host that shades every frame keeps one and
    /// allocates nothing.
    pub fn vertex_normals_in(&self, out: &mut [Vec3], faces: &mut Vec<Vec3>) -> Result<(), Error> {
        if out.len() != self.vertex_count() {
            return Err(Error::invalid(format!(
                "expected {} normals, got room for {}",
                self.vertex_count(),
                out.len()
            )));
        }
        let t = &self.topology;
        faces.clear();
        faces
            .try_reserve_exact(t.triangles.len())
            .map_err(|_| Error::out_of_memory(format!("no memory for {} face normals", t.triangles.len())))?;
        faces.resize(t.triangles.len(), Vec3::zeros());
        forces::vertex_normals_with(
            &self.state.x,
            &t.triangles,
            &t.vertex_triangles,
            false,
            faces,
            out,
        );
        Ok(())
    }

    /// Velocities, m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.state.v
    }
    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.state.time
    }
    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.state.steps
    }
    /// The half-derivative history state.
    pub fn history(&self) -> &History {
        self.state.histories.get(forces::Memory::Particles)
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

    /// Teleports every vertex (velocities and history are kept); pins move with it.
    pub fn set_positions(&mut self, x: &[Vec3]) -> Result<(), Error> {
        self.check_all(x, "position")?;
        self.state.x.copy_from_slice(x);
        for &i in &self.pins.list {
            self.pins.target[i as usize] = x[i as usize];
        }
        // Teleported: the sides self-collision remembered no longer hold.
        self.self_collision.set_pairs(Vec::new(), Vec::new());
        Ok(())
    }

    /// Sets every velocity (m/s).
    pub fn set_velocities(&mut self, v: &[Vec3]) -> Result<(), Error> {
        self.check_all(v, "velocity")?;
        self.state.v.copy_from_slice(v);
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

    /// Advances by `dt` seconds with the configured integrator, split into
    /// `ceil(dt / max_substep)` equal substeps when `max_substep` is positive, into as few as
    /// the cloth needs when it is negative ([`AUTO`]: retried with twice the substeps when one
    /// is refused). Atomic.
    pub fn step(&mut self, dt: f64) -> Result<(), Error> {
        check_dt(dt)?;
        let max = self.config.max_substep;
        if max < 0.0 {
            return self.step_auto(dt);
        }
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
        self.call(dt, n as u32, false)
    }

    /// Advances by `dt` seconds in `substeps` equal substeps. Pins travel in a straight
    /// line to their targets over the whole call. Atomic over the whole call: if any
    /// substep fails, the cloth is restored to its state before the call. With self-collision
    /// a substep may be taken in pieces (`cloth/split.rs`).
    pub fn step_substeps(&mut self, dt: f64, substeps: u32) -> Result<(), Error> {
        check_dt(dt)?;
        self.call(dt, substeps, false)
    }

    /// One call of `dt` seconds (checked) in `substeps` substeps, `auto` when the automatic
    /// step chose them, on the cloth's threads.
    fn call(&mut self, dt: f64, substeps: u32, auto: bool) -> Result<(), Error> {
        match &self.threads {
            // A cloth that spreads its passes over the shared pool, called from outside it:
            // the whole call runs on one of its workers (`rayon::scope` hands it over once),
            // so each pass's split is work the pool's threads share among themselves, not a
            // hand-over from this thread and back (measured on a 2-vCPU Intel Xeon: about
            // 0.3 ms a hand-over, which made two threads no faster than one at 201 x 201).
            Threads::Shared
                if crate::parallel::worth_it(self.vertex_count())
                    && rayon::current_thread_index().is_none() =>
            {
                rayon::scope(|_| self.call_here(dt, substeps, auto))
            }
            Threads::Shared => self.call_here(dt, substeps, auto),
            threads => threads.clone().run(|| self.call_here(dt, substeps, auto)),
        }
    }

    /// Which threads the step runs on: 0 = the shared pool (default), 1 = the calling thread,
    /// n >= 2 = the cloth's own pool of n threads. The result does not depend on it.
    pub fn set_threads(&mut self, count: u32) -> Result<(), Error> {
        self.threads = Threads::with_count(count).map_err(Error::invalid)?;
        Ok(())
    }

    /// The count given to [`Cloth::set_threads`] (0 by default).
    pub fn threads(&self) -> u32 {
        self.threads.count()
    }

    /// One call: the mesh colliders travel to where the host put them over it.
    fn call_here(&mut self, dt: f64, substeps: u32, auto: bool) -> Result<(), Error> {
        self.begin_collider_motion(dt)?;
        self.call_substeps(dt, substeps, auto)?;
        self.colliders_arrive();
        Ok(())
    }

    /// The substeps of a call, atomic: on an error the call's start is put back.
    fn call_substeps(&mut self, dt: f64, substeps: u32, auto: bool) -> Result<(), Error> {
        if substeps == 0 || substeps > MAX_SUBSTEPS {
            return Err(Error::invalid(format!(
                "substeps must be in 1..={MAX_SUBSTEPS}, got {substeps}"
            )));
        }
        self.step_stats = StepStats {
            substeps,
            ..StepStats::default()
        };
        let h = dt / f64::from(substeps);
        let mut snap = std::mem::take(&mut self.rollback);
        // A call of one first-order step commits nothing before its end, so it needs no copy
        // of its start (unless self-collision splits it: `split.rs` makes one then).
        let mut saved = substeps > 1 || self.config.integrator.is_extrapolated();
        if saved {
            if let Err(e) = snap.save(self) {
                self.rollback = snap;
                return Err(e);
            }
        }
        self.start_pin_paths();
        let mut pieces = 0u32;
        for k in 1..=substeps {
            let f0 = f64::from(k - 1) / f64::from(substeps);
            let goal = (k < substeps).then_some(f64::from(k) / f64::from(substeps));
            match self.take_substep(h, (f0, goal), auto, &mut snap, &mut saved) {
                Ok(taken) => pieces = pieces.saturating_add(taken),
                Err(mut e) => {
                    if saved {
                        snap.restore(self);
                    }
                    self.rollback = snap;
                    if substeps > 1 {
                        e.message = format!("substep {k} of {substeps}: {}", e.message);
                    }
                    return Err(e);
                }
            }
        }
        self.rollback = snap;
        self.step_stats.substeps = pieces;
        Ok(())
    }

    /// What the last call to [`Cloth::step`] or [`Cloth::step_substeps`] did: its substeps,
    /// the automatic step's retries and estimate.
    pub fn step_stats(&self) -> StepStats {
        self.step_stats
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

    /// Total mechanical energy (J): kinetic with the water's inertia (`1/2 v^T M v`,
    /// [`forces::Inertia`]) + spring + potential of the net weight in water.
    pub fn energy(&self) -> f64 {
        let m = &self.config.model;
        let t = &self.topology;
        let n = self.state.x.len();
        let (mut normals, mut projected) = (vec![Vec3::zeros(); n], vec![1.0; n]);
        if m.water.normal_water() {
            forces::patch_normals(&self.state.x, t, &mut normals, &mut projected);
        }
        let mut e = 0.0;
        for (i, (x, v)) in self.state.x.iter().zip(&self.state.v).enumerate() {
            let inertia = forces::Inertia::of(m, t.masses[i], t.areas[i], normals[i], projected[i]);
            e += inertia.kinetic_energy(v) - forces::body_force(m, t.masses[i]).dot(x);
        }
        let w = &m.water;
        if w.coarse_added_mass > 0.0 {
            let s = |i: usize| projected[i] * normals[i].dot(&self.state.v[i]);
            match &self.scratch.coarse {
                Some(c) if c.built_for(w.coarse_added_mass, w.coarse_length, &self.pins.pinned) => {
                    e += c.kinetic_energy(s);
                }
                // Not stepped yet with these pins: the level the next step will build.
                _ => {
                    if let Ok(c) = forces::coarse_water::CoarseWater::new(
                        t,
                        w.coarse_added_mass,
                        w.coarse_length,
                        &self.pins.pinned,
                    ) {
                        e += c.kinetic_energy(s);
                    }
                }
            }
        }
        for s in &t.springs {
            let k = m.stiffness(s.kind, t.spacing);
            let d = (self.state.x[s.i as usize] - self.state.x[s.j as usize]).norm() - s.rest;
            e += 0.5 * k * d * d;
        }
        e
    }
}
