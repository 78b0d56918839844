//! What makes an agent's body other than ideal (issue 35, item 3): the
//! limits of its actuator ([`crate::actuator`]) so far. One box per agent,
//! absent for an ideal body, so that an ideal agent's data does not grow
//! with every effect.

use crate::actuator::Saturation;
use serde::{Deserialize, Serialize};

/// The non-ideal effects of one agent's body.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Effects {
    /// The limits of the torque the body receives.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub saturation: Option<Saturation>,
}

impl Effects {
    /// Whether the body is ideal (then the model has no effects at all).
    #[must_use]
    pub fn is_ideal(&self) -> bool {
        self.saturation.is_none()
    }
}
