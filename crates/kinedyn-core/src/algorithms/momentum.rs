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
    if !(m > 0.0) {
        return Err(Error::InvalidModel("the centre of mass is undefined: the moving bodies have zero total mass".into()));
    }
    Ok(h / m)
}

/// Spatial momentum `sum_i ^0X_i^* I_i v_i`: `[p; L_o]`, L about the base origin, base axes.
pub fn spatial_momentum(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> Force {
    forward_velocity(model, data, q, qd);
    // h = sum_i ^0X_i^* (I_i v_i)
    (0..model.n).fold(Force::zero(), |acc, i| acc + data.world_from_body[i].act_force(&model.inertia[i].mul_motion(&data.v[i])))
}
