//! Gravity and buoyancy, Eq. 2: `F_g = (rho_c - rho_w) V_c g` with `V_c = m / rho_c`.

use crate::model::Model;
use crate::Vec3;

/// Net weight in water of a particle of mass `m` (N): `m` times [`body_acceleration`].
pub fn body_force(model: &Model, m: f64) -> Vec3 {
    m * body_acceleration(model)
}

/// Net weight in water per kilogram of cloth, `(1 - rho_w / rho_c) g` (m/s^2).
pub fn body_acceleration(model: &Model) -> Vec3 {
    ((model.cloth_density - model.water_density) / model.cloth_density) * model.gravity
}
