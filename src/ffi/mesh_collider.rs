//! Triangle-mesh colliders: any mesh, static, moving or deforming (a skinned character).

use crate::math::Vec3;

use super::cloth::{handle, handle_and_scratch, handle_mut, put, slice_in, triples_into, FcCloth};
use super::status::{guard, FcStatus, FfiError};

/// `3 * count` floats at `xyz` as vectors.
unsafe fn points_in(xyz: *const f32, count: usize, what: &str) -> Result<Vec<Vec3>, FfiError> {
    let mut out = Vec::new();
    // SAFETY: forwarded caller promises.
    unsafe { points_into(xyz, count, what, &mut out) }?;
    Ok(out)
}

/// [`points_in`] into `out` (its contents replaced, in its room when it has enough).
///
/// # Safety
/// `xyz` NULL or `3 * count` readable floats.
unsafe fn points_into(
    xyz: *const f32,
    count: usize,
    what: &str,
    out: &mut Vec<Vec3>,
) -> Result<(), FfiError> {
    if xyz.is_null() {
        return Err(FfiError::null(what));
    }
    let floats = count
        .checked_mul(3)
        .ok_or_else(|| FfiError::invalid(format!("{what}: count too large")))?;
    // SAFETY: non-NULL; the caller promises `3 * count` readable floats.
    triples_into(unsafe { slice_in(xyz, floats, what) }?, what, out)
}

/// Velocities: NULL for none (then from the motion between calls).
unsafe fn velocities_in(v: *const f32, count: usize) -> Result<Option<Vec<Vec3>>, FfiError> {
    if v.is_null() {
        return Ok(None);
    }
    // SAFETY: forwarded caller promise.
    unsafe { points_in(v, count, "velocities") }.map(Some)
}

/// Adds a triangle-mesh collider and writes its id to `*out_id` (only on success). The id is
/// shared with the other colliders: `fc_cloth_set_collider_friction` and
/// `fc_cloth_remove_collider` take it.
///
/// `xyz`: `vertex_count` positions (3 floats each, m). `indices`: `index_count` vertex
/// indices, three per triangle (any winding on an open mesh; on a closed one, counter-clockwise
/// seen from outside, as Blender, Maya and glTF write them). `velocities`: NULL (the surface
/// moves as its positions do between calls) or `vertex_count` velocities (3 floats each, m/s).
///
/// The cloth keeps `collision_margin` from the mesh, with `collision_stiffness` and
/// `collision_damping` as for the other colliders. A closed mesh (every edge shared by two
/// triangles) has an inside: a cloth vertex that ends up in it is pushed out. An open mesh is a
/// two-sided shell. Mesh vertices push cloth triangles too, so a collider thinner than the
/// cloth's spacing does not slip between cloth vertices. See docs/collisions.md.
///
/// Errors: `FC_ERROR_NULL_ARGUMENT`; `FC_ERROR_OUT_OF_RANGE` for an index not below
/// `vertex_count`; `FC_ERROR_INVALID_ARGUMENT` for no triangle, an index count not a multiple
/// of 3, or a non-finite value; `FC_ERROR_OUT_OF_MEMORY`.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `3 * vertex_count` readable floats; `indices` NULL or
/// `index_count` readable values; `velocities` NULL or `3 * vertex_count` readable floats;
/// `out_id` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_add_mesh_collider(
    cloth: *mut FcCloth,
    xyz: *const f32,
    vertex_count: usize,
    indices: *const u32,
    index_count: usize,
    velocities: *const f32,
    out_id: *mut u32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle_mut(cloth) }?;
        if out_id.is_null() {
            return Err(FfiError::null("out_id"));
        }
        if indices.is_null() {
            return Err(FfiError::null("indices"));
        }
        if index_count == 0 || index_count % 3 != 0 {
            return Err(FfiError::invalid(format!(
                "index_count must be a positive multiple of 3 (three indices a triangle), got {index_count}"
            )));
        }
        // SAFETY: forwarded caller promises.
        let positions = unsafe { points_in(xyz, vertex_count, "xyz") }?;
        // SAFETY: non-NULL; the caller promises `index_count` readable indices.
        let flat = unsafe { slice_in(indices, index_count, "indices") }?;
        let mut triangles = Vec::new();
        triangles.try_reserve_exact(index_count / 3).map_err(|_| {
            FfiError::from(crate::Error::out_of_memory(
                "no memory for the mesh collider's triangles",
            ))
        })?;
        triangles.extend(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        // SAFETY: forwarded caller promise.
        let v = unsafe { velocities_in(velocities, vertex_count) }?;
        let id = cloth.add_mesh_collider(&positions, &triangles, v.as_deref())?;
        // SAFETY: checked non-NULL; the caller promises it is writable.
        unsafe { *out_id = id };
        Ok(())
    })
}

/// Moves or deforms mesh collider `id`: `vertex_count` new positions (3 floats each, m) of
/// the same vertices in the same order, and their velocities (NULL: from the motion). The mesh
/// travels there in a straight line over the next `fc_cloth_step` call, as the pins do; call
/// it once a frame with the evaluated mesh (armature, shape keys, modifiers). A mesh sent again
/// where it is (the same floats) keeps its search: a still collider sent every frame costs a
/// comparison of its positions, not a new search. No allocation once a call has been made with as
/// many vertices (and velocities, when given).
///
/// Errors: `FC_ERROR_OUT_OF_RANGE` for no mesh collider `id`; `FC_ERROR_INVALID_ARGUMENT` for
/// a vertex count other than the mesh's or a non-finite value. Nothing changes on an error.
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `3 * vertex_count` readable floats; `velocities` NULL or
/// `3 * vertex_count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_mesh_collider(
    cloth: *mut FcCloth,
    id: u32,
    xyz: *const f32,
    vertex_count: usize,
    velocities: *const f32,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let (cloth, scratch) = unsafe { handle_and_scratch(cloth) }?;
        // Into the handle's room: a host sets a skinned mesh every frame.
        // SAFETY: forwarded caller promises.
        unsafe { points_into(xyz, vertex_count, "xyz", &mut scratch.input) }?;
        let v = if velocities.is_null() {
            None
        } else {
            // SAFETY: forwarded caller promise.
            unsafe { points_into(velocities, vertex_count, "velocities", &mut scratch.second) }?;
            Some(&scratch.second[..])
        };
        Ok(cloth.set_mesh_collider(id, &scratch.input, v)?)
    })
}

/// Reads mesh collider `id`'s vertex and triangle counts (either output may be NULL).
///
/// # Safety
/// `cloth` NULL or live; `vertex_count`, `triangle_count` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_mesh_collider(
    cloth: *const FcCloth,
    id: u32,
    vertex_count: *mut usize,
    triangle_count: *mut usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let mesh = cloth.mesh_collider(id).ok_or_else(|| {
            FfiError::from(crate::Error::out_of_range(format!(
                "no mesh collider with id {id}"
            )))
        })?;
        // SAFETY: each is NULL or writable (caller's promise).
        unsafe {
            put(vertex_count, mesh.vertex_count());
            put(triangle_count, mesh.triangles().len());
        }
        Ok(())
    })
}
