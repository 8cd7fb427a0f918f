//! Snapshots through the ABI: save a cloth's complete state to a caller buffer and restore it.

use std::ffi::c_void;

use super::cloth::{handle, handle_mut, slice_in, FcCloth};
use super::status::{guard, guard_value, FcStatus, FfiError};

/// Bytes `fc_cloth_save_snapshot` needs now (it grows with the history for `FC_HISTORY_FULL`;
/// constant otherwise), counted without building the snapshot. 0 for NULL.
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_snapshot_size(cloth: *const FcCloth) -> usize {
    // SAFETY: forwarded caller promise.
    guard_value(0, || unsafe { handle(cloth) }.map_or(0, |c| c.snapshot_size()))
}

/// Writes the cloth's complete state (positions, velocities, pins and targets, colliders with
/// friction, current, solver settings, time, and the fractional history) into `buffer`:
/// a versioned, CRC-32-checked binary snapshot. `capacity` is the buffer size in bytes; the
/// size written goes to `*out_written` (may be NULL). A buffer smaller than
/// `fc_cloth_snapshot_size` gives `FC_ERROR_INVALID_ARGUMENT` and writes nothing;
/// `FC_ERROR_OUT_OF_MEMORY` when the snapshot cannot be assembled. The bytes depend only on
/// the cloth's state: after a refused step they equal the bytes saved before it.
///
/// # Safety
/// `cloth` NULL or live; `buffer` NULL or `capacity` writable bytes; `out_written` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_save_snapshot(
    cloth: *const FcCloth,
    buffer: *mut c_void,
    capacity: usize,
    out_written: *mut usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        if buffer.is_null() {
            return Err(FfiError::null("buffer"));
        }
        let size = cloth.snapshot_size();
        if size > capacity {
            return Err(FfiError::invalid(format!(
                "snapshot needs {size} bytes, buffer has {capacity}"
            )));
        }
        let bytes = cloth.save_snapshot()?;
        // SAFETY: non-NULL; the caller promises `capacity` >= bytes.len() writable bytes.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer.cast::<u8>(), bytes.len()) };
        if !out_written.is_null() {
            // SAFETY: non-NULL; the caller promises it is writable.
            unsafe { *out_written = bytes.len() };
        }
        Ok(())
    })
}

/// Restores a snapshot saved from a cloth of the same mesh and history settings. Stepping on
/// gives bitwise the same results as the saved cloth would have. A truncated, corrupted or
/// foreign snapshot gives `FC_ERROR_INVALID_ARGUMENT` (the message says why) and leaves the
/// cloth exactly as it was. Beyond the checksum, the contents are checked for meaning: every
/// number finite and within the float range, speeds within this cloth's `max_speed`, history
/// times ordered and within the span the cloth has lived, step sizes positive; then a trial step
/// (at the mean step the state was reached with, pins held, mesh colliders moving to where
/// the host put them as the next call would move them; taken on the cloth itself and rolled
/// back) must succeed, so a snapshot that loads can always be stepped. The message names what was refused (the
/// half-derivative history when the trial succeeds without it).
///
/// **What a snapshot carries.** The state: positions, velocities, pins and their targets,
/// colliders and their friction, the current, the solver settings, the half-derivative
/// histories, the time and the step count. Not the model: the receiving cloth keeps its own
/// coefficients, integrator, `max_speed` and `max_substep`, so a snapshot saved with one model
/// continues with the receiving cloth's (and is refused only if that cloth cannot take a step
/// from it). The receiving cloth must have the same topology (vertex, spring and triangle counts
/// and rest shape: a grid and the same vertices built as a quad mesh have different springs and
/// are refused) and the same history scheme and settings.
///
/// # Safety
/// `cloth` NULL or live; `data` NULL or `size` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_load_snapshot(
    cloth: *mut FcCloth,
    data: *const c_void,
    size: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        if data.is_null() {
            return Err(FfiError::null("data"));
        }
        let bytes = unsafe { slice_in(data.cast::<u8>(), size, "data") }?;
        Ok(cloth.load_snapshot(bytes)?)
    })
}
