//! `fc_cache_write_positions`: frames the host gives, checked, and read back exactly.

use std::ffi::CString;

use fraccloth::ffi::FcStatus::{FC_ERROR_INVALID_ARGUMENT, FC_OK};
use fraccloth::ffi::*;
use fraccloth_tools::read::read_cache;

#[test]
fn host_positions_are_written_as_given_and_bad_ones_refused() {
    let dir = std::env::temp_dir().join(format!("fraccloth-cache-positions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("host.pc2");
    let mut d = fc_cloth_desc_default();
    d.width = 4;
    d.height = 3;
    let mut cloth = std::ptr::null_mut();
    let mut cache = std::ptr::null_mut();
    let c_path = CString::new(path.to_str().unwrap()).unwrap();
    let frames: Vec<Vec<f32>> = (0..3)
        .map(|f| (0..36).map(|k| k as f32 * 0.01 + f as f32).collect())
        .collect();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&d, &mut cloth), FC_OK);
        assert_eq!(
            fc_cache_open(c_path.as_ptr(), 0, cloth, 1.0, 24.0, 3, &mut cache),
            FC_OK
        );
        for f in &frames {
            assert_eq!(fc_cache_write_positions(cache, f.as_ptr(), 36), FC_OK);
        }
        // A wrong count, NULL and a NaN are refused, and write nothing.
        assert_eq!(
            fc_cache_write_positions(cache, frames[0].as_ptr(), 33),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            fc_cache_write_positions(cache, frames[0].as_ptr(), 35),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            fc_cache_write_positions(cache, std::ptr::null(), 36),
            FcStatus::FC_ERROR_NULL_ARGUMENT
        );
        let mut bad = frames[0].clone();
        bad[7] = f32::NAN;
        assert_eq!(
            fc_cache_write_positions(cache, bad.as_ptr(), 36),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(fc_cache_close(cache), FC_OK);
        fc_cloth_destroy(cloth);
    }
    let back = read_cache(&path).unwrap();
    assert_eq!(back.frames.len(), 3);
    for (got, want) in back.frames.iter().zip(&frames) {
        let flat: Vec<f32> = got
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        assert_eq!(&flat, want);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
