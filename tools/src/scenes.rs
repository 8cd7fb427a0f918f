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
//!   along +z at [`SPHERE_SPEED`], starting behind it at z = [`SPHERE_START_Z`];
//! - `current`: the towel pinned at its top edge, still, in a current ([`CURRENT_SPEED`]
//!   along its plane by default);
//! - `kelp`: a buoyant strip [`KELP_WIDTH`] x [`KELP_LENGTH`] pinned at its foot, in still
//!   water (density [`KELP_DENSITY`]: it stands up);
//! - `curtain`: a 1 x 1.5 m curtain ([`CURTAIN_EXTENT`]), the same cloth as the towel, swung
//!   at its top edge like it.
//!
//! Every scene's drive ([`Drive`]: amplitude, frequency, a fade-in and the current) can be
//! changed ([`SceneSpec::drive`]); the pinned edge moves along the scene's axis (z, out of
//! plane, for all but `sway`).
//!
//! Each comes in a `fractional` variant (the paper's model), `regular` variants (damped
//! springs, no half-derivative) with every other parameter the same, and the `underwater`
//! preset (the water's physics per unit area, [`Model::underwater`]; its swing is 4 cm).
//!
//! Drag coefficients are per particle, so they are given here per unit area and
//! scaled by the area a particle represents; spring constants of a square lattice
//! are independent of the spacing.

use fraccloth::cloth::{Cloth, ClothConfig};
use fraccloth::error::Error;
use fraccloth::forces::Sphere;
use fraccloth::history::Scheme;
use fraccloth::integrate::Integrator;
use fraccloth::math::Vec3;
use fraccloth::model::{Model, RegularDrag};
use fraccloth::topology::{grid_index, GridSpec};

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

/// Width and height of the `curtain`, m.
pub const CURTAIN_EXTENT: (f64, f64) = (1.0, 1.5);

/// Speed of the `current` scene's water by default, m/s (along the towel's plane, +x).
pub const CURRENT_SPEED: f64 = 0.3;
/// Width of the `kelp` strip, m.
pub const KELP_WIDTH: f64 = 0.1;
/// Length of the `kelp` strip, m.
pub const KELP_LENGTH: f64 = 1.0;
/// Density of the `kelp` strip, kg/m^3 (below the water's: it floats up).
pub const KELP_DENSITY: f64 = 900.0;

/// Which motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    Swing,
    Sway,
    Sphere,
    /// The towel, still, in a current.
    Current,
    /// A buoyant strip pinned at its foot.
    Kelp,
    /// A 1 x 1.5 m curtain swung at its top edge like the towel.
    Curtain,
}

