//! Snapshots: the complete state of a cloth as bytes, to save a bake and resume it later
//! (or undo in a host), continuing bitwise identically.
//!
//! Format version 8, little-endian; version 7 (no skin drag mean) is read with the unsteady
//! skin drag's running mean at the loaded relative velocities (a flow that has always been
//! there, as at creation); version 6 (no motion averages) is read with the motion
//! unseen (implicit Euler's automatic step then bounds nothing by accuracy until the averages
//! fill, `cloth/motion.rs`), version 5 (no colliders' own margins) is read with every
//! collider at the model's margin, version 4 (no collision state) as a cloth with no mesh
//! collider and no remembered self-collision pair. Older versions are refused: version 1
//! stored the SOE modes in their in-memory block layout, version 2 unshifted modes, version 3
//! the SOE history's past
//! sum instead of the sample that waits to be folded (`history/soe.rs`).
//!
//! ```text
//! header   b"FCSNAP\0\0"  u32 version = 8  u32 flags = 0  u64 payload_len
//! payload  u64 vertex_count  u64 spring_count  u64 triangle_count  u64 topology_fingerprint
//!          u8 history_tag  u64 history_config_fingerprint
//!          f64 time  u64 steps  vec3 current  f64 solver_tolerance  u32 solver_max_iterations
//!          vec3s positions  vec3s velocities  f64s pin_weights  u64 n + u32[n] pin_order
//!          vec3s pin_targets  u64 slots, per slot: u8 present [u8 kind, shape f64s, f64 friction,
//!            f64 margin (-1: the model's)]
//!          history state (scheme specific: see history/*.rs `write_state`)
//!          [history state of the springs, with rotation-invariant fractional springs only]
//!          u64 mesh slots, per slot: u8 present [u64 nv, u64 nt, u32[3 nt] triangles,
//!            vec3s start, vec3s target, u8 has_velocities [vec3s velocities], f64 friction,
//!            f64 margin (-1: the model's)]
//!          u64 n + n (u32 vertex, u32 triangle, i8 side)  self-collision pairs
//!          u64 n + n (u32 edge, u32 edge, i8 side)
//!          f64 motion accel2  f64 motion vel2  (`cloth/motion.rs`; version 7)
//!          vec3s skin_mean  (0 or vertex_count; the unsteady skin drag's running mean;
//!            version 8)
//! trailer  u32 CRC-32 (IEEE) of header and payload
//! ```
//!
//! A snapshot loads only into a cloth of the same topology (vertex, spring and triangle counts and
//! a fingerprint of rest positions and springs) and the same history configuration; everything
//! else that can change after creation is in it. Loading checks the magic, version, length,
//! checksum and every value before touching the cloth: a truncated, corrupted or foreign snapshot
//! is rejected with a message and the cloth is left exactly as it was.

use super::plan::{Stage, StepPlan};
use super::state::Change;
use super::{check_weight, checked_collider, Cloth, Histories};
use crate::bytes::{ByteReader, ByteWriter};
use crate::cloth::MAX_COORDINATE;
use crate::collide::self_collision::Pair;
use crate::collide::MeshCollider;
use crate::error::{check_finite_vec, Error};
use crate::forces::{Capsule, Collider, Plane, Sphere};
use crate::history::Scheme;
use crate::integrate::SolverSettings;
use crate::math::Vec3;

const MAGIC: &[u8; 8] = b"FCSNAP\0\0";
/// Current format version.
pub const SNAPSHOT_VERSION: u32 = 8;
const HEADER: usize = 8 + 4 + 4 + 8;

