//! The core's Lie-group operations of configurations (`kinedyn_core::lie`) on arrays: `q ⊕ v` and
//! `difference(q0, q1)` of a sequence of joint blocks, over one state or a batch (leading axes).
//! Blocks cross as names ("floating", "spherical", "planar", "" for a 1-DOF joint), decoded by
//! `JointType::block_of_kind`; no `Model` is needed (a symbolic robot's joints have blocks too).

use kinedyn_core::joint::JointType;
use kinedyn_core::lie::Block;
use kinedyn_core::lie::{
    difference_block, difference_jacobians_block, integrate_block, integrate_jacobians_block, GroupJacobians, Square,
};
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

/// A block's two Jacobians (its nv x nv in their top-left).
type Pair = (Square, Square);
/// Two arrays returned together.
type Arrays2<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

/// Writes each state's block-diagonal Jacobians: for state `s`, `per_block(s, block, at_q, at_v)`
/// gives the block's pair, placed at rows and columns `at_v..at_v + nv` of the state's two (nv, nv)
/// outputs. Returns the two arrays (..., nv, nv).
fn block_diagonal<'py>(
    py: Python<'py>,
    what: &str,
    blocks: &[Block],
    lead: &[usize],
    per_block: impl Fn(usize, Block, usize, usize) -> Pair,
) -> PyResult<Arrays2<'py>> {
    let nv: usize = blocks.iter().map(|b| b.nv()).sum();
    let shape: Vec<usize> = lead.iter().copied().chain([nv, nv]).collect();
    let (first, second) = (
        guard::zeros::<f64>(py, what, &shape)?,
        guard::zeros::<f64>(py, what, &shape)?,
    );
    // SAFETY: created above; nothing else refers to them yet
    let (a, b) = unsafe { (first.as_slice_mut()?, second.as_slice_mut()?) };
    let count: usize = lead.iter().product();
    for s in 0..count {
        let (mut at, mut iv) = (0, 0);
        for &block in blocks {
            let (x, y) = per_block(s, block, at, iv);
            for i in 0..block.nv() {
                for j in 0..block.nv() {
                    let k = s * nv * nv + (iv + i) * nv + iv + j;
                    (a[k], b[k]) = (x[(i, j)], y[(i, j)]);
                }
            }
            (at, iv) = (at + block.nq(), iv + block.nv());
        }
    }
    Ok((first, second))
}

/// `(∂(q ⊕ v dt)/∂q, ∂(q ⊕ v dt)/∂v)` per joint block (`kinedyn_core::lie::integrate_jacobians_block`;
/// neither depends on q): `v` (..., nv); returns two (..., nv, nv), block diagonal.
#[pyfunction]
pub fn lie_integrate_jacobians<'py>(
    py: Python<'py>,
    names: Vec<String>,
    v: PyReadonlyArrayDyn<'py, f64>,
    dt: f64,
) -> PyResult<Arrays2<'py>> {
    guarded("lie_integrate_jacobians", || {
        let blocks = blocks(&names)?;
        let nv = blocks.iter().map(|b| b.nv()).sum();
        let (v, lead) = states("v", &v, nv, None)?;
        block_diagonal(py, "lie_integrate_jacobians", &blocks, &lead, |s, block, _, iv| {
            integrate_jacobians_block(block, &v[s * nv + iv..], dt)
        })
    })
}

/// `(∂ difference/∂q0, ∂ difference/∂q1)` per joint block
/// (`kinedyn_core::lie::difference_jacobians_block`): `q0`, `q1` (..., nq) with the same leading axes;
/// returns two (..., nv, nv), block diagonal.
#[pyfunction]
pub fn lie_difference_jacobians<'py>(
    py: Python<'py>,
    names: Vec<String>,
    q0: PyReadonlyArrayDyn<'py, f64>,
    q1: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Arrays2<'py>> {
    guarded("lie_difference_jacobians", || {
        let blocks = blocks(&names)?;
        let nq = blocks.iter().map(|b| b.nq()).sum();
        let (q0, lead) = states("q0", &q0, nq, None)?;
        let (q1, _) = states("q1", &q1, nq, Some(&lead))?;
        block_diagonal(py, "lie_difference_jacobians", &blocks, &lead, |s, block, at, _| {
            difference_jacobians_block(block, &q0[s * nq + at..], &q1[s * nq + at..])
        })
    })
}