impl SceneKind {
    pub const ALL: [SceneKind; 6] = [
        SceneKind::Swing,
        SceneKind::Sway,
        SceneKind::Sphere,
        SceneKind::Current,
        SceneKind::Kelp,
        SceneKind::Curtain,
    ];
    pub fn name(&self) -> &'static str {
        match self {
            SceneKind::Swing => "swing",
            SceneKind::Sway => "sway",
            SceneKind::Sphere => "sphere",
            SceneKind::Current => "current",
            SceneKind::Kelp => "kelp",
            SceneKind::Curtain => "curtain",
        }
    }
    /// The cloth's width and height, m.
    pub fn extent(&self) -> (f64, f64) {
        match self {
            SceneKind::Kelp => (KELP_WIDTH, KELP_LENGTH),
            SceneKind::Curtain => CURTAIN_EXTENT,
            _ => (CLOTH_WIDTH, CLOTH_WIDTH * 2.0 / 3.0),
        }
    }
    /// Columns and rows: 1 cm spacing (the paper's 61 x 41 for the towel), 2 cm for the
    /// curtain.
    pub fn default_size(&self) -> (u32, u32) {
        match self {
            SceneKind::Kelp => (11, 101),
            SceneKind::Curtain => (51, 76),
            _ => (61, 41),
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

/// How a scene is driven: its pinned edge moves `amplitude sin(2 pi frequency t)` along the
/// scene's axis, faded in over `ramp` seconds (`(1 - cos(pi t / ramp)) / 2`), in water
/// flowing at `current`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// m.
    pub amplitude: f64,
    /// Hz.
    pub frequency: f64,
    /// s; 0 starts at once (the paper's swing).
    pub ramp: f64,
    /// m/s.
    pub current: Vec3,
}

impl Drive {
    /// The drive of a built-in scene with a variant (the paper's swing is 8 cm, the underwater
    /// preset's 4 cm, both at 0.5 Hz).
    pub fn of(kind: SceneKind, variant: Variant) -> Drive {
        let still = Drive {
            amplitude: 0.0,
            frequency: SWING_FREQUENCY,
            ramp: 0.0,
            current: Vec3::zeros(),
        };
        match kind {
            SceneKind::Swing | SceneKind::Curtain => Drive {
                amplitude: if variant == Variant::Underwater {
                    UNDERWATER_SWING_AMPLITUDE
                } else {
                    SWING_AMPLITUDE
                },
                ..still
            },
            SceneKind::Sway => Drive {
                amplitude: SWAY_AMPLITUDE,
                frequency: SWAY_FREQUENCY,
                ..still
            },
            SceneKind::Sphere | SceneKind::Kelp => still,
            SceneKind::Current => Drive {
                current: Vec3::new(CURRENT_SPEED, 0.0, 0.0),
                ..still
            },
        }
    }

    /// Offset of the pinned edge from its rest position at time `t` (s) in a scene of `kind`.
    pub fn offset(&self, kind: SceneKind, t: f64) -> Vec3 {
        use std::f64::consts::{PI, TAU};
        if self.amplitude == 0.0 {
            return Vec3::zeros();
        }
        let fade = if t < self.ramp {
            0.5 * (1.0 - (PI * t / self.ramp).cos())
        } else {
            1.0
        };
        let s = fade * self.amplitude * (TAU * self.frequency * t).sin();
        match kind {
            SceneKind::Sway => Vec3::new(s, 0.0, 0.0),
            _ => Vec3::new(0.0, 0.0, s),
        }
    }
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
    /// How the pinned edge moves and the water flows.
    pub drive: Drive,
    /// The cloth's model instead of the variant's (its current is the drive's); None: the
    /// variant's.
    pub model: Option<Model>,
    /// The cloth's `max_substep`: 0 steps `dt` at once (the paper's scenes), negative
    /// ([`fraccloth::cloth::AUTO`]) lets the cloth split each `dt` as it needs.
    pub max_substep: f64,
    /// Build the cloth as an irregular triangle mesh ([`jittered_mesh`]) instead of the grid:
    /// the same vertices in the same order, moved and triangulated at random.
    pub jittered: bool,
    /// Self-collision thickness in the cloth's spacings (`Model::self_collision_relative`)
    /// added to the model's; 0 adds none.
    pub self_collision: f64,
}

/// A grid's vertices (same order, edges kept straight) moved by up to 15 % of the spacing in
/// its plane and triangulated with random diagonals, as a DCC's irregular mesh; masses and
/// areas lumped from the faces at `areal_density` (kg/m^2). The same `seed` gives the same mesh.
pub fn jittered_mesh(
    grid: &fraccloth::Topology,
    width: u32,
    areal_density: f64,
    seed: u64,
) -> Result<fraccloth::Topology, Error> {
    let (w, h) = (width, (grid.vertex_count() as u32) / width.max(1));
    let spacing = grid
        .rest_positions
        .get(1)
        .zip(grid.rest_positions.first())
        .map_or(0.0, |(a, b)| (a - b).norm());
    let mut seed = seed;
    let mut r = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let positions: Vec<Vec3> = grid
        .rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (col, row) = (i as u32 % w, i as u32 / w);
            let inner = col > 0 && col + 1 < w && row > 0 && row + 1 < h;
            if inner {
                p + Vec3::new(0.3 * spacing * r(), 0.3 * spacing * r(), 0.0)
            } else {
                *p
            }
        })
        .collect();
    let mut indices = Vec::with_capacity(6 * (w as usize) * (h as usize));
    for j in 0..h.saturating_sub(1) {
        for i in 0..w.saturating_sub(1) {
            let (a, b, c, d) = (j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i);
            if r() < 0.0 {
                indices.extend([a, d, b, b, d, c]);
            } else {
                indices.extend([a, d, c, a, c, b]);
            }
        }
    }
    fraccloth::topology::MeshSpec {
        positions: &positions,
        indices: &indices,
        face_size: 3,
        mass: fraccloth::topology::MeshMass::ArealDensity(areal_density),
    }
    .build()
}

