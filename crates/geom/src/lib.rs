//! Geometry kernel: exact orientation predicates, small vector maths and
//! axis-aligned boxes. Everything above it (surface checks, the front's
//! crossing tests, the mesh `check()`) decides topology only through the
//! exact predicates here, never through a float tolerance.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod aabb;
pub mod intersect;
pub mod kernel;
pub mod morton;
pub mod predicates;
pub mod vec3;

pub use aabb::Aabb;
pub use morton::morton_key;
pub use predicates::{in_sphere, orient2d, orient3d, orient3d_sign, Sign};
pub use vec3::*;

/// A point in space. Plain arrays keep the struct-of-arrays stores compact.
pub type P3 = [f64; 3];
