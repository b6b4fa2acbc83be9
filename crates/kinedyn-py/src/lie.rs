//! The core's Lie-group operations of configurations (`kinedyn_core::lie`) on arrays: `q ⊕ v` and
//! `difference(q0, q1)` of a sequence of joint blocks, over one state or a batch (leading axes).
//! Blocks cross as names ("floating", "spherical", "planar", "" for a 1-DOF joint), decoded by
//! `JointType::block_of_kind`; no `Model` is needed (a symbolic robot's joints have blocks too).

use kinedyn_core::joint::JointType;
use kinedyn_core::lie::{difference_block, integrate_block, Block};
use numpy::{PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::guard::{self, guarded};

fn blocks(names: &[String]) -> PyResult<Vec<Block>> {
    names
        .iter()
        .enumerate()
        .map(|(i, name)| JointType::block_of_kind(name).map_err(|e| PyValueError::new_err(format!("joint {i}: {e}"))))
        .collect()
}

/// `a`'s numbers in C order after checking that its last axis has `width` entries and its leading
/// axes are `lead` (when given): (the numbers, the leading axes).
fn states(
    name: &str,
    a: &PyReadonlyArrayDyn<f64>,
    width: usize,
    lead: Option<&[usize]>,
) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let shape = a.shape();
    let ok = shape.last() == Some(&width) && lead.is_none_or(|l| &shape[..shape.len() - 1] == l);
    if !ok {
        let mut want: Vec<String> = lead
            .unwrap_or(&shape[..shape.len().saturating_sub(1)])
            .iter()
            .map(|d| d.to_string())
            .collect();
        want.push(width.to_string());
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({}), got {shape:?}",
            want.join(", ")
        )));
    }
    let view = a.as_array();
    let mut v = guard::try_vec(&format!("copying {name}"), view.len())?;
    v.extend(view.iter().copied());
    Ok((v, shape[..shape.len() - 1].to_vec()))
}

/// `q ⊕ v` per joint block (`kinedyn_core::lie::integrate_block`): `q` (..., nq), `v` (..., nv)
/// with the same leading axes; returns (..., nq).
#[pyfunction]
pub fn lie_integrate<'py>(
    py: Python<'py>,
    names: Vec<String>,
    q: PyReadonlyArrayDyn<'py, f64>,
    v: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    guarded("lie_integrate", || {
        let blocks = blocks(&names)?;
        let (nq, nv) = blocks.iter().fold((0, 0), |(a, b), k| (a + k.nq(), b + k.nv()));
        let (q, lead) = states("q", &q, nq, None)?;
        let (v, _) = states("v", &v, nv, Some(&lead))?;
        let shape: Vec<usize> = lead.iter().copied().chain([nq]).collect();
        let out = guard::zeros::<f64>(py, "lie_integrate", &shape)?;
        // SAFETY: created above; nothing else refers to it yet
        let o = unsafe { out.as_slice_mut()? };
        for (s, (qs, vs)) in q.chunks(nq.max(1)).zip(v.chunks(nv.max(1))).enumerate() {
            let (mut at, mut iv) = (0, 0);
            for &b in &blocks {
                integrate_block(b, &qs[at..], &vs[iv..], 1.0, &mut o[s * nq + at..s * nq + at + b.nq()]);
                (at, iv) = (at + b.nq(), iv + b.nv());
            }
        }
        Ok(out)
    })
}

/// `difference(q0, q1)` per joint block (`kinedyn_core::lie::difference_block`): the v with
/// q0 ⊕ v = q1; `q0`, `q1` (..., nq) with the same leading axes; returns (..., nv).
#[pyfunction]
pub fn lie_difference<'py>(
    py: Python<'py>,
    names: Vec<String>,
    q0: PyReadonlyArrayDyn<'py, f64>,
    q1: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    guarded("lie_difference", || {
        let blocks = blocks(&names)?;
        let (nq, nv) = blocks.iter().fold((0, 0), |(a, b), k| (a + k.nq(), b + k.nv()));
        let (q0, lead) = states("q0", &q0, nq, None)?;
        let (q1, _) = states("q1", &q1, nq, Some(&lead))?;
        let shape: Vec<usize> = lead.iter().copied().chain([nv]).collect();
        let out = guard::zeros::<f64>(py, "lie_difference", &shape)?;
        // SAFETY: created above; nothing else refers to it yet
        let o = unsafe { out.as_slice_mut()? };
        for (s, (a, b)) in q0.chunks(nq.max(1)).zip(q1.chunks(nq.max(1))).enumerate() {
            let (mut at, mut iv) = (0, 0);
            for &k in &blocks {
                difference_block(k, &a[at..], &b[at..], &mut o[s * nv + iv..s * nv + iv + k.nv()]);
                (at, iv) = (at + k.nq(), iv + k.nv());
            }
        }
        Ok(out)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lie_integrate, m)?)?;
    m.add_function(wrap_pyfunction!(lie_difference, m)?)?;
    Ok(())
}
