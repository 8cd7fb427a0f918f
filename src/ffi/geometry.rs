//! What a renderer needs every frame besides positions: the index buffer and vertex normals.

use super::cloth::{check_float_count, handle, to_f32, write_triples, FcCloth};
use super::status::{guard, FcStatus, FfiError};
use crate::math::Vec3;

/// Copies the triangles (three vertex indices each, counter-clockwise seen from the side the
/// normals point to; quads of a mesh split on one diagonal, grids as the OBJ and caches write
/// them) into `indices`; `index_count` must be 3 * `fc_cloth_triangle_count`. The buffer does
/// not change while the cloth lives: read it once.
///
/// # Safety
/// `cloth` NULL or live; `indices` NULL or `index_count` writable `uint32_t`.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_triangles(
    cloth: *const FcCloth,
    indices: *mut u32,
    index_count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let triangles = &cloth.topology().triangles;
        if index_count != 3 * triangles.len() {
            return Err(FfiError::invalid(format!(
                "index_count must be 3 * triangle_count = {}, got {index_count}",
                3 * triangles.len()
            )));
        }
        if indices.is_null() {
            return Err(FfiError::null("indices"));
        }
        // SAFETY: non-NULL and the caller promises `index_count` writable values.
        let out = unsafe { std::slice::from_raw_parts_mut(indices, index_count) };
        for (o, t) in out.chunks_exact_mut(3).zip(triangles) {
            o.copy_from_slice(t);
        }
        Ok(())
    })
}

/// Writes the unit normal of every vertex at the current positions into `xyz` (float triples;
/// `float_count` = 3 * vertex_count): the area-weighted sum of its triangles' normals, pointing to
/// the side from which they wind counter-clockwise (+z for a fresh grid); (0, 0, 0) for a vertex
/// whose triangles have collapsed. For smooth shading of the cloth as it is now; no allocation
/// once it has been called (the handle keeps the room for them).
///
/// # Safety
/// `cloth` NULL or live; `xyz` NULL or `float_count` writable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_normals(
    cloth: *const FcCloth,
    xyz: *mut f32,
    float_count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: the caller promises a live handle or NULL.
        let handle = unsafe { cloth.as_ref() }.ok_or_else(|| FfiError::null("cloth"))?;
        let cloth = &handle.cloth;
        check_float_count(cloth, float_count)?;
        if xyz.is_null() {
            return Err(FfiError::null("xyz"));
        }
        // The handle's room (a host reads the normals every frame), or room of this call's
        // own when another call holds it.
        let mut own = (Vec::new(), Vec::new());
        let mut locked = handle.scratch.normals.try_lock().ok();
        let (normals, faces) = locked.as_deref_mut().unwrap_or(&mut own);
        let n = cloth.vertex_count();
        normals.clear();
        normals
            .try_reserve_exact(n)
            .map_err(|_| FfiError::from(crate::Error::out_of_memory("no memory for the normals")))?;
        normals.resize(n, Vec3::zeros());
        cloth.vertex_normals_in(normals, faces)?;
        // SAFETY: non-NULL and the caller promises `float_count` writable floats.
        let out = unsafe { std::slice::from_raw_parts_mut(xyz, float_count) };
        write_triples(normals, out, to_f32);
        Ok(())
    })
}
