//! Forces on the particles (paper, section 4.1): one file per force family, the per-particle
//! terms listed once (`terms`), and the pass that sums them tile by tile (`pass`).
//!
//! | file | what |
//! |---|---|
//! | `springs.rs` | Eq. 5 fractional viscoelastic springs, damped springs (Fig. 7) |
//! | `body.rs` | Eq. 2 gravity and buoyancy |
//! | `drag.rs` | Eq. 3 viscous, Eq. 4 history, and normal drag |
//! | `contact.rs` | collider contacts and friction |
//! | `elements.rs` | the list of pair elements (springs, strain springs): what each remembers, how its forces are summed, its damping block |
//! | `strain.rs` | the rotation-invariant fractional spring: D^{1/2} of each spring's elongation |
//! | `inertia.rs` | a particle's inertia: its mass and the water it carries (the mass matrix, its inverse, its energy) |
//! | `turning_grid.rs` | the carried water's turning forces on a grid, gathered by each vertex (the same bits as `inertia.rs`'s scatter) |
//! | `memories.rs` | which half-derivative histories a model keeps, derived from what its terms read |
//! | `terms.rs` | the list of per-particle terms, what each reads, its Jacobian block |
//! | `jacobian.rs` | the linearised forces of the implicit integrator |
//! | `pass.rs` | the force pass: spring sums plus terms, tile by tile |
//! | `tiles.rs`, `inputs.rs`, `assemble.rs`, `normals.rs` | how the pass sums springs and reads its inputs |

mod assemble;
mod body;
pub(crate) mod coarse_water;
mod contact;
mod drag;
mod elements;
pub(crate) mod inertia;
mod inputs;
mod jacobian;
mod memories;
mod normals;
mod pass;
mod patch;
mod springs;
mod strain;
pub(crate) mod terms;
mod tiles;
pub(crate) mod turning;
mod turning_grid;
mod wide_drag;

// The public face: the colliders, a particle's inertia and weight, what a model remembers,
// and the forces of a state (`total_forces` on a `ForceInput`).
pub use body::{body_acceleration, body_force};
pub use contact::{Capsule, Collider, Plane, Sphere};
pub use drag::follow_skin_mean;
pub use elements::{damping_rate, DampingRate, Memory, Weights};
pub use inertia::Inertia;
pub use memories::{memories, Memories};
pub use normals::vertex_normals;
pub use pass::{total_forces, ForceInput, ForceScratch};
pub use springs::{spring_rate, SpringRate};
pub use wide_drag::{add_wide_form_drag, wide as wide_drag, WideDragScratch};

// The step's machinery, for the crate only.
pub(crate) use assemble::add_spring_values;
pub(crate) use contact::{apply_friction, friction_active};
pub(crate) use elements::{prior_elements_on, prior_forces, spring_damping, ElementScratch};
pub(crate) use inertia::{carries_water, effective_forces};
pub(crate) use jacobian::{linearise, Linearisation, SpringBlock};
pub(crate) use normals::vertex_normals_with;
pub(crate) use pass::{for_each_tile_ahead, total_forces_with, Ahead, SpringInputs};
pub(crate) use tiles::TILE;
pub(crate) use turning::{patch_normals, turning_forces, TurningScratch};
