//! Closed kinematic loops: constraints that close the tree between two of its frames.
//!
//! A loop says "frame a and frame b coincide": their origins (`Point`, 3 rows, MJCF `<connect>`),
//! or origins and axes (`Weld`, 6 rows, MJCF `<weld>`). LaValle, Planning Algorithms §13.4
//! (holonomic constraints with Lagrange multipliers); Featherstone, RBDA ch. 8 (closed loops).
//!
//! | symbol   | here                        | meaning                                                    |
//! |----------|-----------------------------|------------------------------------------------------------|
//! | `r(q)`   | [`loop_residual`]           | closure error, stacked over the loops (m rows)              |
//! | `J(q)`   | [`loop_jacobian`]           | `J qd` = relative velocity of frame a w.r.t. frame b (m x n) |
//! | `gamma`  | [`loop_gamma`]              | `dJ/dt qd`: a closed motion has `J qdd + gamma = 0`         |
//! | `lambda` | [`constrained_forward_dynamics`] | the loop forces: `M qdd + h = tau + J^T lambda`       |
//!
//! Everything is in base axes (kinedyn's `"world"` reference, Pinocchio's LOCAL_WORLD_ALIGNED):
//! a point loop's rows are `p_a - p_b` and `J = Jv_a - Jv_b` (linear rows of the `World`
//! Jacobians); a weld adds the rotation rows `e = R_b log3(R_b^T R_a)` (the rotation vector from
//! b to a, in base axes) and `Jw_a - Jw_b`. `J` is the exact derivative of the point rows
//! everywhere and of the rotation rows where the loop is closed (`R_a = R_b`, where
//! `d/dt e = w_a - w_b`); away from closure the rotation rows of `J` are the relative angular
//! velocity, the velocity constraint every weld solver uses.

mod dense;
mod dynamics;
mod kinematics;
mod solve;

pub use dynamics::{constrained_forward_dynamics, Proximal, PROXIMAL};
pub use kinematics::{loop_gamma, loop_jacobian, loop_residual};
pub use solve::{constrained_inverse_dynamics, project_configuration, project_velocity};

use crate::error::{Error, Result};
use crate::model::Model;
use crate::scalar::Real;

/// What a loop makes coincide.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopKind {
    /// The two frames' origins (3 rows).
    Point,
    /// The two frames whole: origins and axes (6 rows).
    Weld,
}

impl LoopKind {
    /// `"point"` or `"weld"`.
    pub fn from_name(name: &str) -> Result<LoopKind> {
        match name {
            "point" => Ok(LoopKind::Point),
            "weld" => Ok(LoopKind::Weld),
            _ => Err(Error::InvalidInput(format!(
                "a loop's kind must be one of ['point', 'weld'], got '{name}'"
            ))),
        }
    }

    /// Constraint rows: 3 for a point, 6 for a weld.
    pub fn rows(self) -> usize {
        match self {
            LoopKind::Point => 3,
            LoopKind::Weld => 6,
        }
    }
}

/// A closure of frame `frame_a` on frame `frame_b` (indices into `Model::frames`).
#[derive(Clone, Debug, PartialEq)]
pub struct Loop {
    pub name: String,
    pub frame_a: usize,
    pub frame_b: usize,
    pub kind: LoopKind,
}

impl Model {
    /// The model with closed loops, each checked: both frames exist and differ, names unique.
    pub fn with_loops(mut self, loops: Vec<Loop>) -> Result<Self> {
        let frames = self.frames.len();
        for (k, l) in loops.iter().enumerate() {
            let bad = |why: String| Err(Error::InvalidModel(format!("loop {k} '{}': {why}", l.name)));
            for f in [l.frame_a, l.frame_b] {
                if f >= frames {
                    return bad(format!("frame {f} does not exist (the model has {frames} frames)"));
                }
            }
            if l.frame_a == l.frame_b {
                return bad(format!("closes frame {} on itself", l.frame_a));
            }
            if self.frames[l.frame_a].body.is_none() && self.frames[l.frame_b].body.is_none() {
                return bad("both frames are on the base: nothing moves".into());
            }
            if loops[..k].iter().any(|o| o.name == l.name) {
                return bad("two loops have this name".into());
            }
        }
        self.loops = loops;
        Ok(self)
    }

    /// Constraint rows of all loops (m).
    pub fn loop_rows(&self) -> usize {
        self.loops.iter().map(|l| l.kind.rows()).sum()
    }

    /// The loop and its row that constraint row `row` belongs to.
    pub fn loop_of_row(&self, mut row: usize) -> (&Loop, usize) {
        for l in &self.loops {
            if row < l.kind.rows() {
                return (l, row);
            }
            row -= l.kind.rows();
        }
        panic!("constraint row beyond the loops' rows")
    }
}

/// Scratch of the loop algorithms (in `Data`, sized by the model's loop rows m).
#[derive(Clone, Debug, Default)]
pub struct LoopData<T: Real = f64> {
    /// `J`, row-major m x n.
    pub j: Vec<T>,
    /// `gamma = dJ/dt qd` (m).
    pub gamma: Vec<T>,
    /// `M^-1 J^T`, one constraint row's column after the other (m blocks of n).
    pub y: Vec<T>,
    /// `J M^-1 J^T + mu 1` and its `L D L^T` factors, row-major m x m.
    pub a: Vec<T>,
    /// The right side `-(J qdd_free + gamma)`, the multipliers and the previous iterate (m each).
    pub b: Vec<T>,
    pub lambda: Vec<T>,
    pub rhs: Vec<T>,
    /// The unconstrained accelerations `M^-1 (tau - h)` (n).
    pub free: Vec<T>,
}

impl<T: Real> LoopData<T> {
    pub fn new(model: &Model) -> Self {
        let (n, m) = (model.n, model.loop_rows());
        let zeros = |k: usize| vec![T::zero(); k];
        Self {
            j: zeros(m * n),
            gamma: zeros(m),
            y: zeros(m * n),
            a: zeros(m * m),
            b: zeros(m),
            lambda: zeros(m),
            rhs: zeros(m),
            free: zeros(n),
        }
    }

    /// Sized for `model` (a `Data` made before the model had loops is resized on first use).
    pub fn fit(&mut self, model: &Model) {
        if self.j.len() != model.n * model.loop_rows() || self.free.len() != model.n {
            *self = Self::new(model);
        }
    }
}

#[cfg(test)]
mod tests;
