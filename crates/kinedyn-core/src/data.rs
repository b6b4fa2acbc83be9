//! `Data`: per-thread scratch space and outputs of the algorithms (allocated once per model).
//!
//! Algorithms overwrite what they use; nothing here is a precondition of another algorithm
//! (no dirty flags): an algorithm that needs forward kinematics runs it.

use crate::model::Model;
use crate::spatial::{Force, Inertia, Motion, Transform};

#[derive(Clone, Debug)]
pub struct Data {
    /// `parent_from_body[i]` at the last q (RBDA's `^i X_{lambda(i)}`, inverted).
    pub parent_from_body: Vec<Transform>,
    /// `world_from_body[i]` at the last q.
    pub world_from_body: Vec<Transform>,
    /// Motion subspace `s_i` of each joint in its body frame.
    pub s: Vec<Motion>,
    /// Body twists `v_i` in body coordinates.
    pub v: Vec<Motion>,
    /// Body spatial accelerations `a_i` in body coordinates.
    pub a: Vec<Motion>,
    /// Body forces `f_i` in body coordinates (RNEA's backward pass).
    pub f: Vec<Force>,
    /// Composite / articulated inertias and other per-body scratch.
    pub ic: Vec<Inertia>,
    /// Joint-space output vector (tau, qdd, ...), length n.
    pub tau: Vec<f64>,
    /// Joint-space output matrix, row-major n x n (M, C, ...).
    pub m: Vec<f64>,
}

impl Data {
    pub fn new(model: &Model) -> Self {
        let n = model.n;
        Self {
            parent_from_body: vec![Transform::identity(); n],
            world_from_body: vec![Transform::identity(); n],
            s: model.joints.iter().map(|j| j.subspace()).collect(),
            v: vec![Motion::zero(); n],
            a: vec![Motion::zero(); n],
            f: vec![Force::zero(); n],
            ic: vec![Inertia::zero(); n],
            tau: vec![0.0; n],
            m: vec![0.0; n * n],
        }
    }
}
