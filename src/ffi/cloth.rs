//! Cloth lifetime, pins, positions and stepping.

use crate::{Cloth, Vec3};

use super::desc::FcClothDesc;
pub use super::handle::FcCloth;
pub(crate) use super::handle::{handle, handle_and_scratch, handle_mut};
use super::status::{guard, guard_value, FcStatus, FfiError};

/// Borrows `len` elements at `ptr`; NULL is accepted only when `len` is 0.
///
/// # Safety
/// Non-NULL `ptr` must point to `len` readable elements.
pub(crate) unsafe fn slice_in<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], FfiError> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: non-NULL, and the caller promises `len` readable elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// Converts xyz triples (float or double) to vectors, rejecting NaN and infinities.
pub(crate) fn triples<T: Copy + Into<f64>>(xyz: &[T], what: &str) -> Result<Vec<Vec3>, FfiError> {
    let mut out = Vec::new();
    triples_into(xyz, what, &mut out)?;
    Ok(out)
}

/// [`triples`] into `out` (its contents replaced), in its room when it has enough: the calls a
/// host makes every frame convert into the handle's [`Scratch`].
pub(crate) fn triples_into<T: Copy + Into<f64>>(
    xyz: &[T],
    what: &str,
    out: &mut Vec<Vec3>,
) -> Result<(), FfiError> {
    out.clear();
    out.try_reserve_exact(xyz.len() / 3).map_err(|_| {
        FfiError::from(crate::Error::out_of_memory(format!(
            "no memory for {} {what}s",
            xyz.len() / 3
        )))
    })?;
    for (k, c) in xyz.chunks_exact(3).enumerate() {
        let v = Vec3::new(c[0].into(), c[1].into(), c[2].into());
        if !v.iter().all(|x| x.is_finite()) {
            return Err(FfiError::invalid(format!(
                "{what} {k} is not finite: ({}, {}, {})",
                v.x, v.y, v.z
            )));
        }
        out.push(v);
    }
    Ok(())
}

/// One xyz triple (float or double) as a vector, rejecting NaN and infinities.
pub(crate) fn triple<T: Copy + Into<f64>>(xyz: &[T], what: &str) -> Result<Vec3, FfiError> {
    let v = Vec3::new(xyz[0].into(), xyz[1].into(), xyz[2].into());
    if !v.iter().all(|x| x.is_finite()) {
        return Err(FfiError::invalid(format!(
            "{what} is not finite: ({}, {}, {})",
            v.x, v.y, v.z
        )));
    }
    Ok(v)
}

pub(crate) fn check_float_count(cloth: &Cloth, float_count: usize) -> Result<(), FfiError> {
    let want = 3 * cloth.vertex_count();
    if float_count == want {
        Ok(())
    } else {
        Err(FfiError::invalid(format!(
            "float_count must be 3 * vertex_count = {want}, got {float_count}"
        )))
    }
}

/// Creates a grid cloth at rest from `*desc` and writes the handle to `*out_cloth`
/// (only on success). Bad fields give `FC_ERROR_INVALID_ARGUMENT` and a message naming them.
///
/// Where the grid sits: in the plane z = 0, centred on x = 0, its top row on y = 0 and its rows
/// going down (-y); vertex `j * width + i` is at
/// `(spacing * (i - (width - 1) / 2), -spacing * j, 0)`. Its triangles wind counter-clockwise
/// seen from +z (normals +z at rest). Gravity defaults to (0, -9.81, 0): y is up.
///
/// # Safety
/// `desc` must be NULL or point to an initialised `FcClothDesc`; `out_cloth` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_create_grid(
    desc: *const FcClothDesc,
    out_cloth: *mut *mut FcCloth,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe {
        create(desc, out_cloth, |d| {
            let by_total = d.total_mass > 0.0;
            let by_area = d.areal_density.is_finite() && d.areal_density > 0.0;
            if !by_total && !by_area {
                return Err(FfiError::invalid(format!(
                    "the cloth has no mass: total_mass is {} (so areal_density is used) and areal_density is {}; set total_mass (kg) > 0, or areal_density (kg/m^2) > 0",
                    d.total_mass, d.areal_density
                )));
            }
            Ok(d.grid_spec().build()?)
        })
    }
}

