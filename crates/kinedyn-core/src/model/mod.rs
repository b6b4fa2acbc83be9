//! `Model`: the immutable, flat description the algorithms read (built once, f64 only).
//!
//! Bodies are numbered so that `parent[i] < i`. Body i's frame is its joint frame after the joint
//! moved: `parent_from_body(q) = parent_from_joint[i] * jcalc(q_i + offset_i)`.
//!
//! Multi-DOF joints (free-flyer, spherical, planar) are held as one body per degree of freedom:
//! the *head* body carries the whole joint transform, read from its block of q (nq numbers:
//! a unit quaternion, or (cos, sin)); each further *member* body sits at the identity on the one
//! before it, is massless except the last, and adds one column `s` of the joint's motion subspace
//! (a unit linear or angular axis of the child frame, constant in it, as RBDA Table 4.1's
//! free-flyer `S = 1`). Every algorithm written for 1-DOF bodies then computes the multi-DOF
//! joint's positions, velocities, forces and mass matrix exactly; the one place where the split
//! would differ is the joint's velocity product `c_J = v_i x S qd` (RBDA eq. 5.8 with `cJ = 0` for
//! these joints), which must use the whole joint velocity: [`Model::velocity_product`] puts it on
//! the last member (the members before it are massless, so their accelerations never act).

mod builder;
mod configuration;

pub use builder::{JointRecord, ModelBuilder};

/// Kept here for the algorithms that read it from the model's module.
pub use crate::lie::quaternion_matrix;
pub use configuration::UNIT_TOLERANCE;

use crate::error::{Error, Result};
use crate::joint::Joint;
use crate::lie::Block;
use crate::spatial::{splat3, AxisRotation, Inertia, Mat3, Motion, Real, Transform, Vec3};

/// Where body i's joint transform comes from in the configuration q.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coordinates {
    /// A 1-DOF joint with coordinate `q[at]`.
    Scalar { at: usize },
    /// The first body of a multi-DOF joint, whose transform is read from `q[at..at + block.nq()]`
    /// (never [`Block::Scalar`]: [`Model::with_coordinates`] refuses it). Columns and q blocks follow
    /// Pinocchio's conventions: a free-flyer's q = (x, y, z, qx, qy, qz, qw) with columns linear x, y,
    /// z then angular x, y, z of the child frame; a spherical joint's q = (qx, qy, qz, qw) with
    /// columns angular x, y, z; a planar joint's q = (x, y, cos th, sin th) with columns linear e1, e2
    /// and angular n (the members' axes, (e1, e2, n) right-handed): translation x e1 + y e2, rotation
    /// th about n.
    Head { block: Block, at: usize },
    /// A further degree of freedom of the multi-DOF joint of the body before (identity transform).
    Member,
}

/// A named frame rigidly attached to a body (`None`: the base).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub body: Option<usize>,
    pub body_from_frame: Transform,
}

