//! The C ABI: a thin, checked, panic-safe shell over [`crate::Cloth`].
//!
//! One file per header area: [`status`] (status codes, last error, the panic
//! boundary), [`desc`] (the description struct and its defaults), [`desc_size`] (its `struct_size` rule), [`cloth`]
//! (lifetime, pins, positions, stepping), [`mesh`] (cloths from meshes), [`collider`]
//! (colliders), [`mesh_collider`] (triangle-mesh colliders), [`cache`] (PC2 / MDD / OBJ writers), [`geometry`] (index buffer, normals), [`state`] (positions and velocities in
//! double precision, velocities in float), [`threads`] (where a step runs), [`version`].
//!
//! Rules every export follows:
//! - it runs inside a panic boundary; a panic becomes `FC_ERROR_PANIC`;
//! - NULL pointers give `FC_ERROR_NULL_ARGUMENT`, never a crash;
//! - a failing call writes no output and leaves the cloth exactly as it was;
//! - `const` pointers are never written through.
//!
//! Threads: one handle must not be used from two threads at once; different handles
//! may be used on different threads concurrently. `fc_last_error_message` is per thread.

#[macro_use]
pub mod status;
pub mod cache;
pub mod cloth;
pub mod collider;
pub mod desc;
pub mod desc_size;
pub mod geometry;
pub mod handle;
pub mod mesh;
pub mod mesh_collider;
pub mod snapshot;
pub mod state;
pub mod threads;
pub mod version;

pub use cache::*;
pub use cloth::*;
pub use collider::*;
pub use desc::*;
pub use geometry::*;
pub use mesh::*;
pub use mesh_collider::*;
pub use snapshot::*;
pub use state::*;
pub use status::*;
pub use threads::*;
pub use version::*;
