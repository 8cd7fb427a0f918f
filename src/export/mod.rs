//! Point caches and meshes that DCC tools read (layouts in DESIGN.md section 6).

mod cache;
mod frame;
mod mdd;
mod obj;
mod pc2;
mod read;

pub use cache::{sequence_path, CacheFormat, CacheWriter};
pub(crate) use frame::encode_frame;
pub use mdd::{MddWriter, MAX_MDD_FRAMES};
pub use obj::write_obj;
pub use pc2::Pc2Writer;
pub use read::{parse_mdd, parse_obj, parse_pc2, read_cache, read_obj, CacheFrames, ObjMesh};
