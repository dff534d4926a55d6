//! A RenderDoc chunk's parameters as the call arguments the importer reads, typed by the same
//! registry tables that decode GFXReconstruct's binary captures: enums by name where the
//! registry says enum, flags and handles as numbers, floats as the shortest decimal of their
//! 32 bits, lists where the registry gives a length. RenderDoc names a call's parameters
//! itself (`CreateInfo`, `Image`, `CmdPool`); each is matched to the registry's parameter
//! (`pCreateInfo`, `pImage`, `pCommandPool`) by rule, so a call is not hand-mapped.

use serde_json::{Map, Value};

use super::super::gfxr::registry::{self, CommandDef, ENUMS, Field, STRUCTS, Ty};
use super::super::value::shortest;
use super::errors::{ArgError, ArgProblem, ChunkError};
use super::xml::Node;

/// Byte buffers read inline as numbers (push constant values, small data); longer ones are
/// contents, read by whoever needs them.
const INLINE_BYTES: u64 = 64 << 10;

/// Reads a `<buffer>`'s bytes from the zip.
pub type Load<'a> = dyn FnMut(&Node) -> Result<Vec<u8>, ChunkError> + 'a;

/// The registry parameter a RenderDoc parameter stands for: the same name; the same name in
/// another case; the registry's `p`-prefixed pointer to it (`CreateInfo` -> `pCreateInfo`);
/// the plural list of it (`Pipeline` -> `pPipelines`); or one of RenderDoc's own spellings.
pub fn param(def: &CommandDef, rdc: &str) -> Option<&'static Field> {
    let rdc = match rdc {
        "CmdPool" => "pCommandPool",
        "count" => "createInfoCount",
        "setCount" => "descriptorSetCount",
        "x" => "groupCountX",
        "y" => "groupCountY",
        "z" => "groupCountZ",
        "start" => "offset",
        "length" => "size",
        "values" => "pValues",
        "Label" => "pLabelInfo",
        "Marker" => "pMarkerInfo",
        "blendConst" => "blendConstants",
        "writeCount" => "descriptorWriteCount",
        "copyCount" => "descriptorCopyCount",
        "memRangeCount" => "memoryRangeCount",
        other => other,
    };
    // RenderDoc spells the registry's `dst` as `dest` (`destStageMask`, `destBuffer`).
    let dst;
    let rdc = match rdc.strip_prefix("dest") {
        Some(rest) => {
            dst = format!("dst{rest}");
            dst.as_str()
        }
        None => rdc,
    };
    let params = def.params;
    params
        .iter()
        .find(|f| f.name == rdc)
        .or_else(|| params.iter().find(|f| f.name.eq_ignore_ascii_case(rdc)))
        .or_else(|| {
            params.iter().find(|f| {
                f.name.len() == rdc.len() + 1
                    && f.name.starts_with('p')
                    && f.name[1..].eq_ignore_ascii_case(rdc)
            })
        })
        .or_else(|| {
            params.iter().find(|f| {
                f.name.len() == rdc.len() + 2
                    && f.name.starts_with('p')
                    && f.name.ends_with('s')
                    && f.name[1..f.name.len() - 1].eq_ignore_ascii_case(rdc)
            })
        })
}

/// The call's arguments: each parameter RenderDoc wrote that the registry knows, converted
/// by its registry type. Parameters RenderDoc adds of its own (`DebugMessages`,
/// `memoryRequirements`) are left to the chunk's reader.
pub fn call_args(def: &CommandDef, chunk: &Node, load: &mut Load<'_>) -> Result<Value, ArgError> {
    let mut args = Map::new();
    for c in &chunk.children {
        let Some(name) = &c.name else { continue };
        if let Some(f) = param(def, name) {
            let v = value(c, Some(f.ty), load).map_err(|e| e.within(name))?;
            args.insert(f.name.to_owned(), v);
        }
    }
    Ok(Value::Object(args))
}

