//! # fraccloth
//!
//! Cloth that moves as if it were underwater, without simulating the water: the
//! "fractional clothes" model, a particle mass-spring cloth whose spring damping and
//! an external history drag are proportional to the half-derivative D^{1/2} of
//! particle displacement. The half-derivative carries the memory of the fluid.
//!
//! The physics core (everything but [`ffi`]) knows nothing of C; the C ABI in
//! [`ffi`] is a thin checked shell over [`Cloth`]. Units are SI throughout. What only the baker,
//! the tests and the examples use (the look meter, the built-in scenes, the fractional
//! oscillator, the cache readers) is the `fraccloth-tools` crate (`tools/`), not this one, so the
//! C library is built from the physics alone.
//!
//! ```
//! use fraccloth::{Cloth, ClothConfig, GridSpec, Vec3};
//!
//! // A 0.2 m x 0.1 m towel of 21 x 11 particles, the paper's forces, the accurate history.
//! let grid = GridSpec { width: 21, height: 11, spacing: 0.01, total_mass: 0.02 }.build()?;
//! let mut cloth = Cloth::new(grid, ClothConfig::default())?;
//! let top: Vec<u32> = (0..21).collect();
//! cloth.set_pinned(&top)?;
//! for _ in 0..200 {
//!     cloth.step(5e-4)?; // seconds
//! }
//! // The free bottom edge has sunk below its rest height; the pinned top has not moved.
//! let bottom_middle = 10 * 21 + 10; // vertex (column i, row j) is j * width + i
//! assert!(cloth.positions()[bottom_middle].y < -0.1);
//! assert_eq!(cloth.positions()[0], cloth.topology().rest_positions[0]);
//! # Ok::<(), fraccloth::Error>(())
//! ```

// Physics loops walk several per-particle arrays with one index; that reads better than zips.
#![allow(clippy::needless_range_loop)]

pub mod cloth;
pub mod collide;
pub mod error;
pub mod export;
pub mod ffi;
pub mod forces;
pub mod history;
pub mod integrate;
pub mod model;
mod plumbing;
#[cfg(test)]
mod testing;
pub mod topology;

pub mod math;
pub use math::Vec3;

pub(crate) use plumbing::{aligned, bytes, memory, parallel, soa};

pub use cloth::{Cloth, ClothConfig};
pub use error::{Error, ErrorKind};
pub use history::{HalfDerivative, History, Scheme};
pub use integrate::Integrator;
pub use model::{Model, RegularDrag, SpringDamping};
/// How many particles a cloth needs for its step to use more than one thread (by CPU).
pub use plumbing::parallel::{min_parallel, MIN_PARALLEL, MIN_PARALLEL_AMD, MIN_PARALLEL_VARIABLE};
/// The vector width the loops run at on this machine ("avx512", "avx2" or "baseline"; capped
/// by the environment variable `FRACCLOTH_SIMD` for measurement).
pub use plumbing::simd::level as simd_level;
/// The vector width the loops run at, and the environment variable that caps it.
#[doc(hidden)]
pub use plumbing::simd::{width as simd_width, Width as SimdWidth, WIDTH_VARIABLE as SIMD_WIDTH_VARIABLE};
pub use topology::{GridSpec, Topology};
