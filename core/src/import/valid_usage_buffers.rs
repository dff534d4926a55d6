//! Valid usage of buffers checked statically from the calls: a buffer's usage flags against
//! each use a call makes of it, each finding with its VUID, as the validation layer reports
//! it: vertex, index and indirect buffers bound or read, transfer sources and destinations
//! (copies, fills, updates), buffer descriptors written (uniform and storage buffers, texel
//! buffer views, also through update templates) and texel buffer views created. A finding is
//! not a refusal: drivers run such frames, and so does the replay.

use super::state::{Descriptor, EntryWrites, Objects, descriptor_kind};
use super::value::{Arg, Got};
use crate::capture::format::ValidUsageFinding;

/// `VkBufferUsageFlagBits` a use needs, with their names.
const TRANSFER_SRC: (u64, &str) = (0x1, "VK_BUFFER_USAGE_TRANSFER_SRC_BIT");
const TRANSFER_DST: (u64, &str) = (0x2, "VK_BUFFER_USAGE_TRANSFER_DST_BIT");
const UNIFORM_TEXEL: (u64, &str) = (0x4, "VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT");
const STORAGE_TEXEL: (u64, &str) = (0x8, "VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT");
const UNIFORM: (u64, &str) = (0x10, "VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT");
const STORAGE: (u64, &str) = (0x20, "VK_BUFFER_USAGE_STORAGE_BUFFER_BIT");
const INDEX: (u64, &str) = (0x40, "VK_BUFFER_USAGE_INDEX_BUFFER_BIT");
const VERTEX: (u64, &str) = (0x80, "VK_BUFFER_USAGE_VERTEX_BUFFER_BIT");
const INDIRECT: (u64, &str) = (0x100, "VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT");

/// A buffer argument of a command: its member (a list of handles for `pBuffers`), the usage it
/// needs and the VUID (without `VUID-`) that says so.
type BufferArgument = (&'static str, (u64, &'static str), &'static str);

/// The buffers command `call` reads or writes: the structure holding them (the `*Info2`
/// argument of the `2` commands) and each argument.
fn buffer_arguments(call: &str) -> Option<(Option<&'static str>, &'static [BufferArgument])> {
    Some(match call {
        "vkCmdBindVertexBuffers" => (
            None,
            &[("pBuffers", VERTEX, "vkCmdBindVertexBuffers-pBuffers-00627")],
        ),
        "vkCmdBindVertexBuffers2" | "vkCmdBindVertexBuffers2EXT" => (
            None,
            &[("pBuffers", VERTEX, "vkCmdBindVertexBuffers2-pBuffers-03359")],
        ),
        "vkCmdBindIndexBuffer" => (
            None,
            &[("buffer", INDEX, "vkCmdBindIndexBuffer-buffer-00433")],
        ),
        "vkCmdDrawIndirect" => (
            None,
            &[("buffer", INDIRECT, "vkCmdDrawIndirect-buffer-02709")],
        ),
        "vkCmdDrawIndexedIndirect" => (
            None,
            &[("buffer", INDIRECT, "vkCmdDrawIndexedIndirect-buffer-02709")],
        ),
        "vkCmdDispatchIndirect" => (
            None,
            &[("buffer", INDIRECT, "vkCmdDispatchIndirect-buffer-02709")],
        ),
        // The KHR and AMD names are the core command's, and so are its rules' ids.
        "vkCmdDrawIndirectCount" | "vkCmdDrawIndirectCountKHR" | "vkCmdDrawIndirectCountAMD" => (
            None,
            &[
                ("buffer", INDIRECT, "vkCmdDrawIndirectCount-buffer-02709"),
                (
                    "countBuffer",
                    INDIRECT,
                    "vkCmdDrawIndirectCount-countBuffer-02715",
                ),
            ],
        ),
        "vkCmdDrawIndexedIndirectCount"
        | "vkCmdDrawIndexedIndirectCountKHR"
        | "vkCmdDrawIndexedIndirectCountAMD" => (
            None,
            &[
                (
                    "buffer",
                    INDIRECT,
                    "vkCmdDrawIndexedIndirectCount-buffer-02709",
                ),
                (
                    "countBuffer",
                    INDIRECT,
                    "vkCmdDrawIndexedIndirectCount-countBuffer-02715",
                ),
            ],
        ),
        "vkCmdCopyBuffer" => (
            None,
            &[
                ("srcBuffer", TRANSFER_SRC, "vkCmdCopyBuffer-srcBuffer-00118"),
                ("dstBuffer", TRANSFER_DST, "vkCmdCopyBuffer-dstBuffer-00120"),
            ],
        ),
        "vkCmdCopyBuffer2" | "vkCmdCopyBuffer2KHR" => (
            Some("pCopyBufferInfo"),
            &[
                (
                    "srcBuffer",
                    TRANSFER_SRC,
                    "VkCopyBufferInfo2-srcBuffer-00118",
                ),
                (
                    "dstBuffer",
                    TRANSFER_DST,
                    "VkCopyBufferInfo2-dstBuffer-00120",
                ),
            ],
        ),
        "vkCmdCopyBufferToImage" => (
            None,
            &[(
                "srcBuffer",
                TRANSFER_SRC,
                "vkCmdCopyBufferToImage-srcBuffer-00174",
            )],
        ),
        "vkCmdCopyBufferToImage2" | "vkCmdCopyBufferToImage2KHR" => (
            Some("pCopyBufferToImageInfo"),
            &[(
                "srcBuffer",
                TRANSFER_SRC,
                "VkCopyBufferToImageInfo2-srcBuffer-00174",
            )],
        ),
        "vkCmdCopyImageToBuffer" => (
            None,
            &[(
                "dstBuffer",
                TRANSFER_DST,
                "vkCmdCopyImageToBuffer-dstBuffer-00191",
            )],
        ),
        "vkCmdCopyImageToBuffer2" | "vkCmdCopyImageToBuffer2KHR" => (
            Some("pCopyImageToBufferInfo"),
            &[(
                "dstBuffer",
                TRANSFER_DST,
                "VkCopyImageToBufferInfo2-dstBuffer-00191",
            )],
        ),
        "vkCmdFillBuffer" => (
            None,
            &[("dstBuffer", TRANSFER_DST, "vkCmdFillBuffer-dstBuffer-00029")],
        ),
        "vkCmdUpdateBuffer" => (
            None,
            &[(
                "dstBuffer",
                TRANSFER_DST,
                "vkCmdUpdateBuffer-dstBuffer-00034",
            )],
        ),
        _ => return None,
    })
}