/// The shared path of the constructors: checks `out`, reads the description, builds the
/// topology with `topology`, creates the cloth and writes its handle to `*out` (only on success).
///
/// # Safety
/// `desc` NULL or an initialised description; `out` NULL or writable.
pub(crate) unsafe fn create(
    desc: *const FcClothDesc,
    out: *mut *mut FcCloth,
    topology: impl FnOnce(&FcClothDesc) -> Result<crate::Topology, FfiError>,
) -> FcStatus {
    guard(|| {
        if out.is_null() {
            return Err(FfiError::null("out_cloth"));
        }
        // SAFETY: the caller promises a valid description or NULL.
        let desc = unsafe { super::desc_size::read_desc(desc, super::desc::fc_cloth_desc_default()) }?;
        let config = desc.config()?;
        let cloth = Cloth::new(topology(&desc)?, config)?;
        let raw = Box::into_raw(Box::new(FcCloth::new(cloth)));
        // SAFETY: checked non-NULL; the caller promises it is writable.
        unsafe { *out = raw };
        Ok(())
    })
}

/// Frees a cloth. NULL is fine. Using the handle afterwards is the host's bug.
///
/// # Safety
/// `cloth` must be NULL or a handle from `fc_cloth_create_grid` or `fc_cloth_create_mesh` not yet
/// destroyed.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_destroy(cloth: *mut FcCloth) {
    guard_value((), || {
        if !cloth.is_null() {
            // SAFETY: the caller promises a live handle created by Box::into_raw.
            drop(unsafe { Box::from_raw(cloth) });
        }
    })
}

/// Number of vertices (particles); 0 for NULL.
///
/// # Safety
/// `cloth` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_vertex_count(cloth: *const FcCloth) -> usize {
    // SAFETY: forwarded caller promise.
    guard_value(0, || unsafe { handle(cloth) }.map_or(0, |c| c.vertex_count()))
}

/// Simulated time in seconds; 0 for NULL.
///
/// # Safety
/// `cloth` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_time(cloth: *const FcCloth) -> f64 {
    // SAFETY: forwarded caller promise.
    guard_value(0.0, || unsafe { handle(cloth) }.map_or(0.0, |c| c.time()))
}

/// Replaces the set of pinned vertices with `indices[0..count]` (count 0 unpins all).
/// Pins hold their current positions until moved with `fc_cloth_set_pin_targets`.
///
/// # Safety
/// `cloth` NULL or live; `indices` NULL or `count` readable values.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_pinned(
    cloth: *mut FcCloth,
    indices: *const u32,
    count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        let indices = unsafe { slice_in(indices, count, "indices") }?;
        Ok(cloth.set_pinned(indices)?)
    })
}

/// Sets the pin weight of every vertex: `weights[0..count]`, `count` = vertex_count, each in
/// [0, 1] (0 = free, 1 = fully pinned). A vertex of weight w in (0, 1) is a soft pin: at the
/// end of every step it is pulled the fraction w of the way onto its target (and its velocity
/// onto the target's). Replaces the pinned set; new pins hold their current positions.
///
/// # Safety
/// `cloth` NULL or live; `weights` NULL or `count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_pin_weights(
    cloth: *mut FcCloth,
    weights: *const f32,
    count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        // The length is checked before anything is read.
        if count != cloth.vertex_count() {
            return Err(FfiError::invalid(format!(
                "count must be vertex_count = {}, got {count}",
                cloth.vertex_count()
            )));
        }
        let weights = unsafe { slice_in(weights, count, "weights") }?;
        let w: Vec<f64> = weights.iter().map(|&w| f64::from(w)).collect();
        Ok(cloth.set_pin_weights(&w)?)
    })
}

