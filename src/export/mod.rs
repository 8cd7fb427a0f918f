//! Point caches and meshes that DCC tools read (layouts in DESIGN.md section 6).

mod cache;
mod mdd;
mod obj;
mod pc2;

pub use cache::{sequence_path, CacheFormat, CacheWriter};
pub use mdd::MddWriter;
pub use obj::write_obj;
pub use pc2::Pc2Writer;