/// A finding where `buffer` (a handle; none for 0 or one not created in the capture) lacks
/// the usage `need`; `at` names the member or element.
fn check(
    objects: &Objects,
    buffer: u64,
    (bit, name): (u64, &str),
    vuid: &str,
    command: &str,
    at: &str,
) -> Option<ValidUsageFinding> {
    let usage = objects.buffers.get(&buffer)?.usage;
    (usage & bit == 0).then(|| ValidUsageFinding {
        vuid: format!("VUID-{vuid}"),
        command: command.to_owned(),
        detail: format!("{at}: the buffer was created without {name} (usage {usage:#x})"),
    })
}

/// The buffers command `call` (recorded as `command`) binds, reads or writes without the
/// usage that use needs.
pub fn command_usage(
    call: &str,
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let mut out = Vec::new();
    let Some((info, arguments)) = buffer_arguments(call) else {
        return Ok(out);
    };
    let holder = super::valid_usage_params::holder(args, info)?;
    for &(member, need, vuid) in arguments {
        if member == "pBuffers" {
            for (i, b) in holder.list(member)?.iter().enumerate() {
                let at = format!("{member} (element {i})");
                out.extend(check(objects, b.handle()?, need, vuid, command, &at));
            }
        } else {
            let buffer = holder.get(member)?.handle()?;
            out.extend(check(objects, buffer, need, vuid, command, member));
        }
    }
    Ok(out)
}

/// The buffer descriptors `vkUpdateDescriptorSets` or `vkCmdPushDescriptorSetKHR` call
/// `command` writes whose buffer was created without the usage their type needs: uniform
/// (`VUID-VkWriteDescriptorSet-descriptorType-00330`) and storage buffers (`-00331`), uniform
/// (`-00334`) and storage texel buffer views (`-00335`).
pub fn descriptor_usage(
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let mut out = Vec::new();
    for (i, w) in args.list("pDescriptorWrites")?.iter().enumerate() {
        let kind = descriptor_kind(&w.get("descriptorType")?.symbol()?);
        let Some((need, number, texel)) = descriptor_needs(&kind) else {
            continue;
        };
        let vuid = format!("VkWriteDescriptorSet-descriptorType-{number}");
        if texel {
            for (j, v) in w.list("pTexelBufferView")?.iter().enumerate() {
                let Some(&(buffer, ..)) = objects.buffer_views.get(&v.handle()?) else {
                    continue;
                };
                let at = format!("pDescriptorWrites[{i}] (pTexelBufferView[{j}], a {kind})");
                out.extend(check(objects, buffer, need, &vuid, command, &at));
            }
        } else {
            for (j, b) in w.list("pBufferInfo")?.iter().enumerate() {
                let at = format!("pDescriptorWrites[{i}] (pBufferInfo[{j}], a {kind})");
                let buffer = b.get("buffer")?.handle()?;
                out.extend(check(objects, buffer, need, &vuid, command, &at));
            }
        }
    }
    Ok(out)
}

