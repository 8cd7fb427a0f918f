//! Colliders, addressed by small integer ids.

use crate::forces::{Capsule, Collider, Plane, Sphere};
use crate::math::Vec3;

use super::cloth::{handle, handle_mut, slice_in, triple};
use super::status::{guard, FcStatus, FfiError};

/// Three floats at `p` as a vector (NULL is an error).
unsafe fn vec_in(p: *const f32, what: &str) -> Result<Vec3, FfiError> {
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: non-NULL; the caller promises 3 readable floats.
    triple(unsafe { slice_in(p, 3, what) }?, what)
}

/// A velocity: three floats, or zero for NULL.
unsafe fn velocity_in(p: *const f32) -> Result<Vec3, FfiError> {
    if p.is_null() {
        Ok(Vec3::zeros())
    } else {
        // SAFETY: forwarded caller promise.
        unsafe { vec_in(p, "velocity") }
    }
}

unsafe fn sphere_from(center: *const f32, radius: f32, velocity: *const f32) -> Result<Sphere, FfiError> {
    // SAFETY: forwarded caller promises.
    Ok(Sphere {
        center: unsafe { vec_in(center, "center") }?,
        radius: f64::from(radius),
        velocity: unsafe { velocity_in(velocity) }?,
    })
}

unsafe fn plane_from(
    point: *const f32,
    normal: *const f32,
    velocity: *const f32,
) -> Result<Collider, FfiError> {
    // SAFETY: forwarded caller promises.
    Ok(Collider::Plane(Plane {
        point: unsafe { vec_in(point, "point") }?,
        normal: unsafe { vec_in(normal, "normal") }?,
        velocity: unsafe { velocity_in(velocity) }?,
    }))
}

unsafe fn capsule_from(
    a: *const f32,
    b: *const f32,
    radius: f32,
    velocity: *const f32,
) -> Result<Collider, FfiError> {
    // SAFETY: forwarded caller promises.
    Ok(Collider::Capsule(Capsule {
        a: unsafe { vec_in(a, "a") }?,
        b: unsafe { vec_in(b, "b") }?,
        radius: f64::from(radius),
        velocity: unsafe { velocity_in(velocity) }?,
    }))
}

/// Adds `collider` and writes its id to `*out_id`.
unsafe fn add(
    cloth: *mut FcCloth,
    out_id: *mut u32,
    make: impl FnOnce() -> Result<Collider, FfiError>,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        if out_id.is_null() {
            return Err(FfiError::null("out_id"));
        }
        let id = cloth.add_collider(make()?)?;
        // SAFETY: checked non-NULL; the caller promises it is writable.
        unsafe { *out_id = id };
        Ok(())
    })
}

/// Replaces collider `id` by `collider`.
unsafe fn set(cloth: *mut FcCloth, id: u32, make: impl FnOnce() -> Result<Collider, FfiError>) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.set_collider(id, make()?)?)
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
    // SAFETY: forwarded caller promises.
    unsafe {
        add(cloth, out_id, || {
            Ok(Collider::Sphere(sphere_from(center, radius, velocity)?))
        })
    }
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
    // SAFETY: forwarded caller promises.
    unsafe {
        set(cloth, id, || {
            Ok(Collider::Sphere(sphere_from(center, radius, velocity)?))
        })
    }
}

/// Adds an infinite plane through `point` (3 floats, m) with normal `normal` (3 floats, any
/// non-zero length; the cloth is kept on the side it points to), moving at `velocity` (m/s,
/// NULL for resting); writes its id to `*out_id` (only on success).
///
/// # Safety
/// `cloth` NULL or live; `point`, `normal` 3 readable floats; `velocity` NULL or 3 readable floats; `out_id` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_add_plane(
    cloth: *mut FcCloth,
    point: *const f32,
    normal: *const f32,
    velocity: *const f32,
    out_id: *mut u32,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { add(cloth, out_id, || plane_from(point, normal, velocity)) }
}

/// Moves or turns plane `id` (same units as `fc_cloth_add_plane`); any collider id may be
/// given a new shape this way.
///
/// # Safety
/// As `fc_cloth_add_plane`.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_plane(
    cloth: *mut FcCloth,
    id: u32,
    point: *const f32,
    normal: *const f32,
    velocity: *const f32,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { set(cloth, id, || plane_from(point, normal, velocity)) }
}

/// Adds a capsule: the points within `radius` (m, > 0) of the segment from `a` to `b` (3
/// floats each, m), moving at `velocity` (m/s, NULL for resting); writes its id to `*out_id`.
///
/// # Safety
/// `cloth` NULL or live; `a`, `b` 3 readable floats; `velocity` NULL or 3 readable floats; `out_id` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_add_capsule(
    cloth: *mut FcCloth,
    a: *const f32,
    b: *const f32,
    radius: f32,
    velocity: *const f32,
    out_id: *mut u32,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { add(cloth, out_id, || capsule_from(a, b, radius, velocity)) }
}