/// FNV-1a over a stream of u64 words: cheap identity checks, not security.
struct Fnv(u64);
impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn word(&mut self, w: u64) {
        for b in w.to_le_bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

fn topology_fingerprint(c: &Cloth) -> u64 {
    let t = &c.topology;
    let mut h = Fnv::new();
    for p in &t.rest_positions {
        for x in p.iter() {
            h.word(x.to_bits());
        }
    }
    for s in &t.springs {
        h.word(u64::from(s.i) << 32 | u64::from(s.j));
        h.word(s.rest.to_bits());
    }
    h.0
}

fn history_fingerprint(c: &Cloth) -> u64 {
    let mut h = Fnv::new();
    match c.config.scheme {
        Scheme::Off => h.word(0),
        Scheme::Truncated { u } => {
            h.word(1);
            h.word(u64::from(u));
        }
        Scheme::Full => h.word(2),
        Scheme::SumOfExponentials {
            tolerance,
            horizon,
            min_dt,
        } => {
            h.word(3);
            for x in [tolerance, horizon, min_dt] {
                h.word(x.to_bits());
            }
        }
    }
    // A history per spring (rotation-invariant fractional springs) changes the state's layout;
    // without one the fingerprint is what it always was.
    if c.state.histories.layout() & 1 != 0 {
        h.word(u64::from(b'S'));
    }
    h.0
}

fn write_collider(w: &mut ByteWriter, c: &Collider) {
    match c {
        Collider::Sphere(s) => {
            w.u8(0);
            w.vec3(&s.center);
            w.f64(s.radius);
            w.vec3(&s.velocity);
        }
        Collider::Plane(p) => {
            w.u8(1);
            w.vec3(&p.point);
            w.vec3(&p.normal);
            w.vec3(&p.velocity);
        }
        Collider::Capsule(k) => {
            w.u8(2);
            w.vec3(&k.a);
            w.vec3(&k.b);
            w.f64(k.radius);
            w.vec3(&k.velocity);
        }
    }
}

fn read_collider(r: &mut ByteReader<'_>) -> Result<Collider, Error> {
    Ok(match r.u8()? {
        0 => Collider::Sphere(Sphere {
            center: r.vec3()?,
            radius: r.f64()?,
            velocity: r.vec3()?,
        }),
        1 => Collider::Plane(Plane {
            point: r.vec3()?,
            normal: r.vec3()?,
            velocity: r.vec3()?,
        }),
        2 => Collider::Capsule(Capsule {
            a: r.vec3()?,
            b: r.vec3()?,
            radius: r.f64()?,
            velocity: r.vec3()?,
        }),
        k => return Err(Error::invalid(format!("snapshot: unknown collider kind {k}"))),
    })
}

/// Exchanges the contents of two vectors, in place when they are as long (no buffer changes
/// hands).
fn swap_contents<T>(a: &mut Vec<T>, b: &mut Vec<T>) {
    if a.len() == b.len() {
        a.swap_with_slice(b);
    } else {
        std::mem::swap(a, b);
    }
}

/// Self-collision's remembered pairs as a snapshot holds them: vertex-triangle, edge-edge.
type SelfPairs = (Vec<Pair>, Vec<Pair>);

/// The analytic colliders' slots: shape, friction and (version 6) their own margin.
fn read_collider_slots(
    r: &mut ByteReader<'_>,
    version: u32,
) -> Result<Vec<Option<super::ColliderSlot>>, Error> {
    let slots = r.len(None, 1)?;
    let mut collider_slots = Vec::with_capacity(slots);
    for _ in 0..slots {
        collider_slots.push(match r.u8()? {
            0 => None,
            1 => {
                let c = checked_collider(read_collider(r)?)?;
                let friction = r.f64()?;
                if !(friction.is_finite() && friction >= 0.0) {
                    return Err(Error::invalid("snapshot: bad collider friction"));
                }
                let margin = if version >= 6 {
                    super::collisions::read_margin(r)?
                } else {
                    None
                };
                Some(super::ColliderSlot {
                    shape: c,
                    friction,
                    margin,
                })
            }
            k => return Err(Error::invalid(format!("snapshot: bad collider slot tag {k}"))),
        });
    }
    Ok(collider_slots)
}

/// The motion averages (version 7; unseen before).
fn read_motion(r: &mut ByteReader<'_>, version: u32) -> Result<super::motion::MotionRate, Error> {
    let motion = if version >= 7 {
        super::motion::MotionRate {
            accel2: r.f64()?,
            vel2: r.f64()?,
        }
    } else {
        super::motion::MotionRate::default()
    };
    if !motion.is_sound() {
        return Err(Error::invalid("snapshot: bad motion averages"));
    }
    Ok(motion)
}

/// A decoded snapshot's state, before it is a cloth's (or a cloth's, after it was replaced):
/// what [`Cloth::swap_state`] exchanges.
struct LoadedState {
    time: f64,
    steps: u64,
    current: Vec3,
    solver: SolverSettings,
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    weights: Vec<f64>,
    pin_list: Vec<u32>,
    targets: Vec<Vec3>,
    collider_slots: Vec<Option<super::ColliderSlot>>,
    histories: Histories,
    meshes: Vec<Option<MeshCollider>>,
    motion: super::motion::MotionRate,
    skin_mean: Vec<Vec3>,
}

impl Cloth {
    /// The cloth's complete state as a snapshot (see the module docs for the format), or an
    /// out-of-memory error. The bytes depend only on the cloth's logical state: a cloth whose
    /// step was refused saves the same bytes as before the attempt.
    pub fn save_snapshot(&self) -> Result<Vec<u8>, Error> {
        let mut w = ByteWriter::with_room(self.snapshot_size())?;
        self.write_snapshot(&mut w)?;
        let payload = (w.buf.len() - HEADER) as u64;
        w.buf[16..24].copy_from_slice(&payload.to_le_bytes());
        let crc = crc32fast::hash(&w.buf);
        w.u32(crc);
        Ok(w.buf)
    }

    /// Writes (or counts) everything but the checksum, with a zero payload length.
    fn write_snapshot(&self, w: &mut ByteWriter) -> Result<(), Error> {
        w.put(MAGIC);
        w.u32(SNAPSHOT_VERSION);
        w.u32(0);
        w.u64(0); // payload length, patched below
        let t = &self.topology;
        w.u64(t.vertex_count() as u64);
        w.u64(t.springs.len() as u64);
        w.u64(t.triangles.len() as u64);
        w.u64(topology_fingerprint(self));
        w.u8(self.history().tag());
        w.u64(history_fingerprint(self));
        w.f64(self.state.time);
        w.u64(self.state.steps);
        w.vec3(&self.config.model.current);
        w.f64(self.config.solver.tolerance);
        w.u32(self.config.solver.max_iterations);
        w.vec3s(&self.state.x);
        w.vec3s(&self.state.v);
        w.f64s(&self.pins.weight);
        w.u64(self.pins.list.len() as u64);
        for &i in &self.pins.list {
            w.u32(i);
        }
        w.vec3s(&self.pins.target);
        w.u64(self.collider_slots.len() as u64);
        for slot in &self.collider_slots {
            match slot {
                None => w.u8(0),
                Some(slot) => {
                    w.u8(1);
                    write_collider(w, &slot.shape);
                    w.f64(slot.friction);
                    w.f64(slot.margin.unwrap_or(-1.0));
                }
            }
        }
        self.state.histories.write_state(w)?;
        self.write_collision_state(w);
        w.f64(self.state.motion.accel2);
        w.f64(self.state.motion.vel2);
        w.vec3s(&self.state.skin_mean);
        Ok(())
    }

    /// Restores a state saved by [`Cloth::save_snapshot`] from a cloth of the same topology and
    /// history configuration. All or nothing: on any error the cloth is unchanged.
    pub fn load_snapshot(&mut self, bytes: &[u8]) -> Result<(), Error> {
        let (mut r, version) = self.open_snapshot(bytes)?;
        // Decode everything into fresh values; commit only when all of it is sound.
        let (state, pairs) = self.decode_state(&mut r, version, bytes.len())?;
        self.check_loaded(&state)?;
        self.commit_loaded(state, pairs)
    }

    /// Checks a snapshot's magic, version, length, checksum, topology and history
    /// configuration: a reader placed after them, and the format version.
    fn open_snapshot<'a>(&self, bytes: &'a [u8]) -> Result<(ByteReader<'a>, u32), Error> {
        if bytes.len() < HEADER + 4 || &bytes[..8] != MAGIC {
            return Err(Error::invalid(
                "not a fraccloth snapshot (bad magic or too short)",
            ));
        }
        let mut r = ByteReader::new(bytes);
        r.bytes(8)?;
        let version = r.u32()?;
        if !(4..=SNAPSHOT_VERSION).contains(&version) {
            return Err(Error::invalid(format!(
                "snapshot format version {version}; this library reads versions 4 to {SNAPSHOT_VERSION}"
            )));
        }
        let _flags = r.u32()?;
        let payload = r.u64()?;
        if payload != (bytes.len() - HEADER - 4) as u64 {
            return Err(Error::invalid(format!(
                "snapshot is {} bytes but its header says {}: truncated or padded",
                bytes.len(),
                payload.saturating_add((HEADER + 4) as u64)
            )));
        }
        let (body, crc) = bytes.split_at(bytes.len() - 4);
        let stored = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
        if crc32fast::hash(body) != stored {
            return Err(Error::invalid(
                "snapshot checksum does not match: the data is corrupted",
            ));
        }
        let t = &self.topology;
        let counts = [r.u64()?, r.u64()?, r.u64()?];
        let want = [
            t.vertex_count() as u64,
            t.springs.len() as u64,
            t.triangles.len() as u64,
        ];
        if counts != want || r.u64()? != topology_fingerprint(self) {
            return Err(Error::invalid(format!(
                "snapshot is of another cloth ({} vertices, {} springs, {} triangles; this one has {}, {}, {}, or different rest shape)",
                counts[0], counts[1], counts[2], want[0], want[1], want[2]
            )));
        }
        if r.u8()? != self.history().tag() || r.u64()? != history_fingerprint(self) {
            return Err(Error::invalid(
                "snapshot was saved with another history scheme or history settings",
            ));
        }
        Ok((r, version))
    }

    /// Decodes the state after the header (of a snapshot `len` bytes long), checking what
    /// decides how the rest is read, up to the trailer.
    fn decode_state(
        &self,
        r: &mut ByteReader<'_>,
        version: u32,
        len: usize,
    ) -> Result<(LoadedState, SelfPairs), Error> {
        let n = self.vertex_count();
        let time = r.f64()?;
        let steps = r.u64()?;
        let current = r.vec3()?;
        let solver = SolverSettings {
            tolerance: r.f64()?,
            max_iterations: r.u32()?,
        };
        let (mut x, mut v, mut weights, mut targets) = (vec![], vec![], vec![], vec![]);
        r.vec3s_into(Some(n), &mut x)?;
        r.vec3s_into(Some(n), &mut v)?;
        r.f64s_into(Some(n), &mut weights)?;
        let pins = r.len(None, 4)?;
        let mut pin_list = Vec::with_capacity(pins);
        for _ in 0..pins {
            pin_list.push(r.u32()?);
        }
        r.vec3s_into(Some(n), &mut targets)?;
        let collider_slots = read_collider_slots(r, version)?;
        crate::memory::ensure_available(
            2 * self.state.histories.bytes(&self.topology) + len as u64,
            "loading a snapshot",
        )?;
        let mut histories = self.state.histories.clone();
        histories.read_state(r)?;
        let collisions = if version >= 5 {
            self.read_collision_state(r, version)?
        } else {
            super::collisions::CollisionState::default()
        };
        let clash = collisions
            .meshes
            .iter()
            .zip(&collider_slots)
            .position(|(m, c)| m.is_some() && c.is_some());
        if let Some(id) = clash {
            return Err(Error::invalid(format!(
                "snapshot: collider id {id} is both a mesh and a shape"
            )));
        }
        let motion = read_motion(r, version)?;
        let skin_mean = self.read_skin_mean(r, version, &v, current)?;
        if r.remaining() != 4 {
            return Err(Error::invalid("snapshot has trailing data"));
        }
        let state = LoadedState {
            time,
            steps,
            current,
            solver,
            x,
            v,
            weights,
            pin_list,
            targets,
            collider_slots,
            histories,
            meshes: collisions.meshes,
            motion,
            skin_mean,
        };
        Ok((state, (collisions.vertex_triangle, collisions.edge_edge)))
    }

    /// The unsteady skin drag's running mean (version 8), as this cloth's model keeps it: one
    /// saved without it starts from the loaded flow (velocities `v` in the water's `current`),
    /// one saved with it is dropped by a cloth without.
    fn read_skin_mean(
        &self,
        r: &mut ByteReader<'_>,
        version: u32,
        v: &[Vec3],
        current: Vec3,
    ) -> Result<Vec<Vec3>, Error> {
        let n = self.vertex_count();
        let mut skin_mean = Vec::new();
        if version >= 8 {
            r.vec3s_into(None, &mut skin_mean)?;
            if !(skin_mean.is_empty() || skin_mean.len() == n) {
                return Err(Error::invalid(format!(
                    "snapshot: {} skin drag means for {n} vertices",
                    skin_mean.len()
                )));
            }
            skin_mean
                .iter()
                .try_for_each(|p| check_finite_vec("skin drag mean", p))?;
        }
        // This cloth's model decides whether the mean is kept, in the loaded current.
        let model = crate::model::Model {
            current,
            ..self.config.model
        };
        match super::state::skin_mean_change(&model, &skin_mean, v)? {
            Change::Keep => {}
            Change::Start(mean) => skin_mean = mean,
            Change::Drop => skin_mean.clear(),
        }
        Ok(skin_mean)
    }

    /// Checks every decoded value that the reading did not: time, current, solver settings,
    /// finite positions, velocities and targets within the float range and the speed limit,
    /// the histories, the pin weights and their list.
    fn check_loaded(&self, s: &LoadedState) -> Result<(), Error> {
        let (n, time) = (self.vertex_count(), s.time);
        if !(time.is_finite() && time >= 0.0) {
            return Err(Error::invalid(format!("snapshot: bad time {time}")));
        }
        check_finite_vec("snapshot current", &s.current)?;
        super::check_solver(&s.solver)?;
        for (what, vs) in [("position", &s.x), ("velocity", &s.v), ("pin target", &s.targets)] {
            vs.iter().try_for_each(|p| check_finite_vec(what, p))?;
            if let Some(i) = vs.iter().position(|p| p.amax() >= MAX_COORDINATE) {
                return Err(Error::invalid(format!(
                    "snapshot: {what} of vertex {i} is beyond the float range the ABI hands out"
                )));
            }
        }
        let limit = self.config.max_speed;
        if let Some(i) = s.v.iter().position(|p| p.norm() > limit) {
            return Err(Error::invalid(format!(
                "snapshot: vertex {i} moves at {:.3e} m/s, above this cloth's max_speed {limit} m/s",
                s.v[i].norm()
            )));
        }
        s.histories.check_state(time)?;
        for (i, &w) in s.weights.iter().enumerate() {
            check_weight(i, w)?;
        }
        let mismatch = || Error::invalid("snapshot: pin list does not match the pin weights");
        let mut seen = vec![false; n];
        for &i in &s.pin_list {
            let i = i as usize;
            if i >= n || seen[i] || s.weights[i] == 0.0 {
                return Err(mismatch());
            }
            seen[i] = true;
        }
        if s.weights.iter().filter(|&&w| w > 0.0).count() != s.pin_list.len() {
            return Err(mismatch());
        }
        Ok(())
    }

    /// The loaded state goes into this cloth, in its own buffers where it can (its scratch
    /// and lists keep their room: the steps after a load allocate nothing); a trial step says
    /// whether it can step (`trial_step`), and the state it replaced comes back, with
    /// self-collision's memory (its pairs and where it last looked), when it cannot.
    fn commit_loaded(&mut self, mut state: LoadedState, pairs: SelfPairs) -> Result<(), Error> {
        let mut old_memory = crate::collide::self_collision::SavedMemory::default();
        self.self_collision.save_memory(&mut old_memory);
        self.swap_state(&mut state);
        self.self_collision.set_pairs(pairs.0, pairs.1);
        if let Err(e) = self.trial_step() {
            self.swap_state(&mut state);
            self.self_collision.swap_memory(&mut old_memory);
            return Err(e);
        }
        // Accepted: a mesh collider made from the snapshot takes the room of the one it
        // replaced at its slot, so its first steps grow no list.
        for (new, old) in self.mesh_slots.iter_mut().zip(&mut state.meshes) {
            if let (Some(new), Some(old)) = (new, old) {
                new.take_room(old);
            }
        }
        Ok(())
    }

    /// Exchanges this cloth's state with `s` (each vector of particles in place), and derives
    /// what follows from it (which particles are fully pinned, the colliders).
    fn swap_state(&mut self, s: &mut LoadedState) {
        std::mem::swap(&mut self.state.time, &mut s.time);
        std::mem::swap(&mut self.state.steps, &mut s.steps);
        std::mem::swap(&mut self.config.model.current, &mut s.current);
        std::mem::swap(&mut self.config.solver, &mut s.solver);
        self.state.x.swap_with_slice(&mut s.x);
        self.state.v.swap_with_slice(&mut s.v);
        swap_contents(&mut self.pins.weight, &mut s.weights);
        swap_contents(&mut self.pins.target, &mut s.targets);
        std::mem::swap(&mut self.pins.list, &mut s.pin_list);
        std::mem::swap(&mut self.collider_slots, &mut s.collider_slots);
        std::mem::swap(&mut self.state.histories, &mut s.histories);
        std::mem::swap(&mut self.mesh_slots, &mut s.meshes);
        std::mem::swap(&mut self.state.motion, &mut s.motion);
        std::mem::swap(&mut self.state.skin_mean, &mut s.skin_mean);
        for (p, &w) in self.pins.pinned.iter_mut().zip(&self.pins.weight) {
            *p = w == 1.0;
        }
        self.rebuild_colliders();
    }

    /// Refuses a loaded state that cannot take one step: one step on the cloth itself, rolled
    /// back ([`Self::trial_in_place`]), at the mean step size the state was reached with
    /// (`time / steps`; 0.1 ms before any step), pins held where they are, an implicit solve
    /// accepted whatever its residual (only an unsound result refuses). When it fails, the same
    /// trial without the half-derivative histories says whether they are what the cloth cannot
    /// step from.
    fn trial_step(&mut self) -> Result<(), Error> {
        let h = if self.state.steps > 0 && self.state.time > 0.0 {
            self.state.time / self.state.steps as f64
        } else {
            1e-4
        };
        let Err(e) = self.trial_in_place(h) else {
            return Ok(());
        };
        if e.kind == crate::ErrorKind::OutOfMemory {
            // No room for the rollback's copy: nothing was stepped.
            return Err(e);
        }
        // Refused (rare): the same trial with empty histories says whether they are at fault.
        let mut histories = Histories::new(&self.config.model, self.config.scheme, &self.topology)?;
        std::mem::swap(&mut self.state.histories, &mut histories);
        let without = self.trial_in_place(h);
        std::mem::swap(&mut self.state.histories, &mut histories);
        let what = if without.is_ok() {
            "its half-derivative history holds values the cloth cannot step from"
        } else {
            "its positions, velocities, pins or colliders are a state the cloth cannot step from"
        };
        Err(Error::invalid(format!(
            "snapshot: {what} (a trial step of {h:.3e} s, rolled back: {}); the cloth is unchanged",
            e.message
        )))
    }

    /// The trial step of [`Self::trial_step`] on this cloth itself, then everything it moved
    /// put back as it was (the rollback a refused call uses, the mesh colliders as loaded, and
    /// the pins' targets, the solve's acceptance, the statistics and the count of vertices
    /// carried through meshes), so that a large cloth is not copied whole: at a million
    /// particles the copy was most of a load's time (fresh pages to zero;
    /// `docs/benchmarks.md`).
    fn trial_in_place(&mut self, h: f64) -> Result<(), Error> {
        let mut snap = std::mem::take(&mut self.rollback);
        if let Err(e) = snap.save(self) {
            self.rollback = snap;
            return Err(e);
        }
        // Pins held where they are.
        let mut targets = std::mem::take(&mut snap.targets);
        targets.clear();
        targets.extend_from_slice(&self.state.x);
        std::mem::swap(&mut self.pins.target, &mut targets);
        let unconverged = std::mem::replace(&mut self.config.accept_unconverged, true);
        let (solver, stats, carried) = (self.solver_stats, self.step_stats, self.mesh_carried);
        let splitter = self.splitter;
        // The mesh colliders as loaded (their lists and trees empty: small to copy), so that
        // the step's refresh of them is not kept.
        let meshes = self.mesh_slots.clone();
        // The mesh colliders travel from where they are to where the host put them, as the
        // next call's step moves them (from the start of the call). Self-collision's limit
        // slows a vertex here (`StepPlan::new`'s), never refuses.
        let plan = StepPlan::new(self.config.integrator, h, 0.0, None, Stage::Whole);
        let done = self
            .begin_collider_motion(h)
            .and_then(|()| self.advance(plan).map(|_| ()));
        self.mesh_slots = meshes;
        snap.restore(self);
        std::mem::swap(&mut self.pins.target, &mut targets);
        snap.targets = targets;
        self.config.accept_unconverged = unconverged;
        (self.solver_stats, self.step_stats, self.mesh_carried) = (solver, stats, carried);
        self.splitter = splitter;
        self.rollback = snap;
        done
    }

    /// Size in bytes of [`Cloth::save_snapshot`]'s result now, counted without building it.
    pub fn snapshot_size(&self) -> usize {
        let mut w = ByteWriter::counter();
        // A counting writer allocates nothing and cannot fail.
        let _ = self.write_snapshot(&mut w);
        w.len() + 4
    }
}

#[cfg(test)]
mod tests;