impl SceneSpec {
    /// The paper's configuration of a scene at 61 x 41 (the kelp at 11 x 101): Eq. 6 with
    /// u = 3, explicit Euler.
    pub fn paper(kind: SceneKind, variant: Variant) -> Self {
        let (width, height) = kind.default_size();
        Self {
            kind,
            variant,
            width,
            height,
            scheme: Scheme::PAPER,
            integrator: Integrator::ExplicitEuler,
            dt: DEFAULT_DT,
            stiffness_scale: 1.0,
            drive: Drive::of(kind, variant),
            model: None,
            max_substep: 0.0,
            jittered: false,
            self_collision: 0.0,
        }
    }

    /// The underwater towel at `width` x `height` swung `amplitude` m at `frequency` Hz with
    /// `model` (the underwater preset, changed: self-collision, say), symplectic Euler at the
    /// automatic step, one call a 30 fps frame: the collision harnesses' and tests' scene.
    pub fn underwater_swing(width: u32, height: u32, frequency: f64, amplitude: f64, model: Model) -> Self {
        Self {
            width,
            height,
            drive: Drive {
                amplitude,
                frequency,
                ..Drive::of(SceneKind::Swing, Variant::Underwater)
            },
            dt: 1.0 / 30.0,
            max_substep: fraccloth::cloth::AUTO,
            integrator: Integrator::SymplecticEuler,
            model: Some(model),
            ..Self::paper(SceneKind::Swing, Variant::Underwater)
        }
    }

    /// Grid spacing, m.
    pub fn spacing(&self) -> f64 {
        self.kind.extent().0 / f64::from(self.width.max(2) - 1)
    }

    pub fn build(&self) -> Result<Scene, Error> {
        let spacing = self.spacing();
        // 1 kg/m^2 (the towel's 0.24 kg over 0.6 x 0.4 m) at any size.
        let areal_density = CLOTH_MASS / (CLOTH_WIDTH * CLOTH_WIDTH * 2.0 / 3.0);
        let (cols, rows) = (
            f64::from(self.width.max(2) - 1),
            f64::from(self.height.max(2) - 1),
        );
        let topology = GridSpec {
            width: self.width,
            height: self.height,
            spacing,
            total_mass: match self.kind {
                SceneKind::Kelp | SceneKind::Curtain => areal_density * cols * rows * spacing * spacing,
                _ => CLOTH_MASS,
            },
        }
        .build()?;
        let topology = if self.jittered {
            jittered_mesh(&topology, self.width, areal_density, 12345)?
        } else {
            topology
        };
        // The pinned edge: the top row, or the foot of the kelp.
        let row = if self.kind == SceneKind::Kelp {
            self.height - 1
        } else {
            0
        };
        let top: Vec<u32> = (0..self.width).map(|i| grid_index(self.width, i, row)).collect();
        self.build_on(topology, &top, spacing)
    }

