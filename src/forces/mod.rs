//! Forces on the particles, one file per family (paper, section 4.1).
//!
//! [`accumulate`] sums every enabled term into a force buffer. A term whose
//! coefficient is zero is skipped entirely, so a scene pays only for what it uses.

mod assemble;
mod body;
mod contact;
mod drag;
mod inputs;
mod jacobian;
mod normals;
mod springs;
mod tiles;

pub use assemble::add_spring_values;
pub use body::{body_acceleration, body_force};
pub use contact::{apply_friction, friction_active, Capsule, Collider, Plane, Sphere};
pub use jacobian::{linearise, Linearisation, SpringBlock};
pub use normals::vertex_normals;
pub use springs::{spring_rate, SpringRate};

use crate::model::Model;
use crate::parallel;
use crate::soa::Soa3;
use crate::topology::Topology;
use crate::Vec3;
use assemble::TILE;
use inputs::{InputWindow, Sources};

/// Everything the forces read at one instant.
pub struct ForceInput<'a> {
    pub model: &'a Model,
    pub topology: &'a Topology,
    /// Positions, m.
    pub x: &'a [Vec3],
    /// Velocities, m/s.
    pub v: &'a [Vec3],
    /// D^{1/2}x of every particle (of the displacement relative to the water), m s^{-1/2};
    /// ignored when the model uses no fractional term.
    pub half_derivative: &'a [Vec3],
    /// Colliders present this step.
    pub colliders: &'a [Collider],
}

/// Scratch buffers the force evaluation reuses (no allocation in a step).
#[derive(Clone, Debug, Default)]
pub struct ForceScratch {
    normals: Vec<Vec3>,
    faces: Vec<Vec3>,
    springs: Soa3,
    spring_inputs: springs::SpringScratch,
    windows: crate::aligned::AlignedF64,
}

impl ForceScratch {
    /// The component arrays the spring pass reads, positions and damping rate (see
    /// [`spring_rate`]), sized for `n` particles: for a caller that fills them in a pass of
    /// its own and then calls [`accumulate_filled`]. Needed only when [`tiled`] is false.
    pub fn spring_arrays(&mut self, n: usize) -> (&mut Soa3, &mut Soa3) {
        let s = &mut self.spring_inputs;
        s.x.resize(n);
        s.q.resize(n);
        (&mut s.x, &mut s.q)
    }

    /// Vertex normals of the last evaluation (empty when no term needed them).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
}

/// Whether the spring pass of `t` walks tiles ([`tiles`]), reading its positions and rates
/// from windows of its own: then it never reads [`ForceScratch::spring_arrays`].
pub fn tiled(t: &Topology) -> bool {
    tiles::Layout::of(t).is_some()
}

/// Writes the total force on every particle into `f` (N).
///
/// Per particle: its springs (in the order of [`assemble::add_spring_forces`]), then net
/// weight, drags and contacts are added to that sum. Springs and face normals are evaluated
/// once each into scratch buffers, then every particle gathers, tile by tile; chunks of
/// particles run on rayon's pool when the cloth is large ([`parallel::worth_it`]) and the
/// result does not depend on the thread count.
pub fn accumulate(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    accumulate_with(input, scratch, f, false)
}

/// As [`accumulate`], with the spring pass's component arrays already filled by the caller
/// ([`ForceScratch::spring_arrays`]: positions `input.x`, and the damping rate `input.v` or
/// `input.half_derivative` as [`spring_rate`] says).
pub fn accumulate_filled(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    accumulate_with(input, scratch, f, true)
}

fn accumulate_with(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3], filled: bool) {
    let out = parallel::Disjoint::new(f);
    for_each_tile(input, scratch, filled, |p0, forces| {
        // SAFETY: tiles are disjoint, each is handed to this closure once.
        unsafe { out.range(p0..p0 + forces.len()) }.copy_from_slice(forces);
    });
}

