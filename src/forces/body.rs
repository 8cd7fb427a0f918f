//! Gravity and buoyancy, Eq. 2: `F_g = (rho_c - rho_w) V_c g` with `V_c = m / rho_c`.

use crate::model::Model;
use crate::Vec3;

/// Net weight in water of a particle of mass `m` (N).
pub fn body_force(model: &Model, m: f64) -> Vec3 {
    let volume = m / model.cloth_density;
    (model.cloth_density - model.water_density) * volume * model.gravity
}
