//! Preview pictures of a bake: a fixed camera, Lambert-shaded cloth over an underwater
//! backdrop, colliders drawn as shaded spheres; contact sheets and animated GIFs.
//!
//! Only the projection and shading glue is ours: rasterising (anti-aliased triangle fill) is
//! tiny-skia's, GIF encoding (with NeuQuant colour quantisation) is the `gif` crate's, and
//! labels use the public-domain 8x8 bitmap font of `font8x8`. Nothing here is used by the
//! physics or the C ABI.

mod camera;
mod frame;
mod label;
mod sheet;

pub use camera::Camera;
pub use frame::{render_frame, Scene3d};
pub use label::draw_label;
pub use sheet::{contact_sheet, save_png, GifWriter};