/// Evaluates the total force on every particle, tile by tile, and calls `sink(p0, forces)`
/// once per tile with the forces (N) on particles `p0 .. p0 + forces.len()` (at most 256 of
/// them, all in one [`parallel::CHUNK`]) while they are still in L1 cache: a
/// caller can use them there (an explicit integrator does) instead of reading a force array
/// back from memory. The spring pass's component arrays must be filled, as for
/// [`accumulate_filled`]. Tiles of different chunks may be handed over on different threads,
/// in any order; the forces do not depend on the thread count.
pub fn accumulate_tiles<S>(input: &ForceInput<'_>, scratch: &mut ForceScratch, sink: S)
where
    S: Fn(usize, &mut [Vec3]) + Sync,
{
    for_each_tile(input, scratch, true, sink)
}

fn for_each_tile<S>(input: &ForceInput<'_>, scratch: &mut ForceScratch, filled: bool, sink: S)
where
    S: Fn(usize, &mut [Vec3]) + Sync,
{
    let m = input.model;
    let t = input.topology;
    let normals = update_normals(input, scratch).then_some(&scratch.normals[..]);
    let gravity = body_acceleration(m);
    let half = (!input.half_derivative.is_empty()).then_some(input.half_derivative);
    // Everything but the springs, added to the springs' sums `s` of the tile starting at p0;
    // then the tile goes to the sink.
    let finish = |p0: usize, s: [&mut [f64]; 3], _: Option<&InputWindow<'_>>, buf: &mut [Vec3; TILE]| {
        let len = s[0].len();
        let out = &mut buf[..len];
        body::add_weight_to_springs_widest(s.map(|c| &*c), &t.masses[p0..p0 + len], gravity, out);
        let range = p0..p0 + len;
        drag::add_tile(
            m,
            &input.v[range.clone()],
            half.map(|h| &h[range.clone()]),
            normals.map(|nr| &nr[range.clone()]),
            out,
        );
        if !input.colliders.is_empty() {
            for (k, fi) in out.iter_mut().enumerate() {
                let p = p0 + k;
                contact::add(m, input.colliders, &input.x[p], &input.v[p], fi);
            }
        }
        sink(p0, out);
    };
    walk(
        input,
        &mut scratch.spring_inputs,
        &mut scratch.springs,
        &mut scratch.windows,
        filled,
        false,
        finish,
    );
}

/// Computes the vertex normals into `scratch` when the normal drag needs them; says whether.
fn update_normals(input: &ForceInput<'_>, scratch: &mut ForceScratch) -> bool {
    let (t, n) = (input.topology, input.x.len());
    if input.model.normal_drag == 0.0 {
        return false;
    }
    scratch.normals.resize(n, Vec3::zeros());
    scratch.faces.resize(t.triangles.len(), Vec3::zeros());
    normals::vertex_normals_with(
        input.x,
        &t.triangles,
        &t.vertex_triangles,
        parallel::worth_it(n),
        &mut scratch.faces,
        &mut scratch.normals,
    );
    true
}

/// Whether [`accumulate_tiles_soa`] can evaluate `input`: a tiled topology ([`tiled`]).
pub fn soa_applies(input: &ForceInput<'_>) -> bool {
    tiled(input.topology)
}

/// A tile's total forces and state as component arrays, each `[x, y, z]` of one length: what
/// [`accumulate_tiles_soa`] hands its sink.
pub struct TileSoa<'a> {
    /// The tile's first particle.
    pub p0: usize,
    /// Total force (N).
    pub force: [&'a [f64]; 3],
    /// Positions (m) and velocities (m/s) of [`ForceInput`].
    pub x: [&'a [f64]; 3],
    pub v: [&'a [f64]; 3],
}

/// [`accumulate_tiles`] for inputs where [`soa_applies`], handing each tile's forces, positions
/// and velocities to `sink` as component arrays (the same forces, bit for bit): the tile walk
/// has them so in cache, and an integrator is several times faster on them than on `Vec3`s.
/// Panics when [`soa_applies`] is false.
pub fn accumulate_tiles_soa<S>(input: &ForceInput<'_>, scratch: &mut ForceScratch, sink: S)
where
    S: Fn(TileSoa<'_>) + Sync,
{
    assert!(soa_applies(input), "accumulate_tiles_soa: an untiled topology");
    let normals = update_normals(input, scratch).then_some(&scratch.normals[..]);
    let m = input.model;
    let gravity = body_acceleration(m);
    let masses = &input.topology.masses;
    let finish = |p0: usize, s: [&mut [f64]; 3], w: Option<&InputWindow<'_>>, _: &mut [Vec3; TILE]| {
        let len = s[0].len();
        let Some(tile) = w.map(|w| w.tile(p0, p0 + len)) else {
            unreachable!("a tiled topology walks with a window");
        };
        let Some(v) = tile.v else {
            unreachable!("the window keeps velocities for this walk");
        };
        let [fx, fy, fz] = s;
        body::add_weight_widest([&mut *fx, &mut *fy, &mut *fz], &masses[p0..p0 + len], gravity);
        drag::add_tile_soa(m, v, tile.half, [&mut *fx, &mut *fy, &mut *fz]);
        let at = |a: [&[f64]; 3], k: usize| Vec3::new(a[0][k], a[1][k], a[2][k]);
        if let Some(normals) = normals {
            // As `Vec3`s, as in `drag::add_tile`: the same numbers.
            let (nr, k_n, c) = (&normals[p0..p0 + len], m.normal_drag, m.current);
            for k in 0..len {
                let f = Vec3::new(fx[k], fy[k], fz[k]) - k_n * (at(v, k) - c).dot(&nr[k]) * nr[k];
                (fx[k], fy[k], fz[k]) = (f.x, f.y, f.z);
            }
        }
        if !input.colliders.is_empty() {
            // Particle by particle, as `Vec3`s: the same numbers as `for_each_tile`'s contacts.
            for k in 0..len {
                let mut f = Vec3::new(fx[k], fy[k], fz[k]);
                contact::add(m, input.colliders, &at(tile.x, k), &at(v, k), &mut f);
                (fx[k], fy[k], fz[k]) = (f.x, f.y, f.z);
            }
        }
        sink(TileSoa {
            p0,
            force: [fx, fy, fz],
            x: tile.x,
            v,
        });
    };
    walk(
        input,
        &mut scratch.spring_inputs,
        &mut scratch.springs,
        &mut scratch.windows,
        true,
        true,
        finish,
    );
}

/// Walks the particles tile by tile: sums each tile's spring forces and calls
/// `finish(p0, sums, window, buf)` with them (component arrays, which the finisher may add to),
/// the tile walk's window of inputs when the topology is [`tiled`] (None otherwise), and a
/// buffer of a tile. With `soa`, the window also keeps velocities and (when the history drag
/// reads them) half-derivatives.
#[allow(clippy::too_many_arguments)]
fn walk<T>(
    input: &ForceInput<'_>,
    spring_inputs: &mut springs::SpringScratch,
    spring_buffer: &mut Soa3,
    windows: &mut crate::aligned::AlignedF64,
    filled: bool,
    soa: bool,
    finish: T,
) where
    T: Fn(usize, [&mut [f64]; 3], Option<&InputWindow<'_>>, &mut [Vec3; TILE]) + Sync,
{
    let m = input.model;
    let t = input.topology;
    let n = input.x.len();
    let par = parallel::worth_it(n);
    let layout = tiles::Layout::of(t);
    let params = springs::params(input, par, spring_inputs, !filled && layout.is_none());
    if let Some(layout) = layout {
        // What the window keeps: positions, the springs' damping rate, and for `soa` the
        // velocities and the half-derivatives the history drag reads.
        let half = (!input.half_derivative.is_empty()).then_some(input.half_derivative);
        let rate = spring_rate(m);
        assert!(
            rate != SpringRate::HalfDerivative || half.is_some(),
            "fractional spring damping needs the half-derivatives (ForceInput::half_derivative)"
        );
        let sources = Sources {
            x: input.x,
            v: (soa || rate == SpringRate::Velocity).then_some(input.v),
            half: if (soa && m.history_drag != 0.0) || rate == SpringRate::HalfDerivative {
                half
            } else {
                None
            },
            rate,
        };
        // One window per task; task k walks groups k, k + tasks, ... (which task walks a group
        // does not change its sums).
        let groups = n.div_ceil(layout.group);
        let tasks = if par {
            groups.min(2 * rayon::current_num_threads())
        } else {
            1
        };
        let w = layout.scratch();
        windows.resize(w * tasks);
        parallel::chunks(par, &mut windows[..w * tasks], w, |first, window| {
            let mut buf = [Vec3::zeros(); TILE];
            let (sums, inputs) = window.split_at_mut(layout.sums_scratch());
            for g in (first / w..groups).step_by(tasks) {
                let c0 = g * layout.group;
                let len = layout.group.min(n - c0);
                let finish = |p0: usize, sums: [&mut [f64]; 3], w: &InputWindow<'_>| {
                    finish(p0, sums, Some(w), &mut buf)
                };
                let start = c0.saturating_sub(t.tile_runs.max_offset);
                let mut inputs = InputWindow::new(sources, inputs, start);
                if layout.gather_runs > 0 {
                    tiles::spring_forces_gathered(&params, t, &layout, c0, len, sums, &mut inputs, finish);
                } else {
                    tiles::spring_forces(&params, t, c0, len, sums, &mut inputs, finish);
                }
            }
        });
    } else {
        springs::compute(&params, &t.spring_runs, par, spring_buffer);
        let spring_force = spring_buffer.slices();
        parallel::for_chunks(par, n, parallel::CHUNK, |first, len| {
            let mut acc = [[0.0; TILE]; 3];
            let mut buf = [Vec3::zeros(); TILE];
            for p0 in (first..first + len).step_by(TILE) {
                let m = TILE.min(first + len - p0);
                assemble::add_spring_forces(t, p0, m, spring_force, &mut acc);
                let [ax, ay, az] = &mut acc;
                finish(p0, [&mut ax[..m], &mut ay[..m], &mut az[..m]], None, &mut buf);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::SpringDamping;
    use crate::testing::numbers;
    use crate::topology::GridSpec;

    #[test]
    fn component_array_tiles_carry_the_same_forces_and_state_bit_for_bit() {
        // 101 x 101: three chunks; 700 x 20: offsets past a tile, so the windows slide.
        for (w, h) in [(101, 101), (700, 20)] {
            let t = GridSpec {
                width: w,
                height: h,
                spacing: 0.01,
                total_mass: 1.0,
            }
            .build()
            .unwrap();
            let n = t.vertex_count();
            let mut rnd = numbers(99);
            let x: Vec<Vec3> = t
                .rest_positions
                .iter()
                .map(|p| p + 0.002 * Vec3::new(rnd(), rnd(), rnd()))
                .collect();
            let mut v: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
            // A particle at rest relative to the water: no history drag direction.
            let mut m = Model::fractional();
            m.current = Vec3::new(0.0, 0.0, 0.2);
            v[7] = m.current;
            let half: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
            let damping = [
                SpringDamping::Fractional,
                SpringDamping::Velocity,
                SpringDamping::None,
            ];
            // A sphere pushing on the particles around the middle one (inside the margin).
            let sphere = [Collider::Sphere(Sphere {
                center: x[n / 2] + Vec3::new(0.0, 0.0, 0.004),
                radius: 0.02,
                velocity: Vec3::new(0.1, 0.0, 0.0),
            })];
            // Spring damping, viscous, history and normal drag, and whether the sphere is there.
            let cases = [
                (0, 1e-3, 2e-3, 0.0, false),
                (1, 0.0, 2e-3, 0.0, true),
                (2, 1e-3, 0.0, 0.0, false),
                (0, 0.0, 0.0, 0.0, true),
                (1, 1e-3, 0.0, 5e-3, false),
                (0, 0.0, 2e-3, 5e-3, true),
            ];
            for (mode, viscous, history, normal, with_sphere) in cases {
                m.spring_damping_mode = damping[mode];
                (m.viscous_drag, m.history_drag, m.normal_drag) = (viscous, history, normal);
                let colliders: &[Collider] = if with_sphere { &sphere } else { &[] };
                let input = ForceInput {
                    model: &m,
                    topology: &t,
                    x: &x,
                    v: &v,
                    half_derivative: &half,
                    colliders,
                };
                assert!(soa_applies(&input));
                let mut expected = vec![Vec3::zeros(); n];
                accumulate(&input, &mut ForceScratch::default(), &mut expected);
                let got = std::sync::Mutex::new(vec![None; n]);
                accumulate_tiles_soa(&input, &mut ForceScratch::default(), |tile| {
                    let mut got = got.lock().unwrap();
                    for k in 0..tile.force[0].len() {
                        let p = tile.p0 + k;
                        let at = |a: [&[f64]; 3]| Vec3::new(a[0][k], a[1][k], a[2][k]);
                        assert_eq!((at(tile.x), at(tile.v)), (x[p], v[p]), "state of {p}");
                        assert!(got[p].is_none(), "particle {p} handed over twice");
                        got[p] = Some(at(tile.force));
                    }
                });
                for (p, (g, e)) in got.into_inner().unwrap().iter().zip(&expected).enumerate() {
                    let g = g.unwrap_or_else(|| panic!("particle {p} not handed over"));
                    let bits = |a: &Vec3| a.map(f64::to_bits);
                    assert_eq!(bits(&g), bits(e), "{w} x {h}, damping {mode}, particle {p}");
                }
            }
        }
    }

    #[test]
    fn component_array_tiles_need_a_tiled_topology() {
        let t = GridSpec {
            width: 30,
            height: 30,
            spacing: 0.01,
            total_mass: 1.0,
        }
        .build()
        .unwrap();
        let (x, v) = (t.rest_positions.clone(), vec![Vec3::zeros(); 900]);
        let mut m = Model::fractional();
        let sphere = Collider::Sphere(Sphere {
            center: Vec3::zeros(),
            radius: 0.1,
            velocity: Vec3::zeros(),
        });
        let input = |m: &Model, c: &[Collider]| {
            soa_applies(&ForceInput {
                model: m,
                topology: &t,
                x: &x,
                v: &v,
                half_derivative: &[],
                colliders: c,
            })
        };
        assert!(input(&m, &[]));
        assert!(input(&m, &[sphere]));
        m.normal_drag = 0.1;
        assert!(input(&m, &[]));
        let mut untiled = t.clone();
        untiled.tile_runs.max_offset = usize::MAX;
        assert!(!soa_applies(&ForceInput {
            model: &m,
            topology: &untiled,
            x: &x,
            v: &v,
            half_derivative: &[],
            colliders: &[],
        }));
    }
}
