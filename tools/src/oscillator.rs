//! The fractional oscillator `m x'' + c D^{1/2}x + k x = F` as a cloth, and its dominant pole.
//!
//! A 2 x 2 grid: vertices 0, 1, 2 pinned; vertex 3 hangs on the shear spring from vertex 0
//! (stretch and bend constants zero), gravity along that spring, no water. The
//! half-derivative force is the history drag of Eq. 4, which for motion along one line is
//! `-c D^{1/2}x`. Used by tests, the stability map and the benchmarks.

use nalgebra::Complex;

use fraccloth::cloth::{Cloth, ClothConfig};
use fraccloth::error::Error;
use fraccloth::history::Scheme;
use fraccloth::integrate::Integrator;
use fraccloth::math::Vec3;
use fraccloth::model::{Model, SpringDamping};
use fraccloth::topology::GridSpec;

/// Parameters of `m x'' + c D^{1/2}x + k x = F`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oscillator {
    pub m: f64,
    pub c: f64,
    pub k: f64,
    pub f: f64,
}

impl Default for Oscillator {
    /// m = 1, c = 0.8, k = 25, F = 1.
    fn default() -> Self {
        Self {
            m: 1.0,
            c: 0.8,
            k: 25.0,
            f: 1.0,
        }
    }
}

/// Unit direction of the oscillator's spring (and of gravity).
pub fn axis() -> Vec3 {
    Vec3::new(1.0, -1.0, 0.0) / 2f64.sqrt()
}

impl Oscillator {
    /// The cloth, at rest, with vertices 0, 1, 2 pinned.
    pub fn cloth(&self, scheme: Scheme, integrator: Integrator) -> Result<Cloth, Error> {
        let topology = GridSpec {
            width: 2,
            height: 2,
            spacing: 0.5,
            total_mass: 4.0 * self.m,
        }
        .build()?;
        let model = Model {
            water_density: 0.0,
            gravity: axis() * (self.f / self.m),
            stretch_stiffness: 0.0,
            bend_stiffness: 0.0,
            shear_stiffness: self.k,
            spring_damping: 0.0,
            spring_damping_mode: SpringDamping::None,
            viscous_drag: 0.0,
            history_drag: self.c,
            normal_drag: 0.0,
            ..Model::fractional()
        };
        let mut cloth = Cloth::new(
            topology,
            ClothConfig {
                model,
                scheme,
                integrator,
                ..ClothConfig::default()
            },
        )?;
        cloth.set_pinned(&[0, 1, 2])?;
        Ok(cloth)
    }

    /// Elongation of the spring (m) in a cloth made by [`Oscillator::cloth`].
    pub fn elongation(cloth: &Cloth) -> f64 {
        (cloth.positions()[3] - cloth.topology().rest_positions[3]).dot(&axis())
    }

    /// The root of `m s^2 + c s^{1/2} + k = 0` (principal branch) in the upper half plane.
    pub fn dominant_pole(&self) -> Complex<f64> {
        let mut s = Complex::new(0.0, (self.k / self.m).sqrt());
        for _ in 0..100 {
            let r = s.sqrt();
            let f = s * s * self.m + r * self.c + self.k;
            let df = s * (2.0 * self.m) + self.c / (r * 2.0);
            let step = f / df;
            s -= step;
            if step.norm() < 1e-15 * s.norm() {
                break;
            }
        }
        s
    }

    /// Forward Euler stability bound with full memory, `2 |Re p| / |p|^2` (s).
    pub fn explicit_euler_bound(&self) -> f64 {
        let p = self.dominant_pole();
        2.0 * p.re.abs() / p.norm_sqr()
    }

    /// Symplectic Euler bound of the undamped oscillator, `2 / omega` (s).
    pub fn symplectic_bound(&self) -> f64 {
        2.0 / (self.k / self.m).sqrt()
    }
}