/// `(Ad(Exp(τ)), Jl(τ), Jl(τ)⁻¹)` of one joint kind's group ("floating", "spherical", "planar", ""
/// for a 1-DOF joint) at tangent vectors `tau` (..., nv) (`kinedyn_core::lie::GroupJacobians`);
/// returns three (..., nv, nv).
#[pyfunction]
pub fn lie_group_jacobians<'py>(
    py: Python<'py>,
    kind: String,
    tau: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    guarded("lie_group_jacobians", || {
        let block = blocks(std::slice::from_ref(&kind))?[0];
        let nv = block.nv();
        let (tau, lead) = states("tau", &tau, nv, None)?;
        let shape: Vec<usize> = lead.iter().copied().chain([nv, nv]).collect();
        let outs = [0, 1, 2].map(|_| guard::zeros::<f64>(py, "lie_group_jacobians", &shape));
        let [ad, jl, jl_inv] = outs;
        let (ad, jl, jl_inv) = (ad?, jl?, jl_inv?);
        // SAFETY: created above; nothing else refers to them yet
        let (a, b, c) = unsafe { (ad.as_slice_mut()?, jl.as_slice_mut()?, jl_inv.as_slice_mut()?) };
        for (s, t) in tau.chunks(nv).enumerate() {
            let g = GroupJacobians::at(block, t);
            for i in 0..nv {
                for j in 0..nv {
                    let k = s * nv * nv + i * nv + j;
                    (a[k], b[k], c[k]) = (g.ad[(i, j)], g.jl[(i, j)], g.jl_inv[(i, j)]);
                }
            }
        }
        pyo3::types::PyTuple::new(py, [ad, jl, jl_inv])
    })
}

/// The core's SO(3) operations on unit quaternions (x, y, z, w) over leading axes (`a` and `b` with
/// the same ones): `op` "multiply" (a ⊗ b, (..., 4) x (..., 4) -> (..., 4)), "rotate" (R(a) b, (..., 4)
/// x (..., 3) -> (..., 3)), "matrix" (R(a), (..., 4) -> (..., 3, 3)), "exp" ((..., 3) -> (..., 4)),
/// "log" ((..., 4) -> (..., 3), the angle in [0, π]).
#[pyfunction]
#[pyo3(signature = (op, a, b=None))]
pub fn lie_quaternion<'py>(
    py: Python<'py>,
    op: &str,
    a: PyReadonlyArrayDyn<'py, f64>,
    b: Option<PyReadonlyArrayDyn<'py, f64>>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    use kinedyn_core::lie::{exp3, log3, quat_mul, quat_rotate, quaternion_matrix};
    guarded("lie_quaternion", || {
        let (wa, wb, each): (usize, usize, &[usize]) = match op {
            "multiply" => (4, 4, &[4]),
            "rotate" => (4, 3, &[3]),
            "matrix" => (4, 0, &[3, 3]),
            "exp" => (3, 0, &[4]),
            "log" => (4, 0, &[3]),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "unknown quaternion operation '{op}' (multiply, rotate, matrix, exp, log)"
                )))
            }
        };
        let (x, lead) = states("a", &a, wa, None)?;
        let y = match (wb, b) {
            (0, None) => Vec::new(),
            (w, Some(b)) if w > 0 => states("b", &b, w, Some(&lead))?.0,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "'{op}' takes {} arrays",
                    1 + (wb > 0) as usize
                )))
            }
        };
        let width: usize = each.iter().product();
        let shape: Vec<usize> = lead.iter().copied().chain(each.iter().copied()).collect();
        let out = guard::zeros::<f64>(py, "lie_quaternion", &shape)?;
        // SAFETY: created above; nothing else refers to it yet
        let o = unsafe { out.as_slice_mut()? };
        let count: usize = lead.iter().product();
        let q4 = |v: &[f64]| [v[0], v[1], v[2], v[3]];
        for s in 0..count {
            let (a, r) = (&x[s * wa..(s + 1) * wa], &mut o[s * width..(s + 1) * width]);
            match op {
                "multiply" => r.copy_from_slice(&quat_mul(q4(a), q4(&y[s * 4..]))),
                "rotate" => r.copy_from_slice(&quat_rotate(q4(a), [y[s * 3], y[s * 3 + 1], y[s * 3 + 2]])),
                "matrix" => {
                    let m = quaternion_matrix(a);
                    (0..9).for_each(|k| r[k] = m[(k / 3, k % 3)]);
                }
                "exp" => r.copy_from_slice(&exp3([a[0], a[1], a[2]])),
                _ => r.copy_from_slice(&log3(q4(a))),
            }
        }
        Ok(out)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lie_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(lie_integrate, m)?)?;
    m.add_function(wrap_pyfunction!(lie_difference, m)?)?;
    m.add_function(wrap_pyfunction!(lie_integrate_jacobians, m)?)?;
    m.add_function(wrap_pyfunction!(lie_difference_jacobians, m)?)?;
    m.add_function(wrap_pyfunction!(lie_group_jacobians, m)?)?;
    Ok(())
}