/// One element as JSON, typed by `ty` where the registry knows it, else by its own tag.
pub fn value(node: &Node, ty: Option<Ty>, load: &mut Load<'_>) -> Result<Value, ArgError> {
    if let Some(Ty::Arr(elem)) = ty
        && node.tag != "array"
        && node.tag != "null"
        && node.tag != "buffer"
    {
        return Ok(Value::Array(vec![value(node, Some(*elem), load)?]));
    }
    Ok(match node.tag.as_str() {
        "null" => Value::Null,
        "struct" => {
            let def = match ty {
                Some(Ty::Struct(i)) => Some(i),
                Some(Ty::Ptr(Ty::Struct(i))) => Some(*i),
                _ => None,
            }
            .or_else(|| node.typename.as_deref().and_then(registry::struct_named))
            .and_then(|i| STRUCTS.get(usize::from(i)));
            let mut map = Map::new();
            for c in &node.children {
                let Some(name) = &c.name else { continue };
                let mty = def
                    .and_then(|d| d.members.iter().find(|m| m.name == name))
                    .map(|m| m.ty);
                let v = value(c, mty, load).map_err(|e| e.within(name))?;
                map.insert(name.clone(), v);
            }
            Value::Object(map)
        }
        "array" => {
            let elem = match ty {
                Some(Ty::Ptr(e) | Ty::Arr(e)) => Some(*e),
                _ => None,
            };
            let mut items = Vec::with_capacity(node.children.len());
            for (i, c) in node.children.iter().enumerate() {
                items.push(value(c, elem, load).map_err(|e| e.within(format_args!("[{i}]")))?);
            }
            Value::Array(items)
        }
        "enum" => enumerant(node, ty),
        "uint" | "ResourceId" => match node.text.trim().parse::<u64>() {
            Ok(v) => enum_or(v as i64, ty, Value::from(v)),
            Err(_) => return Err(ArgProblem::NotUnsigned(node.text.clone()).into()),
        },
        "int" => match node.text.trim().parse::<i64>() {
            // RenderDoc writes some unsigned members signed (`VK_QUEUE_FAMILY_IGNORED` as -1).
            Ok(v) if matches!(ty, Some(Ty::U32 | Ty::Flags32)) => Value::from(v as u32),
            Ok(v) if matches!(ty, Some(Ty::U64 | Ty::Flags64 | Ty::Handle)) => {
                Value::from(v as u64)
            }
            Ok(v) => enum_or(v, ty, Value::from(v)),
            Err(_) => return Err(ArgProblem::NotNumber(node.text.clone()).into()),
        },
        "float" | "double" => {
            let v: f64 = node
                .text
                .trim()
                .parse()
                .map_err(|_| ArgProblem::NotNumber(node.text.clone()))?;
            if node.tag == "float" {
                Value::from(shortest(v as f32))
            } else {
                Value::from(v)
            }
        }
        "bool" => Value::Bool(node.text.trim() == "true"),
        "string" => Value::from(node.text.clone()),
        "buffer" => {
            let len = node.byte_length.unwrap_or(0);
            let elem = match ty {
                Some(Ty::Ptr(e) | Ty::Arr(e)) => Some(*e),
                _ => None,
            };
            // Small byte arrays (push constants, update data) inline; code and contents are
            // read by whoever needs them, as GFXReconstruct's long arrays are.
            match elem {
                Some(Ty::U8) if len <= INLINE_BYTES => {
                    Value::Array(load(node)?.iter().map(|b| Value::from(*b)).collect())
                }
                _ => Value::from(format!("({len} bytes)")),
            }
        }
        _ => Value::Null,
    })
}

/// A number the registry types as an enum, given by name as the other routes give it.
fn enum_or(raw: i64, ty: Option<Ty>, number: Value) -> Value {
    match ty {
        Some(Ty::Enum(e)) => ENUMS
            .get(usize::from(e))
            .and_then(|d| d.name_of(raw as i32))
            .map_or(number, Value::from),
        _ => number,
    }
}

