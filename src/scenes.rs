//! Built-in scenes, shared by the CLI baker, the tests and the benchmarks.
//!
//! Every scene is a towel hanging from its top edge (row 0 pinned) in still water,
//! 0.6 m wide and 0.4 m tall whatever its resolution (31 x 21 and 61 x 41 in the
//! paper), with mass 0.24 kg (1 kg/m^2, a wet cotton towel):
//! - `swing`: the top edge swings back and forth (out of plane, along z):
//!   `z(t) = A sin(2 pi f t)`, A = [`SWING_AMPLITUDE`], f = [`SWING_FREQUENCY`];
//! - `sway`: the top edge is moved energetically sideways (in plane, along x):
//!   `x(t) = A sin(2 pi f t)`, A = [`SWAY_AMPLITUDE`], f = [`SWAY_FREQUENCY`];
//! - `sphere`: a sphere of radius [`SPHERE_RADIUS`] moves through the hanging cloth
//!   along +z at [`SPHERE_SPEED`], starting behind it at z = [`SPHERE_START_Z`].
//!
//! Each comes in a `fractional` variant (the paper's model), `regular` variants (damped
//! springs, no half-derivative) with every other parameter the same, and the `underwater`
//! preset (the water's physics per unit area, [`Model::underwater`]; its swing is 4 cm).
//!
//! Drag coefficients are per particle, so they are given here per unit area and
//! scaled by the area a particle represents; spring constants of a square lattice
//! are independent of the spacing.

use crate::cloth::{Cloth, ClothConfig};
use crate::error::Error;
use crate::forces::Sphere;
use crate::history::Scheme;
use crate::integrate::Integrator;
use crate::model::{Model, RegularDrag};
use crate::topology::{grid_index, GridSpec};
use crate::Vec3;

/// Cloth width, m.
pub const CLOTH_WIDTH: f64 = 0.6;
/// Cloth mass, kg.
pub const CLOTH_MASS: f64 = 0.24;
/// Swing amplitude, m (the paper's models).
pub const SWING_AMPLITUDE: f64 = 0.08;
/// Swing amplitude of the underwater preset, m: a towel swung in a tank by hand.
pub const UNDERWATER_SWING_AMPLITUDE: f64 = 0.04;
/// Swing frequency, Hz.
pub const SWING_FREQUENCY: f64 = 0.5;
/// Sway amplitude, m.
pub const SWAY_AMPLITUDE: f64 = 0.12;
/// Sway frequency, Hz.
pub const SWAY_FREQUENCY: f64 = 1.0;
/// Sphere radius, m.
pub const SPHERE_RADIUS: f64 = 0.08;
/// Sphere speed along +z, m/s.
pub const SPHERE_SPEED: f64 = 0.2;
/// Sphere start, z in m (its centre is at x = 0, y = -0.2 m: the middle of the cloth).
pub const SPHERE_START_Z: f64 = -0.25;

/// Which motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    Swing,
    Sway,
    Sphere,
}

impl SceneKind {
    pub const ALL: [SceneKind; 3] = [SceneKind::Swing, SceneKind::Sway, SceneKind::Sphere];
    pub fn name(&self) -> &'static str {
        match self {
            SceneKind::Swing => "swing",
            SceneKind::Sway => "sway",
            SceneKind::Sphere => "sphere",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
}

/// Which cloth model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The paper's fractional cloth.
    Fractional,
    /// A regular damped-spring cloth with the given drags (Fig. 7).
    Regular(RegularDrag),
    /// The underwater preset: the water's physics per unit area ([`Model::underwater`]).
    Underwater,
}

impl Variant {
    pub const ALL: [Variant; 5] = [
        Variant::Regular(RegularDrag::ViscousAndNormal),
        Variant::Regular(RegularDrag::Viscous),
        Variant::Regular(RegularDrag::Normal),
        Variant::Fractional,
        Variant::Underwater,
    ];
    pub fn name(&self) -> &'static str {
        match self {
            Variant::Fractional => "fractional",
            Variant::Underwater => "underwater",
            Variant::Regular(RegularDrag::ViscousAndNormal) => "regular-viscous-normal",
            Variant::Regular(RegularDrag::Viscous) => "regular-viscous",
            Variant::Regular(RegularDrag::Normal) => "regular",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
    /// The model for a cloth whose particles are `spacing` apart.
    pub fn model(&self, spacing: f64) -> Model {
        match self {
            Variant::Fractional => scale_drags(Model::fractional(), spacing),
            Variant::Regular(d) => scale_drags(Model::regular(*d), spacing),
            // Per unit area already: the same at any spacing.
            Variant::Underwater => Model::underwater(),
        }
    }
}

/// Reference spacing at which [`Model`]'s drag coefficients are stated, m.
pub const REFERENCE_SPACING: f64 = 0.01;

/// Scales per-particle drag coefficients from [`REFERENCE_SPACING`] to `spacing`.
pub fn scale_drags(mut m: Model, spacing: f64) -> Model {
    let area = (spacing / REFERENCE_SPACING).powi(2);
    m.viscous_drag *= area;
    m.history_drag *= area;
    m.normal_drag *= area;
    m
}

/// What to build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSpec {
    pub kind: SceneKind,
    pub variant: Variant,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    pub scheme: Scheme,
    pub integrator: Integrator,
    /// Step, s.
    pub dt: f64,
    /// Multiplies every spring constant (1 = the model's own); for stiffness sweeps.
    pub stiffness_scale: f64,
}

