//! Where the parallel engine's threads leave values for each other: one
//! slot of atomic words per value, written and read with relaxed ordering
//! between two barrier waits (the barrier orders them).
//!
//! An `f64` travels as its bits (`to_bits` / `from_bits`), so a value read
//! is the value written, bit for bit (NaN payloads included).

use crate::network::{AgentState, Exchanged};
use crate::reference::LeaderState;
use nalgebra::{Matrix3, Vector3};
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// A value that packs into `N` `f64` words.
pub trait Words<const N: usize>: Sized {
    /// The value's numbers, in a fixed order.
    fn to_words(&self) -> [f64; N];
    /// The value from [`Words::to_words`]'s numbers.
    fn from_words(w: &[f64; N]) -> Self;
}

/// One shared value of `N` words.
#[derive(Debug)]
pub struct Slot<const N: usize>([AtomicU64; N]);

impl<const N: usize> Default for Slot<N> {
    fn default() -> Self {
        Self(std::array::from_fn(|_| AtomicU64::new(0)))
    }
}

impl<const N: usize> Slot<N> {
    /// Stores `x` (visible to other threads after the next barrier).
    pub fn store<T: Words<N>>(&self, x: &T) {
        for (slot, v) in self.0.iter().zip(x.to_words()) {
            slot.store(v.to_bits(), Relaxed);
        }
    }

    /// The value stored last (before the last barrier).
    #[must_use]
    pub fn load<T: Words<N>>(&self) -> T {
        T::from_words(&std::array::from_fn(|i| {
            f64::from_bits(self.0[i].load(Relaxed))
        }))
    }
}

/// A value aligned to a cache line (64 B), as [`Judged`] is: a shared
/// published value is two lines, not three.
#[derive(Debug, Default)]
#[repr(align(64))]
pub struct Lined<T>(pub T);

impl<T> std::ops::Deref for Lined<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.0
    }
}

/// `n` shared slots.
#[must_use]
pub fn slots<const N: usize>(n: usize) -> Vec<Slot<N>> {
    (0..n).map(|_| Slot::default()).collect()
}

fn put(w: &mut [f64], at: usize, xs: &[f64]) {
    w[at..at + xs.len()].copy_from_slice(xs);
}

fn mat(w: &[f64], at: usize) -> Matrix3<f64> {
    Matrix3::from_column_slice(&w[at..at + 9])
}

fn vec3(w: &[f64], at: usize) -> Vector3<f64> {
    Vector3::from_column_slice(&w[at..at + 3])
}

/// Words of an [`Exchanged`].
pub const EXCHANGED: usize = 15;

/// Words of a vector (a torque).
pub const VECTOR: usize = 3;

impl Words<VECTOR> for Vector3<f64> {
    fn to_words(&self) -> [f64; VECTOR] {
        [self.x, self.y, self.z]
    }
    fn from_words(w: &[f64; VECTOR]) -> Self {
        vec3(w, 0)
    }
}

impl Words<1> for f64 {
    fn to_words(&self) -> [f64; 1] {
        [*self]
    }
    fn from_words(w: &[f64; 1]) -> Self {
        w[0]
    }
}

impl Words<EXCHANGED> for Exchanged {
    fn to_words(&self) -> [f64; EXCHANGED] {
        let mut w = [0.0; EXCHANGED];
        put(&mut w, 0, self.r.as_slice());
        put(&mut w, 9, self.w.as_slice());
        put(&mut w, 12, self.s.as_slice());
        w
    }

    fn from_words(w: &[f64; EXCHANGED]) -> Self {
        Self {
            r: mat(w, 0),
            w: vec3(w, 9),
            s: vec3(w, 12),
        }
    }
}

impl Words<EXCHANGED> for LeaderState {
    fn to_words(&self) -> [f64; EXCHANGED] {
        self.exchanged().to_words()
    }

