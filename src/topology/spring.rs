//! One spring element between two particles.

/// The three Choi & Ko spring families.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpringKind {
    /// p(i±1, j), p(i, j±1).
    Stretch,
    /// p(i±1, j±1).
    Shear,
    /// p(i±2, j), p(i, j±2), p(i±2, j±2).
    Bend,
}

/// A spring linking particles `i` and `j` with rest length `rest` (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    pub i: u32,
    pub j: u32,
    pub rest: f64,
    pub kind: SpringKind,
}
