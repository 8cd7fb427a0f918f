//! Point caches and meshes that DCC tools read (layouts in DESIGN.md section 6). Reading them
//! back is the tools crate's (`fraccloth_tools::read`).

mod cache;
mod frame;
mod mdd;
mod obj;
mod pc2;

pub use cache::{sequence_path, CacheFormat, CacheWriter};
pub(crate) use frame::encode_frame;
pub use mdd::{MddWriter, MAX_MDD_FRAMES};
pub use obj::write_obj;
pub use pc2::Pc2Writer;