    fn from_words(w: &[f64; EXCHANGED]) -> Self {
        let x = Exchanged::from_words(w);
        Self {
            r0: x.r,
            w0: x.w,
            s0: x.s,
        }
    }
}

/// A published value and whether receivers may use it
/// ([`Exchanged::trust`], judged once by the sender's thread). Aligned to
/// a cache line (64 B on x86-64 and AArch64), so that one is two lines,
/// not three: the engine reads each neighbour's at every stage.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(align(64))]
pub struct Judged(pub Exchanged, pub bool);

impl Default for Judged {
    /// Nothing published yet: the identity, not trusted.
    fn default() -> Self {
        Self(Exchanged::identity(), false)
    }
}

impl Judged {
    /// `x` with its verdict.
    #[must_use]
    pub fn of(x: Exchanged) -> Self {
        let trusted = x.trust().is_ok();
        Self(x, trusted)
    }

    /// What every receiver of a sender holds once it publishes `x` with
    /// the verdict `trusted`, `before` being what they held: `x` if
    /// trusted, else `before` (a receiver refuses an untrusted value and
    /// keeps what it had, [`crate::agent::Agent::receive_neighbour`]). The
    /// same for every receiver of the sender, so kept once, on the board.
    #[must_use]
    pub fn held(x: Exchanged, trusted: bool, before: &Exchanged) -> Self {
        Self(if trusted { x } else { *before }, trusted)
    }
}

/// Words of a [`Judged`]: the value, then 1 (trusted) or 0.
pub const JUDGED: usize = EXCHANGED + 1;

impl Words<JUDGED> for Judged {
    fn to_words(&self) -> [f64; JUDGED] {
        let mut w = [0.0; JUDGED];
        put(&mut w, 0, &self.0.to_words());
        w[EXCHANGED] = f64::from(u8::from(self.1));
        w
    }

    fn from_words(w: &[f64; JUDGED]) -> Self {
        let x: &[f64; EXCHANGED] = w[..EXCHANGED].try_into().expect("15 words");
        Self(Exchanged::from_words(x), w[EXCHANGED] == 1.0)
    }
}

/// Words of an [`AgentState`].
pub const AGENT_STATE: usize = 27;

impl Words<AGENT_STATE> for AgentState {
    fn to_words(&self) -> [f64; AGENT_STATE] {
        let mut w = [0.0; AGENT_STATE];
        put(&mut w, 0, self.r.as_slice());
        put(&mut w, 9, self.w.as_slice());
        put(&mut w, 12, self.r_hat.as_slice());
        put(&mut w, 21, self.w_hat.as_slice());
        put(&mut w, 24, self.s_hat.as_slice());
        w
    }

    fn from_words(w: &[f64; AGENT_STATE]) -> Self {
        Self {
            r: mat(w, 0),
            w: vec3(w, 9),
            r_hat: mat(w, 12),
            w_hat: vec3(w, 21),
            s_hat: vec3(w, 24),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_come_back_bit_for_bit() {
        let x = Exchanged {
            r: Matrix3::from_fn(|i, j| (3 * i + j) as f64 + 0.1),
            w: Vector3::new(f64::NAN, -0.0, f64::MIN_POSITIVE / 2.0),
            s: Vector3::new(1e300, f64::INFINITY, -7.5),
        };
        let slot = Slot::<EXCHANGED>::default();
        slot.store(&x);
        let y: Exchanged = slot.load();
        assert_eq!(
            x.to_words().map(f64::to_bits),
            y.to_words().map(f64::to_bits)
        );
        let s = AgentState {
            r: x.r,
            w: x.w,
            r_hat: x.r.transpose(),
            w_hat: x.s,
            s_hat: Vector3::new(1.0, 2.0, 3.0),
        };
        let slot = Slot::<AGENT_STATE>::default();
        slot.store(&s);
        let t: AgentState = slot.load();
        assert_eq!(
            s.to_words().map(f64::to_bits),
            t.to_words().map(f64::to_bits)
        );
    }
}
