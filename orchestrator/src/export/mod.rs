//! Recordings for the robotics tools: a run's `states.bin` as an MCAP file
//! that Foxglove, Lichtblick and Rerun open (`attsync export --mcap`;
//! docs/recordings.md). Built with the cargo feature `mcap` (on by default).
//!
//! Everything is Protobuf-encoded: Rerun decodes Foxglove's schemas only in
//! Protobuf, and Foxglove and Lichtblick read Protobuf too.
//!
//! # Layout
//! - [`recording`]: [`write_mcap`] (states.bin → MCAP: schemas, channels,
//!   messages stamped with simulated time), [`McapExportError`], the topics.
//! - [`scene`]: the frames of the bodies, where they are drawn, and the
//!   messages of one sample (transforms, errors).
//! - [`proto`]: the messages (`foxglove.FrameTransforms` and its parts,
//!   `attsync.AgentErrors`) as prost structs.
//! - [`descriptor`]: their schemas, `FileDescriptorSet`s built in code.

pub mod descriptor;
pub mod proto;
pub mod recording;
pub mod scene;

pub use recording::{McapExportError, McapSummary, write_mcap};