/// Moves or resizes capsule `id` (same units as `fc_cloth_add_capsule`).
///
/// # Safety
/// As `fc_cloth_add_capsule`.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_capsule(
    cloth: *mut FcCloth,
    id: u32,
    a: *const f32,
    b: *const f32,
    radius: f32,
    velocity: *const f32,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { set(cloth, id, || capsule_from(a, b, radius, velocity)) }
}

/// Sets the Coulomb friction coefficient (>= 0; default 0) of collider `id`. Friction acts
/// as a velocity correction after each step: a particle in contact loses up to `friction`
/// times the normal velocity change of its tangential velocity relative to the collider.
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_collider_friction(
    cloth: *mut FcCloth,
    id: u32,
    friction: f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.set_collider_friction(id, f64::from(friction))?)
    })
}

/// Sets collider `id`'s own margin, m (>= 0, finite; any kind, meshes too): the distance from
/// it at which the cloth is pushed away, instead of the description's `collision_margin` (a
/// collider's own thickness, as Blender's per-object collision settings give it). Stiffness
/// and damping stay the description's. Kept when the collider is moved; a collider added
/// again starts at the description's margin.
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_collider_margin(cloth: *mut FcCloth, id: u32, margin: f32) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle_mut(cloth) }?;
        Ok(cloth.set_collider_margin(id, f64::from(margin))?)
    })
}

/// Writes collider `id`'s margin, m (its own, or the description's `collision_margin`), into
/// `*margin` (`FC_ERROR_OUT_OF_RANGE` if there is no such collider).
///
/// # Safety
/// `cloth` NULL or live; `margin` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_collider_margin(
    cloth: *const FcCloth,
    id: u32,
    margin: *mut f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let m = cloth
            .collider_margin(id)
            .ok_or_else(|| FfiError::from(crate::Error::out_of_range(format!("no collider with id {id}"))))?;
        // SAFETY: NULL or writable (caller's promise).
        unsafe { super::cloth::put(margin, m as f32) };
        Ok(())
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

/// Writes `v` as 3 floats to `out` when it is not NULL.
///
/// # Safety
/// `out` NULL or 3 writable floats.
unsafe fn put3(out: *mut f32, v: &crate::math::Vec3) {
    if !out.is_null() {
        // SAFETY: non-NULL; the caller promises 3 writable floats.
        let o = unsafe { std::slice::from_raw_parts_mut(out, 3) };
        o.copy_from_slice(&[v.x as f32, v.y as f32, v.z as f32]);
    }
}

/// Reads plane `id`: a point on it (3 floats, m), its unit normal (3 floats) and its velocity
/// (3 floats, m/s). Any output may be NULL. `FC_ERROR_OUT_OF_RANGE` if `id` is not a plane.
///
/// # Safety
/// `cloth` NULL or live; each output NULL or 3 writable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_plane(
    cloth: *const FcCloth,
    id: u32,
    point: *mut f32,
    normal: *mut f32,
    velocity: *mut f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let Some(Collider::Plane(p)) = cloth.collider(id) else {
            return Err(FfiError {
                status: FcStatus::FC_ERROR_OUT_OF_RANGE,
                message: format!("no plane with id {id}"),
            });
        };
        // SAFETY: forwarded caller promises.
        unsafe {
            put3(point, &p.point);
            put3(normal, &p.normal);
            put3(velocity, &p.velocity);
        }
        Ok(())
    })
}

/// Reads capsule `id`: its segment's ends `a` and `b` (3 floats each, m), radius (m) and
/// velocity (3 floats, m/s). Any output may be NULL. `FC_ERROR_OUT_OF_RANGE` if `id` is not a
/// capsule.
///
/// # Safety
/// `cloth` NULL or live; `a`, `b`, `velocity` NULL or 3 writable floats; `radius` NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_capsule(
    cloth: *const FcCloth,
    id: u32,
    a: *mut f32,
    b: *mut f32,
    radius: *mut f32,
    velocity: *mut f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let Some(Collider::Capsule(c)) = cloth.collider(id) else {
            return Err(FfiError {
                status: FcStatus::FC_ERROR_OUT_OF_RANGE,
                message: format!("no capsule with id {id}"),
            });
        };
        // SAFETY: forwarded caller promises.
        unsafe {
            put3(a, &c.a);
            put3(b, &c.b);
            put3(velocity, &c.velocity);
            if !radius.is_null() {
                *radius = c.radius as f32;
            }
        }
        Ok(())
    })
}

use super::cloth::FcCloth;
