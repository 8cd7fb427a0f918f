//! A cache dropped without being finished (a host, or the baker, stopping on an error) leaves a
//! file whose header counts exactly the frames written whole. (The baker's own refused bake:
//! `cli/tests/refused_bake.rs`.)

use fraccloth::export::{CacheFormat, CacheWriter};
use fraccloth::Vec3;
use fraccloth_tools::read::read_cache;

#[test]
fn a_dropped_cache_counts_exactly_its_frames() {
    let dir = std::env::temp_dir().join(format!("fc-cache-drop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tri = [[0u32, 1, 2]];
    for (format, name) in [(CacheFormat::Pc2, "a.pc2"), (CacheFormat::Mdd, "a.mdd")] {
        let path = dir.join(name);
        {
            // 361 frames announced, 3 written, never finished.
            let mut w = CacheWriter::create(&path, format, 3, &tri, 1.0, 30.0, 361).unwrap();
            for k in 0..3 {
                let p = vec![Vec3::new(k as f64, 0.0, 0.0); 3];
                w.write_frame(&p).unwrap();
            }
        }
        let back = read_cache(&path).unwrap();
        assert_eq!(back.frames.len(), 3, "{name}");
        assert_eq!(back.frames[2][1], Vec3::new(2.0, 0.0, 0.0), "{name}");
        let len = std::fs::metadata(&path).unwrap().len();
        let header = if format == CacheFormat::Pc2 { 32 } else { 8 + 4 * 3 };
        assert_eq!(len, header + 3 * 3 * 12, "{name}: no bytes beyond its frames");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
