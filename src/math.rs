//! The ground floor: the vector type every module builds on, defined here so that no module
//! imports from the crate root (which re-exports it for users).

/// 3-vector of f64, the core's only vector type.
pub type Vec3 = nalgebra::Vector3<f64>;
