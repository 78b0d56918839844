//! Rotation specs (axis + angle, quaternion, matrix) → rotation matrices.

use super::ctx::{Ctx, rows};
use crate::schema::RotationSpec;
use attitude::so3::{orthogonality_defect, rot};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use std::fmt::Display;

impl Ctx {
    /// The rotation `r` describes, or `None` (with an error) if it is not
    /// exactly one well-formed form.
    pub(super) fn rotation(
        &mut self,
        field: impl Display + Copy,
        r: &RotationSpec,
    ) -> Option<Matrix3<f64>> {
        let angles = [
            r.angle_rad.map(|a| ("angle_rad", a)),
            r.angle_deg.map(|a| ("angle_deg", a.to_radians())),
            r.angle_pi.map(|a| ("angle_pi", a * std::f64::consts::PI)),
        ];
        let given = angles.iter().flatten().count();
        let forms = usize::from(r.axis.is_some() || given > 0)
            + usize::from(r.quaternion.is_some())
            + usize::from(r.matrix.is_some());
        if forms != 1 {
            self.err(
                field.to_string(),
                "give exactly one of: axis with one of angle_rad/angle_deg/angle_pi; quaternion = [w, x, y, z]; matrix = [[..], [..], [..]]",
            );
            return None;
        }
        if let Some(q) = r.quaternion {
            return self.rotation_quaternion(field, q);
        }
        if let Some(m) = r.matrix {
            return self.rotation_matrix(field, &m);
        }
        self.rotation_axis_angle(field, r.axis, &angles)
    }

    /// `quaternion = [w, x, y, z]`: finite, non-zero, normalised.
    fn rotation_quaternion(&mut self, field: impl Display, q: [f64; 4]) -> Option<Matrix3<f64>> {
        if q.iter().any(|x| !x.is_finite()) || q.iter().all(|&x| x == 0.0) {
            self.err(format!("{field}.quaternion"), "must be finite and non-zero");
            return None;
        }
        // Scale by the largest component first so that tiny or huge
        // inputs normalise without underflow or overflow.
        let m = q.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let q = UnitQuaternion::from_quaternion(Quaternion::new(
            q[0] / m,
            q[1] / m,
            q[2] / m,
            q[3] / m,
        ));
        Some(*q.to_rotation_matrix().matrix())
    }

    /// `matrix = [[..], [..], [..]]`: finite, a rotation to 1e-9.
    fn rotation_matrix(&mut self, field: impl Display, m: &[[f64; 3]; 3]) -> Option<Matrix3<f64>> {
        let m = rows(m);
        if m.iter().any(|x| !x.is_finite()) {
            self.err(format!("{field}.matrix"), "must hold finite numbers");
            return None;
        }
        if orthogonality_defect(&m) > 1e-9 || (m.determinant() - 1.0).abs() > 1e-9 {
            self.err(
                format!("{field}.matrix"),
                format!(
                    "is not a rotation: ‖RᵀR − I‖ = {:.3e}, det = {} (need orthogonal, det +1, to 1e-9)",
                    orthogonality_defect(&m),
                    m.determinant()
                ),
            );
            return None;
        }
        Some(m)
    }

    /// `axis` with exactly one of the `angles` given (name, radians).
    fn rotation_axis_angle(
        &mut self,
        field: impl Display + Copy,
        axis: Option<[f64; 3]>,
        angles: &[Option<(&str, f64)>; 3],
    ) -> Option<Matrix3<f64>> {
        let Some(axis) = axis else {
            self.err(format!("{field}.axis"), "an angle needs an axis");
            return None;
        };
        let mut given = angles.iter().flatten();
        let (Some(&(name, angle)), None) = (given.next(), given.next()) else {
            self.err(
                field.to_string(),
                "give exactly one of angle_rad, angle_deg, angle_pi",
            );
            return None;
        };
        if !self.finite(format_args!("{field}.{name}"), angle) {
            return None;
        }
        let u = Vector3::from(axis);
        if u.iter().any(|x| !x.is_finite()) || u.amax() == 0.0 {
            self.err(
                format!("{field}.axis"),
                format!("must be finite and non-zero, got {axis:?}"),
            );
            return None;
        }
        Some(rot(angle, &(u / u.amax()).normalize()))
    }
}
