//! kinedyn-core: rigid-body kinematics and dynamics of robot manipulators, in pure Rust.
//!
//! A [`Model`] (immutable, built once) and a [`Data`] (scratch and outputs, one per thread) are
//! passed to free functions in [`algorithms`], `algorithm(&model, &mut data, inputs)`, as in
//! Featherstone's RBDA and Pinocchio. Spatial vectors are `[linear; angular]` (docs/architecture.md).

pub mod algorithms;
pub mod batch;
pub mod constraints;
pub mod data;
pub mod error;
pub mod ik;
pub mod joint;
pub mod lie;
pub mod model;
pub mod rng;
pub mod scalar;
pub mod sim;
pub mod spatial;
pub mod testing;
pub mod trace;

pub use data::Data;
pub use error::{Error, Result};
pub use joint::{Joint, JointKind};
pub use model::{Frame, Model};
pub use scalar::{Lanes, Real};
