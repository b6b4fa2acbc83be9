//! One file per algorithm; each reads like the table of the source it cites.

pub mod jacobian;
pub mod kinematics;

pub use jacobian::{frame_jacobian, frame_pose_at, frame_velocity, jacobian_dot_qd, Reference};
pub use kinematics::{forward_acceleration, forward_kinematics, forward_velocity, frame_pose};
