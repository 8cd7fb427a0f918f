//! Point caches and meshes written through the ABI, streaming frame by frame.

use std::ffi::{c_char, CStr};
use std::path::PathBuf;

use crate::export::{write_obj, CacheFormat, CacheWriter};

use super::cloth::{handle, FcCloth};
use super::status::{guard, guard_value, FcStatus, FfiError};

/// Values of the `format` argument of `fc_cache_open`.
#[allow(non_camel_case_types)]
#[repr(C)]
pub enum FcCacheFormat {
    /// PC2 point cache, little-endian (Blender's Mesh Cache modifier, Maya, 3ds Max).
    FC_CACHE_PC2 = 0,
    /// MDD point cache, big-endian; needs `expected_frames` up front (fewer is fine: the file is compacted on close).
    FC_CACHE_MDD = 1,
    /// One OBJ per frame: `path` "dir/name.obj" gives "dir/name_0001.obj", ... numbered from `start_frame`.
    FC_CACHE_OBJ_SEQUENCE = 2,
}

/// An open cache file. Create with `fc_cache_open`, free with `fc_cache_close`.
pub struct FcCache {
    writer: Option<CacheWriter>,
    path: PathBuf,
}

/// # Safety
/// `path` NULL or a NUL-terminated string.
unsafe fn path_in(path: *const c_char) -> Result<PathBuf, FfiError> {
    if path.is_null() {
        return Err(FfiError::null("path"));
    }
    // SAFETY: non-NULL; the caller promises a NUL-terminated string.
    let s = unsafe { CStr::from_ptr(path) }
        .to_str()
        .map_err(|_| FfiError::invalid("path is not UTF-8"))?;
    if s.is_empty() {
        return Err(FfiError::invalid("path is empty"));
    }
    Ok(PathBuf::from(s))
}

/// Opens a cache file at `path` (UTF-8) for the vertices of `cloth` and writes its header.
/// `start_frame`: the host frame of the first sample; `frames_per_second` (> 0): the frame
/// rate (MDD stores times in seconds); `expected_frames`: how many frames will be written
/// (MDD only; ignored otherwise). Write frames with `fc_cache_write_frame`; finish with
/// `fc_cache_close`. Errors: `FC_ERROR_IO` if the file cannot be created,
/// `FC_ERROR_INVALID_ARGUMENT` for a bad format, |start_frame| > 1e9, a rate outside
/// [1e-3, 1e6] frames per second, or more than 1000000 expected frames for MDD (whose frame
/// times are written when it opens).
///
/// # Safety
/// `path` NULL or a NUL-terminated string; `cloth` NULL or live; `out_cache` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cache_open(
    path: *const c_char,
    format: u32,
    cloth: *const FcCloth,
    start_frame: f64,
    frames_per_second: f64,
    expected_frames: u32,
    out_cache: *mut *mut FcCache,
) -> FcStatus {
    guard(|| {
        if out_cache.is_null() {
            return Err(FfiError::null("out_cache"));
        }
        // SAFETY: forwarded caller promises.
        let path = unsafe { path_in(path) }?;
        let cloth = unsafe { handle(cloth) }?;
        let format = match format {
            0 => CacheFormat::Pc2,
            1 => CacheFormat::Mdd,
            2 => CacheFormat::ObjSequence,
            x => {
                return Err(FfiError::invalid(format!(
                    "format {x} is not an FcCacheFormat value"
                )))
            }
        };
        let writer = CacheWriter::create(
            &path,
            format,
            cloth.vertex_count(),
            &cloth.topology().triangles,
            start_frame,
            frames_per_second,
            expected_frames,
        )
        .map_err(|e| FfiError::io(&format!("cannot open {}", path.display()), &e))?;
        let raw = Box::into_raw(Box::new(FcCache {
            writer: Some(writer),
            path,
        }));
        // SAFETY: checked non-NULL; the caller promises it is writable.
        unsafe { *out_cache = raw };
        Ok(())
    })
}

