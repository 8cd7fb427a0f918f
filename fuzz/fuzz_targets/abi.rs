//! Fuzzes the C ABI with random sequences of calls and arguments: NULL pointers, NaN,
//! infinities, huge and negative numbers, wrong lengths, out-of-range indices and ids,
//! random and corrupted snapshots, meshes with random indices. Up to three live handles.
//! Every call must return (a status or a value), never crash or hang; after any failed call
//! the handle must still be usable. Use after destroy is the host's bug and is not generated.
//!
//! Limits that keep one input fast (so the fuzzer explores rather than waits): grids of at
//! most 32 x 32 through the "valid size" path (sizes above the library's limit are still
//! passed to check they are refused), at most 400 steps per input, `history_u` below 256.
#![no_main]

use std::ffi::{c_void, CString};
use std::ptr::{null, null_mut};

use fraccloth::ffi::*;
use libfuzzer_sys::fuzz_target;

struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }
    fn done(&self) -> bool {
        self.pos >= self.data.len()
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    /// A float that is often interesting: NaN, infinities, zero, negative, huge, tiny, or raw bits.
    fn f32(&mut self) -> f32 {
        match self.u8() % 10 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => -1.0,
            3 => 0.0,
            4 => 1e30,
            5 => 1e-30,
            6 => f32::from_bits(self.u32()),
            _ => (self.u8() as f32 - 128.0) / 256.0,
        }
    }
    fn f64(&mut self) -> f64 {
        match self.u8() % 10 {
            0 => f64::NAN,
            1 => f64::NEG_INFINITY,
            2 => -1e-3,
            3 => 0.0,
            4 => 1e300,
            5 => f64::from_bits(u64::from(self.u32()) << 32 | u64::from(self.u32())),
            _ => f64::from(self.u8()) * 1e-4,
        }
    }
    fn floats(&mut self, n: usize) -> Vec<f32> {
        (0..n).map(|_| self.f32()).collect()
    }
    /// A length near `n`: exact, off by one, zero, or huge.
    fn len(&mut self, n: usize) -> usize {
        match self.u8() % 8 {
            0 => n.wrapping_sub(1),
            1 => n + 1,
            2 => 0,
            3 => usize::MAX / 2,
            _ => n,
        }
    }
}

fn desc(b: &mut Bytes<'_>) -> FcClothDesc {
    let mut d = fc_cloth_desc_default();
    d.width = u32::from(b.u8() % 32);
    d.height = u32::from(b.u8() % 32);
    match b.u8() % 16 {
        0 => d.width = b.u32(), // mostly refused (too large), never allocated beyond the limit check
        1 => d.spacing = b.f32(),
        2 => d.stretch_stiffness = b.f64(),
        3 => d.history_drag = b.f64(),
        4 => d.cloth_density = b.f64(),
        5 => d.history_tolerance = b.f64(),
        6 => d.history_min_dt = b.f64(),
        7 => d.max_speed = b.f64(),
        8 => d.collision_margin = b.f64(),
        9 => d.total_mass = b.f64(),
        10 => d.solver_max_iterations = u32::from(b.u8()),
        // Any size: one beyond the library's is refused before anything is read past it.
        11 => d.struct_size = b.u32(),
        _ => {}
    }
    if d.width > 32 && u64::from(d.width) * u64::from(d.height.max(2)) < (1 << 24) {
        d.width %= 32; // keep valid-sized grids small
    }
    d.history_scheme = u32::from(b.u8() % 5);
    d.history_u = u32::from(b.u8());
    d.integrator = u32::from(b.u8() % 6);
    d.spring_damping_mode = u32::from(b.u8() % 4);
    d.max_substep = if b.u8() % 4 == 0 { 1e-3 } else { 0.0 };
    d
}

