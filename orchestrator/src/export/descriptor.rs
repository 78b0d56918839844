//! The schemas of a recording: for each message of [`super::proto`], a
//! serialized `google.protobuf.FileDescriptorSet` holding its `.proto` file
//! and every file it imports, built in code (no `protoc`, no `.proto` files).
//!
//! This is what an MCAP Schema record with `encoding = "protobuf"` must hold
//! (the MCAP registry of well-known encodings): a reader builds the message
//! types from it at run time, so Foxglove, Lichtblick, Rerun and the Python
//! `mcap-protobuf-support` decoder need nothing but the file. The set is
//! self-contained: it carries `google/protobuf/timestamp.proto` too, as a
//! reader may start from an empty descriptor pool.

use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet};

/// `google/protobuf/timestamp.proto`.
const TIMESTAMP_FILE: &str = "google/protobuf/timestamp.proto";
/// `foxglove/Vector3.proto`.
const VECTOR3_FILE: &str = "foxglove/Vector3.proto";
/// `foxglove/Quaternion.proto`.
const QUATERNION_FILE: &str = "foxglove/Quaternion.proto";
/// `foxglove/FrameTransform.proto`.
const FRAME_TRANSFORM_FILE: &str = "foxglove/FrameTransform.proto";
/// `foxglove/FrameTransforms.proto`.
const FRAME_TRANSFORMS_FILE: &str = "foxglove/FrameTransforms.proto";
/// `attsync/AgentErrors.proto`.
const AGENT_ERRORS_FILE: &str = "attsync/AgentErrors.proto";
/// `attsync/AgentTorque.proto`.
const AGENT_TORQUE_FILE: &str = "attsync/AgentTorque.proto";

/// `.google.protobuf.Timestamp`, the fully qualified name fields refer to.
const TIMESTAMP: &str = ".google.protobuf.Timestamp";

/// The schema name of `/tf` messages, as Foxglove and Rerun recognise it.
pub const FRAME_TRANSFORMS: &str = "foxglove.FrameTransforms";
/// The schema name of error messages.
pub const AGENT_ERRORS: &str = "attsync.AgentErrors";
/// The schema name of torque messages.
pub const AGENT_TORQUE: &str = "attsync.AgentTorque";

/// A scalar or message field, `optional` (proto3's implicit presence for
/// scalars) unless `repeated`.
fn field(name: &str, number: i32, ty: Type, type_name: Option<&str>) -> FieldDescriptorProto {
    FieldDescriptorProto {
        name: Some(name.into()),
        number: Some(number),
        label: Some(Label::Optional as i32),
        r#type: Some(ty as i32),
        type_name: type_name.map(Into::into),
        ..FieldDescriptorProto::default()
    }
}

/// A message of doubles named `fields`, numbered from 1.
fn doubles(name: &str, fields: &[&str]) -> DescriptorProto {
    message(
        name,
        (1..)
            .zip(fields)
            .map(|(n, f)| field(f, n, Type::Double, None))
            .collect(),
    )
}

/// A message.
fn message(name: &str, field: Vec<FieldDescriptorProto>) -> DescriptorProto {
    DescriptorProto {
        name: Some(name.into()),
        field,
        ..DescriptorProto::default()
    }
}

/// A proto3 file of `package` importing `dependency`.
fn file(
    name: &str,
    package: &str,
    dependency: &[&str],
    message_type: Vec<DescriptorProto>,
) -> FileDescriptorProto {
    FileDescriptorProto {
        name: Some(name.into()),
        package: Some(package.into()),
        dependency: dependency.iter().map(|d| (*d).into()).collect(),
        message_type,
        syntax: Some("proto3".into()),
        ..FileDescriptorProto::default()
    }
}

/// `google.protobuf.Timestamp { int64 seconds = 1; int32 nanos = 2; }`.
fn timestamp_file() -> FileDescriptorProto {
    let fields = vec![
        field("seconds", 1, Type::Int64, None),
        field("nanos", 2, Type::Int32, None),
    ];
    file(
        TIMESTAMP_FILE,
        "google.protobuf",
        &[],
        vec![message("Timestamp", fields)],
    )
}