/// Pins a vertex group in one call: sets the pin weight of `indices[0..count]` to `weight`
/// (in [0, 1]; 0 frees them), leaving every other vertex as it is.
///
/// # Safety
/// `cloth` NULL or live; `indices` NULL or `count` readable values.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_pin_group(
    cloth: *mut FcCloth,
    indices: *const u32,
    count: usize,
    weight: f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        let indices = unsafe { slice_in(indices, count, "indices") }?;
        Ok(cloth.pin_group(indices, f64::from(weight))?)
    })
}

/// Moves pinned vertices: after the next step, vertex `indices[k]` sits exactly at
/// `(xyz[3k], xyz[3k+1], xyz[3k+2])` (m). Every index must be pinned; the pin
/// travels in a straight line over the step, which is its velocity.
///
/// Like every call a host makes each frame (pin targets, colliders, the current, stepping,
/// reading positions and normals), it allocates nothing once a call of its size has been
/// made: the handle keeps the room it converts the floats in (`tests/no_alloc.rs`).
///
/// # Safety
/// `cloth` NULL or live; `indices` `count` readable values; `xyz` `3 * count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_pin_targets(
    cloth: *mut FcCloth,
    indices: *const u32,
    xyz: *const f32,
    count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let (cloth, scratch) = unsafe { handle_and_scratch(cloth) }?;
        let indices = unsafe { slice_in(indices, count, "indices") }?;
        let floats = count
            .checked_mul(3)
            .ok_or_else(|| FfiError::invalid("count too large"))?;
        let xyz = unsafe { slice_in(xyz, floats, "xyz") }?;
        triples_into(xyz, "target", &mut scratch.input)?;
        Ok(cloth.set_pin_targets(indices, &scratch.input)?)
    })
}

/// Sets every vertex position from float xyz triples (m); `float_count` must be
/// 3 * vertex_count. Velocities and history are kept; pinned vertices are re-pinned there.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `float_count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_positions(
    cloth: *mut FcCloth,
    xyz: *const f32,
    float_count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let (cloth, scratch) = unsafe { handle_and_scratch(cloth) }?;
        check_float_count(cloth, float_count)?;
        let xyz = unsafe { slice_in(xyz, float_count, "xyz") }?;
        triples_into(xyz, "position", &mut scratch.input)?;
        Ok(cloth.set_positions(&scratch.input)?)
    })
}

/// Writes `values` as triples into `out`, each component converted by `convert`.
pub(crate) fn write_triples<T>(values: &[Vec3], out: &mut [T], convert: fn(f64) -> T) {
    for (o, v) in out.chunks_exact_mut(3).zip(values) {
        o[0] = convert(v.x);
        o[1] = convert(v.y);
        o[2] = convert(v.z);
    }
}

/// Copies `values(cloth)` into the caller's buffer of `count` values (float or double) after
/// the usual checks.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `count` writable values.
pub(crate) unsafe fn copy_out<T>(
    cloth: *const FcCloth,
    xyz: *mut T,
    count: usize,
    values: fn(&Cloth) -> &[Vec3],
    convert: fn(f64) -> T,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle(cloth) }?;
        check_float_count(cloth, count)?;
        if xyz.is_null() {
            return Err(FfiError::null("xyz"));
        }
        // SAFETY: non-NULL and the caller promises `count` writable values.
        let out = unsafe { std::slice::from_raw_parts_mut(xyz, count) };
        write_triples(values(cloth), out, convert);
        Ok(())
    })
}

/// f64 to the ABI's float.
/// Writes `value` to an optional output (nothing for NULL).
///
/// # Safety
/// `out` NULL or writable.
pub(crate) unsafe fn put<T>(out: *mut T, value: T) {
    // SAFETY: NULL or writable (caller's promise).
    if let Some(o) = unsafe { out.as_mut() } {
        *o = value;
    }
}