/// Appends the current positions of `cloth` (which must have the vertex count the cache was
/// opened for) as the next frame. A frame that cannot be written whole (`FC_ERROR_IO`: a full
/// disk, a file-size limit) poisons the cache: the file is cut back to its complete frames with
/// a header that counts them (or removed if that fails too), and every later frame and
/// `fc_cache_close` return the first error.
///
/// # Safety
/// `cache` NULL or live (not closed); `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cache_write_frame(cache: *mut FcCache, cloth: *const FcCloth) -> FcStatus {
    guard(|| {
        // SAFETY: the caller promises a live cache or NULL.
        let cache = unsafe { cache.as_mut() }.ok_or_else(|| FfiError::null("cache"))?;
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { handle(cloth) }?;
        let path = cache.path.display().to_string();
        let writer = cache
            .writer
            .as_mut()
            .ok_or_else(|| FfiError::invalid("the cache failed earlier and was abandoned"))?;
        writer
            .write_frame(cloth.positions())
            .map_err(|e| FfiError::io(&format!("cannot write a frame to {path}"), &e))
    })
}

/// Appends a frame of positions the host gives (float xyz triples, one per vertex of the cloth
/// the cache was opened for; `float_count` = 3 * vertex_count): for a host that stores the
/// cloth in another frame than it simulates it (a DCC object's local space while the cloth
/// moves in world space). Errors as `fc_cache_write_frame`, and `FC_ERROR_INVALID_ARGUMENT` for
/// a wrong count or a non-finite value (the cache is unchanged then).
///
/// # Safety
/// `cache` NULL or live (not closed); `xyz` NULL or `float_count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn fc_cache_write_positions(
    cache: *mut FcCache,
    xyz: *const f32,
    float_count: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: the caller promises a live cache or NULL.
        let cache = unsafe { cache.as_mut() }.ok_or_else(|| FfiError::null("cache"))?;
        // SAFETY: forwarded caller promise.
        let xyz = unsafe { super::cloth::slice_in(xyz, float_count, "xyz") }?;
        if float_count % 3 != 0 {
            return Err(FfiError::invalid(format!(
                "float_count must be 3 * vertex_count, got {float_count}"
            )));
        }
        let positions = super::cloth::triples(xyz, "position")?;
        let path = cache.path.display().to_string();
        let writer = cache
            .writer
            .as_mut()
            .ok_or_else(|| FfiError::invalid("the cache failed earlier and was abandoned"))?;
        if positions.len() != writer.vertex_count() {
            return Err(FfiError::invalid(format!(
                "float_count must be 3 * vertex_count = {}, got {float_count}",
                3 * writer.vertex_count()
            )));
        }
        writer
            .write_frame(&positions)
            .map_err(|e| FfiError::io(&format!("cannot write a frame to {path}"), &e))
    })
}

/// Completes the cache file (patches its frame count, flushes it to disk) and frees the handle,
/// also when completing fails (the status then says why). A cache that failed earlier returns
/// that first error. NULL is fine.
///
/// # Safety
/// `cache` NULL or a live handle from `fc_cache_open`; not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn fc_cache_close(cache: *mut FcCache) -> FcStatus {
    guard(|| {
        if cache.is_null() {
            return Ok(());
        }
        // SAFETY: the caller promises a live handle created by Box::into_raw.
        let cache = unsafe { Box::from_raw(cache) };
        match cache.writer {
            Some(w) => w
                .finish()
                .map_err(|e| FfiError::io(&format!("cannot complete {}", cache.path.display()), &e)),
            None => Ok(()),
        }
    })
}

/// Writes the current positions of `cloth` as one OBJ mesh (vertices and triangles) at
/// `path` (UTF-8). Errors: `FC_ERROR_IO` when the file cannot be written whole (every byte is
/// flushed and checked).
///
/// # Safety
/// `cloth` NULL or live; `path` NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_write_obj(cloth: *const FcCloth, path: *const c_char) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { handle(cloth) }?;
        let path = unsafe { path_in(path) }?;
        let file = std::fs::File::create(&path)
            .map_err(|e| FfiError::io(&format!("cannot create {}", path.display()), &e))?;
        write_obj(
            std::io::BufWriter::new(file),
            cloth.positions(),
            &cloth.topology().triangles,
        )
        .map_err(|e| FfiError::io(&format!("cannot write {}", path.display()), &e))
    })
}

/// Number of triangles of `cloth` (quads count as two); 0 for NULL.
///
/// # Safety
/// `cloth` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_triangle_count(cloth: *const FcCloth) -> usize {
    // SAFETY: forwarded caller promise.
    guard_value(0, || {
        unsafe { handle(cloth) }.map_or(0, |c| c.topology().triangles.len())
    })
}