/// Foxglove's `FrameTransforms` and the files it imports (mirrors
/// [`super::proto::FrameTransforms`] and its parts).
fn frame_transforms_files() -> Vec<FileDescriptorProto> {
    let transform = vec![
        field("timestamp", 1, Type::Message, Some(TIMESTAMP)),
        field("parent_frame_id", 2, Type::String, None),
        field("child_frame_id", 3, Type::String, None),
        field("translation", 4, Type::Message, Some(".foxglove.Vector3")),
        field("rotation", 5, Type::Message, Some(".foxglove.Quaternion")),
    ];
    let transforms = FieldDescriptorProto {
        label: Some(Label::Repeated as i32),
        ..field(
            "transforms",
            1,
            Type::Message,
            Some(".foxglove.FrameTransform"),
        )
    };
    vec![
        timestamp_file(),
        file(
            VECTOR3_FILE,
            "foxglove",
            &[],
            vec![doubles("Vector3", &["x", "y", "z"])],
        ),
        file(
            QUATERNION_FILE,
            "foxglove",
            &[],
            vec![doubles("Quaternion", &["x", "y", "z", "w"])],
        ),
        file(
            FRAME_TRANSFORM_FILE,
            "foxglove",
            &[QUATERNION_FILE, VECTOR3_FILE, TIMESTAMP_FILE],
            vec![message("FrameTransform", transform)],
        ),
        file(
            FRAME_TRANSFORMS_FILE,
            "foxglove",
            &[FRAME_TRANSFORM_FILE],
            vec![message("FrameTransforms", vec![transforms])],
        ),
    ]
}

/// attsync's `AgentErrors` and `ObserverErrors` (mirror
/// [`super::proto::AgentErrors`]), with the timestamp file.
fn agent_errors_files() -> Vec<FileDescriptorProto> {
    let errors = vec![
        field("timestamp", 1, Type::Message, Some(TIMESTAMP)),
        field("att_err", 2, Type::Double, None),
        field("angvel_err", 3, Type::Double, None),
        field(
            "observer",
            4,
            Type::Message,
            Some(".attsync.ObserverErrors"),
        ),
    ];
    vec![
        timestamp_file(),
        file(
            AGENT_ERRORS_FILE,
            "attsync",
            &[TIMESTAMP_FILE],
            vec![
                doubles("ObserverErrors", &["att_err", "angvel_err"]),
                message("AgentErrors", errors),
            ],
        ),
    ]
}

/// attsync's `AgentTorque` (mirrors [`super::proto::AgentTorque`]), with the
/// timestamp file.
fn agent_torque_files() -> Vec<FileDescriptorProto> {
    let mut torque = vec![field("timestamp", 1, Type::Message, Some(TIMESTAMP))];
    let doubles = ["x", "y", "z", "norm"].into_iter().zip(2..);
    torque.extend(doubles.map(|(name, n)| field(name, n, Type::Double, None)));
    vec![
        timestamp_file(),
        file(
            AGENT_TORQUE_FILE,
            "attsync",
            &[TIMESTAMP_FILE],
            vec![message("AgentTorque", torque)],
        ),
    ]
}

/// The serialized `FileDescriptorSet` of `foxglove.FrameTransforms`.
#[must_use]
pub fn frame_transforms() -> Vec<u8> {
    FileDescriptorSet {
        file: frame_transforms_files(),
    }
    .encode_to_vec()
}

/// The serialized `FileDescriptorSet` of `attsync.AgentErrors`.
#[must_use]
pub fn agent_errors() -> Vec<u8> {
    FileDescriptorSet {
        file: agent_errors_files(),
    }
    .encode_to_vec()
}

/// The serialized `FileDescriptorSet` of `attsync.AgentTorque`.
#[must_use]
pub fn agent_torque() -> Vec<u8> {
    FileDescriptorSet {
        file: agent_torque_files(),
    }
    .encode_to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    /// Every import is in the set, and every field's message type is defined
    /// in it: a reader starting from an empty pool can build the types.
    fn assert_self_contained(files: &[FileDescriptorProto]) {
        let names: BTreeSet<&str> = files.iter().map(|f| f.name()).collect();
        assert_eq!(names.len(), files.len(), "no file twice");
        let mut types = BTreeSet::new();
        for f in files {
            for m in &f.message_type {
                types.insert(format!(".{}.{}", f.package(), m.name()));
            }
        }
        for f in files {
            for d in &f.dependency {
                assert!(names.contains(d.as_str()), "{} imports {d}", f.name());
            }
            for fd in f.message_type.iter().flat_map(|m| &m.field) {
                if let Some(t) = &fd.type_name {
                    assert!(types.contains(t), "{}: {t} undefined", fd.name());
                }
            }
        }
    }

    #[test]
    fn both_sets_are_self_contained() {
        assert_self_contained(&frame_transforms_files());
        assert_self_contained(&agent_errors_files());
        assert_self_contained(&agent_torque_files());
    }

    #[test]
    fn the_sets_decode_back_and_define_their_schema_names() {
        for (bytes, schema) in [
            (frame_transforms(), FRAME_TRANSFORMS),
            (agent_errors(), AGENT_ERRORS),
            (agent_torque(), AGENT_TORQUE),
        ] {
            let set = FileDescriptorSet::decode(bytes.as_slice()).unwrap();
            let (package, name) = schema.split_once('.').unwrap();
            let found = set
                .file
                .iter()
                .filter(|f| f.package() == package)
                .flat_map(|f| &f.message_type)
                .any(|m| m.name() == name);
            assert!(found, "{schema} is defined");
        }
    }
}
