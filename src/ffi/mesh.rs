//! Cloths from arbitrary triangle or quad meshes.

use crate::topology::{MeshMass, MeshSpec};

use super::cloth::{create, slice_in, triples, FcCloth};
use super::desc::FcClothDesc;
use super::status::{FcStatus, FfiError};

/// Creates a cloth from a mesh at rest: `vertex_count` positions (xyz floats, m) and
/// `index_count` corner indices, `face_size` (3: triangles, 4: quads with corners in order
/// around the face) per face. Writes the handle to `*out_cloth` only on success.
///
/// Springs: stretch on every edge, shear on both diagonals of each quad, bend across every
/// interior edge. Masses are lumped from face areas: `desc->total_mass` spread over the
/// area, or `desc->areal_density` (kg/m^2) when `total_mass` <= 0. The grid fields of `desc`
/// (`width`, `height`, `spacing`) are ignored. Drag coefficients act per particle, as for
/// grids: scale them by (vertex spacing / 1 cm)^2 for meshes much finer or coarser than 1 cm.
///
/// Errors (the message names the face, edge or vertex): `FC_ERROR_OUT_OF_RANGE` for an index
/// not below vertex_count; `FC_ERROR_INVALID_ARGUMENT` for an index count that is not a positive
/// multiple of `face_size`, `face_size` other than 3 or 4, a face repeating a vertex or of
/// (near) zero area, an edge shared by more than two faces (non-manifold), a vertex used by
/// no face, a non-finite position, or a bad description field.
///
/// # Safety
/// `desc` NULL or an initialised description; `positions` NULL or `3 * vertex_count` readable
/// floats; `indices` NULL or `index_count` readable values; `out_cloth` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_create_mesh(
    desc: *const FcClothDesc,
    positions: *const f32,
    vertex_count: usize,
    indices: *const u32,
    index_count: usize,
    face_size: u32,
    out_cloth: *mut *mut FcCloth,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe {
        create(desc, out_cloth, |desc| {
            if positions.is_null() {
                return Err(FfiError::null("positions"));
            }
            if indices.is_null() {
                return Err(FfiError::null("indices"));
            }
            let floats = vertex_count
                .checked_mul(3)
                .ok_or_else(|| FfiError::invalid("vertex_count too large"))?;
            let xyz = slice_in(positions, floats, "positions")?;
            let indices = slice_in(indices, index_count, "indices")?;
            let positions = triples(xyz, "position")?;
            let mass = if desc.total_mass > 0.0 {
                MeshMass::Total(desc.total_mass)
            } else {
                MeshMass::ArealDensity(desc.areal_density)
            };
            Ok(MeshSpec {
                positions: &positions,
                indices,
                face_size: face_size as usize,
                mass,
            }
            .build()?)
        })
    }
}
