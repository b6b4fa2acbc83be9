//! The joint records `_core.Model` takes: one mapping per joint, taken whole (multi-DOF joints
//! included), converted into the core's [`JointRecord`]s and frames for its [`ModelBuilder`], which
//! expands and checks them (docs/architecture.md, "The joint seam"). Every error names the joint
//! and the key.

use kinedyn_core::joint::JointType;
use kinedyn_core::model::{JointRecord, ModelBuilder};
use kinedyn_core::spatial::{Inertia, Transform, Vec3};
use kinedyn_core::Model;
use numpy::PyArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::conv::numbers;
use crate::run::core_err;

/// The keys of a joint record; the first three have no default.
const KEYS: [&str; 12] = [
    "name",
    "kind",
    "placement",
    "parent",
    "axis",
    "inertia",
    "link_origin",
    "offset",
    "armature",
    "viscous",
    "coulomb",
    "coulomb_negative",
];

/// Joint `k`'s record from its mapping.
fn record(k: usize, d: &Bound<'_, PyDict>) -> PyResult<JointRecord> {
    let name: String = match d.get_item("name")? {
        Some(x) => x
            .extract()
            .map_err(|_| PyValueError::new_err(format!("joint {k}: 'name' must be a string")))?,
        None => return Err(PyValueError::new_err(format!("joint {k}: the record has no 'name'"))),
    };
    let what = |key: &str| format!("joint {k} '{name}': {key}");
    for key in d.keys() {
        let key: String = key.extract()?;
        if !KEYS.contains(&key.as_str()) {
            return Err(PyValueError::new_err(format!(
                "joint {k} '{name}': unknown key '{key}' (expected some of {KEYS:?})"
            )));
        }
    }
    let required = |key: &str| -> PyResult<Bound<'_, PyAny>> {
        d.get_item(key)?
            .ok_or_else(|| PyValueError::new_err(format!("joint {k} '{name}': the record has no '{key}'")))
    };
    let number = |key: &str| -> PyResult<f64> {
        match d.get_item(key)? {
            None => Ok(0.0),
            Some(x) => x
                .extract()
                .map_err(|_| PyValueError::new_err(format!("{} must be a number", what(key)))),
        }
    };
    let kind: String = required("kind")?
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{} must be a string", what("kind"))))?;
    let axis = match d.get_item("axis")? {
        Some(a) if !a.is_none() => Some(Vec3::from_column_slice(&numbers(&what("axis"), &a, &[3])?)),
        _ => None,
    };
    let joint =
        JointType::from_name(&kind, axis).map_err(|e| PyValueError::new_err(format!("joint {k} '{name}': {e}")))?;
    let parent = match d.get_item("parent")? {
        None => None,
        Some(p) => match p.extract::<i64>() {
            Ok(-1) => None,
            Ok(p) if p >= 0 => Some(p as usize),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "{} must be an earlier joint's index or -1 (the base), got {p}",
                    what("parent")
                )))
            }
        },
    };
    let placement = Transform::from_homogeneous(&numbers(&what("placement"), &required("placement")?, &[4, 4])?);
    let inertia = match d.get_item("inertia")? {
        Some(x) => Inertia::from_parameters(&numbers(&what("inertia"), &x, &[10])?),
        None => Inertia::zero(),
    };
    // the link frame's origin in the joint frame (where the moments of f_ext are taken): zero by default
    let link_origin = match d.get_item("link_origin")? {
        Some(u) if !u.is_none() => Vec3::from_column_slice(&numbers(&what("link_origin"), &u, &[3])?),
        _ => Vec3::zeros(),
    };
    let coulomb_negative = match d.get_item("coulomb_negative")? {
        Some(x) if !x.is_none() => Some(number("coulomb_negative")?),
        _ => None,
    };
    Ok(JointRecord {
        offset: number("offset")?,
        armature: number("armature")?,
        viscous: number("viscous")?,
        coulomb: number("coulomb")?,
        coulomb_negative,
        link_origin,
        ..JointRecord::new(&name, joint, parent, placement, inertia)
    })
}

/// The model of `joints` (records in order, parents first), `frames` ((joint index or -1, (4, 4)
/// placement in that joint's link) each) under `gravity`.
pub(crate) fn build(
    joints: &[Bound<'_, PyDict>],
    gravity: &Bound<'_, PyAny>,
    frames: &[(i64, Bound<'_, PyAny>)],
) -> PyResult<Model> {
    let g = numbers("gravity", gravity, &[3])?;
    let mut builder = ModelBuilder::new(Vec3::new(g[0], g[1], g[2]));
    for (k, d) in joints.iter().enumerate() {
        builder.joint(record(k, d)?).map_err(core_err)?;
    }
    for (k, (joint, placement)) in frames.iter().enumerate() {
        let joint = match *joint {
            -1 => None,
            j if j >= 0 => Some(j as usize),
            j => {
                return Err(PyValueError::new_err(format!(
                    "frame {k}: joint index {j} is out of range (-1 for the base)"
                )))
            }
        };
        let placement = numbers(&format!("placement of frame {k}"), placement, &[4, 4])?;
        builder
            .frame(joint, Transform::from_homogeneous(&placement))
            .map_err(core_err)?;
    }
    builder.build().map_err(core_err)
}

/// The motion `joint_from_body` (4, 4) of a joint of `kind` (with its `axis`, the planar joint's
/// normal; None for "floating" and "spherical") at its block of q: the core's
/// `JointType::transform` (what `Robot.lock_joints` folds into a placement). ValueError for a block
/// of the wrong length, not finite, or whose quaternion / (cos, sin) pair is not unit.
#[pyfunction]
#[pyo3(signature = (kind, axis, q))]
pub(crate) fn joint_transform<'py>(
    py: Python<'py>,
    kind: &str,
    axis: Option<Bound<'py, PyAny>>,
    q: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let axis = match axis {
        Some(a) if !a.is_none() => Some(Vec3::from_column_slice(&numbers("axis", &a, &[3])?)),
        _ => None,
    };
    let joint = JointType::from_name(kind, axis).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let q = crate::conv::f64_array("q", &q)?;
    let q: Vec<f64> = q.readonly().as_array().iter().copied().collect();
    let t = joint.transform(&q).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let m = t.to_homogeneous(); // row-major
    let rows: Vec<Vec<f64>> = m.chunks(4).map(<[f64]>::to_vec).collect();
    Ok(numpy::PyArray2::from_vec2(py, &rows)?)
}