/// What a buffer descriptor type needs of its buffer's usage, the number of the
/// `VUID-VkWriteDescriptorSet-descriptorType-*` that says so, and whether it is a texel
/// buffer view.
fn descriptor_needs(kind: &str) -> Option<((u64, &'static str), &'static str, bool)> {
    Some(match kind {
        "UNIFORM_BUFFER" | "UNIFORM_BUFFER_DYNAMIC" => (UNIFORM, "00330", false),
        "STORAGE_BUFFER" | "STORAGE_BUFFER_DYNAMIC" => (STORAGE, "00331", false),
        "UNIFORM_TEXEL_BUFFER" => (UNIFORM_TEXEL, "00334", true),
        "STORAGE_TEXEL_BUFFER" => (STORAGE_TEXEL, "00335", true),
        _ => return None,
    })
}

/// The buffer descriptors a template writes (`entries`: each entry's index and what it
/// writes, which the layer takes as the write `pDescriptorWrites[index]`) whose buffer lacks
/// the usage their type needs.
pub fn written_usage(
    command: &str,
    entries: &EntryWrites,
    objects: &Objects,
) -> Vec<ValidUsageFinding> {
    let mut out = Vec::new();
    for (i, written) in entries {
        for ((binding, element), d) in written {
            let (buffer, kind) = match d {
                Descriptor::Buffer { buffer, ty, .. } => (*buffer, ty),
                Descriptor::TexelBuffer { view, ty } => match objects.buffer_views.get(view) {
                    Some(&(buffer, ..)) => (buffer, ty),
                    None => continue,
                },
                _ => continue,
            };
            let Some((need, number, _)) = descriptor_needs(kind) else {
                continue;
            };
            let vuid = format!("VkWriteDescriptorSet-descriptorType-{number}");
            let at =
                format!("pDescriptorWrites[{i}] (binding {binding} element {element}, a {kind})");
            out.extend(check(objects, buffer, need, &vuid, command, &at));
        }
    }
    out
}

/// `vkCreateBufferView` call `command`: a texel buffer view of a buffer created with neither
/// texel buffer usage (`VUID-VkBufferViewCreateInfo-buffer-00932`).
pub fn buffer_view_usage(
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let buffer = args.get("pCreateInfo")?.get("buffer")?.handle()?;
    let either = (
        UNIFORM_TEXEL.0 | STORAGE_TEXEL.0,
        "VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT or VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT",
    );
    let vuid = "VkBufferViewCreateInfo-buffer-00932";
    Ok(
        check(objects, buffer, either, vuid, command, "pCreateInfo.buffer")
            .into_iter()
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::state::BufferInfo;
    use crate::import::tree::Tree;
    use serde_json::{Value, json};

    const BUFFER: u64 = 7;
    const VIEW: u64 = 9;

    fn objects(usage: u64) -> Objects {
        let mut o = Objects::default();
        o.buffers.insert(
            BUFFER,
            BufferInfo {
                created_at: 0,
                destroyed_at: None,
                size: 256,
                usage,
                bound: None,
                alignment: None,
            },
        );
        o.buffer_views.insert(VIEW, (BUFFER, 0, 256));
        o
    }

    fn vuids(found: Vec<ValidUsageFinding>) -> Vec<String> {
        found.into_iter().map(|f| f.vuid).collect()
    }

    fn on(call: &str, args: &Value, usage: u64) -> Vec<String> {
        let tree = Tree::from_json(args);
        vuids(command_usage(call, "cmd #1", &Arg::root(&tree), &objects(usage)).unwrap())
    }

    /// Every command of the table, its buffer arguments all naming a buffer created with no
    /// usage: one finding per argument, with the table's VUID; with the usage each needs,
    /// none; and a null handle or a buffer the capture never created, none.
    #[test]
    fn each_command_names_the_usage_each_buffer_argument_needs() {
        let calls = [
            "vkCmdBindVertexBuffers",
            "vkCmdBindVertexBuffers2",
            "vkCmdBindVertexBuffers2EXT",
            "vkCmdBindIndexBuffer",
            "vkCmdDrawIndirect",
            "vkCmdDrawIndexedIndirect",
            "vkCmdDispatchIndirect",
            "vkCmdDrawIndirectCount",
            "vkCmdDrawIndirectCountKHR",
            "vkCmdDrawIndirectCountAMD",
            "vkCmdDrawIndexedIndirectCount",
            "vkCmdDrawIndexedIndirectCountKHR",
            "vkCmdDrawIndexedIndirectCountAMD",
            "vkCmdCopyBuffer",
            "vkCmdCopyBuffer2",
            "vkCmdCopyBuffer2KHR",
            "vkCmdCopyBufferToImage",
            "vkCmdCopyBufferToImage2",
            "vkCmdCopyBufferToImage2KHR",
            "vkCmdCopyImageToBuffer",
            "vkCmdCopyImageToBuffer2",
            "vkCmdCopyImageToBuffer2KHR",
            "vkCmdFillBuffer",
            "vkCmdUpdateBuffer",
        ];
        for call in calls {
            let (info, arguments) = buffer_arguments(call).unwrap();
            let mut holder = serde_json::Map::new();
            for &(member, ..) in arguments {
                let handle = if member == "pBuffers" {
                    json!([BUFFER, 0])
                } else {
                    json!(BUFFER)
                };
                holder.insert(member.to_owned(), handle);
            }
            let args = match info {
                Some(key) => json!({ key: holder }),
                None => Value::Object(holder),
            };
            let expected: Vec<String> = arguments
                .iter()
                .map(|(_, _, vuid)| format!("VUID-{vuid}"))
                .collect();
            assert_eq!(on(call, &args, 0), expected, "{call}");
            let all = arguments.iter().fold(0, |u, (_, (bit, _), _)| u | bit);
            assert!(on(call, &args, all).is_empty(), "{call}");
            let tree = Tree::from_json(&args);
            let none = command_usage(call, "cmd #1", &Arg::root(&tree), &Objects::default());
            assert!(none.unwrap().is_empty(), "{call}");
        }
        // Each VUID names its own command, or its `*Info2` structure.
        for call in calls {
            let (info, arguments) = buffer_arguments(call).unwrap();
            for (_, _, vuid) in arguments {
                let named = vuid.split('-').next().unwrap();
                let stem = call
                    .trim_end_matches("KHR")
                    .trim_end_matches("EXT")
                    .trim_end_matches("AMD");
                assert!(
                    named == stem || info.is_some() && named.starts_with("Vk"),
                    "{call}: {vuid}"
                );
            }
        }
        assert!(buffer_arguments("vkCmdDraw").is_none());
    }

    /// Each buffer descriptor type against the usage it needs, texel buffers through their
    /// view's buffer; image descriptors are not this check's.
    #[test]
    fn buffer_descriptors_need_their_type_of_usage() {
        let cases = [
            ("VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER", 0x10, "00330", false),
            (
                "VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC",
                0x10,
                "00330",
                false,
            ),
            ("VK_DESCRIPTOR_TYPE_STORAGE_BUFFER", 0x20, "00331", false),
            (
                "VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC",
                0x20,
                "00331",
                false,
            ),
            (
                "VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER",
                0x4,
                "00334",
                true,
            ),
            (
                "VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER",
                0x8,
                "00335",
                true,
            ),
        ];
        for (ty, bit, number, texel) in cases {
            let write = if texel {
                json!({"descriptorType": ty, "pTexelBufferView": [VIEW]})
            } else {
                json!({"descriptorType": ty, "pBufferInfo": [{"buffer": BUFFER}]})
            };
            let args = json!({ "pDescriptorWrites": [write] });
            let tree = Tree::from_json(&args);
            let found = |usage| {
                vuids(descriptor_usage("w #1", &Arg::root(&tree), &objects(usage)).unwrap())
            };
            assert_eq!(
                found(0x1ff & !bit),
                [format!("VUID-VkWriteDescriptorSet-descriptorType-{number}")],
                "{ty}"
            );
            assert!(found(bit).is_empty(), "{ty}");
        }
        let image = json!({"pDescriptorWrites": [{"descriptorType": "VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE", "pImageInfo": [{"imageView": VIEW}]}]});
        let tree = Tree::from_json(&image);
        assert!(
            descriptor_usage("w #1", &Arg::root(&tree), &objects(0))
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn a_texel_buffer_view_needs_a_texel_buffer_usage() {
        let args = json!({"pCreateInfo": {"buffer": BUFFER}});
        let tree = Tree::from_json(&args);
        let found =
            |usage| vuids(buffer_view_usage("v #1", &Arg::root(&tree), &objects(usage)).unwrap());
        assert_eq!(found(0x10), ["VUID-VkBufferViewCreateInfo-buffer-00932"]);
        assert!(found(0x4).is_empty());
        assert!(found(0x8).is_empty());
    }
}
