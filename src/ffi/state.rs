//! The cloth's state in double precision, and velocities in both precisions: for hosts that
//! keep their own state (an undo stack, a network replica) and for tests and references that
//! need exact initial states. Positions and velocities in `float` are in `cloth.rs`.

use super::cloth::{check_float_count, copy_out, handle_and_scratch, slice_in, triples_into, FcCloth};
use super::status::{guard, FcStatus};
use crate::{Cloth, Vec3};

/// Reads `float_count` values of the caller's after the usual checks and hands the vectors to
/// `set`.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `count` readable values.
unsafe fn set_all<T: Copy + Into<f64>>(
    cloth: *mut FcCloth,
    xyz: *const T,
    count: usize,
    what: &str,
    set: fn(&mut Cloth, &[Vec3]) -> Result<(), crate::Error>,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let (cloth, scratch) = unsafe { handle_and_scratch(cloth) }?;
        check_float_count(cloth, count)?;
        let xyz = unsafe { slice_in(xyz, count, "xyz") }?;
        triples_into(xyz, what, &mut scratch.input)?;
        Ok(set(cloth, &scratch.input)?)
    })
}

/// Sets every vertex velocity from float xyz triples (m/s); `float_count` must be
/// 3 * vertex_count. The history is kept (it holds the past, not the present velocity).
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `float_count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_velocities(
    cloth: *mut FcCloth,
    xyz: *const f32,
    float_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { set_all(cloth, xyz, float_count, "velocity", Cloth::set_velocities) }
}

/// `fc_cloth_set_velocities` from double triples (m/s), exactly.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `double_count` readable doubles.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_velocities_f64(
    cloth: *mut FcCloth,
    xyz: *const f64,
    double_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { set_all(cloth, xyz, double_count, "velocity", Cloth::set_velocities) }
}

/// `fc_cloth_set_positions` from double triples (m), exactly: velocities and history are kept,
/// pinned vertices are re-pinned there.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `double_count` readable doubles.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_positions_f64(
    cloth: *mut FcCloth,
    xyz: *const f64,
    double_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { set_all(cloth, xyz, double_count, "position", Cloth::set_positions) }
}

/// Copies every vertex position (m) into `xyz` as double triples, exactly; `double_count`
/// must be 3 * vertex_count.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `double_count` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_positions_f64(
    cloth: *const FcCloth,
    xyz: *mut f64,
    double_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { copy_out(cloth, xyz, double_count, Cloth::positions, |x| x) }
}

/// Copies every vertex velocity (m/s) into `xyz` as double triples, exactly; `double_count`
/// must be 3 * vertex_count.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `double_count` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_velocities_f64(
    cloth: *const FcCloth,
    xyz: *mut f64,
    double_count: usize,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { copy_out(cloth, xyz, double_count, Cloth::velocities, |x| x) }
}

/// `fc_cloth_set_current` from a double triple (m/s), exactly as the description's
/// `current` holds it.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or 3 readable doubles.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_current_f64(cloth: *mut FcCloth, xyz: *const f64) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { super::cloth::set_current_from(cloth, xyz) }
}
