//! `states.bin` → an MCAP recording (`attsync export --mcap`).
//!
//! # Contents
//! ```text
//! metadata "attsync"          scenario, dt, sample_every, agents, time = simulated
//! /tf                         foxglove.FrameTransforms, one message per sample (see `scene`)
//! /errors/agent-<id>          attsync.AgentErrors, one message per sample, per agent
//! /torque/agent-<id>          attsync.AgentTorque, one message per sample, per agent
//!                             (τᵢ at stage 0 of the sample's step; NaN at the last sample)
//! ```
//! Every channel has `message_encoding = "protobuf"`, every schema
//! `encoding = "protobuf"` with a `FileDescriptorSet` ([`super::descriptor`]).
//! A message's log time and publish time are both the sample's simulated
//! time in ns from t = 0 ([`scene::time_ns`]), not wall time: the file's
//! timeline starts at the Unix epoch. Chunks are not compressed (mcap's
//! `zstd`/`lz4` features build C code; the file is a few MB per 1000
//! samples of the paper's network).

use super::descriptor;
use super::scene;
use crate::results::layout::node_name;
use crate::results::states::{self, Header};
use mcap::records::{MessageHeader, Metadata};
use mcap::{WriteOptions, Writer};
use prost::Message;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The topic of the frame transforms.
pub const TF_TOPIC: &str = "/tf";

/// `/errors/agent-<id>`: the topic of agent `id`'s errors.
#[must_use]
pub fn errors_topic(id: u32) -> String {
    format!("/errors/{}", node_name(id))
}

/// `/torque/agent-<id>`: the topic of agent `id`'s torque.
#[must_use]
pub fn torque_topic(id: u32) -> String {
    format!("/torque/{}", node_name(id))
}

/// Why a recording could not be written.
#[derive(Debug, thiserror::Error)]
pub enum McapExportError {
    /// `states.bin` could not be read (the message names the file and why).
    #[error(transparent)]
    States(#[from] crate::results::states::StatesError),
    /// The output file could not be created or written (the OS error).
    #[error("writing {}: {source}", path.display())]
    Io {
        /// The MCAP file.
        path: PathBuf,
        /// The OS error.
        source: io::Error,
    },
    /// The MCAP writer refused (e.g. more than 65535 channels).
    #[error("writing {}: {source}", path.display())]
    Mcap {
        /// The MCAP file.
        path: PathBuf,
        /// The writer's error.
        source: mcap::McapError,
    },
}

/// What a recording holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct McapSummary {
    /// Samples (records of `states.bin`).
    pub samples: u64,
    /// Channels: `/tf` and two per agent (errors, torque).
    pub channels: usize,
    /// Messages, all channels.
    pub messages: u64,
}

/// The channel ids of a recording.
struct Channels {
    tf: u16,
    errors: Vec<u16>,
    torques: Vec<u16>,
}

/// Writes the recording of `states_file` to `out` (replacing it); on any
/// error `out` is removed, so no half-written recording is left.
pub fn write_mcap(states_file: &Path, out: &Path) -> Result<McapSummary, McapExportError> {
    let records = states::open(states_file).map_err(McapExportError::States)?;
    let written = write_to(records, out);
    if written.is_err() {
        let _ = std::fs::remove_file(out);
    }
    written
}

