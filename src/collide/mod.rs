//! Collisions beyond the analytic colliders: triangle meshes (static, moving, deforming) and
//! the cloth against itself, as [`Contact`] elements of the step (`docs/collisions.md`).
//!
//! | file | what |
//! |---|---|
//! | `geometry.rs` | closest points and crossings of points, segments and triangles |
//! | `intersections.rs` | counting self-intersections and vertices inside a mesh (tests, reports) |
//! | `bvh.rs` | a bounding-volume hierarchy over boxes, refitted as things move |
//! | `ccd.rs` | continuous collision: when a vertex passes a triangle, an edge an edge, in a step |
//! | `guard.rs` | neighbour pairs never listed, watched for passing through each other |
//! | `impact_zones.rs` | the fail-safe after a step: vertices that would pass move as one |
//! | `contact.rs` | the contact element: force, Jacobian blocks, friction |
//! | `mesh.rs` | triangle-mesh colliders |
//! | `neighbours.rs` | self-collision's pairs as the rest shape tells them: excluded, and rest-near |
//! | `ownership.rs` | which triangle owns each vertex and edge (pair walks meet each pair once) |
//! | `room.rs` | bounded, fallibly grown lists (entries a caller's input sets) |
//! | `self_collision.rs` | the cloth against itself |
//! | `shapes.rs` | closed meshes of simple solids (scenes and tests) |
//! | `unfolded.rs` | a proof that an unfolded sheet keeps its distances: pairs a look need not test |

pub mod bvh;
pub mod ccd;
pub mod contact;
pub mod geometry;
pub mod guard;
pub mod impact_zones;
pub mod intersections;
pub mod mesh;
mod neighbours;
pub mod ownership;
mod pair;
pub(crate) mod room;
pub mod self_collision;
pub mod shapes;
mod unfolded;

pub use contact::Contact;
pub use mesh::MeshCollider;
pub use self_collision::SelfCollision;
