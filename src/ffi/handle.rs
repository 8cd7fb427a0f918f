//! The cloth handle the host holds ([`FcCloth`]), and the handle from the host's pointer:
//! NULL refused with a message, the cloth (and its scratch) borrowed for the call.

use super::status::FfiError;
use crate::{Cloth, Vec3};

/// Opaque handle to one simulated cloth. Create with `fc_cloth_create_grid` or `fc_cloth_create_mesh`,
/// free with `fc_cloth_destroy`.
pub struct FcCloth {
    pub(crate) cloth: Cloth,
    /// Room for what the calls a host makes every frame convert: no allocation once a call has
    /// been made with as many values.
    pub(crate) scratch: Scratch,
}

/// The handle's room for the host's values on their way in and out.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// The values of an input call (positions, pin targets, a mesh collider's positions).
    pub(crate) input: Vec<Vec3>,
    /// A second input of the same call (a mesh collider's velocities).
    pub(crate) second: Vec<Vec3>,
    /// The vertex and triangle normals of `fc_cloth_get_normals`, which takes a `const`
    /// handle (locked for the call; a call that finds it locked uses room of its own).
    pub(crate) normals: std::sync::Mutex<(Vec<Vec3>, Vec<Vec3>)>,
}

impl FcCloth {
    pub(crate) fn new(cloth: Cloth) -> Self {
        Self {
            cloth,
            scratch: Scratch::default(),
        }
    }
}

/// # Safety
/// Non-NULL `cloth` must be a live handle.
pub(crate) unsafe fn handle<'a>(cloth: *const FcCloth) -> Result<&'a Cloth, FfiError> {
    // SAFETY: the caller promises a live handle or NULL.
    unsafe { cloth.as_ref() }
        .map(|c| &c.cloth)
        .ok_or_else(|| FfiError::null("cloth"))
}

/// # Safety
/// Non-NULL `cloth` must be a live handle not used elsewhere during the call.
pub(crate) unsafe fn handle_mut<'a>(cloth: *mut FcCloth) -> Result<&'a mut Cloth, FfiError> {
    // SAFETY: the caller promises a live, unaliased handle or NULL.
    unsafe { cloth.as_mut() }
        .map(|c| &mut c.cloth)
        .ok_or_else(|| FfiError::null("cloth"))
}

/// # Safety
/// Non-NULL `cloth` must be a live handle not used elsewhere during the call.
pub(crate) unsafe fn handle_and_scratch<'a>(
    cloth: *mut FcCloth,
) -> Result<(&'a mut Cloth, &'a mut Scratch), FfiError> {
    // SAFETY: the caller promises a live, unaliased handle or NULL.
    unsafe { cloth.as_mut() }
        .map(|c| (&mut c.cloth, &mut c.scratch))
        .ok_or_else(|| FfiError::null("cloth"))
}
