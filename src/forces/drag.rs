//! External drags on each particle, acting on the velocity relative to the water.
//!
//! - viscous drag, Eq. 3: `-k_vd v`;
//! - history (Basset) drag, Eq. 4: `-k_hd (D^{1/2}x . v_hat) v_hat`, zero when v = 0;
//! - normal drag (regular models of Fig. 7): `-k_nd (v . n_hat) n_hat`.

use super::ForceInput;
use crate::Vec3;

pub(super) fn add_viscous(input: &ForceInput<'_>, f: &mut [Vec3]) {
    let k = input.model.viscous_drag;
    if k == 0.0 {
        return;
    }
    let c = input.model.current;
    for (fi, v) in f.iter_mut().zip(input.v) {
        *fi -= k * (v - c);
    }
}

pub(super) fn add_history(input: &ForceInput<'_>, f: &mut [Vec3]) {
    let k = input.model.history_drag;
    if k == 0.0 {
        return;
    }
    let c = input.model.current;
    for ((fi, v), d) in f.iter_mut().zip(input.v).zip(input.half_derivative) {
        let rel = v - c;
        let speed2 = rel.norm_squared();
        if speed2 > 0.0 {
            // (d . v_hat) v_hat = (d . rel) rel / |rel|^2
            *fi -= k * (d.dot(&rel) / speed2) * rel;
        }
    }
}

pub(super) fn add_normal(input: &ForceInput<'_>, normals: &[Vec3], f: &mut [Vec3]) {
    let k = input.model.normal_drag;
    let c = input.model.current;
    for ((fi, v), n) in f.iter_mut().zip(input.v).zip(normals) {
        *fi -= k * (v - c).dot(n) * n;
    }
}
