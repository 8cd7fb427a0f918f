//! The host-facing calls through the C ABI: meshes (good and bad), colliders, pins, and
//! caches read back byte for byte.

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;

fn message() -> String {
    unsafe { CStr::from_ptr(fc_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// A 4 x 3 vertex quad grid (3 x 2 quads) in the x-y plane.
fn quad_grid() -> (Vec<f32>, Vec<u32>) {
    let (w, h) = (4u32, 3u32);
    let mut xyz = vec![];
    for j in 0..h {
        for i in 0..w {
            xyz.extend([i as f32 * 0.02, -(j as f32) * 0.02, 0.0]);
        }
    }
    let mut idx = vec![];
    for j in 0..h - 1 {
        for i in 0..w - 1 {
            let a = j * w + i;
            idx.extend([a, a + w, a + w + 1, a + 1]);
        }
    }
    (xyz, idx)
}

fn create(xyz: &[f32], idx: &[u32], face_size: u32) -> (FcStatus, *mut FcCloth) {
    let desc = fc_cloth_desc_default();
    let mut c = null_mut();
    let s = unsafe {
        fc_cloth_create_mesh(
            &desc,
            xyz.as_ptr(),
            xyz.len() / 3,
            idx.as_ptr(),
            idx.len(),
            face_size,
            &mut c,
        )
    };
    (s, c)
}

#[test]
fn meshes_good_and_bad() {
    let (xyz, quads) = quad_grid();
    let (s, c) = create(&xyz, &quads, 4);
    assert_eq!(s, FC_OK, "{}", message());
    unsafe {
        assert_eq!(fc_cloth_vertex_count(c), 12);
        assert_eq!(fc_cloth_triangle_count(c), 12);
        assert_eq!(fc_cloth_step(c, 1e-3), FC_OK);
        fc_cloth_destroy(c);
    }
    let tris: Vec<u32> = quads
        .chunks(4)
        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
        .collect();
    let cases: Vec<(&str, Vec<u32>, u32, FcStatus, &str)> = vec![
        (
            "out-of-range index",
            vec![0, 1, 12],
            3,
            FC_ERROR_OUT_OF_RANGE,
            "index 12 out of range",
        ),
        (
            "count not a multiple of 3",
            tris[..7].to_vec(),
            3,
            FC_ERROR_INVALID_ARGUMENT,
            "multiple",
        ),
        (
            "degenerate triangle",
            [&tris[..], &[0, 1, 2]].concat(),
            3,
            FC_ERROR_INVALID_ARGUMENT,
            "degenerate",
        ),
        (
            "repeated vertex",
            [&tris[..], &[0, 0, 5]].concat(),
            3,
            FC_ERROR_INVALID_ARGUMENT,
            "appears twice",
        ),
        (
            "non-manifold edge",
            [&tris[..], &tris[..3]].concat(),
            3,
            FC_ERROR_INVALID_ARGUMENT,
            "not manifold",
        ),
        (
            "face size 5",
            tris.clone(),
            5,
            FC_ERROR_INVALID_ARGUMENT,
            "face size",
        ),
    ];
    for (what, idx, face_size, want, says) in cases {
        let (s, c) = create(&xyz, &idx, face_size);
        assert_eq!(s, want, "{what}: {}", message());
        assert!(c.is_null(), "{what}: a handle was written");
        assert!(message().contains(says), "{what}: message {:?}", message());
    }
    // The degenerate face is named.
    let _ = create(&xyz, &[&tris[..], &[0, 1, 2]].concat(), 3);
    assert!(message().contains("face 12"), "{}", message());
    // NULL pointers and NaN positions.
    let desc = fc_cloth_desc_default();
    let mut c = null_mut();
    unsafe {
        assert_eq!(
            fc_cloth_create_mesh(&desc, null(), 12, tris.as_ptr(), tris.len(), 3, &mut c),
            FC_ERROR_NULL_ARGUMENT
        );
        let mut bad = xyz.clone();
        bad[4] = f32::NAN;
        assert_eq!(
            fc_cloth_create_mesh(&desc, bad.as_ptr(), 12, tris.as_ptr(), tris.len(), 3, &mut c),
            FC_ERROR_INVALID_ARGUMENT
        );
    }
    assert!(c.is_null());
}

#[test]
fn colliders_by_id() {
    let (xyz, quads) = quad_grid();
    let (_, c) = create(&xyz, &quads, 4);
    unsafe {
        let mut plane = u32::MAX;
        let mut capsule = u32::MAX;
        let p = [0.0f32, -1.0, 0.0];
        let n = [0.0f32, 1.0, 0.0];
        assert_eq!(
            fc_cloth_add_plane(c, p.as_ptr(), n.as_ptr(), null(), &mut plane),
            FC_OK
        );
        let (a, b) = ([0.0f32, 0.0, 0.1], [0.1f32, 0.0, 0.1]);
        assert_eq!(
            fc_cloth_add_capsule(c, a.as_ptr(), b.as_ptr(), 0.01, null(), &mut capsule),
            FC_OK
        );
        assert_eq!((plane, capsule), (0, 1));
        assert_eq!(fc_cloth_set_collider_friction(c, capsule, 0.5), FC_OK);
        assert_eq!(
            fc_cloth_set_collider_friction(c, capsule, -1.0),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(fc_cloth_set_collider_friction(c, 7, 0.5), FC_ERROR_OUT_OF_RANGE);
        // A collider's own margin: set, read back, refused when negative, not finite or absent.
        let mut margin = 0.0f32;
        assert_eq!(fc_cloth_get_collider_margin(c, capsule, &mut margin), FC_OK);
        assert_eq!(margin, fc_cloth_desc_default().collision_margin as f32);
        assert_eq!(fc_cloth_set_collider_margin(c, capsule, 0.03), FC_OK);
        assert_eq!(fc_cloth_get_collider_margin(c, capsule, &mut margin), FC_OK);
        assert_eq!(margin, 0.03);
        for bad in [-0.01, f32::NAN, f32::INFINITY] {
            assert_eq!(
                fc_cloth_set_collider_margin(c, capsule, bad),
                FC_ERROR_INVALID_ARGUMENT,
                "{bad}"
            );
        }
        assert_eq!(fc_cloth_set_collider_margin(c, 7, 0.01), FC_ERROR_OUT_OF_RANGE);
        assert_eq!(
            fc_cloth_get_collider_margin(c, 7, &mut margin),
            FC_ERROR_OUT_OF_RANGE
        );
        assert_eq!(fc_cloth_get_collider_margin(c, capsule, null_mut()), FC_OK);
        let zero = [0.0f32; 3];
        assert_eq!(
            fc_cloth_set_plane(c, plane, p.as_ptr(), zero.as_ptr(), null()),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert!(message().contains("normal"), "{}", message());
        let v = [0.0f32, 0.1, 0.0];
        assert_eq!(
            fc_cloth_set_plane(c, plane, p.as_ptr(), n.as_ptr(), v.as_ptr()),
            FC_OK
        );
        assert_eq!(
            fc_cloth_set_capsule(c, capsule, a.as_ptr(), b.as_ptr(), 0.0, null()),
            FC_ERROR_INVALID_ARGUMENT
        );
        // Read back: the plane as set (normal unit, velocity v), the capsule as added.
        let (mut gp, mut gn, mut gv) = ([9f32; 3], [9f32; 3], [9f32; 3]);
        assert_eq!(
            fc_cloth_get_plane(c, plane, gp.as_mut_ptr(), gn.as_mut_ptr(), gv.as_mut_ptr()),
            FC_OK
        );
        assert_eq!((gp, gn, gv), (p, n, v));
        let (mut ga, mut gb, mut gr, mut gcv) = ([9f32; 3], [9f32; 3], 9f32, [9f32; 3]);
        assert_eq!(
            fc_cloth_get_capsule(
                c,
                capsule,
                ga.as_mut_ptr(),
                gb.as_mut_ptr(),
                &mut gr,
                gcv.as_mut_ptr()
            ),
            FC_OK
        );
        assert_eq!((ga, gb, gr, gcv), (a, b, 0.01, [0.0; 3]));
        // NULL outputs are skipped; the wrong kind or id is out of range.
        assert_eq!(
            fc_cloth_get_plane(c, plane, null_mut(), null_mut(), null_mut()),
            FC_OK
        );
        assert_eq!(
            fc_cloth_get_capsule(c, plane, null_mut(), null_mut(), null_mut(), null_mut()),
            FC_ERROR_OUT_OF_RANGE
        );
        assert_eq!(
            fc_cloth_get_plane(c, 42, null_mut(), null_mut(), null_mut()),
            FC_ERROR_OUT_OF_RANGE
        );
        assert_eq!(fc_cloth_remove_collider(c, plane), FC_OK);
        assert_eq!(
            fc_cloth_set_plane(c, plane, p.as_ptr(), n.as_ptr(), null()),
            FC_ERROR_OUT_OF_RANGE
        );
        // The freed id is reused.
        let mut again = u32::MAX;
        assert_eq!(
            fc_cloth_add_plane(c, p.as_ptr(), n.as_ptr(), null(), &mut again),
            FC_OK
        );
        assert_eq!(again, plane);
        assert_eq!(fc_cloth_step(c, 1e-3), FC_OK);
        fc_cloth_destroy(c);
    }
}

#[test]
fn pin_weights_and_groups() {
    let (xyz, quads) = quad_grid();
    let (_, c) = create(&xyz, &quads, 4);
    unsafe {
        let group = [0u32, 1, 2, 3];
        assert_eq!(fc_cloth_pin_group(c, group.as_ptr(), 4, 1.0), FC_OK);
        assert_eq!(
            fc_cloth_pin_group(c, group.as_ptr(), 4, 1.5),
            FC_ERROR_INVALID_ARGUMENT
        );
        let bad = [0u32, 99];
        assert_eq!(fc_cloth_pin_group(c, bad.as_ptr(), 2, 1.0), FC_ERROR_OUT_OF_RANGE);
        let w = [0.5f32; 11];
        assert_eq!(
            fc_cloth_set_pin_weights(c, w.as_ptr(), 11),
            FC_ERROR_INVALID_ARGUMENT
        );
        let w = [0.5f32; 12];
        assert_eq!(fc_cloth_set_pin_weights(c, w.as_ptr(), 12), FC_OK);
        // Every vertex is (softly) pinned now, so every vertex can take a target.
        let t = [0.0f32, 0.0, 0.1];
        let v = [11u32];
        assert_eq!(fc_cloth_set_pin_targets(c, v.as_ptr(), t.as_ptr(), 1), FC_OK);
        assert_eq!(fc_cloth_step(c, 1e-3), FC_OK);
        fc_cloth_destroy(c);
    }
}

fn positions(c: *mut FcCloth) -> Vec<f32> {
    let n = unsafe { fc_cloth_vertex_count(c) };
    let mut x = vec![0f32; 3 * n];
    assert_eq!(
        unsafe { fc_cloth_get_positions(c, x.as_mut_ptr(), x.len()) },
        FC_OK
    );
    x
}

#[test]
fn caches_read_back_exactly() {
    let dir = std::env::temp_dir().join(format!("fc_caches_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let desc = fc_cloth_desc_default();
    let mut c = null_mut();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&desc, &mut c), FC_OK);
        let top: Vec<u32> = (0..desc.width).collect();
        assert_eq!(fc_cloth_set_pinned(c, top.as_ptr(), top.len()), FC_OK);
        let current = [0.0f32, 0.0, 0.2];
        assert_eq!(fc_cloth_set_current(c, current.as_ptr()), FC_OK);
    }
    let path = |name: &str| CString::new(dir.join(name).to_str().unwrap()).unwrap();
    let open = |name: &str, format: u32, expected: u32| {
        let mut cache = null_mut();
        let s = unsafe { fc_cache_open(path(name).as_ptr(), format, c, 1.0, 24.0, expected, &mut cache) };
        assert_eq!(s, FC_OK, "{}", message());
        cache
    };
    let pc2 = open("a.pc2", 0, 0);
    let mdd = open("a.mdd", 1, 10); // announces more frames than written: compacted on close
    let obj = open("a.obj", 2, 0);
    let mut frames = vec![];
    for _ in 0..4 {
        for _ in 0..40 {
            assert_eq!(unsafe { fc_cloth_step(c, 1e-3) }, FC_OK);
        }
        for cache in [pc2, mdd, obj] {
            assert_eq!(unsafe { fc_cache_write_frame(cache, c) }, FC_OK, "{}", message());
        }
        frames.push(positions(c));
    }
    for cache in [pc2, mdd, obj] {
        assert_eq!(unsafe { fc_cache_close(cache) }, FC_OK, "{}", message());
    }
    assert_eq!(unsafe { fc_cache_close(null_mut()) }, FC_OK);
    let n = frames[0].len() / 3;
    // PC2: little-endian, 32-byte header.
    let b = std::fs::read(dir.join("a.pc2")).unwrap();
    assert_eq!(i32::from_le_bytes(b[28..32].try_into().unwrap()), 4);
    assert_eq!(f32::from_le_bytes(b[20..24].try_into().unwrap()), 1.0);
    let body: Vec<f32> = b[32..]
        .chunks(4)
        .map(|q| f32::from_le_bytes(q.try_into().unwrap()))
        .collect();
    assert_eq!(body, frames.concat());
    // MDD: big-endian, frame count, vertex count, times, frames.
    let b = std::fs::read(dir.join("a.mdd")).unwrap();
    let be = |o: usize| i32::from_be_bytes(b[o..o + 4].try_into().unwrap());
    assert_eq!((be(0), be(4)), (4, n as i32));
    let times: Vec<f32> = b[8..24]
        .chunks(4)
        .map(|q| f32::from_be_bytes(q.try_into().unwrap()))
        .collect();
    assert_eq!(times, vec![0.0, 1.0 / 24.0, 2.0 / 24.0, 3.0 / 24.0]);
    let body: Vec<f32> = b[24..]
        .chunks(4)
        .map(|q| f32::from_be_bytes(q.try_into().unwrap()))
        .collect();
    assert_eq!(body, frames.concat());
    // OBJ sequence: a_0001.obj .. a_0004.obj, vertices as written.
    for (k, frame) in frames.iter().enumerate() {
        let text = std::fs::read_to_string(dir.join(format!("a_{:04}.obj", k + 1))).unwrap();
        let v: Vec<f32> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .flat_map(|l| {
                l.split_whitespace()
                    .map(|t| t.parse::<f32>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect();
        assert_eq!(&v, frame, "frame {}", k + 1);
        assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 2 * 60 * 40);
    }
    // Errors: a directory that does not exist, a bad format.
    let mut cache = null_mut();
    let nowhere = CString::new("/nonexistent-dir/x.pc2").unwrap();
    unsafe {
        assert_eq!(
            fc_cache_open(nowhere.as_ptr(), 0, c, 1.0, 24.0, 0, &mut cache),
            FC_ERROR_IO
        );
        assert!(message().contains("nonexistent"), "{}", message());
        assert_eq!(
            fc_cache_open(path("b.pc2").as_ptr(), 9, c, 1.0, 24.0, 0, &mut cache),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            fc_cache_open(path("b.pc2").as_ptr(), 0, c, 1.0, 0.0, 0, &mut cache),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert!(cache.is_null());
        assert_eq!(fc_cloth_write_obj(c, path("rest.obj").as_ptr()), FC_OK);
        fc_cloth_destroy(c);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
