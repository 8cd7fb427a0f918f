//! The `struct_size` rule of `FcClothDesc`: how a description crosses the ABI when the host's
//! header and the library disagree on how many fields it has.
//!
//! A host sets `struct_size = sizeof(FcClothDesc)` from its own header (the header's inline
//! `fc_cloth_desc_default` does). Reading, the library takes the bytes that fit in
//! `struct_size` and keeps its defaults for the rest; writing, it writes no more than
//! `struct_size` bytes. Fields are only added at the end and every field is 4 or 8 bytes on
//! an 8-aligned struct, so any multiple of 8 ends on a field boundary.

use std::mem::size_of;

use super::desc::{fc_cloth_desc_default, FcClothDesc};
use super::status::FfiError;

/// `sizeof(FcClothDesc)` in this library.
pub const DESC_SIZE: usize = size_of::<FcClothDesc>();

/// The smallest description the library reads: `struct_size`, `width`, `height`, `spacing`.
const MIN_SIZE: usize = 16;

/// Checks a host's `struct_size` and returns it as a byte count.
pub(crate) fn check_size(size: usize) -> Result<usize, FfiError> {
    if size == 0 {
        return Err(FfiError::invalid(
            "FcClothDesc.struct_size is 0: start from fc_cloth_desc_default() or fc_cloth_desc_preset(), \
             or set struct_size = sizeof(FcClothDesc)",
        ));
    }
    if size > DESC_SIZE {
        return Err(FfiError::invalid(format!(
            "FcClothDesc.struct_size is {size} bytes but this library (fraccloth {}) knows {DESC_SIZE}: \
             the host was built against a newer fraccloth.h than the library it runs with; use the newer library",
            env!("CARGO_PKG_VERSION")
        )));
    }
    if size < MIN_SIZE || size % 8 != 0 {
        return Err(FfiError::invalid(format!(
            "FcClothDesc.struct_size is {size}: it must be sizeof(FcClothDesc) of some fraccloth.h \
             (a multiple of 8, at least {MIN_SIZE}; this library's is {DESC_SIZE})"
        )));
    }
    Ok(size)
}

/// Reads a host's description: the fields its `struct_size` holds, defaults for the others.
/// The result has `struct_size = DESC_SIZE`.
///
/// # Safety
/// `desc` NULL or pointing to at least `struct_size` readable bytes, `struct_size` first.
pub(crate) unsafe fn read_desc(desc: *const FcClothDesc) -> Result<FcClothDesc, FfiError> {
    if desc.is_null() {
        return Err(FfiError::null("desc"));
    }
    // SAFETY: non-NULL; every description starts with its u32 size, which the caller promises
    // is readable. Unaligned read: the host's struct need not be 8-aligned in memory.
    let size = unsafe { std::ptr::addr_of!((*desc).struct_size).read_unaligned() } as usize;
    let size = check_size(size)?;
    let mut out = fc_cloth_desc_default();
    // SAFETY: `size` <= DESC_SIZE bytes are readable at `desc` (caller's promise: the host's
    // struct is `struct_size` long) and writable at `out`; the regions do not overlap. Every
    // field is plain data, so any bytes make a valid value (checked later by `config`).
    unsafe {
        std::ptr::copy_nonoverlapping(
            desc.cast::<u8>(),
            (&mut out as *mut FcClothDesc).cast::<u8>(),
            size,
        )
    };
    out.struct_size = DESC_SIZE as u32;
    Ok(out)
}

/// Writes `desc` into a host's struct of `size` bytes (checked), setting its `struct_size`.
///
/// # Safety
/// `out` NULL or pointing to `size` writable bytes.
pub(crate) unsafe fn write_desc(
    out: *mut FcClothDesc,
    size: usize,
    desc: &FcClothDesc,
) -> Result<(), FfiError> {
    if out.is_null() {
        return Err(FfiError::null("out_desc"));
    }
    let size = check_size(size)?;
    let mut d = *desc;
    d.struct_size = size as u32;
    // SAFETY: `size` <= DESC_SIZE bytes readable from `d`, writable at `out` (caller's promise).
    unsafe { std::ptr::copy_nonoverlapping((&d as *const FcClothDesc).cast::<u8>(), out.cast::<u8>(), size) };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert!(check_size(0).is_err());
        assert!(check_size(12).is_err());
        assert!(check_size(DESC_SIZE + 8).is_err());
        assert!(check_size(DESC_SIZE - 4).is_err());
        assert_eq!(check_size(DESC_SIZE).ok(), Some(DESC_SIZE));
        assert_eq!(check_size(16).ok(), Some(16));
    }

    #[test]
    fn a_short_struct_reads_its_fields_and_defaults_the_rest() {
        let mut host = fc_cloth_desc_default();
        host.width = 7;
        host.self_collision_friction = 0.5; // the last field: beyond a host 8 bytes shorter
        host.struct_size = (DESC_SIZE - 8) as u32;
        // SAFETY: a whole struct is readable.
        let d = unsafe { read_desc(&host) }.expect("accepted");
        assert_eq!(d.width, 7);
        assert_eq!(
            d.self_collision_friction,
            fc_cloth_desc_default().self_collision_friction
        );
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