pub(crate) fn to_f32(x: f64) -> f32 {
    x as f32
}

/// Copies every vertex position (m) into `xyz` as float triples; `float_count` must be 3 * vertex_count.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `float_count` writable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_positions(
    cloth: *const FcCloth,
    xyz: *mut f32,
    float_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { copy_out(cloth, xyz, float_count, Cloth::positions, to_f32) }
}

/// Copies every vertex velocity (m/s) into `xyz` as float triples; `float_count` must be 3 * vertex_count.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `float_count` writable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_velocities(
    cloth: *const FcCloth,
    xyz: *mut f32,
    float_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { copy_out(cloth, xyz, float_count, Cloth::velocities, to_f32) }
}

/// Sets the uniform water current (m/s), effective from the next step.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or 3 readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_current(cloth: *mut FcCloth, xyz: *const f32) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { set_current_from(cloth, xyz) }
}

/// `fc_cloth_set_current` from three values of either precision.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or 3 readable values.
pub(crate) unsafe fn set_current_from<T: Copy + Into<f64>>(cloth: *mut FcCloth, xyz: *const T) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        let xyz = unsafe { slice_in(xyz, 3, "xyz") }?;
        Ok(cloth.set_current(triple(xyz, "current")?)?)
    })
}

/// Advances the cloth by `dt` seconds (finite, > 0). Atomic: on any error
/// (`FC_ERROR_INVALID_ARGUMENT` for a bad dt, `FC_ERROR_UNSTABLE` when the result
/// would be non-finite or faster than `max_speed`) the cloth is exactly as before.
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_step(cloth: *mut FcCloth, dt: f64) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.step(dt)?)
    })
}

/// Exponential modes the SOE history uses per particle (0 for other schemes, for a cloth
/// without fractional terms, or for NULL).
///
/// # Safety
/// `cloth` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_history_mode_count(cloth: *const FcCloth) -> u32 {
    // SAFETY: forwarded caller promise.
    guard_value(0, || {
        unsafe { handle(cloth) }.map_or(0, |c| c.history().mode_count() as u32)
    })
}

/// Bytes of half-derivative history held per particle now (0 when no history is kept, or for NULL).
///
/// # Safety
/// `cloth` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_history_bytes_per_particle(cloth: *const FcCloth) -> usize {
    use crate::HalfDerivative;
    // SAFETY: forwarded caller promise.
    guard_value(0, || {
        unsafe { handle(cloth) }.map_or(0, |c| c.history().bytes_per_particle())
    })
}

/// Advances by `dt` seconds in `substeps` equal substeps (1 ..= 1000000); pins travel in a
/// straight line to their targets over the whole call. Atomic over the whole call. With
/// self-collision a substep in which a vertex would move more than half its thickness is taken
/// in up to 32 equal pieces (`fc_cloth_get_step_stats` counts them).
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_step_substeps(cloth: *mut FcCloth, dt: f64, substeps: u32) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.step_substeps(dt, substeps)?)
    })
}

/// Sets the implicit solver's relative residual tolerance (> 0) and iteration cap (>= 1).
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_solver(
    cloth: *mut FcCloth,
    tolerance: f64,
    max_iterations: u32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.set_solver(crate::integrate::SolverSettings {
            tolerance,
            max_iterations,
        })?)
    })
}

/// Reads what the last implicit solve did: CG iterations and final relative residual.
/// Both are 0 before the first implicit step and for explicit integrators. Either output may be NULL.
///
/// # Safety
/// `cloth` NULL or live; outputs NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_solver_stats(
    cloth: *const FcCloth,
    iterations: *mut u32,
    residual: *mut f64,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let stats = unsafe { handle(cloth) }?.solver_stats();
        // SAFETY: each output is NULL or writable, as the caller promises.
        unsafe {
            put(iterations, stats.iterations);
            put(residual, stats.residual);
        }
        Ok(())
    })
}

