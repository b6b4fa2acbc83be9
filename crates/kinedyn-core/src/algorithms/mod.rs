//! One file per algorithm; each reads like the table of the source it cites.

pub mod aba;
pub mod coriolis;
pub mod crba;
pub mod derivatives;
pub mod energy;
pub mod gravity;
pub mod jacobian;
pub mod kinematics;
pub mod minv;
pub mod momentum;
pub mod regressor;
pub mod rnea;

pub use aba::aba;
pub use coriolis::{christoffel, coriolis_matrix};
pub use crba::crba;
pub use derivatives::{aba_derivatives, rnea_derivatives};
pub use energy::{kinetic_energy, potential_energy};
pub use gravity::gravity_torque;
pub use jacobian::{frame_jacobian, frame_jacobian_hessian, frame_pose_at, frame_velocity, jacobian_dot_qd, Reference};
pub use kinematics::{forward_acceleration, forward_kinematics, forward_velocity, frame_pose, parent_from_body};
pub use minv::mass_matrix_inverse;
pub use momentum::{center_of_mass, centroidal_momentum_matrix, spatial_momentum};
pub use regressor::regressor;
pub use rnea::{bias_torque, rnea, rnea_with, RneaTerms};
