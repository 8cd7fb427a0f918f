//! The water carried by the cloth's large-scale normal motion: a scale-aware added mass.
//!
//! The local normal added mass ([`super::Inertia`], `m_a` per unit area) is one value for every
//! motion, but a sheet moving as a whole carries far more water than its ripples do (a rigid
//! plate of width W about `rho_w pi W / 4` per unit area, a ripple of wavelength lambda about
//! `rho_w lambda / pi`). This module adds the whole-sheet part on a coarse level: the cloth's
//! rest shape is covered by bilinear hats `phi_p` a coarse spacing `L` apart (a partition of
//! unity), each patch p averages the normal velocity of its vertices,
//! `S_p = sum_i W_pi (a_i . v_i)`, `W_pi = phi_p(X_i) A_i / A_p`, `A_p = sum_i phi_p(X_i) A_i`
//! (`a_i` the patch normal of [`super::patch_normals`]), and carries `K_p = m_c A_p` of water
//! (`m_c` the coarse added mass per unit area). The water's kinetic energy gains
//! `1/2 sum_p K_p S_p^2`: a sheet moving rigidly along its normal carries `m_c` more per unit
//! area, a ripple shorter than the patches averages out and carries only the local `m_a`.
//!
//! The mass matrix stays `iso I` in the cloth's plane; along the normals it is
//! `E + W'^T K W'` on the normal components (E diagonal, `W'_pi = W_pi p_i`), which the step
//! inverts by Woodbury with one patches-by-patches solve ([`CoarseWater::effective_forces`]).
//! The forces as the normals turn take the coarse momentum the same way as the local one
//! ([`super::turning_forces`]).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::error::Error;
use crate::math::Vec3;
use crate::model::Model;
use crate::topology::Topology;

/// The coarse level of a cloth: its patches, each vertex's weights in them, and what each
/// patch carries.
#[derive(Clone, Debug, Default)]
pub struct CoarseWater {
    /// Vertex i's patches and weights `W_pi`: `patch[4 i..4 i + 4]`, `weight[4 i..4 i + 4]`
    /// (unused slots weigh 0).
    patch: Vec<u32>,
    weight: Vec<f64>,
    /// The coarse added mass and patch spacing it was built for.
    made_of: (f64, f64),
    /// The pins it was built for.
    pub pinned: Vec<bool>,
    /// `K_p`, kg.
    carried: Vec<f64>,
    /// Per-step scratch: patch sums, the coarse matrix.
    sums: Vec<f64>,
    sums2: Vec<f64>,
    /// The step's patches-by-patches matrix and right-hand side, kept between steps.
    gram: DMatrix<f64>,
    rhs: DVector<f64>,
}

/// Most patches a coarse level may have: its patches-by-patches matrix is dense and factored
/// every step (256: 0.5 MB and about 6 M flops).
pub const MAX_PATCHES: usize = 256;

/// Where the patches lie: the rest shape's coordinates in its two principal directions, and
/// the fewest cells no longer than the coarse length along each (a hat on every node).
struct PatchGrid {
    /// Each vertex's coordinates, m.
    uv: Vec<(f64, f64)>,
    /// The lowest coordinates.
    lo: (f64, f64),
    cells: (usize, usize),
    /// The cells' sides, m.
    step: (f64, f64),
}

