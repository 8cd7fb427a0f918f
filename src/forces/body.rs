//! Gravity and buoyancy, Eq. 2: `F_g = (rho_c - rho_w) V_c g` with `V_c = m / rho_c`.

use crate::math::Vec3;
use crate::model::Model;

/// Net weight in water of a particle of mass `m` (N): `m` times [`body_acceleration`].
pub fn body_force(model: &Model, m: f64) -> Vec3 {
    m * body_acceleration(model)
}

/// Net weight in water per kilogram of cloth, `(1 - rho_w / rho_c) g` (m/s^2).
pub fn body_acceleration(model: &Model) -> Vec3 {
    ((model.cloth_density - model.water_density) / model.cloth_density) * model.gravity
}

crate::simd_dispatch! { pub(super) fn add_weight_widest(forces: [&mut [f64]; 3], masses: &[f64], gravity: Vec3) => add_weight }

/// `forces[c][k] += masses[k] gravity[c]`: the net weight added to a tile's forces (component
/// arrays; `gravity` from [`body_acceleration`]).
#[inline(always)]
fn add_weight(forces: [&mut [f64]; 3], masses: &[f64], gravity: Vec3) {
    for (c, f) in forces.into_iter().enumerate() {
        let len = f.len();
        let g = gravity[c];
        for (fk, &m) in f.iter_mut().zip(&masses[..len]) {
            *fk += m * g;
        }
    }
}
