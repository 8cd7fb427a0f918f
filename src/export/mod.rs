//! Point caches and meshes that DCC tools read (layouts in DESIGN.md section 6).

mod cache;
mod mdd;
mod obj;
mod pc2;
mod read;

pub use cache::{sequence_path, CacheFormat, CacheWriter};
pub use mdd::MddWriter;
pub use obj::write_obj;
pub use pc2::Pc2Writer;
pub use read::{parse_mdd, parse_obj, parse_pc2, read_cache, read_obj, CacheFrames, ObjMesh};

/// One frame as f32 triples, little- or big-endian (the caches' only difference in encoding).
pub(crate) fn encode_frame(positions: &[crate::Vec3], big_endian: bool) -> Vec<u8> {
    let mut buf = Vec::with_capacity(12 * positions.len());
    for p in positions {
        for c in p.iter() {
            let v = *c as f32;
            buf.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    }
    buf
}