impl PatchGrid {
    fn of(t: &Topology, length: f64) -> Result<PatchGrid, Error> {
        let x = &t.rest_positions;
        let n = x.len();
        let centre: Vec3 = x.iter().sum::<Vec3>() / n.max(1) as f64;
        let mut cov = nalgebra::Matrix3::zeros();
        for p in x {
            let d = p - centre;
            cov += d * d.transpose();
        }
        let eig = SymmetricEigen::new(cov);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let (e1, e2): (Vec3, Vec3) = (
            eig.eigenvectors.column(order[0]).into(),
            eig.eigenvectors.column(order[1]).into(),
        );
        let mut uv = Vec::new();
        uv.try_reserve_exact(n).map_err(|e| {
            Error::out_of_memory(format!(
                "the coarse water's patch coordinates for {n} vertices: {e}"
            ))
        })?;
        uv.extend(x.iter().map(|p| ((p - centre).dot(&e1), (p - centre).dot(&e2))));
        let lo = uv
            .iter()
            .fold((f64::MAX, f64::MAX), |a, b| (a.0.min(b.0), a.1.min(b.1)));
        let hi = uv
            .iter()
            .fold((f64::MIN, f64::MIN), |a, b| (a.0.max(b.0), a.1.max(b.1)));
        let span = if n == 0 {
            (0.0, 0.0)
        } else {
            (hi.0 - lo.0, hi.1 - lo.1)
        };
        // Patches at most `length` apart (a rounding's worth of slack, so that a span of exactly
        // two lengths takes two cells); `as` saturates a huge count.
        let cells = |span: f64| ((span / length * (1.0 - 1e-9)).ceil() as usize).max(1);
        let (cu, cv) = (cells(span.0), cells(span.1));
        let patches = cu.saturating_add(1).saturating_mul(cv.saturating_add(1));
        if patches > MAX_PATCHES {
            // The fewest cells a side that fit: about sqrt(MAX_PATCHES) over the longer span.
            // Rounded up to the millimetre it is printed with.
            let shortest = (span.0.max(span.1) / ((MAX_PATCHES as f64).sqrt() - 1.0) * 1e3).ceil() / 1e3;
            return Err(Error::invalid(format!(
                "coarse_length {length} m makes {cu} x {cv} cells ({patches} patches) over this cloth ({:.3} x {:.3} m); at most {MAX_PATCHES} patches: use a coarse_length of at least {shortest:.3} m",
                span.0, span.1
            )));
        }
        Ok(PatchGrid {
            uv,
            lo,
            cells: (cu, cv),
            step: (span.0 / cu as f64, span.1 / cv as f64),
        })
    }
}

/// Checks that `model`'s coarse water (if any) fits cloth `t` ([`MAX_PATCHES`]), so that a
/// cloth is refused when it is made or reconfigured, not at its first step.
pub fn check(t: &Topology, model: &Model) -> Result<(), Error> {
    if model.water.coarse_added_mass > 0.0 {
        PatchGrid::of(t, model.water.coarse_length)?;
    }
    Ok(())
}

impl CoarseWater {
    /// The coarse level of `t` with `mass` kg/m^2 carried by motion smoother than `length` m
    /// ([`PatchGrid`]).
    ///
    /// # Errors
    /// `InvalidArgument` when `length` makes more than [`MAX_PATCHES`] patches over the cloth;
    /// `OutOfMemory` when the weights (48 bytes a vertex) cannot be allocated.
    pub fn new(t: &Topology, mass: f64, length: f64, pinned: &[bool]) -> Result<CoarseWater, Error> {
        let n = t.rest_positions.len();
        let PatchGrid {
            uv,
            lo,
            cells: (cu, cv),
            step: (du, dv),
        } = PatchGrid::of(t, length)?;
        let nodes_u = cu + 1;
        let room = |e: std::collections::TryReserveError| {
            Error::out_of_memory(format!("the coarse water's weights for {n} vertices: {e}"))
        };
        let (mut patch, mut weight) = (Vec::new(), Vec::new());
        patch.try_reserve_exact(4 * n).map_err(room)?;
        weight.try_reserve_exact(4 * n).map_err(room)?;
        patch.resize(4 * n, 0u32);
        weight.resize(4 * n, 0.0);
        let mut area = vec![0.0; nodes_u * (cv + 1)];
        for (i, &(u, v)) in uv.iter().enumerate() {
            let fu = if du > 0.0 {
                ((u - lo.0) / du).clamp(0.0, cu as f64)
            } else {
                0.0
            };
            let fv = if dv > 0.0 {
                ((v - lo.1) / dv).clamp(0.0, cv as f64)
            } else {
                0.0
            };
            let (iu, iv) = ((fu as usize).min(cu - 1), (fv as usize).min(cv - 1));
            let (su, sv) = (fu - iu as f64, fv - iv as f64);
            let corners = [
                (iu, iv, (1.0 - su) * (1.0 - sv)),
                (iu + 1, iv, su * (1.0 - sv)),
                (iu, iv + 1, (1.0 - su) * sv),
                (iu + 1, iv + 1, su * sv),
            ];
            // A pinned vertex moves as its host says: it carries no coarse water.
            let own = if pinned.get(i).copied().unwrap_or(false) {
                0.0
            } else {
                t.areas[i]
            };
            for (k, &(a, b, phi)) in corners.iter().enumerate() {
                let p = b * nodes_u + a;
                patch[4 * i + k] = p as u32;
                weight[4 * i + k] = phi * own;
                area[p] += phi * own;
            }
        }
        for i in 0..4 * n {
            let a = area[patch[i] as usize];
            weight[i] = if a > 0.0 { weight[i] / a } else { 0.0 };
        }
        let carried = area.iter().map(|a| mass * a).collect();
        Ok(CoarseWater {
            made_of: (mass, length),
            pinned: pinned.to_vec(),
            patch,
            weight,
            carried,
            sums: Vec::new(),
            sums2: Vec::new(),
            gram: DMatrix::zeros(0, 0),
            rhs: DVector::zeros(0),
        })
    }

