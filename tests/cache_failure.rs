//! A cache whose writer fails part-way is poisoned: every later frame and the close return
//! the first error, and the file on disk holds exactly its complete frames with a header that
//! counts them (an OBJ sequence loses the partial frame's file).
//!
//! One test in its own binary: the file-size limit it sets applies to the whole process.

use std::ffi::CString;
use std::ptr::null_mut;

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;

#[test]
fn a_cache_that_fails_part_way_keeps_its_whole_frames_and_says_so() {
    let dir = std::env::temp_dir().join(format!("fc-cache-fail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut desc = fc_cloth_desc_default();
    desc.width = 4;
    desc.height = 3;
    let mut c = null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(&desc, &mut c) }, FC_OK);
    let frame = 12 * 12; // bytes of one frame of 12 vertices
                         // Writes past the limit fail with EFBIG instead of killing the process with SIGXFSZ.
    let limit: u64 = 32 + 2 * frame + 50;
    let old = unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
        let mut old = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        assert_eq!(libc::getrlimit(libc::RLIMIT_FSIZE, &mut old), 0);
        let new = libc::rlimit {
            rlim_cur: limit as libc::rlim_t,
            rlim_max: old.rlim_max,
        };
        assert_eq!(libc::setrlimit(libc::RLIMIT_FSIZE, &new), 0);
        old
    };
    // (format, file, header bytes once cut to two frames)
    for (format, name, header) in [(0u32, "a.pc2", 32u64), (1, "a.mdd", 8 + 4 * 2)] {
        let path = dir.join(name);
        let p = CString::new(path.to_str().unwrap()).unwrap();
        let mut cache = null_mut();
        assert_eq!(
            unsafe { fc_cache_open(p.as_ptr(), format, c, 1.0, 24.0, 6, &mut cache) },
            FC_OK
        );
        let statuses: Vec<FcStatus> = (0..6)
            .map(|_| unsafe { fc_cache_write_frame(cache, c) })
            .collect();
        assert_eq!(&statuses[..2], &[FC_OK, FC_OK], "{name}");
        assert!(
            statuses[2..].iter().all(|s| *s == FC_ERROR_IO),
            "{name}: {statuses:?}"
        );
        assert_eq!(
            unsafe { fc_cache_close(cache) },
            FC_ERROR_IO,
            "{name}: close must report the failure"
        );
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(
            bytes.len() as u64,
            header + 2 * frame,
            "{name}: cut to its whole frames"
        );
        let count = match format {
            0 => i32::from_le_bytes(bytes[28..32].try_into().unwrap()),
            _ => i32::from_be_bytes(bytes[0..4].try_into().unwrap()),
        };
        assert_eq!(count, 2, "{name}: the header counts the frames that are there");
        // And it reads back as a valid cache.
        let back = match format {
            0 => fraccloth_tools::read::parse_pc2(&bytes),
            _ => fraccloth_tools::read::parse_mdd(&bytes),
        };
        assert_eq!(back.unwrap().frames.len(), 2);
    }
    // An OBJ sequence whose first frame does not fit: no partial file is left.
    let path = dir.join("seq.obj");
    let p = CString::new(path.to_str().unwrap()).unwrap();
    let mut cache = null_mut();
    let tight = libc::rlimit {
        rlim_cur: 200,
        rlim_max: old.rlim_max,
    };
    unsafe { libc::setrlimit(libc::RLIMIT_FSIZE, &tight) };
    assert_eq!(
        unsafe { fc_cache_open(p.as_ptr(), 2, c, 1.0, 24.0, 0, &mut cache) },
        FC_OK
    );
    assert_eq!(unsafe { fc_cache_write_frame(cache, c) }, FC_ERROR_IO);
    assert!(
        !dir.join("seq_0001.obj").exists(),
        "the partial frame's file is removed"
    );
    assert_eq!(unsafe { fc_cache_write_frame(cache, c) }, FC_ERROR_IO);
    assert_eq!(unsafe { fc_cache_close(cache) }, FC_ERROR_IO);
    unsafe {
        libc::setrlimit(libc::RLIMIT_FSIZE, &old);
        fc_cloth_destroy(c);
    }
    std::fs::remove_dir_all(&dir).ok();
}
