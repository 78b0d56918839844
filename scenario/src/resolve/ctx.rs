//! The resolution context: the problems found so far, and the checks every
//! table shares (finite numbers, SPD and gain matrices, multiples of `dt`).
//!
//! A check takes its field's name as anything `Display` (e.g.
//! `format_args!("agent[{k}].inertia")`): it is written out only for a
//! problem, not for each of 10⁵ valid agents.

use super::Issue;
use super::theory::Departure;
use crate::schema::MatrixSpec;
use attitude::checks::{has_distinct_eigenvalues, is_spd, sym_eigenvalues};
use nalgebra::{Matrix3, Vector3};
use std::fmt::Display;

/// Most steps a run (or a period) may have: 2⁴⁰ ≈ 1.1e12, far beyond any
/// useful run, well inside u64 and f64's exact integers.
pub const MAX_STEPS: f64 = 1_099_511_627_776.0;

/// Errors and warnings collected by every phase, in the order found.
#[derive(Default)]
pub(super) struct Ctx {
    /// Problems that stop the run.
    pub(super) errors: Vec<Issue>,
    /// Problems that do not.
    pub(super) warnings: Vec<Issue>,
    /// `[graph] assumptions = "off"`: departures from Assumption 1 are
    /// recorded, not refused.
    pub(super) theory_off: bool,
    /// The departures recorded.
    pub(super) departures: Vec<Departure>,
}

impl Ctx {
    /// A departure from Assumption 1 at `field`: an error saying `reason`,
    /// or with `[graph] assumptions = "off"` recorded.
    pub(super) fn departs(&mut self, field: impl Into<String>, d: Departure, reason: String) {
        if self.theory_off {
            self.departures.push(d);
        } else {
            self.err(
                field,
                format!("{reason} (Assumption 1; `[graph] assumptions = \"off\"` allows it)"),
            );
        }
    }

    pub(super) fn err(&mut self, field: impl Into<String>, reason: impl Into<String>) {
        self.errors.push(Issue {
            field: field.into(),
            reason: reason.into(),
        });
    }

    pub(super) fn warn(&mut self, field: impl Into<String>, reason: impl Into<String>) {
        self.warnings.push(Issue {
            field: field.into(),
            reason: reason.into(),
        });
    }

    pub(super) fn finite(&mut self, field: impl Display, x: f64) -> bool {
        if x.is_finite() {
            true
        } else {
            self.err(
                field.to_string(),
                format!("must be a finite number, got {x}"),
            );
            false
        }
    }

    pub(super) fn positive(&mut self, field: impl Display + Copy, x: f64) -> f64 {
        if self.finite(field, x) && x <= 0.0 {
            self.err(field.to_string(), format!("must be > 0, got {x}"));
        }
        x
    }

    pub(super) fn vec3(&mut self, field: impl Display, v: &[f64; 3]) -> Vector3<f64> {
        if v.iter().any(|x| !x.is_finite()) {
            self.err(
                field.to_string(),
                format!("must hold finite numbers, got {v:?}"),
            );
        }
        Vector3::from(*v)
    }

    fn matrix(&mut self, field: impl Display, m: &MatrixSpec) -> Option<Matrix3<f64>> {
        let m = match m {
            MatrixSpec::Diagonal(d) => Matrix3::from_diagonal(&Vector3::from(*d)),
            MatrixSpec::Rows(r) => rows(r),
        };
        if m.iter().any(|x| !x.is_finite()) {
            self.err(field.to_string(), "must hold finite numbers");
            return None;
        }
        Some(m)
    }

    /// SPD (inertia).
    pub(super) fn spd(
        &mut self,
        field: impl Display + Copy,
        m: &MatrixSpec,
        what: &str,
    ) -> Option<Matrix3<f64>> {
        let m = self.matrix(field, m)?;
        if !is_spd(&m) {
            self.err(
                field.to_string(),
                format!("{what} must be symmetric positive definite; eigenvalues of its symmetric part are {:?}", sym_eigenvalues(&((m + m.transpose()) * 0.5))),
            );
            return None;
        }
        Some(m)
    }

    /// SPD with three distinct eigenvalues (every gain matrix A of the paper).
    pub(super) fn gain(
        &mut self,
        field: impl Display + Copy,
        m: &MatrixSpec,
    ) -> Option<Matrix3<f64>> {
        let m = self.spd(field, m, "a gain matrix A")?;
        if !has_distinct_eigenvalues(&m) {
            self.err(
                field.to_string(),
                format!(
                    "a gain matrix A must have three distinct eigenvalues (the paper's assumption), got {:?}",
                    sym_eigenvalues(&m)
                ),
            );
            return None;
        }
        Some(m)
    }

    /// `x` seconds as a whole, positive number of steps of `dt`.
    pub(super) fn multiple_of_dt(
        &mut self,
        field: impl Display + Copy,
        x: f64,
        dt: f64,
    ) -> Option<u64> {
        if !(self.finite(field, x) && dt > 0.0 && dt.is_finite()) {
            return None;
        }
        if x <= 0.0 {
            self.err(field.to_string(), format!("must be > 0, got {x}"));
            return None;
        }
        let n = (x / dt).round();
        if n > MAX_STEPS {
            self.err(
                field.to_string(),
                format!("{x} s is {n:e} steps of simulation.dt = {dt}; at most {MAX_STEPS:e} are allowed"),
            );
            return None;
        }
        if n < 1.0 || (n * dt - x).abs() > 1e-9 * x.max(dt) {
            self.err(
                field.to_string(),
                format!("must be a whole multiple of simulation.dt = {dt}, got {x}"),
            );
            return None;
        }
        Some(n as u64)
    }
}

/// A matrix from its rows.
pub(super) fn rows(r: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    )
}