    /// Whether this level is the one of coarse added mass `mass` over `length` with pins
    /// `pinned`.
    pub fn built_for(&self, mass: f64, length: f64, pinned: &[bool]) -> bool {
        self.made_of == (mass, length) && self.pinned == pinned
    }

    /// The number of patches.
    pub fn patches(&self) -> usize {
        self.carried.len()
    }

    /// `S = W s` into `out` (one per patch).
    fn gather(&self, s: impl Fn(usize) -> f64, out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.patches(), 0.0);
        for i in 0..self.patch.len() / 4 {
            let si = s(i);
            for k in 4 * i..4 * i + 4 {
                out[self.patch[k] as usize] += self.weight[k] * si;
            }
        }
    }

    /// The coarse water's kinetic energy `1/2 sum_p K_p S_p^2` (J) for normal components
    /// `s(i) = a_i . v_i`.
    pub fn kinetic_energy(&self, s: impl Fn(usize) -> f64) -> f64 {
        let mut sums = Vec::new();
        self.gather(s, &mut sums);
        sums.iter().zip(&self.carried).map(|(s, k)| 0.5 * k * s * s).sum()
    }

    /// `(W^T q)_i`.
    #[inline]
    fn scatter_at(&self, i: usize, q: &[f64]) -> f64 {
        (4 * i..4 * i + 4)
            .map(|k| self.weight[k] * q[self.patch[k] as usize])
            .sum()
    }

    /// The coarse part of the turning forces: with `a_i`, `adot_i` the patch normals and their
    /// rates (unnormalised, as in [`super::turning_forces`]) and `scale_i`, adds
    /// `-(mu_i adot_i + rho_i a_i)` to `out[i]` and `mu_i scale_i v_i` to `w[i]`, where
    /// `mu = W^T K W s`, `rho = W^T K W r`, `s_i = a_i . v_i`, `r_i = adot_i . v_i`.
    pub fn add_turning(
        &mut self,
        a: impl Fn(usize) -> (Vec3, Vec3, f64),
        v: &[Vec3],
        out: &mut [Vec3],
        w: &mut [Vec3],
    ) {
        let n = v.len();
        let mut sums = std::mem::take(&mut self.sums);
        let mut sums2 = std::mem::take(&mut self.sums2);
        self.gather(|i| a(i).0.dot(&v[i]), &mut sums);
        self.gather(|i| a(i).1.dot(&v[i]), &mut sums2);
        for p in 0..self.patches() {
            sums[p] *= self.carried[p];
            sums2[p] *= self.carried[p];
        }
        for i in 0..n {
            let (ai, adot, scale) = a(i);
            let (mu, rho) = (self.scatter_at(i, &sums), self.scatter_at(i, &sums2));
            out[i] -= mu * adot + rho * ai;
            w[i] += (mu * scale) * v[i];
        }
        self.sums = sums;
        self.sums2 = sums2;
    }

    /// Overwrites `f` (one force per particle) with the effective forces `m_i (M^{-1} f)_i`
    /// of the whole mass matrix: per particle its [`super::Inertia`] in `model` (`iso I +
    /// D n n^T`, with `normals` and `projected` as the step has them), plus the coarse
    /// `W'^T K W'` on the normal components (`W'_pi = W_pi p_i`). By Woodbury: with
    /// `E = iso + D` and `y = E^{-1} (n . f)`, solve `(K^{-1} + W' E^{-1} W'^T) q = W' y`
    /// (patches by patches, Cholesky); then the normal acceleration's water force is
    /// `nu_i = D_i sigma_i + (W'^T q)_i` with `sigma_i = (n_i . f_i - (W'^T q)_i) / E_i`, and
    /// the acceleration `(f_i - nu_i n_i) / iso_i`.
    pub fn effective_forces(
        &mut self,
        model: &Model,
        t: &Topology,
        normals: &[Vec3],
        projected: &[f64],
        f: &mut [Vec3],
    ) {
        let n = f.len();
        let np = self.patches();
        let inertia = |i: usize| super::Inertia::of(model, t.masses[i], t.areas[i], normals[i], projected[i]);
        // The buffers of the last step, filled afresh (no allocation after the first step).
        let mut g = std::mem::replace(&mut self.gram, DMatrix::zeros(0, 0));
        if g.shape() != (np, np) {
            g = DMatrix::zeros(np, np);
        }
        g.fill(0.0);
        for p in 0..np {
            // A patch of pinned vertices only carries nothing and meets nothing.
            g[(p, p)] = if self.carried[p] > 0.0 {
                1.0 / self.carried[p]
            } else {
                1.0
            };
        }
        let mut z = std::mem::replace(&mut self.rhs, DVector::zeros(0));
        if z.len() != np {
            z = DVector::zeros(np);
        }
        z.fill(0.0);
        for i in 0..n {
            let inr = inertia(i);
            let e = inr.isotropic() + inr.normal_mass;
            let y = normals[i].dot(&f[i]) / e;
            let p = projected[i];
            for k in 4 * i..4 * i + 4 {
                let (pa, wa) = (self.patch[k] as usize, self.weight[k] * p);
                z[pa] += wa * y;
                for l in 4 * i..4 * i + 4 {
                    g[(pa, self.patch[l] as usize)] += wa * self.weight[l] * p / e;
                }
            }
        }
        // G is K^{-1} (positive) plus a Gram matrix: symmetric positive definite.
        // The factor is solved in place and handed back as next step's buffer. (Not positive
        // definite only with non-finite forces: no coarse correction, and the step's soundness
        // check refuses the result.)
        match nalgebra::Cholesky::new(g) {
            Some(c) => {
                c.solve_mut(&mut z);
                self.gram = c.unpack();
            }
            None => z.fill(0.0),
        }
        let q = z;
        for i in 0..n {
            let inr = inertia(i);
            let (iso, e) = (inr.isotropic(), inr.isotropic() + inr.normal_mass);
            let wq = projected[i] * self.scatter_at(i, q.as_slice());
            let sigma = (normals[i].dot(&f[i]) - wq) / e;
            let nu = inr.normal_mass * sigma + wq;
            f[i] = (inr.mass / iso) * (f[i] - nu * normals[i]);
        }
        self.rhs = q;
    }

    /// Adds the coarse water's `M u` to `out`: `a_i (W^T K W s)_i`, `s_i = a_i . u_i`, with
    /// `a_i = p_i n_i` (the implicit solver's product).
    pub fn add_product(&self, normals: &[Vec3], projected: &[f64], u: &[Vec3], out: &mut [Vec3]) {
        let mut sums = Vec::with_capacity(self.patches());
        self.gather(|i| projected[i] * normals[i].dot(&u[i]), &mut sums);
        for (s, k) in sums.iter_mut().zip(&self.carried) {
            *s *= k;
        }
        for (i, o) in out.iter_mut().enumerate() {
            *o += (projected[i] * self.scatter_at(i, &sums)) * normals[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::{patch_normals, Inertia};
    use crate::model::Model;
    use crate::topology::GridSpec;

    /// A crumpled, moving 6 x 5 patch, a model with normal added mass, and a coarse level of
    /// 3 x 2 patches carrying 40 kg/m^2.
    fn setup() -> (Topology, Vec<Vec3>, Vec<Vec3>, Model, CoarseWater) {
        let (t, x, v) = crate::testing::crumpled_grid(6, 5, 5);
        let mut m = Model::fractional();
        m.water.added_mass = 30.0;
        let c = CoarseWater::new(&t, 40.0, 0.25, &[]).expect("room");
        (t, x, v, m, c)
    }

    /// `a_i = p_i n_i` at `x`.
    fn patch_vectors(t: &Topology, x: &[Vec3]) -> Vec<Vec3> {
        let (mut n, mut p) = (vec![Vec3::zeros(); x.len()], vec![0.0; x.len()]);
        patch_normals(x, t, &mut n, &mut p);
        n.iter().zip(&p).map(|(n, p)| *p * n).collect()
    }

    /// The water's kinetic energy, local and coarse, and `M(x) v` of its water part.
    fn energy_and_momentum(
        t: &Topology,
        m: &Model,
        c: &CoarseWater,
        x: &[Vec3],
        v: &[Vec3],
    ) -> (f64, Vec<Vec3>) {
        let a = patch_vectors(t, x);
        let s: Vec<f64> = a.iter().zip(v).map(|(a, v)| a.dot(v)).collect();
        let mut local = 0.0;
        let mut mom = vec![Vec3::zeros(); x.len()];
        for i in 0..x.len() {
            let p = a[i].norm();
            let n = if p > 0.0 { a[i] / p } else { a[i] };
            let inr = Inertia::of(m, 0.0, t.areas[i], n, p);
            local += inr.kinetic_energy(&v[i]);
            mom[i] = inr.apply(&v[i]);
        }
        let mut sums = Vec::new();
        c.gather(|i| s[i], &mut sums);
        for (p, k) in sums.iter_mut().zip(&c.carried) {
            *p *= k;
        }
        for i in 0..x.len() {
            mom[i] += c.scatter_at(i, &sums) * a[i];
        }
        (local + c.kinetic_energy(|i| s[i]), mom)
    }

    #[test]
    fn the_hats_are_a_partition_and_a_rigid_motion_carries_the_coarse_mass() {
        let (t, _, _, _, c) = setup();
        assert_eq!(c.patches(), 9);
        let total: f64 = t.areas.iter().sum();
        // Every vertex's weights times the patch areas give back its area.
        let carried: f64 = c.carried.iter().sum();
        assert!((carried - 40.0 * total).abs() < 1e-12 * carried);
        // A rigid normal motion of 1 m/s on the flat sheet: 1/2 m_c A.
        let e = c.kinetic_energy(|_| 1.0);
        assert!((e - 20.0 * total).abs() < 1e-12 * e, "{e}");
    }

    #[test]
    fn a_ripple_shorter_than_the_patches_carries_little_coarse_water() {
        // A 0.8 x 0.4 m sheet, patches 0.1 m apart, a normal velocity rippled along x with
        // wavelength lambda (a rigid motion carries the whole coarse mass exactly). A hat of half-width L
        // averages a ripple of wavelength L to nothing (its transform vanishes there), so only
        // the border hats keep some; a wavelength of many patches is carried in full.
        let t = GridSpec {
            width: 81,
            height: 41,
            spacing: 0.01,
            total_mass: 0.32,
        }
        .build()
        .expect("a valid grid");
        let c = CoarseWater::new(&t, 40.0, 0.1, &[]).expect("room");
        // Against the energy were the whole coarse mass carried by every vertex's own motion.
        let ripple = |lambda: f64| {
            let x = &t.rest_positions;
            let s = |i: usize| (2.0 * std::f64::consts::PI * x[i].x / lambda).sin();
            let full: f64 = (0..x.len()).map(|i| 0.5 * 40.0 * t.areas[i] * s(i) * s(i)).sum();
            c.kinetic_energy(s) / full
        };
        assert!((c.kinetic_energy(|_| 1.0) / (20.0 * t.areas.iter().sum::<f64>()) - 1.0).abs() < 1e-12);
        let (short, long) = (ripple(0.1), ripple(3.2));
        println!("coarse water a ripple carries, against its whole coarse mass: lambda 0.1 m {short:.4}, 3.2 m {long:.4}");
        assert!(short < 0.05, "{short}");
        assert!(long > 0.9, "{long}");
    }

    #[test]
    fn the_coarse_turning_forces_are_lagranges_terms() {
        let (t, x, v, m, mut c) = setup();
        let (got, _, _) = crate::forces::turning::check::turning_of(&m, &t, &x, &v, Some(&mut c));
        crate::forces::turning::check::lagranges_terms(
            &got,
            &x,
            &v,
            |y| energy_and_momentum(&t, &m, &c, y, &v).0,
            |y, j| energy_and_momentum(&t, &m, &c, y, &v).1[j],
        );
    }

    #[test]
    fn the_effective_force_inverts_the_whole_mass_matrix() {
        let (t, x, _, m, mut c) = setup();
        let n = x.len();
        let a = patch_vectors(&t, &x);
        let mut r = crate::testing::numbers(9);
        let f: Vec<Vec3> = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
        let (mut normals, mut projected) = (vec![Vec3::zeros(); n], vec![0.0; n]);
        for i in 0..n {
            projected[i] = a[i].norm();
            normals[i] = a[i] / projected[i];
        }
        let mut eff = f.clone();
        c.effective_forces(&m, &t, &normals, &projected, &mut eff);
        // M (eff / m) = f, M v = m v + (water part of energy_and_momentum).
        let acc: Vec<Vec3> = eff.iter().zip(&t.masses).map(|(e, m)| e / *m).collect();
        let (_, water) = energy_and_momentum(&t, &m, &c, &x, &acc);
        for i in 0..n {
            let back = t.masses[i] * acc[i] + water[i];
            assert!(
                (back - f[i]).norm() < 1e-9 * (1.0 + f[i].norm()),
                "{i}: {back} against {}",
                f[i]
            );
        }
    }
}
