//! Spring forces, Eq. 5, for the three spring families.
//!
//! On particle i from the spring to j, with `l = x_i - x_j`, rest length r:
//! `F = -k_s (|l| - r) l_hat - k_d [(q_i - q_j) . l_hat] l_hat`,
//! where q is D^{1/2}x for fractional springs (Eq. 5) and v for regular damped springs.
//! Particle j receives the opposite force.

use super::ForceInput;
use crate::model::SpringDamping;
use crate::Vec3;

pub(super) fn add(input: &ForceInput<'_>, f: &mut [Vec3]) {
    let m = input.model;
    let kd = m.spring_damping;
    let rate: Option<&[Vec3]> = match m.spring_damping_mode {
        _ if kd == 0.0 => None,
        SpringDamping::None => None,
        SpringDamping::Velocity => Some(input.v),
        SpringDamping::Fractional => Some(input.half_derivative),
    };
    for s in &input.topology.springs {
        let ks = m.stiffness(s.kind);
        let (i, j) = (s.i as usize, s.j as usize);
        let l = input.x[i] - input.x[j];
        let len = l.norm();
        if len == 0.0 {
            continue; // direction undefined; no force rather than NaN
        }
        let dir = l / len;
        let mut mag = -ks * (len - s.rest);
        if let Some(q) = rate {
            mag -= kd * (q[i] - q[j]).dot(&dir);
        }
        let fij = mag * dir;
        f[i] += fij;
        f[j] -= fij;
    }
}
