//! # fraccloth
//!
//! Cloth that moves as if it were underwater, without simulating the water: the
//! "fractional clothes" model, a particle mass-spring cloth whose spring damping and
//! an external history drag are proportional to the half-derivative D^{1/2} of
//! particle displacement. The half-derivative carries the memory of the fluid.
//!
//! The physics core (everything but [`ffi`]) knows nothing of C; the C ABI in
//! [`ffi`] is a thin checked shell over [`Cloth`]. Units are SI throughout.

// Physics loops walk several per-particle arrays with one index; that reads better than zips.
#![allow(clippy::needless_range_loop)]

pub mod cloth;
pub mod error;
pub mod export;
pub mod ffi;
pub mod forces;
pub mod history;
pub mod integrate;
pub mod model;
pub mod oscillator;
pub mod scenes;
pub mod topology;

/// 3-vector of f64, the core's only vector type.
pub type Vec3 = nalgebra::Vector3<f64>;

pub use cloth::{Cloth, ClothConfig};
pub use error::{Error, ErrorKind};
pub use history::{HalfDerivative, History, Scheme};
pub use integrate::Integrator;
pub use model::{Model, RegularDrag, SpringDamping};
pub use topology::{GridSpec, Topology};
