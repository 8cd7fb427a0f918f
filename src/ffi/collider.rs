//! Colliders, addressed by small integer ids.

use crate::forces::{Collider, Sphere};
use crate::Vec3;

use super::cloth::{handle, handle_mut, slice_in, triples};
use super::status::{guard, FcStatus, FfiError};

unsafe fn sphere_from(center: *const f32, radius: f32, velocity: *const f32) -> Result<Sphere, FfiError> {
    // SAFETY: forwarded caller promises.
    let c = triples(unsafe { slice_in(center, 3, "center") }?, "center")?;
    let v = if velocity.is_null() {
        Vec3::zeros()
    } else {
        triples(unsafe { slice_in(velocity, 3, "velocity") }?, "velocity")?[0]
    };
    Ok(Sphere {
        center: c[0],
        radius: f64::from(radius),
        velocity: v,
    })
}

/// Adds a sphere collider (centre in m, radius in m > 0; velocity in m/s, NULL for
/// resting) and writes its id to `*out_id` (only on success).
///
/// # Safety
/// `cloth` NULL or live; `center` 3 readable floats; `velocity` NULL or 3 readable floats; `out_id` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_add_sphere(
    cloth: *mut FcCloth,
    center: *const f32,
    radius: f32,
    velocity: *const f32,
    out_id: *mut u32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        if out_id.is_null() {
            return Err(FfiError::null("out_id"));
        }
        let sphere = unsafe { sphere_from(center, radius, velocity) }?;
        let id = cloth.add_sphere(sphere)?;
        // SAFETY: checked non-NULL; the caller promises it is writable.
        unsafe { *out_id = id };
        Ok(())
    })
}

/// Moves, resizes or re-speeds sphere `id` (same units as `fc_cloth_add_sphere`).
///
/// # Safety
/// As `fc_cloth_add_sphere`.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_sphere(
    cloth: *mut FcCloth,
    id: u32,
    center: *const f32,
    radius: f32,
    velocity: *const f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        let sphere = unsafe { sphere_from(center, radius, velocity) }?;
        Ok(cloth.set_sphere(id, sphere)?)
    })
}

/// Removes collider `id` (`FC_ERROR_OUT_OF_RANGE` if there is none); the id may be reused.
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_remove_collider(cloth: *mut FcCloth, id: u32) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.remove_collider(id)?)
    })
}

/// Reads sphere `id`: centre (3 floats, m) and radius (m). Either output may be NULL.
///
/// # Safety
/// `cloth` NULL or live; `center` NULL or 3 writable floats; `radius` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_sphere(
    cloth: *const FcCloth,
    id: u32,
    center: *mut f32,
    radius: *mut f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let Some(Collider::Sphere(s)) = cloth.collider(id) else {
            return Err(FfiError {
                status: FcStatus::FC_ERROR_OUT_OF_RANGE,
                message: format!("no sphere with id {id}"),
            });
        };
        if !center.is_null() {
            // SAFETY: non-NULL; the caller promises 3 writable floats.
            let c = unsafe { std::slice::from_raw_parts_mut(center, 3) };
            c.copy_from_slice(&[s.center.x as f32, s.center.y as f32, s.center.z as f32]);
        }
        if !radius.is_null() {
            // SAFETY: non-NULL; the caller promises it is writable.
            unsafe { *radius = s.radius as f32 };
        }
        Ok(())
    })
}

use super::cloth::FcCloth;