/// An `<enum>`: by name where the registry types it as an enum (or, untyped, where RenderDoc
/// names a single enumerant); flags as their number.
fn enumerant(node: &Node, ty: Option<Ty>) -> Value {
    let raw: i64 = node.text.trim().parse().unwrap_or(0);
    let number = Value::from(raw);
    match ty {
        Some(Ty::Enum(_)) => enum_or(raw, ty, number),
        Some(_) => number,
        None => match node.string.as_deref() {
            Some(s)
                if s.starts_with("VK_")
                    && !s.contains('|')
                    && !node
                        .typename
                        .as_deref()
                        .is_some_and(|t| t.ends_with("Flags")) =>
            {
                Value::from(s)
            }
            _ => number,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(name: &str) -> &'static CommandDef {
        registry::command_named(name).unwrap_or_else(|| panic!("{name} is in the tables"))
    }

    #[test]
    fn renderdoc_parameters_find_the_registry_ones() {
        let cases = [
            ("vkCreateImage", "CreateInfo", "pCreateInfo"),
            ("vkCreateImage", "Image", "pImage"),
            ("vkCreateCommandPool", "CmdPool", "pCommandPool"),
            ("vkCreateSwapchainKHR", "SwapChain", "pSwapchain"),
            ("vkBeginCommandBuffer", "CommandBuffer", "commandBuffer"),
            (
                "vkAllocateCommandBuffers",
                "CommandBuffer",
                "pCommandBuffers",
            ),
            ("vkCreateGraphicsPipelines", "CreateInfo", "pCreateInfos"),
            ("vkCreateGraphicsPipelines", "Pipeline", "pPipelines"),
            ("vkCmdPipelineBarrier", "destStageMask", "dstStageMask"),
            ("vkCmdCopyBuffer", "destBuffer", "dstBuffer"),
            ("vkCmdDispatch", "y", "groupCountY"),
            ("vkCmdPushConstants", "values", "pValues"),
            ("vkCmdBindDescriptorSets", "setCount", "descriptorSetCount"),
            ("vkCmdSetBlendConstants", "blendConst", "blendConstants"),
            (
                "vkUpdateDescriptorSets",
                "writeCount",
                "descriptorWriteCount",
            ),
            ("vkUpdateDescriptorSets", "copyCount", "descriptorCopyCount"),
            (
                "vkFlushMappedMemoryRanges",
                "memRangeCount",
                "memoryRangeCount",
            ),
        ];
        for (cmd, rdc, ours) in cases {
            assert_eq!(
                param(command(cmd), rdc).map(|f| f.name),
                Some(ours),
                "{cmd} {rdc}"
            );
        }
        // RenderDoc's own records match nothing.
        assert!(param(command("vkBeginCommandBuffer"), "BakedCommandBuffer").is_none());
        assert!(param(command("vkCreateImage"), "memoryRequirements").is_none());
    }

    fn leaf(tag: &str, name: &str, text: &str, string: Option<&str>) -> Node {
        Node {
            tag: tag.to_owned(),
            name: Some(name.to_owned()),
            string: string.map(str::to_owned),
            text: text.to_owned(),
            ..Node::default()
        }
    }

    #[test]
    fn values_are_typed_by_the_registry() {
        let ci = Node {
            tag: "struct".to_owned(),
            name: Some("CreateInfo".to_owned()),
            typename: Some("VkImageCreateInfo".to_owned()),
            children: vec![
                leaf("enum", "format", "124", Some("VK_FORMAT_D16_UNORM")),
                leaf(
                    "enum",
                    "usage",
                    "32",
                    Some("VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT"),
                ),
                leaf("enum", "samples", "1", Some("VK_SAMPLE_COUNT_1_BIT")),
                leaf("int", "mipLevels", "-1", None),
            ],
            ..Node::default()
        };
        let chunk = Node {
            tag: "chunk".to_owned(),
            children: vec![ci, leaf("ResourceId", "Image", "160", None)],
            ..Node::default()
        };
        let mut load = |_: &Node| -> Result<Vec<u8>, ChunkError> { Err(ChunkError::NoByteLength) };
        let args = call_args(command("vkCreateImage"), &chunk, &mut load).unwrap();
        assert_eq!(args["pImage"], 160);
        let ci = &args["pCreateInfo"];
        assert_eq!(ci["format"], "VK_FORMAT_D16_UNORM");
        assert_eq!(ci["usage"], 32, "flags stay numbers");
        assert_eq!(
            ci["samples"], "VK_SAMPLE_COUNT_1_BIT",
            "the registry says enum"
        );
        assert_eq!(
            ci["mipLevels"],
            u64::from(u32::MAX),
            "unsigned written signed"
        );
        // A float is the shortest decimal of its 32 bits.
        let f = leaf("float", "x", "0.20000000298023224", None);
        assert_eq!(value(&f, Some(Ty::F32), &mut load).unwrap(), 0.2);
        // A parameter the registry makes a list comes as one, even from a single value.
        let one = leaf("ResourceId", "DescriptorSet", "192", None);
        let def = command("vkAllocateDescriptorSets");
        let f = param(def, "DescriptorSet").unwrap();
        assert_eq!(
            value(&one, Some(f.ty), &mut load).unwrap(),
            serde_json::json!([192])
        );
    }
}
