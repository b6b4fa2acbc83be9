//! `Model`: the immutable, flat description the algorithms read (built once, f64 only).
//!
//! Bodies are numbered so that `parent[i] < i`. Body i's frame is its joint frame after the joint
//! moved: `parent_from_body(q) = parent_from_joint[i] * jcalc(q_i + offset_i)`.

use crate::error::{Error, Result};
use crate::joint::Joint;
use crate::spatial::{AxisRotation, Inertia, Transform, Vec3};

/// A named frame rigidly attached to a body (`None`: the base).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub body: Option<usize>,
    pub body_from_frame: Transform,
}

/// The compiled robot: kinematic tree, inertias, drive and friction data, gravity and frames.
#[derive(Clone, Debug)]
pub struct Model {
    /// Number of bodies = number of joint coordinates.
    pub n: usize,
    /// Parent body of each body (`None` = base); `parent[i] < i`.
    pub parent: Vec<Option<usize>>,
    pub joints: Vec<Joint>,
    /// Added to the joint coordinate before `jcalc` (DH theta / d offsets).
    pub offset: Vec<f64>,
    /// Fixed placement of each joint frame in its parent body's frame.
    pub parent_from_joint: Vec<Transform>,
    /// The class of each placement's rotation (identity, about a coordinate axis, general).
    pub placement_rotation: Vec<AxisRotation>,
    /// Rigid-body inertia of each body about its frame origin, body axes.
    pub inertia: Vec<Inertia>,
    /// Reflected rotor inertia `r^2 J_m` per joint (added to `M[i][i]`).
    pub armature: Vec<f64>,
    /// Viscous friction coefficient per joint: `tau_f = viscous qd + coulomb sign(qd)`.
    pub viscous: Vec<f64>,
    /// Coulomb friction level per joint for `qd > 0` (for both directions when symmetric).
    pub coulomb: Vec<f64>,
    /// Coulomb friction level (a magnitude) per joint for `qd < 0`, when it differs from `coulomb`
    /// (Corke's PUMA 560 motors, `Tc = [Tc+, Tc-]`); `None`: symmetric. See [`Model::coulomb_torque`].
    pub coulomb_negative: Option<Vec<f64>>,
    /// Gravity acceleration in base coordinates (e.g. `[0, 0, -9.81]`).
    pub gravity: Vec3,
    pub frames: Vec<Frame>,
    /// `support[i]`: body i and its ancestors, ascending (the joints that move body i).
    pub support: Vec<Vec<usize>>,
    /// `subtree_end[i]`: one past the largest index in body i's subtree (i and its descendants).
    pub subtree_end: Vec<usize>,
    /// Whether every subtree is the contiguous range `i..subtree_end[i]` (depth-first numbering:
    /// always true for a serial chain), which lets the CRBA treat a subtree's columns as a block.
    pub subtrees_contiguous: bool,
}

fn finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(Error::InvalidModel(format!("{what} has a non-finite value at index {k}"))),
        None => Ok(()),
    }
}

