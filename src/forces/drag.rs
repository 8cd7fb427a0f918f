//! External drags on one particle, acting on its velocity relative to the water.
//!
//! - viscous drag, Eq. 3: `-k_vd v`;
//! - history (Basset) drag, Eq. 4: `-k_hd (D^{1/2}x . v_hat) v_hat`, zero when v = 0;
//! - normal drag (regular models of Fig. 7): `-k_nd (v . n_hat) n_hat`.
//!
//! A term whose coefficient is zero is skipped.

use crate::model::Model;
use crate::Vec3;

/// Adds the drags on a particle with velocity `v`, half-derivative `d` and unit normal `n`
/// (read only when normal drag is on) to `f`.
#[inline]
pub(super) fn add(m: &Model, v: &Vec3, d: &Vec3, n: Option<&Vec3>, f: &mut Vec3) {
    let c = m.current;
    if m.viscous_drag != 0.0 {
        *f -= m.viscous_drag * (v - c);
    }
    if m.history_drag != 0.0 {
        let rel = v - c;
        let speed2 = rel.norm_squared();
        if speed2 > 0.0 {
            // (d . v_hat) v_hat = (d . rel) rel / |rel|^2
            *f -= m.history_drag * (d.dot(&rel) / speed2) * rel;
        }
    }
    if let Some(n) = n {
        *f -= m.normal_drag * (v - c).dot(n) * n;
    }
}
