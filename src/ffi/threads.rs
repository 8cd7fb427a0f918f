//! Where a cloth's step runs: the host's own threads, a pool of the cloth's own, or the
//! library's shared pool.

use super::cloth::{handle, handle_mut};
use super::status::{guard, guard_value, FcStatus};
use super::FcCloth;

/// Chooses the threads `fc_cloth_step` runs on; the result is bit for bit the same for every
/// choice.
/// - `0` (the default): the library's shared pool (size from `RAYON_NUM_THREADS`, else one
///   thread per core). Cloths under 16,000 particles step on the calling thread anyway.
/// - `1`: every pass on the calling thread, whatever the cloth's size. For a host with its own
///   job system: step different cloths from different jobs (one handle per thread at a time),
///   and no thread but the caller's is used.
/// - `n >= 2` (at most 256): a pool of `n` threads owned by this cloth, started now; the calling
///   thread waits for each step. `FC_ERROR_INVALID_ARGUMENT` if the threads cannot be started.
///
/// A cloth with self-collision makes its neighbour lists when it is created (on the shared pool
/// for a cloth whose step would use it: this call comes after) and again when `fc_cloth_set_desc`
/// changes the thickness (then on the threads chosen here).
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_threads(cloth: *mut FcCloth, threads: u32) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.set_threads(threads)?)
    })
}

/// The value last given to `fc_cloth_set_threads` (0 by default, and for NULL).
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_threads(cloth: *const FcCloth) -> u32 {
    // SAFETY: forwarded caller promise.
    guard_value(0, || unsafe { handle(cloth) }.map_or(0, |c| c.threads()))
}
