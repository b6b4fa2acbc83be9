//! Torque sources of a run: the [`TorqueFn`] trait (a torque and, for the implicit step, its
//! derivatives with respect to the state), any closure, and samples held or interpolated.
//!
//! | symbol | here     | meaning                                                    |
//! |--------|----------|------------------------------------------------------------|
//! | `tau`  | `out`    | joint torque at `(t, q, qd)`, length `n`                   |
//! | `t_k`  | `t0 + k dt` | time of sample `k`                                      |

/// The torque source: `tau(t, q, qd, out)`; an `Err` stops the run with [`FailureKind::Source`](super::FailureKind::Source).
pub trait TorqueFn {
    fn torque(
        &mut self,
        step: usize,
        t: f64,
        q: &[f64],
        qd: &[f64],
        out: &mut [f64],
    ) -> std::result::Result<(), String>;

    /// `dtau/dq` and `dtau/dqd` (row-major n x n, `[i * n + j] = dtau_i / dx_j`) at a state, for
    /// the implicit method; `Ok(false)` (the default) when the torque does not depend on the state
    /// or its derivatives are unknown (they are then left out of the step's Jacobian).
    fn jacobian(
        &mut self,
        _step: usize,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        _dtau_dq: &mut [f64],
        _dtau_dqd: &mut [f64],
    ) -> std::result::Result<bool, String> {
        Ok(false)
    }

    /// External wrenches at a state into `out` (`n * 6`: per body `[force; moment]` in base axes,
    /// the moment about the body's link-frame origin, as [`crate::algorithms::rnea`] takes them),
    /// evaluated at every stage; `Ok(false)` (the default): none.
    fn wrenches(
        &mut self,
        _step: usize,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        _out: &mut [f64],
    ) -> std::result::Result<bool, String> {
        Ok(false)
    }
}

/// A torque source with constant external wrenches `f_ext` (`n * 6`, as [`TorqueFn::wrenches`]).
pub struct WithWrenches<'a, S> {
    pub source: S,
    pub f_ext: &'a [f64],
}

impl<S: TorqueFn> TorqueFn for WithWrenches<'_, S> {
    fn torque(
        &mut self,
        step: usize,
        t: f64,
        q: &[f64],
        qd: &[f64],
        out: &mut [f64],
    ) -> std::result::Result<(), String> {
        self.source.torque(step, t, q, qd, out)
    }

    fn jacobian(
        &mut self,
        step: usize,
        t: f64,
        q: &[f64],
        qd: &[f64],
        dtau_dq: &mut [f64],
        dtau_dqd: &mut [f64],
    ) -> std::result::Result<bool, String> {
        self.source.jacobian(step, t, q, qd, dtau_dq, dtau_dqd)
    }

    fn wrenches(
        &mut self,
        _step: usize,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        out: &mut [f64],
    ) -> std::result::Result<bool, String> {
        out.copy_from_slice(self.f_ext);
        Ok(true)
    }
}

impl<F: FnMut(usize, f64, &[f64], &[f64], &mut [f64]) -> std::result::Result<(), String>> TorqueFn for F {
    fn torque(
        &mut self,
        step: usize,
        t: f64,
        q: &[f64],
        qd: &[f64],
        out: &mut [f64],
    ) -> std::result::Result<(), String> {
        self(step, t, q, qd, out)
    }
}

/// Torque from samples at `t0 + k dt`, `k = 0..`, row-major `(samples, n)`: one row is a constant,
/// no rows is zero. `linear`: interpolate between samples `k` and `k + 1` (needs `steps + 1` rows);
/// else hold sample `k` over step `k` (zero-order hold; needs `steps` rows).
pub struct Sampled<'a> {
    pub values: &'a [f64],
    pub n: usize,
    pub t0: f64,
    pub dt: f64,
    pub linear: bool,
}

impl TorqueFn for Sampled<'_> {
    fn torque(
        &mut self,
        step: usize,
        t: f64,
        _q: &[f64],
        _qd: &[f64],
        out: &mut [f64],
    ) -> std::result::Result<(), String> {
        let n = self.n;
        let rows = self.values.len() / n.max(1);
        match rows {
            0 => out.fill(0.0),
            1 => out.copy_from_slice(&self.values[..n]),
            _ => {
                let k = step.min(rows - 1);
                let row = |k: usize| &self.values[k * n..(k + 1) * n];
                if self.linear && k + 1 < rows {
                    // tau(t) = (1 - s) tau_k + s tau_{k+1},  s = (t - t_k) / dt
                    let s = ((t - (self.t0 + k as f64 * self.dt)) / self.dt).clamp(0.0, 1.0);
                    for ((o, a), b) in out.iter_mut().zip(row(k)).zip(row(k + 1)) {
                        *o = (1.0 - s) * a + s * b;
                    }
                } else {
                    out.copy_from_slice(row(k));
                }
            }
        }
        Ok(())
    }
}