impl SceneSpec {
    /// The paper's configuration of a scene at 61 x 41: Eq. 6 with u = 3, explicit Euler.
    pub fn paper(kind: SceneKind, variant: Variant) -> Self {
        Self {
            kind,
            variant,
            width: 61,
            height: 41,
            scheme: Scheme::PAPER,
            integrator: Integrator::ExplicitEuler,
            dt: DEFAULT_DT,
            stiffness_scale: 1.0,
        }
    }

    /// Grid spacing, m.
    pub fn spacing(&self) -> f64 {
        CLOTH_WIDTH / f64::from(self.width.max(2) - 1)
    }

    pub fn build(&self) -> Result<Scene, Error> {
        let spacing = self.spacing();
        let topology = GridSpec {
            width: self.width,
            height: self.height,
            spacing,
            total_mass: CLOTH_MASS,
        }
        .build()?;
        let mut model = self.variant.model(spacing);
        model.stretch_stiffness *= self.stiffness_scale;
        model.shear_stiffness *= self.stiffness_scale;
        model.bend_stiffness *= self.stiffness_scale;
        let config = ClothConfig {
            model,
            scheme: self.scheme,
            integrator: self.integrator,
            ..ClothConfig::default()
        };
        let mut cloth = Cloth::new(topology, config)?;
        let top: Vec<u32> = (0..self.width).map(|i| grid_index(self.width, i, 0)).collect();
        cloth.set_pinned(&top)?;
        let top_rest = top.iter().map(|&i| cloth.positions()[i as usize]).collect();
        let sphere = match self.kind {
            SceneKind::Sphere => Some(cloth.add_sphere(sphere_at(0.0))?),
            _ => None,
        };
        let targets = Vec::with_capacity(top.len());
        Ok(Scene {
            spec: *self,
            cloth,
            top,
            top_rest,
            targets,
            sphere,
        })
    }
}

/// Step of the built-in scenes at 61 x 41 (1 cm spacing), s.
pub const DEFAULT_DT: f64 = 5.0e-4;

/// A stable step for a built-in scene at `spacing` (m) with `integrator`: [`DEFAULT_DT`] at
/// 1 cm and below, shrinking with the spacing for the explicit integrators (their bound is
/// `~2/omega`, and omega grows as 1/spacing at a fixed cloth mass: `docs/stability.md`), and
/// one frame at 30 fps for the implicit one (stable at any step).
pub fn stable_dt(spacing: f64, integrator: Integrator) -> f64 {
    match integrator {
        i if i.is_implicit() => 1.0 / 30.0,
        _ => DEFAULT_DT * (spacing / REFERENCE_SPACING).min(1.0),
    }
}

/// Offset of the top edge from its rest position at time `t` (s) for a variant.
pub fn top_offset(kind: SceneKind, variant: Variant, t: f64) -> Vec3 {
    use std::f64::consts::TAU;
    let swing = if variant == Variant::Underwater {
        UNDERWATER_SWING_AMPLITUDE
    } else {
        SWING_AMPLITUDE
    };
    match kind {
        SceneKind::Swing => Vec3::new(0.0, 0.0, swing * (TAU * SWING_FREQUENCY * t).sin()),
        SceneKind::Sway => Vec3::new(SWAY_AMPLITUDE * (TAU * SWAY_FREQUENCY * t).sin(), 0.0, 0.0),
        SceneKind::Sphere => Vec3::zeros(),
    }
}

/// The sphere of the `sphere` scene at time `t` (s).
pub fn sphere_at(t: f64) -> Sphere {
    Sphere {
        center: Vec3::new(0.0, -0.2, SPHERE_START_Z + SPHERE_SPEED * t),
        radius: SPHERE_RADIUS,
        velocity: Vec3::new(0.0, 0.0, SPHERE_SPEED),
    }
}

/// A built scene: the cloth plus what drives it.
#[derive(Clone, Debug)]
pub struct Scene {
    pub spec: SceneSpec,
    pub cloth: Cloth,
    top: Vec<u32>,
    top_rest: Vec<Vec3>,
    targets: Vec<Vec3>,
    sphere: Option<u32>,
}

impl Scene {
    /// Moves the pins (and the sphere) to where they are at the end of the next step,
    /// then steps the cloth by the scene's dt.
    pub fn step(&mut self) -> Result<(), Error> {
        let dt = self.spec.dt;
        let t_end = self.cloth.time() + dt;
        let off = top_offset(self.spec.kind, self.spec.variant, t_end);
        self.targets.clear();
        self.targets.extend(self.top_rest.iter().map(|p| p + off));
        self.cloth.set_pin_targets(&self.top, &self.targets)?;
        if let Some(id) = self.sphere {
            // The sphere's position over the step: where it is at the start.
            self.cloth.set_sphere(id, sphere_at(self.cloth.time()))?;
        }
        self.cloth.step(dt)
    }

    /// Steps until simulated time reaches `t` (s).
    pub fn run_until(&mut self, t: f64) -> Result<(), Error> {
        while self.cloth.time() + 0.5 * self.spec.dt < t {
            self.step()?;
        }
        Ok(())
    }

    /// Pinned top-row vertex indices.
    pub fn top_row(&self) -> &[u32] {
        &self.top
    }
}
