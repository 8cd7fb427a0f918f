//! # fraccloth-tools
//!
//! What the `fraccloth` baker, the tests and the examples use beside the library, kept out of the
//! library so that the C library is built from the physics alone:
//!
//! | module | what |
//! |---|---|
//! | [`look`] | the look meter: half-waves, phase speed, depth of motion, zigzag; lean and flutter in a current |
//! | [`scenes`] | the built-in scenes (`swing`, `sway`, `sphere`, `current`, `kelp`, `curtain`, the collision towel), each with its drive |
//! | [`oscillator`] | the fractional oscillator as a one-particle cloth |
//! | [`read`] | PC2, MDD and OBJ readers (the caches the library writes, and meshes to bake) |

// Analysis loops walk several per-particle arrays with one index; that reads better than zips.
#![allow(clippy::needless_range_loop)]

pub mod args;
pub mod look;
pub mod oscillator;
pub mod read;
pub mod scenes;