/// [`write_mcap`] without the clean-up.
fn write_to(records: states::Records, out: &Path) -> Result<McapSummary, McapExportError> {
    let mcap_err = |source| match source {
        mcap::McapError::Io(source) => McapExportError::Io {
            path: out.to_owned(),
            source,
        },
        source => McapExportError::Mcap {
            path: out.to_owned(),
            source,
        },
    };
    let file = File::create(out).map_err(|e| mcap_err(e.into()))?;
    let opts = WriteOptions::new()
        .compression(None)
        .library(format!("attsync {}", env!("CARGO_PKG_VERSION")));
    let mut w = Writer::with_options(BufWriter::new(file), opts).map_err(mcap_err)?;
    let h = records.header.clone();
    w.write_metadata(&metadata(&h)).map_err(mcap_err)?;
    let channels = add_channels(&mut w, &h).map_err(mcap_err)?;
    let mut summary = McapSummary {
        samples: 0,
        channels: 1 + channels.errors.len() + channels.torques.len(),
        messages: 0,
    };
    for rec in records {
        let rec = rec.map_err(McapExportError::States)?;
        let sequence = summary.samples as u32;
        summary.messages +=
            write_sample(&mut w, &channels, sequence, &h, &rec).map_err(mcap_err)?;
        summary.samples += 1;
    }
    w.finish().map_err(mcap_err)?;
    w.into_inner().flush().map_err(|e| mcap_err(e.into()))?;
    Ok(summary)
}

/// The `attsync` metadata record: what the recording is of.
fn metadata(h: &Header) -> Metadata {
    let ids: Vec<String> = h.agent_ids.iter().map(u32::to_string).collect();
    let entries = [
        ("scenario", h.scenario.clone()),
        ("dt", h.dt.to_string()),
        ("sample_every", h.sample_every.to_string()),
        ("agents", ids.join(",")),
        ("observer", h.has_observer.to_string()),
        ("time", "simulated, ns from t = 0".into()),
    ];
    Metadata {
        name: "attsync".into(),
        metadata: entries.map(|(k, v)| (k.to_string(), v)).into(),
    }
}

/// Adds the three schemas, `/tf`, and an error and a torque channel per agent.
fn add_channels<W: Write + io::Seek>(w: &mut Writer<W>, h: &Header) -> mcap::McapResult<Channels> {
    let (protobuf, none) = ("protobuf", BTreeMap::new());
    let tf_schema = w.add_schema(
        descriptor::FRAME_TRANSFORMS,
        protobuf,
        &descriptor::frame_transforms(),
    )?;
    let errors_schema = w.add_schema(
        descriptor::AGENT_ERRORS,
        protobuf,
        &descriptor::agent_errors(),
    )?;
    let torque_schema = w.add_schema(
        descriptor::AGENT_TORQUE,
        protobuf,
        &descriptor::agent_torque(),
    )?;
    let tf = w.add_channel(tf_schema, TF_TOPIC, protobuf, &none)?;
    let mut per_agent = |schema, topic: fn(u32) -> String| {
        (h.agent_ids.iter())
            .map(|&id| {
                let meta = BTreeMap::from([("agent".to_string(), id.to_string())]);
                w.add_channel(schema, &topic(id), protobuf, &meta)
            })
            .collect::<mcap::McapResult<Vec<_>>>()
    };
    let errors = per_agent(errors_schema, errors_topic)?;
    let torques = per_agent(torque_schema, torque_topic)?;
    Ok(Channels {
        tf,
        errors,
        torques,
    })
}

/// Writes one sample's messages (`sequence`: the sample's index, the same
/// on every channel); returns how many.
fn write_sample<W: Write + io::Seek>(
    w: &mut Writer<W>,
    channels: &Channels,
    sequence: u32,
    h: &Header,
    rec: &states::Record,
) -> mcap::McapResult<u64> {
    let ns = scene::time_ns(rec.step, h.dt);
    let header = |channel_id| MessageHeader {
        channel_id,
        sequence,
        log_time: ns,
        publish_time: ns,
    };
    w.write_to_known_channel(
        &header(channels.tf),
        &scene::transforms(h, rec).encode_to_vec(),
    )?;
    let errors = scene::agent_errors(h, rec);
    for (&channel, e) in channels.errors.iter().zip(&errors) {
        w.write_to_known_channel(&header(channel), &e.encode_to_vec())?;
    }
    let torques = scene::agent_torques(h, rec);
    for (&channel, t) in channels.torques.iter().zip(&torques) {
        w.write_to_known_channel(&header(channel), &t.encode_to_vec())?;
    }
    Ok(1 + (errors.len() + torques.len()) as u64)
}