/// The compiled robot: kinematic tree, inertias, drive and friction data, gravity and frames.
#[derive(Clone, Debug)]
pub struct Model {
    /// Number of bodies = number of degrees of freedom (nv; velocity coordinates).
    pub n: usize,
    /// Length of a configuration q (= n without multi-DOF joints).
    pub nq: usize,
    /// Where each body's joint reads q.
    pub coordinates: Vec<Coordinates>,
    /// The first and last body of the joint each body belongs to (i, i for a 1-DOF joint).
    pub group_first: Vec<usize>,
    pub group_last: Vec<usize>,
    /// No multi-DOF joint: body i's coordinate is q[i] (the fast paths).
    pub plain: bool,
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
    /// The origin of each body's link frame in the body frame (body axes; zero by default): the
    /// point about which the moment of an external wrench `f_ext` on that body is given. A
    /// standard-DH link frame sits at `Tx(a)` from its joint frame, a URDF link frame at the joint
    /// frame (zero). Set by [`Model::with_link_origins`]; see `rnea.rs` for how a wrench is moved.
    pub link_origin: Vec<Vec3>,
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
        Some(k) => Err(Error::InvalidModel(format!(
            "{what} has a non-finite value at index {k}"
        ))),
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
                return Err(Error::InvalidModel(format!(
                    "joint {i}: axis {:?} is not a unit vector",
                    j.axis.as_slice()
                )));
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
                    return Err(Error::InvalidModel(format!(
                        "frame {k} is attached to body {b}, but there are {n} bodies"
                    )));
                }
            }
            finite(&format!("placement of frame {k}"), &f.body_from_frame.to_homogeneous())?;
        }
        let mut support: Vec<Vec<usize>> = Vec::with_capacity(n);
        for (i, p) in parent.iter().enumerate().take(n) {
            let mut s = match p {
                Some(p) => support[*p].clone(),
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
        let placement_rotation = parent_from_joint
            .iter()
            .map(|x| AxisRotation::classify(&x.rot))
            .collect();
        Ok(Self {
            n,
            nq: n,
            coordinates: (0..n).map(|at| Coordinates::Scalar { at }).collect(),
            group_first: (0..n).collect(),
            group_last: (0..n).collect(),
            plain: true,
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
            link_origin: vec![Vec3::zeros(); n],
            support,
            subtree_end,
            subtrees_contiguous,
        })
    }

    /// The model with multi-DOF joints: `coordinates[i]` says where body i reads q (see the module
    /// documentation for the layout of a multi-DOF joint's bodies, which is checked here).
    pub fn with_coordinates(mut self, coordinates: Vec<Coordinates>) -> Result<Self> {
        let n = self.n;
        if coordinates.len() != n {
            return Err(Error::InvalidModel(format!(
                "coordinates has {} entries for {n} bodies",
                coordinates.len()
            )));
        }
        let bad = |i: usize, why: String| Err(Error::InvalidModel(format!("body {i}: {why}")));
        let (mut nq, mut first, mut last) = (0usize, (0..n).collect::<Vec<_>>(), (0..n).collect::<Vec<_>>());
        let mut i = 0;
        while i < n {
            match coordinates[i] {
                Coordinates::Member => return bad(i, "a multi-DOF member without its head body before it".into()),
                Coordinates::Scalar { at } => {
                    if at != nq {
                        return bad(i, format!("reads q[{at}], expected q[{nq}] (blocks in body order)"));
                    }
                    nq += 1;
                    i += 1;
                }
                Coordinates::Head {
                    block: Block::Scalar, ..
                } => {
                    return bad(
                        i,
                        "a multi-DOF head with a scalar block (use Coordinates::Scalar)".into(),
                    )
                }
                Coordinates::Head { block, at } => {
                    if at != nq {
                        return bad(i, format!("reads q[{at}..], expected q[{nq}..] (blocks in body order)"));
                    }
                    let end = i + block.nv();
                    if end > n {
                        return bad(
                            i,
                            format!("a {block:?} joint needs {} bodies, only {} remain", block.nv(), n - i),
                        );
                    }
                    self.check_block(i, block, &coordinates)?;
                    for k in i..end {
                        (first[k], last[k]) = (i, end - 1);
                    }
                    nq += block.nq();
                    i = end;
                }
            }
        }
        // a multi-DOF joint's bodies before its last carry nothing: no child, no frame
        for (k, p) in self.parent.iter().enumerate() {
            if let Some(p) = *p {
                if last[p] != p && !(k == p + 1 && first[k] == first[p]) {
                    return bad(
                        k,
                        format!(
                            "its parent {p} is an inner body of a multi-DOF joint (attach to body {})",
                            last[p]
                        ),
                    );
                }
            }
        }
        for (k, f) in self.frames.iter().enumerate() {
            if let Some(b) = f.body {
                if last[b] != b {
                    return Err(Error::InvalidModel(format!(
                        "frame {k} is attached to inner body {b} of a multi-DOF joint"
                    )));
                }
            }
        }
        self.plain = coordinates.iter().all(|c| matches!(c, Coordinates::Scalar { .. }));
        (self.nq, self.coordinates, self.group_first, self.group_last) = (nq, coordinates, first, last);
        Ok(self)
    }

    /// The bodies `i..i + block.nv()` form one multi-DOF joint: columns as [`Block`] says, members at
    /// the identity on the body before, massless except the last, no drive or friction data.
    fn check_block(&self, i: usize, block: Block, coordinates: &[Coordinates]) -> Result<()> {
        let nv = block.nv();
        // the columns the block's kind says (the planar joint's in-plane axes are its first members')
        let in_plane = (self.joints[i].axis, self.joints[(i + 1).min(self.n - 1)].axis);
        let expected = crate::joint::block_columns(block, in_plane);
        let bad = |k: usize, why: &str| {
            Err(Error::InvalidModel(format!(
                "body {k} ({block:?} joint starting at body {i}): {why}"
            )))
        };
        if block == Block::Planar && self.joints[i].axis.dot(&self.joints[i + 1].axis).abs() > 1e-12 {
            return bad(i, "the planar joint's in-plane axes are not orthogonal");
        }
        for (m, column) in expected.iter().enumerate() {
            let k = i + m;
            let joint = &self.joints[k];
            if joint.kind != column.kind || (joint.axis - column.axis).norm() > 1e-12 {
                return bad(
                    k,
                    &format!(
                        "column {m} must be {:?} along {:?}",
                        column.kind,
                        column.axis.as_slice()
                    ),
                );
            }
            if m > 0 {
                if coordinates[k] != Coordinates::Member || self.parent[k] != Some(k - 1) {
                    return bad(k, "must be a member whose parent is the body before");
                }
                if self.parent_from_joint[k] != Transform::identity() {
                    return bad(k, "a member's placement must be the identity");
                }
            }
            if m + 1 < nv && self.inertia[k].to_parameters().iter().any(|x| *x != 0.0) {
                return bad(k, "only the last body of a multi-DOF joint has inertia");
            }
            if self.offset[k] != 0.0 || self.armature[k] != 0.0 || self.viscous[k] != 0.0 || self.coulomb[k] != 0.0 {
                return bad(k, "a multi-DOF joint has no offset, armature or friction");
            }
        }
        Ok(())
    }

    /// The joint transform `joint_from_body` of the multi-DOF joint whose head is body i, from its
    /// block of q ([`crate::joint::block_transform`], the planar joint's in-plane axes being its
    /// first two bodies' axes).
    #[inline(always)]
    pub fn block_transform<T: Real>(&self, i: usize, block: Block, qb: &[T]) -> Transform<T> {
        let in_plane = match block {
            Block::Planar => (self.joints[i].axis, self.joints[i + 1].axis),
            _ => (Vec3::x(), Vec3::y()),
        };
        crate::joint::block_transform(block, in_plane, qb)
    }

    /// `out = q ⊕ (v dt)`: each joint's block moved by its velocity (Lie-group exponential of a
    /// multi-DOF joint, [`crate::lie::integrate_block`]; `q + v dt` for a 1-DOF joint).
    pub fn integrate_configuration(&self, q: &[f64], v: &[f64], dt: f64, out: &mut [f64]) {
        if self.plain {
            for j in 0..self.n {
                out[j] = q[j] + v[j] * dt;
            }
            return;
        }
        for (i, c) in self.coordinates.iter().enumerate() {
            match *c {
                Coordinates::Scalar { at } => out[at] = q[at] + v[i] * dt,
                Coordinates::Head { block, at } => {
                    let end = at + block.nq();
                    crate::lie::integrate_block(block, &q[at..end], &v[i..i + block.nv()], dt, &mut out[at..end]);
                }
                Coordinates::Member => {}
            }
        }
    }

    /// `out = dexp⁻¹_{-Ω}(v) ≈ v + [Ω, v]/2 + [Ω, [Ω, v]]/12` per multi-DOF joint (`v` on a 1-DOF
    /// joint): the rate of the chart `q(t) = q0 ⊕ Ω(t)` for the body velocity `v`, to the order
    /// RKMK4 needs (Munthe-Kaas, "High order Runge-Kutta methods on manifolds", Appl. Numer. Math.
    /// 29, 1999; the brackets of so(3), se(3) in [linear; angular] and se(2)).
    pub fn chart_rate(&self, omega: &[f64], v: &[f64], out: &mut [f64]) {
        out[..self.n].copy_from_slice(&v[..self.n]);
        if self.plain {
            return;
        }
        for (i, c) in self.coordinates.iter().enumerate() {
            if let Coordinates::Head { block, .. } = *c {
                let k = block.nv();
                let (w, x) = (&omega[i..i + k], &v[i..i + k]);
                let bracket = |a: &[f64], b: &[f64]| -> [f64; 6] { crate::lie::lie_bracket(block, a, b) };
                let wx = bracket(w, x);
                let wwx = bracket(w, &wx[..k]);
                for j in 0..k {
                    out[i + j] = x[j] + 0.5 * wx[j] + wwx[j] / 12.0;
                }
            }
        }
    }

    /// The (q index, v index) of every 1-DOF joint's coordinate (the ones with position limits).
    pub fn scalar_coordinates(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.coordinates.iter().enumerate().filter_map(|(i, c)| match c {
            Coordinates::Scalar { at } => Some((*at, i)),
            _ => None,
        })
    }

    /// The velocity product `c_J` of body i (RBDA eq. 5.8's `v_i x v_J` for `cJ = 0`): `v_i x s_i qd_i`
    /// for a 1-DOF joint; for a multi-DOF joint `v_i x (S qd)` of the whole joint on its last body,
    /// zero on the others (massless: their accelerations never act).
    #[inline(always)]
    pub fn velocity_product<T: Real>(&self, i: usize, v: &Motion<T>, qd: &[T]) -> Motion<T> {
        if self.plain {
            return self.joints[i].cross(v, qd[i]);
        }
        let (first, last) = (self.group_first[i], self.group_last[i]);
        if first == last {
            self.joints[i].cross(v, qd[i])
        } else if i != last {
            Motion::zero()
        } else {
            let mut vj = Motion::zero();
            for (joint, &qd_l) in self.joints[first..=last].iter().zip(&qd[first..=last]) {
                vj += joint.motion(qd_l);
            }
            v.cross_motion(&vj)
        }
    }

    /// The model with external wrenches given about link-frame origins: `origins[i]` is body i's
    /// link-frame origin in body i's frame (see [`Model::link_origin`]).
    pub fn with_link_origins(mut self, origins: Vec<Vec3>) -> Result<Self> {
        if origins.len() != self.n {
            return Err(Error::InvalidModel(format!(
                "link origins has {} entries for {} bodies",
                origins.len(),
                self.n
            )));
        }
        for (i, u) in origins.iter().enumerate() {
            finite(&format!("link origin of body {i}"), u.as_slice())?;
        }
        self.link_origin = origins;
        Ok(self)
    }

    /// The body that carries each link, in joint order: the last body of each joint (a 1-DOF
    /// joint's own body; a multi-DOF joint's last member, where the builder puts the link's inertia,
    /// frames and link origin). A model of 1-DOF joints has one link per body.
    pub fn link_bodies(&self) -> Vec<usize> {
        (0..self.n).filter(|&i| self.group_last[i] == i).collect()
    }

    /// External wrenches given one per link (`links` = [`Model::link_bodies`]`.len()` of 6 numbers,
    /// as [`Model::body_wrench`] reads them) laid out one per body in `out` (6 n): each link's
    /// wrench on the body that carries it, zero on a multi-DOF joint's inner bodies (massless, they
    /// carry no link). `Err` names the expected length when `per_link` has another.
    pub fn link_wrenches(&self, per_link: &[f64], out: &mut [f64]) -> Result<()> {
        let bodies = self.link_bodies();
        if per_link.len() != 6 * bodies.len() || out.len() != 6 * self.n {
            return Err(Error::InvalidModel(format!(
                "external wrenches: {} numbers for {} links (6 each), into {} for {} bodies",
                per_link.len(),
                bodies.len(),
                out.len(),
                self.n
            )));
        }
        out.fill(0.0);
        for (l, &b) in bodies.iter().enumerate() {
            out[6 * b..6 * b + 6].copy_from_slice(&per_link[6 * l..6 * l + 6]);
        }
        Ok(())
    }

    /// An external wrench `(f, n)` (base axes, moment about body i's link-frame origin) in body
    /// i's axes with the moment about the body origin, given `rot` = body i's `world_from_body`
    /// rotation: `f_b = R^T f`, `n_b = R^T n + u_i x f_b` (`n_p = n_l + (l - p) x f`, and
    /// `l - p = R u_i`; a rotation preserves the cross product).
    #[inline(always)]
    pub fn body_wrench<T: Real>(&self, i: usize, rot: &Mat3<T>, fx: &[T]) -> crate::spatial::Force<T> {
        use crate::spatial::{cross, mtv};
        let f = mtv(rot, &Vec3::new(fx[6 * i], fx[6 * i + 1], fx[6 * i + 2]));
        let n = mtv(rot, &Vec3::new(fx[6 * i + 3], fx[6 * i + 4], fx[6 * i + 5]));
        crate::spatial::Force::new(f, n + cross(&splat3::<T>(&self.link_origin[i]), &f))
    }

    /// The model with direction-dependent Coulomb friction: `levels[i]` (>= 0) acts against
    /// `qd_i < 0`, `coulomb[i]` against `qd_i > 0`.
    pub fn with_coulomb_negative(mut self, levels: Vec<f64>) -> Result<Self> {
        if levels.len() != self.n {
            return Err(Error::InvalidModel(format!(
                "coulomb_negative has {} entries for {} bodies",
                levels.len(),
                self.n
            )));
        }
        finite("coulomb_negative", &levels)?;
        if let Some(k) = levels.iter().position(|c| *c < 0.0) {
            return Err(Error::InvalidModel(format!(
                "coulomb_negative of joint {k} is {}, a level must be >= 0",
                levels[k]
            )));
        }
        self.coulomb_negative = Some(levels);
        Ok(self)
    }

    /// Coulomb friction torque of joint i at rate `qd`: `coulomb_i` for `qd > 0`,
    /// `-coulomb_negative_i` for `qd < 0`, 0 at rest (`coulomb_i sign(qd)` when symmetric).
    #[inline(always)]
    pub fn coulomb_torque<T: Real>(&self, i: usize, qd: T) -> T {
        qd.signed_level(
            self.coulomb[i],
            self.coulomb_negative.as_ref().map_or(self.coulomb[i], |c| c[i]),
        )
    }

    /// Whether joint i has Coulomb friction in either direction.
    #[inline]
    pub fn has_coulomb(&self, i: usize) -> bool {
        self.coulomb[i] != 0.0 || self.coulomb_negative.as_ref().is_some_and(|c| c[i] != 0.0)
    }
}
