//! Plumbing: how the passes run, not what they compute. Crate-private.
//!
//! | file | what |
//! |---|---|
//! | `parallel.rs` | chunked passes over rayon with results independent of the thread count; the tile and chunk sizes |
//! | `simd.rs` | run-time choice of vector width (`simd_dispatch!`) |
//! | `aligned.rs` | arrays of f64 and of `Vec3` that start on a cache line |
//! | `soa.rs` | component arrays (x, y, z) of a cloth |
//! | `bytes.rs` | the snapshot format's byte writer and bounds-checked reader |
//! | `memory.rs` | memory checked before a caller-sized allocation (out of memory is an error, never an abort) |

pub mod aligned;
pub mod bytes;
pub mod memory;
pub mod parallel;
pub mod simd;
pub mod soa;