    /// The scene on any topology (a host's own mesh), pinned at `pins` (vertex indices), with
    /// the model of the variant at the mesh's `spacing` (m; its drag coefficients are given
    /// per 1 cm spacing, `scale_drags`) unless the spec has its own. The drive moves the pins.
    pub fn build_on(
        &self,
        topology: fraccloth::Topology,
        pins: &[u32],
        spacing: f64,
    ) -> Result<Scene, Error> {
        let mut model = self.variant.model(spacing);
        if self.kind == SceneKind::Kelp {
            model.cloth_density = KELP_DENSITY;
        }
        if let Some(own) = self.model {
            model = own;
        }
        model.current = self.drive.current;
        model.self_collision_relative += self.self_collision;
        model.stretch_stiffness *= self.stiffness_scale;
        model.shear_stiffness *= self.stiffness_scale;
        model.bend_stiffness *= self.stiffness_scale;
        let config = ClothConfig {
            model,
            scheme: self.scheme,
            integrator: self.integrator,
            max_substep: self.max_substep,
            ..ClothConfig::default()
        };
        let mut cloth = Cloth::new(topology, config)?;
        let top = pins.to_vec();
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

/// Offset of the top edge from its rest position at time `t` (s) for a variant, with the
/// scene's own drive ([`Drive::of`]).
pub fn top_offset(kind: SceneKind, variant: Variant, t: f64) -> Vec3 {
    Drive::of(kind, variant).offset(kind, t)
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
        let off = self.spec.drive.offset(self.spec.kind, t_end);
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

    /// Pinned vertex indices (the top row; the foot of the kelp).
    pub fn top_row(&self) -> &[u32] {
        &self.top
    }
}

/// How [`collision_towel`] places its towel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TowelPose {
    /// Flat in the x-z plane at the height given, centred over the origin.
    Flat,
    /// Hanging in the x-y plane from the height given, centred in x.
    Hanging,
    /// Hanging, with a 2 cm wave across it (period 31 cm down the towel) so that it folds
    /// when it lands: the drop of `tests/collisions.rs` and `docs/collisions.md`.
    Wavy,
}

/// The towel of the collision scenes (`tests/collisions.rs`, `examples/collision_pictures.rs`,
/// `examples/collision_cost.rs`): `w x h` vertices `spacing` apart at 1 kg/m^2 (the C preset's),
/// the underwater preset's model with self-collision `thickness` (friction 0.3), the automatic
/// step, placed by `pose` at height `y`.
pub fn collision_towel(
    w: u32,
    h: u32,
    spacing: f64,
    y: f64,
    pose: TowelPose,
    thickness: f64,
    integrator: Integrator,
) -> Result<Cloth, Error> {
    let model = Model {
        self_collision_thickness: thickness,
        self_collision_friction: 0.3,
        ..Model::underwater()
    };
    collision_towel_with(w, h, spacing, y, pose, model, integrator)
}

/// [`collision_towel`] with a model of the caller's.
pub fn collision_towel_with(
    w: u32,
    h: u32,
    spacing: f64,
    y: f64,
    pose: TowelPose,
    model: Model,
    integrator: Integrator,
) -> Result<Cloth, Error> {
    let area = spacing * spacing * f64::from((w.max(2) - 1) * (h.max(2) - 1));
    let grid = GridSpec {
        width: w,
        height: h,
        spacing,
        total_mass: area,
    }
    .build()?;
    let config = ClothConfig {
        model,
        scheme: Scheme::DEFAULT,
        integrator,
        max_substep: fraccloth::cloth::AUTO,
        ..ClothConfig::default()
    };
    let mut cloth = Cloth::new(grid, config)?;
    let (cx, cy) = (
        0.5 * spacing * f64::from(w - 1),
        -0.5 * spacing * f64::from(h - 1),
    );
    let placed: Vec<Vec3> = cloth
        .topology()
        .rest_positions
        .iter()
        .map(|p| match pose {
            TowelPose::Flat => Vec3::new(p.x - cx, y, p.y - cy),
            TowelPose::Hanging => Vec3::new(p.x - cx, y + p.y, p.z),
            TowelPose::Wavy => {
                let (hx, hy) = (p.x - cx, y + p.y);
                Vec3::new(hx, hy, p.z + 0.02 * (20.0 * (y - hy)).sin())
            }
        })
        .collect();
    cloth.set_positions(&placed)?;
    Ok(cloth)
}
