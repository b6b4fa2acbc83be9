//! `Data`: per-thread scratch space and outputs of the algorithms (allocated once per model).
//!
//! Algorithms overwrite what they use; nothing here is a precondition of another algorithm
//! (no dirty flags): an algorithm that needs forward kinematics runs it.

use crate::algorithms::derivatives::Tangent;
use crate::model::Model;
use crate::spatial::{ArticulatedInertia, Force, Inertia, Mat3, Motion, Transform, Vec3};

#[derive(Clone, Debug)]
pub struct Data {
    /// `parent_from_body[i]` at the last q (RBDA's `^i X_{lambda(i)}`, inverted).
    pub parent_from_body: Vec<Transform>,
    /// `world_from_body[i]` at the last q.
    pub world_from_body: Vec<Transform>,
    /// `sin` and `cos` of each joint coordinate `q_i + offset_i` (`kinematics::joint_trig`).
    pub sin: Vec<f64>,
    pub cos: Vec<f64>,
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

    // ---- articulated-body algorithm (RBDA Table 7.1) ----
    /// Articulated inertias `IA_i` (body coordinates).
    pub ia: Vec<ArticulatedInertia>,
    /// Articulated bias forces `pA_i` (body coordinates).
    pub pa: Vec<Force>,
    /// `U_i = IA_i s_i`.
    pub u_f: Vec<Force>,
    /// `1 / D_i`, `D_i = s_i^T U_i + armature_i`.
    pub d_inv: Vec<f64>,
    /// `u_i = tau_i - s_i^T pA_i`.
    pub u: Vec<f64>,
    /// Velocity-product accelerations `c_i = v_i x s_i qd_i`.
    pub c: Vec<Motion>,
    /// Joint accelerations (forward dynamics output), length n.
    pub qdd: Vec<f64>,
    /// Second joint-space matrix, row-major n x n (M^-1, factorisations).
    pub m2: Vec<f64>,
    /// Joint-space scratch vector, length n.
    pub x: Vec<f64>,

    // ---- Coriolis matrix, world coordinates (coriolis.rs) ----
    /// `s_i` in world coordinates.
    pub s_w: Vec<Motion>,
    /// Body twists in world coordinates.
    pub v_w: Vec<Motion>,
    /// `ds_i/dt = v_i x s_i` in world coordinates.
    pub sd_w: Vec<Motion>,
    /// Body inertias in world coordinates.
    pub i_w: Vec<Inertia>,
    /// Composite inertias and their time derivatives (world coordinates).
    pub ic_w: Vec<Inertia>,
    pub icd_w: Vec<Inertia>,
    /// Composite momenta `sum I_k v_k` over each subtree (world coordinates).
    pub hc_w: Vec<Force>,
    /// Body accelerations (gravity included) and composite forces, world coordinates (derivatives.rs).
    pub a_w: Vec<Motion>,
    pub fc_w: Vec<Force>,
    /// Scratch composite force changes, world coordinates (derivatives.rs).
    pub dfc_w: Vec<Force>,
    /// Per body `I^c s`, `dI^c/dt s`, `s x* h^c` (world coordinates, derivatives.rs).
    pub alpha: Vec<Force>,
    pub beta: Vec<Force>,
    pub sigma: Vec<Force>,
    /// Sums over each subtree of the external forces, their moments and `f p^T` (derivatives.rs).
    pub ext_f: Vec<Vec3>,
    pub ext_n: Vec<Vec3>,
    pub ext_p: Vec<Mat3>,

    // ---- derivatives (derivatives.rs): tangents of one sweep, body coordinates ----
    /// Derivatives of twist, acceleration and composite force along q_j and along qd_j.
    pub tangent_q: Vec<Tangent>,
    pub tangent_qd: Vec<Tangent>,
    /// `psi_i`: the moved coordinate's joint axis in body i's coordinates.
    pub dpsi: Vec<Motion>,
    /// Whether body i moves with the coordinate of the sweep.
    pub moved: Vec<bool>,
    /// Body momenta `I_i v_i` (body coordinates).
    pub iv: Vec<Force>,
    /// Forward dynamics' qdd while its derivatives are taken.
    pub qdd_fd: Vec<f64>,

    // ---- gravity (gravity.rs) ----
    /// Composite mass and first moment of each subtree, body coordinates.
    pub mc: Vec<f64>,
    pub hc: Vec<Vec3>,
    /// Gravity acceleration in body axes.
    pub g_b: Vec<Vec3>,
}

impl Data {
    pub fn new(model: &Model) -> Self {
        let n = model.n;
        Self {
            parent_from_body: vec![Transform::identity(); n],
            world_from_body: vec![Transform::identity(); n],
            sin: vec![0.0; n],
            cos: vec![1.0; n],
            s: model.joints.iter().map(|j| j.subspace()).collect(),
            v: vec![Motion::zero(); n],
            a: vec![Motion::zero(); n],
            f: vec![Force::zero(); n],
            ic: vec![Inertia::zero(); n],
            tau: vec![0.0; n],
            m: vec![0.0; n * n],
            ia: vec![ArticulatedInertia::default(); n],
            pa: vec![Force::zero(); n],
            u_f: vec![Force::zero(); n],
            d_inv: vec![0.0; n],
            u: vec![0.0; n],
            c: vec![Motion::zero(); n],
            qdd: vec![0.0; n],
            m2: vec![0.0; n * n],
            x: vec![0.0; n],
            s_w: vec![Motion::zero(); n],
            v_w: vec![Motion::zero(); n],
            sd_w: vec![Motion::zero(); n],
            i_w: vec![Inertia::zero(); n],
            ic_w: vec![Inertia::zero(); n],
            icd_w: vec![Inertia::zero(); n],
            hc_w: vec![Force::zero(); n],
            a_w: vec![Motion::zero(); n],
            fc_w: vec![Force::zero(); n],
            dfc_w: vec![Force::zero(); n],
            alpha: vec![Force::zero(); n],
            beta: vec![Force::zero(); n],
            sigma: vec![Force::zero(); n],
            ext_f: vec![Vec3::zeros(); n],
            ext_n: vec![Vec3::zeros(); n],
            ext_p: vec![Mat3::zeros(); n],
            tangent_q: vec![Tangent::default(); n],
            tangent_qd: vec![Tangent::default(); n],
            dpsi: vec![Motion::zero(); n],
            moved: vec![false; n],
            iv: vec![Force::zero(); n],
            qdd_fd: vec![0.0; n],
            mc: vec![0.0; n],
            hc: vec![Vec3::zeros(); n],
            g_b: vec![Vec3::zeros(); n],
        }
    }
}
