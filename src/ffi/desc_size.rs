//! The `struct_size` rule of `FcClothDesc`: how a description crosses the ABI when the host's
//! header and the library disagree on how many fields it has.
//!
//! A host sets `struct_size = sizeof(FcClothDesc)` from its own header (the header's inline
//! `fc_cloth_desc_default` does). Reading, the library takes the bytes that fit in
//! `struct_size` and keeps its defaults for the rest; writing, it writes no more than
//! `struct_size` bytes. Fields are only added at the end and every field is 4 or 8 bytes on
//! an 8-aligned struct, so any multiple of 8 ends on a field boundary.

//!
//! The rule knows nothing of the description's fields: it moves the bytes of any `#[repr(C)]`
//! struct `T` whose first field is its `u32` size (so this module sits below `desc.rs`).

use std::mem::size_of;

use super::status::FfiError;

/// The smallest description the library reads: `struct_size`, `width`, `height`, `spacing`.
const MIN_SIZE: usize = 16;

/// Checks a host's `struct_size` of a struct this library knows as `known` bytes and
/// returns it as a byte count.
pub(crate) fn check_size(size: usize, known: usize) -> Result<usize, FfiError> {
    if size == 0 {
        return Err(FfiError::invalid(
            "FcClothDesc.struct_size is 0: start from fc_cloth_desc_default() or fc_cloth_desc_preset(), \
             or set struct_size = sizeof(FcClothDesc)",
        ));
    }
    if size > known {
        return Err(FfiError::invalid(format!(
            "FcClothDesc.struct_size is {size} bytes but this library (fraccloth {}) knows {known}: \
             the host was built against a newer fraccloth.h than the library it runs with; use the newer library",
            env!("CARGO_PKG_VERSION")
        )));
    }
    if size < MIN_SIZE || size % 8 != 0 {
        return Err(FfiError::invalid(format!(
            "FcClothDesc.struct_size is {size}: it must be sizeof(FcClothDesc) of some fraccloth.h \
             (a multiple of 8, at least {MIN_SIZE}; this library's is {known})"
        )));
    }
    Ok(size)
}

/// Reads a host's struct: the fields its `struct_size` holds, `defaults` for the others.
/// The result's `struct_size` is `size_of::<T>()`.
///
/// # Safety
/// `T` is `#[repr(C)]` plain data whose first field is its `u32` size; `desc` NULL or pointing
/// to at least `struct_size` readable bytes, `struct_size` first.
pub(crate) unsafe fn read_desc<T: Copy>(desc: *const T, defaults: T) -> Result<T, FfiError> {
    if desc.is_null() {
        return Err(FfiError::null("desc"));
    }
    // SAFETY: non-NULL; every description starts with its u32 size, which the caller promises
    // is readable. Unaligned read: the host's struct need not be 8-aligned in memory.
    let size = unsafe { desc.cast::<u32>().read_unaligned() } as usize;
    let size = check_size(size, size_of::<T>())?;
    let mut out = defaults;
    // SAFETY: `size` <= size_of::<T>() bytes are readable at `desc` (caller's promise: the
    // host's struct is `struct_size` long) and writable at `out`; the regions do not overlap.
    // Every field is plain data, so any bytes make a valid value (checked later by its user).
    unsafe { std::ptr::copy_nonoverlapping(desc.cast::<u8>(), (&mut out as *mut T).cast::<u8>(), size) };
    // SAFETY: the first field is the u32 size (caller's promise).
    unsafe { (&mut out as *mut T).cast::<u32>().write(size_of::<T>() as u32) };
    Ok(out)
}

/// Writes `desc` into a host's struct of `size` bytes (checked), setting its `struct_size`.
///
/// # Safety
/// As [`read_desc`]'s `T`; `out` NULL or pointing to `size` writable bytes.
pub(crate) unsafe fn write_desc<T: Copy>(out: *mut T, size: usize, desc: &T) -> Result<(), FfiError> {
    if out.is_null() {
        return Err(FfiError::null("out_desc"));
    }
    let size = check_size(size, size_of::<T>())?;
    let mut d = *desc;
    // SAFETY: the first field is the u32 size (caller's promise).
    unsafe { (&mut d as *mut T).cast::<u32>().write(size as u32) };
    // SAFETY: `size` <= size_of::<T>() bytes readable from `d`, writable at `out` (caller's
    // promise).
    unsafe { std::ptr::copy_nonoverlapping((&d as *const T).cast::<u8>(), out.cast::<u8>(), size) };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::desc::{fc_cloth_desc_default, FcClothDesc, DESC_SIZE};

    #[test]
    fn sizes_are_checked() {
        assert!(check_size(0, DESC_SIZE).is_err());
        assert!(check_size(12, DESC_SIZE).is_err());
        assert!(check_size(DESC_SIZE + 8, DESC_SIZE).is_err());
        assert!(check_size(DESC_SIZE - 4, DESC_SIZE).is_err());
        assert_eq!(check_size(DESC_SIZE, DESC_SIZE).ok(), Some(DESC_SIZE));
        assert_eq!(check_size(16, DESC_SIZE).ok(), Some(16));
    }

    #[test]
    fn a_short_struct_reads_its_fields_and_defaults_the_rest() {
        let mut host = fc_cloth_desc_default();
        host.width = 7;
        host.skin_drag_unsteady = 0.5; // the field before the last: inside a host 8 bytes shorter
        host.skin_drag_memory = 0.4; // the last field: beyond it
        host.struct_size = (DESC_SIZE - 8) as u32;
        // SAFETY: a whole struct is readable.
        let d = unsafe { read_desc(&host, fc_cloth_desc_default()) }.expect("accepted");
        assert_eq!(d.width, 7);
        assert_eq!(d.skin_drag_unsteady, 0.5);
        assert_eq!(d.skin_drag_memory, fc_cloth_desc_default().skin_drag_memory);
        assert_eq!(d.struct_size as usize, DESC_SIZE);
    }

    #[test]
    fn writing_stops_at_the_host_size() {
        let mut buf = [0xAAu8; DESC_SIZE + 8];
        let out = buf.as_mut_ptr().cast::<FcClothDesc>();
        // SAFETY: `buf` has DESC_SIZE + 8 writable bytes (alignment: unaligned writes by bytes).
        unsafe { write_desc(out, 24, &fc_cloth_desc_default()) }.expect("written");
        assert_eq!(u32::from_ne_bytes([buf[0], buf[1], buf[2], buf[3]]), 24);
        assert!(
            buf[24..].iter().all(|&b| b == 0xAA),
            "no byte past struct_size is written"
        );
    }
}
