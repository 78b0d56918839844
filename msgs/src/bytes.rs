//! The payloads as bytes, for transports that are not shared memory (the
//! bridge across hosts carries them over Zenoh): every field little-endian,
//! in declaration order, no padding — the same bytes as the `#[repr(C)]`
//! struct on a little-endian machine (PROTOCOL.md § 5), written without
//! `unsafe`. A round trip is exact (f64s by their bits).

use crate::payload::{ControlMsg, StateMsg};
use crate::telemetry::{BODY_BYTES, TelemetryMsg};
use thiserror::Error;

/// Bytes that are not a payload of the expected kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("{kind}: {got} bytes, expected {expected}")]
pub struct WrongSize {
    /// The payload's name.
    pub kind: &'static str,
    /// Bytes received.
    pub got: usize,
    /// Its size.
    pub expected: usize,
}

/// A payload with a fixed-size byte form.
pub trait Bytes: Sized {
    /// Its name in errors.
    const KIND: &'static str;
    /// Its size in bytes.
    const SIZE: usize;
    /// Appends its bytes to `out`.
    fn put(&self, out: &mut Vec<u8>);
    /// Reads it from exactly [`Self::SIZE`] bytes.
    fn get(r: &mut Reader<'_>) -> Self;

    /// Its bytes.
    fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(Self::SIZE);
        self.put(&mut out);
        out
    }

    /// Reads it from `b`, which must hold exactly its bytes.
    fn from_bytes(b: &[u8]) -> Result<Self, WrongSize> {
        if b.len() != Self::SIZE {
            return Err(WrongSize {
                kind: Self::KIND,
                got: b.len(),
                expected: Self::SIZE,
            });
        }
        Ok(Self::get(&mut Reader(b)))
    }
}

/// Reads little-endian fields off the front of a slice known to be long enough.
#[derive(Debug)]
pub struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let (head, rest) = self.0.split_at(N);
        self.0 = rest;
        head.try_into().expect("split_at gave N bytes")
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn f64s<const N: usize>(&mut self) -> [f64; N] {
        std::array::from_fn(|_| f64::from_le_bytes(self.take()))
    }
}

fn put_f64s(out: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

impl Bytes for StateMsg {
    const KIND: &'static str = "StateMsg";
    const SIZE: usize = 152;
    fn put(&self, out: &mut Vec<u8>) {
        for w in [self.version, self.sender] {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(&self.step.to_le_bytes());
        for w in [self.stage, self.reserved] {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(&self.sent_unix_ns.to_le_bytes());
        put_f64s(out, &self.r);
        put_f64s(out, &self.w);
        put_f64s(out, &self.s);
    }
    fn get(r: &mut Reader<'_>) -> Self {
        Self {
            version: r.u32(),
            sender: r.u32(),
            step: r.u64(),
            stage: r.u32(),
            reserved: r.u32(),
            sent_unix_ns: r.u64(),
            r: r.f64s(),
            w: r.f64s(),
            s: r.f64s(),
        }
    }
}

impl Bytes for TelemetryMsg {
    const KIND: &'static str = "TelemetryMsg";
    const SIZE: usize = 16 + BODY_BYTES;
    fn put(&self, out: &mut Vec<u8>) {
        for w in [self.version, self.sender, self.kind, self.reserved] {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(&self.body);
    }
    fn get(r: &mut Reader<'_>) -> Self {
        Self {
            version: r.u32(),
            sender: r.u32(),
            kind: r.u32(),
            reserved: r.u32(),
            body: r.take(),
        }
    }
}

impl Bytes for ControlMsg {
    const KIND: &'static str = "ControlMsg";
    const SIZE: usize = 16;
    fn put(&self, out: &mut Vec<u8>) {
        for w in [self.version, self.command] {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(&self.start_unix_ns.to_le_bytes());
    }
    fn get(r: &mut Reader<'_>) -> Self {
        Self {
            version: r.u32(),
            command: r.u32(),
            start_unix_ns: r.u64(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::telemetry::Telemetry;

    #[test]
    fn sizes_are_the_structs_sizes() {
        assert_eq!(StateMsg::SIZE, std::mem::size_of::<StateMsg>());
        assert_eq!(TelemetryMsg::SIZE, std::mem::size_of::<TelemetryMsg>());
        assert_eq!(ControlMsg::SIZE, std::mem::size_of::<ControlMsg>());
    }

    #[test]
    fn a_state_round_trips_bit_for_bit_and_lays_fields_out_in_order() {
        let mut m = StateMsg {
            version: 3,
            sender: 7,
            step: 1 << 40,
            stage: 2,
            reserved: 0,
            sent_unix_ns: 99,
            r: [0.0; 9],
            w: [f64::MIN_POSITIVE, -0.0, 1e300],
            s: [1.0 / 3.0, f64::NAN, 2.0],
        };
        m.r[4] = -1.5;
        let b = m.to_bytes();
        assert_eq!(b.len(), 152);
        assert_eq!(&b[4..8], &7u32.to_le_bytes());
        assert_eq!(&b[8..16], &(1u64 << 40).to_le_bytes());
        assert_eq!(&b[32 + 4 * 8..32 + 5 * 8], &(-1.5f64).to_le_bytes());
        let back = StateMsg::from_bytes(&b).expect("152 bytes");
        assert_eq!(back.to_bytes(), b);
        assert_eq!(back.w[1].to_bits(), (-0.0f64).to_bits());
    }

    #[test]
    fn telemetry_and_control_round_trip() {
        let t = TelemetryMsg::encode(5, &Telemetry::Ready);
        assert_eq!(TelemetryMsg::from_bytes(&t.to_bytes()), Ok(t));
        let c = ControlMsg::start_at(123);
        assert_eq!(ControlMsg::from_bytes(&c.to_bytes()), Ok(c));
    }

    #[test]
    fn bytes_of_the_wrong_length_are_refused_naming_the_payload() {
        let e = StateMsg::from_bytes(&[0; 151]).unwrap_err();
        assert_eq!(e.to_string(), "StateMsg: 151 bytes, expected 152");
    }
}