impl Model {
    /// Build and validate a model. All per-body vectors must have length `parent.len()`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        parent: Vec<Option<usize>>,
        joints: Vec<Joint>,
        offset: Vec<f64>,
        parent_from_joint: Vec<Transform>,
        inertia: Vec<Inertia>,
        armature: Vec<f64>,
        viscous: Vec<f64>,
        coulomb: Vec<f64>,
        gravity: Vec3,
        frames: Vec<Frame>,
    ) -> Result<Self> {
        let n = parent.len();
        let lens = [
            ("joints", joints.len()),
            ("offset", offset.len()),
            ("placement", parent_from_joint.len()),
            ("inertia", inertia.len()),
            ("armature", armature.len()),
            ("viscous", viscous.len()),
            ("coulomb", coulomb.len()),
        ];
        for (what, len) in lens {
            if len != n {
                return Err(Error::InvalidModel(format!("{what} has {len} entries for {n} bodies")));
            }
        }
        for (i, p) in parent.iter().enumerate() {
            if let Some(p) = p {
                if *p >= i {
                    return Err(Error::InvalidModel(format!(
                        "body {i} has parent {p}: bodies must be numbered so that parent < child (a cycle or bad order)"
                    )));
                }
            }
        }
        for (i, j) in joints.iter().enumerate() {
            let norm = j.axis.norm();
            if !norm.is_finite() || (norm - 1.0).abs() > 1e-9 {
                return Err(Error::InvalidModel(format!("joint {i}: axis {:?} is not a unit vector", j.axis.as_slice())));
            }
        }
        finite("offset", &offset)?;
        finite("armature", &armature)?;
        finite("viscous", &viscous)?;
        finite("coulomb", &coulomb)?;
        finite("gravity", gravity.as_slice())?;
        for (i, x) in parent_from_joint.iter().enumerate() {
            finite(&format!("placement of body {i}"), &x.to_homogeneous())?;
        }
        for (i, inr) in inertia.iter().enumerate() {
            finite(&format!("inertia of body {i}"), &inr.to_parameters())?;
            if inr.mass < 0.0 {
                return Err(Error::InvalidModel(format!("body {i} has negative mass {}", inr.mass)));
            }
        }
        for (k, f) in frames.iter().enumerate() {
            if let Some(b) = f.body {
                if b >= n {
                    return Err(Error::InvalidModel(format!("frame {k} is attached to body {b}, but there are {n} bodies")));
                }
            }
            finite(&format!("placement of frame {k}"), &f.body_from_frame.to_homogeneous())?;
        }
        let mut support: Vec<Vec<usize>> = Vec::with_capacity(n);
        for i in 0..n {
            let mut s = match parent[i] {
                Some(p) => support[p].clone(),
                None => Vec::new(),
            };
            s.push(i);
            support.push(s);
        }
        let mut subtree_end: Vec<usize> = (1..=n).collect();
        let mut subtree_size = vec![1usize; n];
        for i in (0..n).rev() {
            if let Some(p) = parent[i] {
                subtree_end[p] = subtree_end[p].max(subtree_end[i]);
                subtree_size[p] += subtree_size[i];
            }
        }
        let subtrees_contiguous = (0..n).all(|i| subtree_end[i] - i == subtree_size[i]);
        let placement_rotation = parent_from_joint.iter().map(|x| AxisRotation::classify(&x.rot)).collect();
        Ok(Self {
            n,
            parent,
            joints,
            offset,
            parent_from_joint,
            placement_rotation,
            inertia,
            armature,
            viscous,
            coulomb,
            coulomb_negative: None,
            gravity,
            frames,
            support,
            subtree_end,
            subtrees_contiguous,
        })
    }

    /// The model with direction-dependent Coulomb friction: `levels[i]` (>= 0) acts against
    /// `qd_i < 0`, `coulomb[i]` against `qd_i > 0`.
    pub fn with_coulomb_negative(mut self, levels: Vec<f64>) -> Result<Self> {
        if levels.len() != self.n {
            return Err(Error::InvalidModel(format!("coulomb_negative has {} entries for {} bodies", levels.len(), self.n)));
        }
        finite("coulomb_negative", &levels)?;
        if let Some(k) = levels.iter().position(|c| *c < 0.0) {
            return Err(Error::InvalidModel(format!("coulomb_negative of joint {k} is {}, a level must be >= 0", levels[k])));
        }
        self.coulomb_negative = Some(levels);
        Ok(self)
    }

    /// Coulomb friction torque of joint i at rate `qd`: `coulomb_i` for `qd > 0`,
    /// `-coulomb_negative_i` for `qd < 0`, 0 at rest (`coulomb_i sign(qd)` when symmetric).
    #[inline]
    pub fn coulomb_torque(&self, i: usize, qd: f64) -> f64 {
        if qd > 0.0 {
            self.coulomb[i]
        } else if qd < 0.0 {
            -self.coulomb_negative.as_ref().map_or(self.coulomb[i], |c| c[i])
        } else {
            0.0
        }
    }

    /// Whether joint i has Coulomb friction in either direction.
    #[inline]
    pub fn has_coulomb(&self, i: usize) -> bool {
        self.coulomb[i] != 0.0 || self.coulomb_negative.as_ref().is_some_and(|c| c[i] != 0.0)
    }
}
