//! Point caches and meshes that DCC tools read (layouts in DESIGN.md section 6).

mod obj;
mod pc2;

pub use obj::write_obj;
pub use pc2::Pc2Writer;
