//! Preview pictures of a bake: a fixed camera, Lambert-shaded cloth over an underwater
//! backdrop, colliders drawn as shaded spheres; contact sheets and animated GIFs.
//!
//! The cloth is drawn by a small z-buffered rasteriser of ours with smooth shading
//! (`raster.rs`: flat shading banded every row of facets); the backdrop, plots and sheets
//! are drawn with tiny-skia, GIF encoding (with NeuQuant colour quantisation) is the `gif` crate's, and
//! labels use the public-domain 8x8 bitmap font of `font8x8`. Nothing here is used by the
//! physics or the C ABI.

mod camera;
mod frame;
mod label;
mod plots;
mod raster;
mod sheet;
#[cfg(test)]
mod tests;

pub use camera::Camera;
pub use frame::{render_frame, Scene3d};
pub use label::draw_label;
pub use plots::{side_view, space_time};
pub use sheet::{contact_sheet, save_png, GifWriter};
