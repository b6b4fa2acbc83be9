//! Centre of mass and spatial momentum of the whole robot.
//!
//! Source: RBDA §2.13 (momentum `h = I v` of a body) summed in base coordinates, and the first
//! moment `h = m c` of eq. 2.63: `c = sum_i world_from_body_i(h_i) / sum_i m_i`.
//!
//! | symbol   | here                 | meaning                                                  |
//! |----------|----------------------|----------------------------------------------------------|
//! | `h_i`    | `I_i v_i`            | body momentum, body coordinates                          |
//! | `h`      | returned `Force`     | `[linear momentum; angular momentum about base origin]`  |
//! | `c`      | returned `Vec3`      | centre of mass of the moving bodies in base coordinates   |
//! | `A_G`    | `out` (row-major 6 x n) | centroidal momentum matrix, `h_G = A_G qd`            |
//!
//! The centroidal momentum matrix (Orin, Goswami & Lee, "Centroidal dynamics of a humanoid robot",
//! Auton. Robots 35, 2013, eq. 23: `A_G = sum_i ^iX_G^T I_i J_i`) maps the joint rates to the
//! momentum about the centre of mass, `h_G = [m c_dot; L_G]` in base axes. Summing the bodies'
//! inertias over each subtree first (as the CRBA), column j is the composite inertia of the
//! subtree that coordinate j moves times its axis, `I^c_j s_j` (world coordinates, about the
//! origin), with the moment moved to the centre of mass: `n_G = n_O - c x f`.

use super::kinematics::forward_kinematics as fk;
use super::kinematics::{forward_kinematics, forward_velocity};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{Force, Vec3};

/// Centre of mass of the moving bodies, base coordinates; an error if their total mass is zero.
pub fn center_of_mass(model: &Model, data: &mut Data, q: &[f64]) -> Result<Vec3> {
    forward_kinematics(model, data, q);
    // c = sum_i (R_i h_i + m_i p_i) / sum_i m_i
    let (mut m, mut h) = (0.0, Vec3::zeros());
    for i in 0..model.n {
        let x = &data.world_from_body[i];
        let inertia = &model.inertia[i];
        m += inertia.mass;
        h += x.rot * inertia.h + inertia.mass * x.trans;
    }
    if m.is_nan() || m <= 0.0 {
        return Err(Error::InvalidModel(
            "the centre of mass is undefined: the moving bodies have zero total mass".into(),
        ));
    }
    Ok(h / m)
}

/// Spatial momentum `sum_i ^0X_i^* I_i v_i`: `[p; L_o]`, L about the base origin, base axes.
pub fn spatial_momentum(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> Force {
    forward_velocity(model, data, q, qd);
    // h = sum_i ^0X_i^* (I_i v_i)
    (0..model.n).fold(Force::zero(), |acc, i| {
        acc + data.world_from_body[i].act_force(&model.inertia[i].mul_motion(&data.v[i]))
    })
}

/// The centroidal momentum matrix `A_G` (6 x n, row-major, `[linear; angular about the centre of
/// mass]` in base axes) into `out`, and the centre of mass; an error for zero total mass.
pub fn centroidal_momentum_matrix(model: &Model, data: &mut Data, q: &[f64], out: &mut [f64]) -> Result<Vec3> {
    let n = model.n;
    fk(model, data, q);
    // I^c_i = sum over subtree(i) of ^0X_k^* I_k ^kX_0 (world coordinates, about the origin)
    for i in 0..n {
        let x = &data.world_from_body[i];
        data.s_w[i] = x.act_motion(&data.s[i]);
        data.ic_w[i] = x.act_inertia(&model.inertia[i]);
    }
    let (mut mass, mut first_moment) = (0.0, Vec3::zeros());
    for i in (0..n).rev() {
        match model.parent[i] {
            Some(p) => {
                let ic = data.ic_w[i];
                data.ic_w[p] += ic;
            }
            None => {
                mass += data.ic_w[i].mass;
                first_moment += data.ic_w[i].h;
            }
        }
    }
    if mass.is_nan() || mass <= 0.0 {
        return Err(Error::InvalidModel(
            "the centre of mass is undefined: the moving bodies have zero total mass".into(),
        ));
    }
    let c = first_moment / mass;
    for j in 0..n {
        // A_G[:, j] = (f, n_O - c x f) with (f, n_O) = I^c_j s_j
        let f = data.ic_w[j].mul_motion(&data.s_w[j]);
        let column = [
            f.lin.x,
            f.lin.y,
            f.lin.z,
            f.ang.x - (c.y * f.lin.z - c.z * f.lin.y),
            f.ang.y - (c.z * f.lin.x - c.x * f.lin.z),
            f.ang.z - (c.x * f.lin.y - c.y * f.lin.x),
        ];
        for (r, value) in column.iter().enumerate() {
            out[r * n + j] = *value;
        }
    }
    Ok(c)
}