fn vcount(c: *mut FcCloth) -> usize {
    unsafe { fc_cloth_vertex_count(c) }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes { data, pos: 0 };
    let mut cloths: Vec<*mut FcCloth> = vec![];
    let mut steps = 0u32;
    let dir = std::env::temp_dir().join("fraccloth-fuzz");
    let _ = std::fs::create_dir_all(&dir);
    let cache_path = CString::new(dir.join("c.pc2").to_str().unwrap_or("c.pc2")).unwrap_or_default();
    let full_path = CString::new("/dev/full").unwrap_or_default();
    let mut snapshot: Vec<u8> = vec![];
    while !b.done() && cloths.len() <= 3 {
        let op = b.u8();
        let pick = b.u8() as usize;
        let c = if cloths.is_empty() || pick % 8 == 7 {
            null_mut() // NULL handle for every call must be harmless
        } else {
            cloths[pick % cloths.len()]
        };
        unsafe {
            match op % 24 {
                0 => {
                    let d = desc(&mut b);
                    let mut out = null_mut();
                    let s = fc_cloth_create_grid(if pick % 16 == 0 { null() } else { &d }, &mut out);
                    if s == FcStatus::FC_OK {
                        assert!(!out.is_null());
                        cloths.push(out);
                    } else {
                        assert!(out.is_null());
                    }
                }
                1 => {
                    let d = desc(&mut b);
                    let n = usize::from(b.u8() % 40);
                    let xyz = b.floats(3 * n);
                    let faces = usize::from(b.u8() % 30);
                    let face_size = u32::from(b.u8() % 6);
                    let idx: Vec<u32> = (0..faces * 4)
                        .map(|_| u32::from(b.u8()) % (n as u32 + 2))
                        .collect();
                    let count = b.len(idx.len());
                    let count = count.min(idx.len());
                    let mut out = null_mut();
                    let s =
                        fc_cloth_create_mesh(&d, xyz.as_ptr(), n, idx.as_ptr(), count, face_size, &mut out);
                    if s == FcStatus::FC_OK {
                        cloths.push(out);
                    }
                }
                2 => {
                    if !c.is_null() {
                        cloths.retain(|&x| x != c);
                    }
                    fc_cloth_destroy(c);
                }
                3 | 4 | 5 => {
                    // Long but legal requests (up to 10^6 substeps of max_substep) are real work,
                    // not bugs; keep them short here. Out-of-range ones are still passed.
                    let dt = if op % 2 == 0 { b.f64() } else { 1e-3 };
                    let dt = if dt > 0.05 && dt < 1e7 { 0.05 } else { dt };
                    if steps < 400 {
                        steps += 1;
                        let _ = fc_cloth_step(c, dt);
                    }
                }
                6 => {
                    let n = u32::from(b.u8() % 8);
                    if steps + n < 400 {
                        steps += n;
                        let dt = b.f64();
                        let _ = fc_cloth_step_substeps(c, if dt > 0.1 && dt < 1e7 { 0.1 } else { dt }, n);
                    }
                }
                7 => {
                    let k = usize::from(b.u8() % 40);
                    let idx: Vec<u32> = (0..k)
                        .map(|_| u32::from(b.u8()) * if pick % 5 == 0 { 1 << 20 } else { 1 })
                        .collect();
                    let _ = fc_cloth_set_pinned(
                        c,
                        if pick % 9 == 0 { null() } else { idx.as_ptr() },
                        b.len(idx.len()).min(idx.len()),
                    );
                }
                8 => {
                    let k = usize::from(b.u8() % 20);
                    let idx: Vec<u32> = (0..k).map(|_| u32::from(b.u8())).collect();
                    let xyz = b.floats(3 * k);
                    let _ = fc_cloth_set_pin_targets(c, idx.as_ptr(), xyz.as_ptr(), k);
                }
                9 => {
                    let n = vcount(c);
                    let w = b.floats(n + 1);
                    let _ = fc_cloth_set_pin_weights(c, w.as_ptr(), b.len(n).min(w.len()));
                }
                10 => {
                    let k = usize::from(b.u8() % 20);
                    let idx: Vec<u32> = (0..k).map(|_| u32::from(b.u8())).collect();
                    let _ = fc_cloth_pin_group(c, idx.as_ptr(), k, b.f32());
                }
                11 => {
                    let n = vcount(c);
                    let xyz = b.floats(3 * n + 3);
                    let _ = fc_cloth_set_positions(c, xyz.as_ptr(), b.len(3 * n).min(xyz.len()));
                }
                12 => {
                    let n = vcount(c);
                    let mut out = vec![0f32; 3 * n + 3];
                    let len = b.len(3 * n).min(out.len());
                    let _ = fc_cloth_get_positions(c, out.as_mut_ptr(), len);
                    let _ = fc_cloth_get_velocities(
                        c,
                        if pick % 3 == 0 {
                            null_mut()
                        } else {
                            out.as_mut_ptr()
                        },
                        len,
                    );
                }
                13 => {
                    let xyz = b.floats(3);
                    let _ = fc_cloth_set_current(c, if pick % 4 == 0 { null() } else { xyz.as_ptr() });
                }
                14 => {
                    let v = b.floats(9);
                    let mut id = 0;
                    let _ = match b.u8() % 3 {
                        0 => fc_cloth_add_sphere(c, v.as_ptr(), v[3], v[6..].as_ptr(), &mut id),
                        1 => fc_cloth_add_plane(c, v.as_ptr(), v[3..].as_ptr(), null(), &mut id),
                        _ => fc_cloth_add_capsule(c, v.as_ptr(), v[3..].as_ptr(), v[6], null(), &mut id),
                    };
                }
                15 => {
                    let v = b.floats(9);
                    let id = u32::from(b.u8() % 6);
                    let _ = match b.u8() % 5 {
                        0 => fc_cloth_set_sphere(c, id, v.as_ptr(), v[3], null()),
                        1 => fc_cloth_set_plane(c, id, v.as_ptr(), v[3..].as_ptr(), v[6..].as_ptr()),
                        2 => fc_cloth_set_capsule(c, id, v.as_ptr(), v[3..].as_ptr(), v[6], null()),
                        3 => fc_cloth_remove_collider(c, id),
                        _ => fc_cloth_set_collider_friction(c, id, v[0]),
                    };
                }
                16 => {
                    let mut centre = [0f32; 3];
                    let mut r = 0f32;
                    let _ = fc_cloth_get_sphere(c, u32::from(b.u8() % 6), centre.as_mut_ptr(), &mut r);
                }
                17 => {
                    let size = fc_cloth_snapshot_size(c);
                    if size < (1 << 22) {
                        let mut buf = vec![0u8; size];
                        let cap = b.len(size).min(size);
                        let mut written = 0;
                        if fc_cloth_save_snapshot(c, buf.as_mut_ptr().cast::<c_void>(), cap, &mut written)
                            == FcStatus::FC_OK
                        {
                            buf.truncate(written);
                            snapshot = buf;
                        }
                    }
                }
                18 => {
                    let mut s = snapshot.clone();
                    if !s.is_empty() && pick % 2 == 0 {
                        let at = usize::from(b.u8()) * 7 % s.len();
                        s[at] ^= b.u8();
                        // Half the time the checksum is made right again, so the mutation
                        // reaches the checks of meaning behind it.
                        if pick % 4 == 0 && s.len() > 28 {
                            let end = s.len() - 4;
                            let crc = crc32fast::hash(&s[..end]);
                            s[end..].copy_from_slice(&crc.to_le_bytes());
                        }
                    }
                    // A finite but possibly absurd number written over an 8-byte word of the
                    // snapshot's tail (where the histories are), checksum made right: the
                    // loader must refuse what cannot step (a trial step), never accept it.
                    if pick % 5 == 1 && s.len() > 64 {
                        let tail = s.len() - 4;
                        let words = (tail / 2) / 8;
                        let at = tail - 8 * (1 + usize::from(b.u8()) % words.max(1));
                        let value = (f64::from(b.u8()) - 128.0) * 10f64.powi(i32::from(b.u8()) * 600 / 255 - 300);
                        if value.is_finite() {
                            s[at..at + 8].copy_from_slice(&value.to_le_bytes());
                            let crc = crc32fast::hash(&s[..tail]);
                            s[tail..].copy_from_slice(&crc.to_le_bytes());
                        }
                    }
                    if pick % 3 == 0 {
                        s = (0..usize::from(b.u8())).map(|_| b.u8()).collect();
                    }
                    let len = b.len(s.len()).min(s.len());
                    if fc_cloth_load_snapshot(c, s.as_ptr().cast::<c_void>(), len) == FcStatus::FC_OK {
                        // A snapshot that loads can be stepped: never a panic.
                        assert_ne!(fc_cloth_step(c, 1e-4), FcStatus::FC_ERROR_PANIC);
                    }
                }
                19 => {
                    let _ = fc_cloth_set_solver(c, b.f64(), u32::from(b.u8()));
                    let (mut it, mut res) = (0u32, 0f64);
                    let _ = fc_cloth_get_solver_stats(c, &mut it, &mut res);
                }
                20 => {
                    let mut cache = null_mut();
                    let format = u32::from(b.u8() % 4);
                    // Half the caches go to a device where every write fails part-way.
                    let path = if pick % 2 == 0 { &cache_path } else { &full_path };
                    if format != 2
                        && fc_cache_open(
                            path.as_ptr(),
                            format,
                            c,
                            b.f64(),
                            b.f64(),
                            u32::from(b.u8() % 4),
                            &mut cache,
                        ) == FcStatus::FC_OK
                    {
                        let mut failed = false;
                        for _ in 0..b.u8() % 6 {
                            let s = fc_cache_write_frame(cache, c);
                            // Once a frame failed, every later one fails too.
                            assert!(!failed || s != FcStatus::FC_OK);
                            failed |= s == FcStatus::FC_ERROR_IO;
                        }
                        let s = fc_cache_close(cache);
                        assert!(!failed || s != FcStatus::FC_OK, "a failed cache closed with FC_OK");
                    }
                }
                21 => {
                    let _ = fc_cloth_time(c);
                    let _ = fc_cloth_history_mode_count(c);
                    let _ = fc_cloth_history_bytes_per_particle(c);
                    let _ = fc_cloth_triangle_count(c);
                    let _ = fc_status_string(i32::from(b.u8()) - 64);
                    let _ = fc_last_error_message();
                }
                22 => {
                    let mut d = fc_cloth_desc_default();
                    let _ = fc_cloth_desc_preset(
                        u32::from(b.u8() % 6),
                        if pick % 5 == 0 { null_mut() } else { &mut d },
                    );
                }
                _ => {
                    // A failed call must leave a handle usable: a sane step on every live cloth.
                    for &h in &cloths {
                        let n = vcount(h);
                        let mut xyz = vec![0f32; 3 * n];
                        let s = fc_cloth_get_positions(h, xyz.as_mut_ptr(), xyz.len());
                        assert_eq!(s, FcStatus::FC_OK);
                    }
                }
            }
        }
    }
    for c in cloths {
        unsafe { fc_cloth_destroy(c) };
    }
});
