//! A Python callable as the control law of every agent ([`attitude::law`]):
//! `attsync.run(scenario, law=f)`. The Python layer hands in an adapter
//! that takes plain numbers (built here, once per call) and gives `f` numpy
//! arrays; what comes back must be three finite numbers. A law that raises
//! or returns anything else is recorded (the first time: the agent, the
//! step, the stage, the cause) and its torque is NaN, so that the
//! divergence guard stops the run at the step's end; the caller then raises
//! `LawError` with what was recorded.

use attitude::law::{Law, LawInput};
use attitude::network::Exchanged;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::sync::Mutex;

/// Why a call of the law gave no torque.
#[derive(Debug, thiserror::Error)]
enum Failed {
    /// The law (or the adapter) raised: the Python exception, as text.
    #[error("{0}")]
    Raised(String),
    /// It returned something that is not 3 numbers.
    #[error("the law's torque is not 3 numbers: {0}")]
    NotThree(String),
    /// It returned a NaN or an infinity.
    #[error("the law returned a torque that is not finite: [{}, {}, {}]", .0[0], .0[1], .0[2])]
    NotFinite([f64; 3]),
}

/// A Python control law.
#[derive(Debug)]
pub struct PyLaw {
    adapter: Py<PyAny>,
    failed: Mutex<Option<String>>,
}

impl PyLaw {
    /// `adapter((agent, step, stage, t, dt), data, neighbours, has_leader,
    /// (k_r, k_ω))` as the law ([`Self::call`] says what `data` holds).
    pub fn new(adapter: Py<PyAny>) -> Self {
        Self {
            adapter,
            failed: Mutex::new(None),
        }
    }

    /// What made the law fail first, if it did.
    pub fn failure(&self) -> Option<String> {
        self.failed.lock().map_or(None, |f| f.clone())
    }

    /// One call: the torque, or why there is none. The numbers travel as
    /// one flat tuple (one numpy array on the other side, viewed in parts):
    /// the state (27), `ω̂̇` (3), the inertia (9), the leader's gain and
    /// value if heard (24), each neighbour's (24).
    fn call(&self, py: Python<'_>, i: &LawInput<'_>) -> Result<Vector3<f64>, Failed> {
        let s = i.state;
        let mut data: Vec<f64> = Vec::with_capacity(39 + 24 * (i.gains.len() + 1));
        data.extend(rows(&s.r));
        data.extend(s.w.iter());
        data.extend(rows(&s.r_hat));
        data.extend(
            s.w_hat
                .iter()
                .chain(s.s_hat.iter())
                .chain(i.w_hat_dot.iter()),
        );
        data.extend(rows(i.inertia));
        if let Some((a, x)) = i.leader {
            heard(&mut data, a, x);
        }
        for (a, x) in i.gains.iter().zip(i.neighbours) {
            heard(&mut data, a, x);
        }
        let args = (
            (i.agent, i.step, i.stage, i.t, i.dt),
            PyTuple::new(py, data).map_err(|e| Failed::Raised(e.to_string()))?,
            i.gains.len(),
            i.leader.is_some(),
            i.k,
        );
        let out = (self.adapter.call1(py, args)).map_err(|e| Failed::Raised(e.to_string()))?;
        let (a, b, c): (f64, f64, f64) = out
            .extract(py)
            .map_err(|e| Failed::NotThree(e.to_string()))?;
        if ![a, b, c].iter().all(|v| v.is_finite()) {
            return Err(Failed::NotFinite([a, b, c]));
        }
        Ok(Vector3::new(a, b, c))
    }
}

impl Law for PyLaw {
    fn torque(&self, i: &LawInput<'_>) -> Vector3<f64> {
        if self.failure().is_some() {
            return Vector3::repeat(f64::NAN);
        }
        Python::attach(|py| match self.call(py, i) {
            Ok(tau) => tau,
            Err(why) => {
                if let Ok(mut f) = self.failed.lock() {
                    f.get_or_insert_with(|| {
                        format!(
                            "agent {}, step {} (t = {} s), stage {}: {why}",
                            i.agent, i.step, i.t, i.stage
                        )
                    });
                }
                Vector3::repeat(f64::NAN)
            }
        })
    }
}

/// `m`'s entries, row by row.
fn rows(m: &Matrix3<f64>) -> [f64; 9] {
    std::array::from_fn(|k| m[(k / 3, k % 3)])
}

/// A heard value with its gain onto `data`: `a` (9), `R` (9), `ω` (3), `σ` (3).
fn heard(data: &mut Vec<f64>, a: &Matrix3<f64>, x: &Exchanged) {
    data.extend(rows(a));
    data.extend(rows(&x.r));
    data.extend(x.w.iter().chain(x.s.iter()));
}
