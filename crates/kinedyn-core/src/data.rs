//! `Data`: per-thread scratch space and outputs of the algorithms (allocated once per model).
//!
//! Algorithms overwrite what they use; nothing here is a precondition of another algorithm
//! (no dirty flags): an algorithm that needs forward kinematics runs it.

use crate::model::Model;
use crate::spatial::{ArticulatedInertia, Force, Inertia, Mat3, Motion, Real, Transform, Vec3};

/// The derivatives of one body's twist, acceleration and composite force along one coordinate
/// (the tangent sweep of `algorithms::derivatives`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Tangent<T: Real = f64> {
    pub dv: Motion<T>,
    pub da: Motion<T>,
    pub dfc: Force<T>,
}

/// Generic over the scalar: `Data` (f64) for single calls, `Data<Lanes<N>>` for N states at once
/// (`crate::batch`).
#[derive(Clone, Debug)]
pub struct Data<T: Real = f64> {
    /// `parent_from_body[i]` at the last q (RBDA's `^i X_{lambda(i)}`, inverted).
    pub parent_from_body: Vec<Transform<T>>,
    /// `world_from_body[i]` at the last q.
    pub world_from_body: Vec<Transform<T>>,
    /// `sin` and `cos` of each joint coordinate `q_i + offset_i` (`kinematics::joint_trig`).
    pub sin: Vec<T>,
    pub cos: Vec<T>,
    /// Motion subspace `s_i` of each joint in its body frame.
    pub s: Vec<Motion<T>>,
    /// Body twists `v_i` in body coordinates.
    pub v: Vec<Motion<T>>,
    /// Body spatial accelerations `a_i` in body coordinates.
    pub a: Vec<Motion<T>>,
    /// Body forces `f_i` in body coordinates (RNEA's backward pass).
    pub f: Vec<Force<T>>,
    /// Composite / articulated inertias and other per-body scratch.
    pub ic: Vec<Inertia<T>>,
    /// Joint-space output vector (tau, qdd, ...), length n.
    pub tau: Vec<T>,
    /// Joint-space output matrix, row-major n x n (M, C, ...).
    pub m: Vec<T>,

    // ---- articulated-body algorithm (RBDA Table 7.1) ----
    /// Articulated inertias `IA_i` (body coordinates).
    pub ia: Vec<ArticulatedInertia<T>>,
    /// Articulated bias forces `pA_i` (body coordinates).
    pub pa: Vec<Force<T>>,
    /// `U_i = IA_i s_i`.
    pub u_f: Vec<Force<T>>,
    /// `1 / D_i`, `D_i = s_i^T U_i + armature_i`.
    pub d_inv: Vec<T>,
    /// `u_i = tau_i - s_i^T pA_i`.
    pub u: Vec<T>,
    /// Velocity-product accelerations `c_i = v_i x s_i qd_i`.
    pub c: Vec<Motion<T>>,
    /// Joint accelerations (forward dynamics output), length n.
    pub qdd: Vec<T>,
    /// Second joint-space matrix, row-major n x n (M^-1, factorisations).
    pub m2: Vec<T>,
    /// Joint-space scratch vector, length n.
    pub x: Vec<T>,

    // ---- Coriolis matrix, world coordinates (coriolis.rs) ----
    /// `s_i` in world coordinates.
    pub s_w: Vec<Motion<T>>,
    /// Body twists in world coordinates.
    pub v_w: Vec<Motion<T>>,
    /// `ds_i/dt = v_i x s_i` in world coordinates.
    pub sd_w: Vec<Motion<T>>,
    /// Body inertias in world coordinates.
    pub i_w: Vec<Inertia<T>>,
    /// Composite inertias and their time derivatives (world coordinates).
    pub ic_w: Vec<Inertia<T>>,
    pub icd_w: Vec<Inertia<T>>,
    /// Composite momenta `sum I_k v_k` over each subtree (world coordinates).
    pub hc_w: Vec<Force<T>>,
    /// Body accelerations (gravity included) and composite forces, world coordinates (derivatives.rs).
    pub a_w: Vec<Motion<T>>,
    pub fc_w: Vec<Force<T>>,
    /// Scratch composite force changes, world coordinates (derivatives.rs).
    pub dfc_w: Vec<Force<T>>,
    /// Per body `I^c s`, `dI^c/dt s`, `s x* h^c` (world coordinates, derivatives.rs).
    pub alpha: Vec<Force<T>>,
    pub beta: Vec<Force<T>>,
    pub sigma: Vec<Force<T>>,
    /// Sums over each subtree of the external forces, their moments and `f p^T` (derivatives.rs).
    pub ext_f: Vec<Vec3<T>>,
    pub ext_n: Vec<Vec3<T>>,
    pub ext_p: Vec<Mat3<T>>,

    // ---- derivatives (derivatives.rs): tangents of one sweep, body coordinates ----
    /// Derivatives of twist, acceleration and composite force along q_j and along qd_j.
    pub tangent_q: Vec<Tangent<T>>,
    pub tangent_qd: Vec<Tangent<T>>,
    /// `psi_i`: the moved coordinate's joint axis in body i's coordinates.
    pub dpsi: Vec<Motion<T>>,
    /// Whether body i moves with the coordinate of the sweep.
    pub moved: Vec<bool>,
    /// Body momenta `I_i v_i` (body coordinates).
    pub iv: Vec<Force<T>>,
    /// Forward dynamics' qdd while its derivatives are taken.
    pub qdd_fd: Vec<T>,

    // ---- gravity (gravity.rs) ----
    /// Composite mass and first moment of each subtree, body coordinates.
    pub mc: Vec<T>,
    pub hc: Vec<Vec3<T>>,
    /// Gravity acceleration in body axes.
    pub g_b: Vec<Vec3<T>>,

    // ---- closed loops (constraints/) ----
    pub loops: crate::constraints::LoopData<T>,
}

impl<T: Real> Data<T> {
    pub fn new(model: &Model) -> Self {
        let (zero, one) = (T::zero(), T::one());
        let n = model.n;
        Self {
            parent_from_body: vec![Transform::identity(); n],
            world_from_body: vec![Transform::identity(); n],
            sin: vec![zero; n],
            cos: vec![one; n],
            s: model.joints.iter().map(|j| j.subspace::<T>()).collect(),
            v: vec![Motion::zero(); n],
            a: vec![Motion::zero(); n],
            f: vec![Force::zero(); n],
            ic: vec![Inertia::zero(); n],
            tau: vec![zero; n],
            m: vec![zero; n * n],
            ia: vec![ArticulatedInertia::default(); n],
            pa: vec![Force::zero(); n],
            u_f: vec![Force::zero(); n],
            d_inv: vec![zero; n],
            u: vec![zero; n],
            c: vec![Motion::zero(); n],
            qdd: vec![zero; n],
            m2: vec![zero; n * n],
            x: vec![zero; n],
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
            qdd_fd: vec![zero; n],
            mc: vec![zero; n],
            hc: vec![Vec3::zeros(); n],
            g_b: vec![Vec3::zeros(); n],
            loops: crate::constraints::LoopData::new(model),
        }
    }
}
