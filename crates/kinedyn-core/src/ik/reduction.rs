//! Reduced coordinates of a model with mimic joints, for the numeric solver: `q_full = expand(q)`
//! affine and `v_full = G v` (Pinocchio 3 reduces mimic joints the same way).
//!
//! | symbol   | here        | meaning                                                     |
//! |----------|-------------|-------------------------------------------------------------|
//! | `q`      | reduced q   | the kept (leader and free) configuration coordinates        |
//! | `G`      | `v_source`  | `v_full = G v`, one nonzero per row                         |

use crate::model::{Coordinates, Model};

/// Reduced coordinates of a model whose mimic joints follow their leaders (as Pinocchio 3 reduces
/// them; `python/kinedyn/description/mimic.py`): `q_full = expand(q)` is affine and `v_full = G v`
/// with a constant `G` whose every row has one nonzero, so a frame's Jacobian in the reduced
/// coordinates is `J G` (chain rule) and `q ⊕ dq` is `q_full ⊕ G dq` read back at the kept entries.
#[derive(Clone, Debug)]
pub struct Reduction {
    /// Per full q coordinate i: `(k, m, b)` with `q_full[i] = m q[k] + b`.
    pub q_source: Vec<(usize, f64, f64)>,
    /// Per full velocity coordinate i: `(k, m)` with `v_full[i] = m v[k]` (row i of G).
    pub v_source: Vec<(usize, f64)>,
    /// The full q index of each reduced coordinate: `q[k] = q_full[q_keep[k]]`.
    pub q_keep: Vec<usize>,
    /// Number of reduced velocity coordinates.
    pub nv: usize,
}

impl Reduction {
    /// Checked against `model`: sizes, indices, each kept coordinate maps to itself, and every
    /// multi-DOF joint is kept whole (its q and v blocks copied, in order).
    pub fn new(
        model: &Model,
        q_source: Vec<(usize, f64, f64)>,
        v_source: Vec<(usize, f64)>,
        q_keep: Vec<usize>,
        nv: usize,
    ) -> Result<Self, String> {
        let (nq_full, nv_full, nq) = (model.nq, model.n, q_keep.len());
        if q_source.len() != nq_full || v_source.len() != nv_full {
            return Err(format!(
                "a reduction maps {nq_full} q and {nv_full} v coordinates of the model; got {} and {}",
                q_source.len(),
                v_source.len()
            ));
        }
        if let Some((i, _)) = q_source
            .iter()
            .enumerate()
            .find(|(_, (k, m, b))| *k >= nq || !m.is_finite() || !b.is_finite())
        {
            return Err(format!("reduction: full q coordinate {i} reads reduced coordinate {} of {nq} (or a non-finite multiplier/offset)", q_source[i].0));
        }
        if let Some((i, _)) = v_source
            .iter()
            .enumerate()
            .find(|(_, (k, m))| *k >= nv || !m.is_finite())
        {
            return Err(format!(
                "reduction: full v coordinate {i} reads reduced velocity {} of {nv} (or a non-finite multiplier)",
                v_source[i].0
            ));
        }
        for (k, &i) in q_keep.iter().enumerate() {
            if i >= nq_full || q_source[i] != (k, 1.0, 0.0) {
                return Err(format!(
                    "reduction: reduced coordinate {k} is kept at full coordinate {i}, which does not copy it"
                ));
            }
        }
        for (qi, vi) in model.scalar_coordinates() {
            if q_keep[q_source[qi].0] == qi && v_source[vi].1 != 1.0 {
                return Err(format!(
                    "reduction: the independent joint at body {vi} must copy its velocity (multiplier 1, got {})",
                    v_source[vi].1
                ));
            }
        }
        for (i, c) in model.coordinates.iter().enumerate() {
            if let Coordinates::Head { block, at } = *c {
                let k0 = q_source[at].0;
                let kv0 = v_source[i].0;
                let whole = (0..block.nq()).all(|j| q_source[at + j] == (k0 + j, 1.0, 0.0) && q_keep[k0 + j] == at + j)
                    && (0..block.nv()).all(|j| v_source[i + j] == (kv0 + j, 1.0));
                if !whole {
                    return Err(format!("reduction: the {block:?} joint at body {i} must be kept whole (no mimic joint follows a multi-DOF joint)"));
                }
            }
        }
        Ok(Self {
            q_source,
            v_source,
            q_keep,
            nv,
        })
    }
}