/// Reads what the last `fc_cloth_step` or `fc_cloth_step_substeps` did: the substeps it took
/// (with the automatic step, those of the attempt that succeeded; with self-collision, the
/// pieces of the substeps it split counted one by one), how many times the automatic
/// step retried with twice the substeps after a refused substep, and its substep estimate in
/// seconds (0 with a fixed step). All 0 before the first step. Any output may be NULL.
///
/// # Safety
/// `cloth` NULL or live; outputs NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_step_stats(
    cloth: *const FcCloth,
    substeps: *mut u32,
    retries: *mut u32,
    estimate: *mut f64,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let stats = unsafe { handle(cloth) }?.step_stats();
        // SAFETY: each output is NULL or writable, as the caller promises.
        unsafe {
            put(substeps, stats.substeps);
            put(retries, stats.retries);
            put(estimate, stats.estimate);
        }
        Ok(())
    })
}

/// Reads what the continuous collision check did since the cloth was made (steps that a
/// refused call undid included): `zone_steps`, the steps in which a self-collision pair would
/// have passed through another; `passages`, how many such passages were found; `zone_moved`,
/// the free vertices moved with an impact zone (summed over steps); `unresolved`, passages
/// still there when the zones stopped (0: the cloth never went through itself where its pairs
/// were listed); `mesh_carried`, cloth vertices a mesh collider carried rather than let pass
/// through it (summed over steps). All 0 for a cloth without self-collision or mesh colliders.
/// Any output may be NULL.
///
/// # Safety
/// `cloth` NULL or live; outputs NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_collision_stats(
    cloth: *const FcCloth,
    zone_steps: *mut u64,
    passages: *mut u64,
    zone_moved: *mut u64,
    unresolved: *mut u64,
    mesh_carried: *mut u64,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let zones = cloth.self_collision_zones();
        // SAFETY: each output is NULL or writable, as the caller promises.
        unsafe {
            put(zone_steps, zones.steps);
            put(passages, zones.passages);
            put(zone_moved, zones.moved);
            put(unresolved, zones.unresolved);
            put(mesh_carried, cloth.mesh_carried());
        }
        Ok(())
    })
}

/// Reads what self-collision's step limit did since the cloth was made (steps that a refused
/// call undid included). No free vertex moves more than half the self-collision thickness in a
/// substep: `split_substeps`, the substeps taken in pieces instead (2 to 32 equal ones; at a
/// fixed step up to 32 times the pieces the substep needs to be stable, since a split
/// substep's pieces are no longer than the automatic step's stable substep, so a step too long
/// to be stable is taken in stable pieces rather than refused) and `pieces`, how many;
/// `slowed`, free vertices slowed to the limit, summed over steps, the last resort when a
/// substep split as far as it goes is not enough (not 0: some motion was held back, e.g. a
/// vertex flung faster than the pieces can follow). All 0 without self-collision. Any output
/// may be NULL.
///
/// # Safety
/// `cloth` NULL or live; outputs NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_step_limit_stats(
    cloth: *const FcCloth,
    split_substeps: *mut u64,
    pieces: *mut u64,
    slowed: *mut u64,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let stats = unsafe { handle(cloth) }?.step_limit_stats();
        // SAFETY: each output is NULL or writable, as the caller promises.
        unsafe {
            put(split_substeps, stats.split_substeps);
            put(pieces, stats.pieces);
            put(slowed, stats.slowed);
        }
        Ok(())
    })
}

/// Whether an implicit step whose solver stops at `solver_max_iterations` above
/// `solver_tolerance` is accepted (`accept` non-zero: the step returns `FC_OK`; read
/// `fc_cloth_get_solver_stats`) or refused (0, the default: `FC_ERROR_NOT_CONVERGED`, the
/// cloth unchanged).
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_solver_accept_unconverged(
    cloth: *mut FcCloth,
    accept: i32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        cloth.set_accept_unconverged(accept != 0);
        Ok(())
    })
}
