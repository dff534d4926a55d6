//! Valid usage checked statically from the calls: statements of the specification that real
//! programs break and that need no execution to see, each finding with its VUID. A finding
//! is not a refusal: drivers run such frames, and so does the replay.
//!
//! Checked here: a render pass that loads an attachment whose initial layout is `UNDEFINED`
//! (its contents are undefined at the load; garbage on some GPUs), for the colour or depth
//! aspect (`loadOp`) and the stencil aspect (`stencilLoadOp`); and an image's usage flags
//! against its use: image descriptors written of it (sampled, storage, input attachment),
//! layout transitions from or to a layout its usage does not allow, transfer commands (copies,
//! blits, colour clears) that read or write it without `TRANSFER_SRC`/`TRANSFER_DST`,
//! framebuffers whose render pass uses it as an attachment of a kind its usage lacks, and
//! render passes begun that put it in a layout its usage does not allow; descriptors
//! written through update templates, as the writes they stand for; barriers that transition
//! to `UNDEFINED` or `PREINITIALIZED`. Regions of buffer-image copies are checked in
//! `valid_usage_copies`. Buffers' usage
//! against their use is checked in `valid_usage_buffers`. Layouts at use (a barrier's old
//! layout, a render pass's initial layout, a descriptor's layout) are checked with the
//! synchronization rules, which track the layouts (`sync`).

use super::state::{Descriptor, Objects, descriptor_kind};
use super::valid_usage_params::holder;
use super::value::{Arg, Got};
use crate::capture::format::ValidUsageFinding;
use crate::capture::vulkan::ImageLayout;

const UNDEFINED: &str = "VK_IMAGE_LAYOUT_UNDEFINED";
const LOAD: &str = "VK_ATTACHMENT_LOAD_OP_LOAD";

/// `vkCreateRenderPass` (`v2`: `vkCreateRenderPass2`) call `command`: every attachment it
/// loads from `initialLayout` UNDEFINED, and every resolve of a single-sampled attachment.
pub fn render_pass(command: &str, v2: bool, args: &Arg<'_>) -> Got<Vec<ValidUsageFinding>> {
    let ci = args.get("pCreateInfo")?;
    let structure = if v2 {
        "VkAttachmentDescription2"
    } else {
        "VkAttachmentDescription"
    };
    let mut out = Vec::new();
    for (i, a) in ci.list("pAttachments")?.iter().enumerate() {
        if a.get("initialLayout")?.name()? != UNDEFINED {
            continue;
        }
        let format = a.get("format")?.name()?;
        let stencil = format == "VK_FORMAT_S8_UINT" || format.ends_with("_S8_UINT");
        let color_or_depth = format != "VK_FORMAT_S8_UINT";
        // Vulkan 1.2's description may give the stencil aspect a layout of its own; without
        // one the stencil starts in `initialLayout` too.
        let separate_stencil = v2 && a.opt("pNext").is_some();
        let stencil_vuid = if v2 { "format-06703" } else { "format-06700" };
        let checks = [
            (color_or_depth, "loadOp", "format-06699"),
            (stencil && !separate_stencil, "stencilLoadOp", stencil_vuid),
        ];
        for (applies, member, number) in checks {
            if applies && a.get(member)?.name()? == LOAD {
                out.push(ValidUsageFinding {
                    vuid: format!("VUID-{structure}-{number}"),
                    command: command.to_owned(),
                    detail: format!(
                        "pAttachments[{i}] ({format}): {member} {LOAD} with initialLayout {UNDEFINED}"
                    ),
                });
            }
        }
    }
    out.extend(single_sample_resolves(&ci, v2, command)?);
    Ok(out)
}

/// Resolve attachments of a render pass's subpasses whose colour attachment has one sample
/// (`VUID-VkSubpassDescription-pResolveAttachments-00848`; the second structure's `03067`):
/// drivers copy the texels, which the replay does too.
fn single_sample_resolves(ci: &Arg<'_>, v2: bool, command: &str) -> Got<Vec<ValidUsageFinding>> {
    const UNUSED: u64 = 0xFFFF_FFFF;
    let (structure, number) = if v2 {
        ("VkSubpassDescription2", "03067")
    } else {
        ("VkSubpassDescription", "00848")
    };
    let attachments = ci.list("pAttachments")?;
    let mut out = Vec::new();
    for (s, sub) in ci.list("pSubpasses")?.iter().enumerate() {
        let colors = sub.list("pColorAttachments")?;
        for (k, r) in sub.list("pResolveAttachments")?.iter().enumerate() {
            let resolve = r.get("attachment")?.u64()?;
            let Some(color) = colors.get(k) else { continue };
            let color = color.get("attachment")?.u64()?;
            if resolve == UNUSED || color == UNUSED {
                continue;
            }
            let Some(a) = attachments.get(color as usize) else {
                continue;
            };
            if super::state::samples(&a.get("samples")?)? == 1 {
                out.push(ValidUsageFinding {
                    vuid: format!("VUID-{structure}-pResolveAttachments-{number}"),
                    command: command.to_owned(),
                    detail: format!(
                        "pSubpasses[{s}].pResolveAttachments[{k}]: attachment {resolve} resolves colour attachment {color}, which has one sample"
                    ),
                });
            }
        }
    }
    Ok(out)
}

/// `vkCreateImage` call `command`: a transient attachment with a use besides attachments
/// (`VUID-VkImageCreateInfo-usage-00963`; vkBasalt adds `SAMPLED` to the transient depth
/// buffer Qt asks for, to read it later).
pub fn image_usage(command: &str, args: &Arg<'_>) -> Got<Vec<ValidUsageFinding>> {
    const TRANSIENT: u64 = 0x40;
    const ATTACHMENTS: u64 = COLOR_ATTACHMENT | DEPTH_STENCIL_ATTACHMENT | INPUT_ATTACHMENT;
    let usage = args.get("pCreateInfo")?.get("usage")?.u64()?;
    let others = usage & !(TRANSIENT | ATTACHMENTS);
    if usage & TRANSIENT == 0 || others == 0 {
        return Ok(Vec::new());
    }
    Ok(vec![ValidUsageFinding {
        vuid: "VUID-VkImageCreateInfo-usage-00963".to_owned(),
        command: command.to_owned(),
        detail: format!(
            "pCreateInfo->usage {usage:#x}: TRANSIENT_ATTACHMENT with usage {others:#x} besides the attachment bits"
        ),
    }])
}

/// `vkCreateDevice` call `command`: features asked for twice, in a `VkPhysicalDeviceFeatures2`
/// of the `pNext` chain and in `pEnabledFeatures` (`VUID-VkDeviceCreateInfo-pNext-00373`; a
/// layer between the program and the driver that adds its own feature structure does so).
pub fn device_features(command: &str, args: &Arg<'_>) -> Got<Vec<ValidUsageFinding>> {
    const FEATURES_2: &str = "VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2";
    // The structure's value, where a stream spells it as a number.
    const FEATURES_2_VALUE: &str = "1000059000";
    let ci = args.get("pCreateInfo")?;
    if ci.opt("pEnabledFeatures").is_none() {
        return Ok(Vec::new());
    }
    let mut next = ci.opt("pNext");
    while let Some(n) = next {
        let s_type = n.opt("sType").and_then(|t| t.symbol().ok());
        if s_type.is_some_and(|t| t == FEATURES_2 || t == FEATURES_2_VALUE) {
            return Ok(vec![ValidUsageFinding {
                vuid: "VUID-VkDeviceCreateInfo-pNext-00373".to_owned(),
                command: command.to_owned(),
                detail: "pCreateInfo->pNext holds a VkPhysicalDeviceFeatures2 and pEnabledFeatures is not NULL".to_owned(),
            }]);
        }
        next = n.opt("pNext");
    }
    Ok(Vec::new())
}

/// `VkImageUsageFlagBits` a use needs.
const TRANSFER_SRC: u64 = 0x1;
const TRANSFER_DST: u64 = 0x2;
const SAMPLED: u64 = 0x4;
const STORAGE: u64 = 0x8;
const COLOR_ATTACHMENT: u64 = 0x10;
const DEPTH_STENCIL_ATTACHMENT: u64 = 0x20;
const INPUT_ATTACHMENT: u64 = 0x80;

/// What a descriptor type needs of its image's usage: the bits (any of them), their names and
/// the number of `VUID-VkWriteDescriptorSet-descriptorType-*` that says so.
fn descriptor_needs(kind: &str) -> Option<(u64, &'static str, &'static str)> {
    match kind {
        "SAMPLED_IMAGE" | "COMBINED_IMAGE_SAMPLER" => {
            Some((SAMPLED, "VK_IMAGE_USAGE_SAMPLED_BIT", "00337"))
        }
        "INPUT_ATTACHMENT" => Some((
            INPUT_ATTACHMENT,
            "VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT",
            "00338",
        )),
        "STORAGE_IMAGE" => Some((STORAGE, "VK_IMAGE_USAGE_STORAGE_BIT", "00339")),
        _ => None,
    }
}

/// The descriptors `vkUpdateDescriptorSets` or `vkCmdPushDescriptorSetKHR` call `command`
/// writes whose image or buffer was created without the usage their type needs.
pub fn descriptor_usage(
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let mut found = image_descriptor_usage(command, args, objects)?;
    found.extend(super::valid_usage_buffers::descriptor_usage(
        command, args, objects,
    )?);
    Ok(found)
}

pub use super::valid_usage_clears::clear_values;

/// The images and buffers command `call` (recorded as `command`) reads, writes or binds
/// without the usage that use needs: transfers of images here, every buffer use in
/// `valid_usage_buffers`.
pub fn command_usage(
    call: &str,
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let mut found = transfer_usage(call, command, args, objects)?;
    found.extend(super::valid_usage_buffers::command_usage(
        call, command, args, objects,
    )?);
    // A call too malformed for this check keeps what the others found.
    found.extend(
        super::valid_usage_clears::clear_values(call, command, args, objects).unwrap_or_default(),
    );
    found.extend(
        super::valid_usage_copies::regions(call, command, args, objects).unwrap_or_default(),
    );
    Ok(found)
}

/// The finding for an image descriptor of type `kind` (written at `at`) whose view's image
/// lacks the usage `needs` (bits, their names, the VUID's number) says its type needs.
fn view_lacks(
    objects: &Objects,
    view: u64,
    kind: &str,
    (bits, names, number): (u64, &str, &str),
    command: &str,
    at: &str,
) -> Option<ValidUsageFinding> {
    let image = objects
        .views
        .get(&view)
        .and_then(|v| objects.images.get(&v.image))?;
    (image.usage & bits == 0).then(|| ValidUsageFinding {
        vuid: format!("VUID-VkWriteDescriptorSet-descriptorType-{number}"),
        command: command.to_owned(),
        detail: format!(
            "{at}: a {kind} descriptor of an image created without {names} (usage {:#x})",
            image.usage
        ),
    })
}

/// The image descriptors of such a call whose image lacks the usage their type needs.
fn image_descriptor_usage(
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let mut out = Vec::new();
    for (i, w) in args.list("pDescriptorWrites")?.iter().enumerate() {
        let kind = descriptor_kind(&w.get("descriptorType")?.symbol()?);
        let Some((bits, names, number)) = descriptor_needs(&kind) else {
            continue;
        };
        for (j, info) in w.list("pImageInfo")?.iter().enumerate() {
            let view = info.get("imageView")?.handle()?;
            let at = format!("pDescriptorWrites[{i}] (pImageInfo[{j}])");
            let needs = (bits, names, number);
            out.extend(view_lacks(objects, view, &kind, needs, command, &at));
        }
    }
    Ok(out)
}

/// The descriptors update template call `command` writes (`template` with its data `data`)
/// whose image or buffer lacks the usage their type needs. The layer takes each entry of the
/// template as the write `pDescriptorWrites[entry]`, and so do the findings.
pub fn template_usage(
    command: &str,
    template: u64,
    data: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let entries = objects.template_entry_writes(template, data)?;
    let mut out = Vec::new();
    for (i, written) in &entries {
        for ((binding, element), d) in written {
            let Descriptor::Image { view, ty, .. } = d else {
                continue;
            };
            let Some(needs) = descriptor_needs(ty) else {
                continue;
            };
            let at = format!("pDescriptorWrites[{i}] (binding {binding} element {element})");
            out.extend(view_lacks(objects, *view, ty, needs, command, &at));
        }
    }
    out.extend(super::valid_usage_buffers::written_usage(
        command, &entries, objects,
    ));
    Ok(out)
}

/// What a layout needs of an image's usage in a layout transition: the bits (any of them),
/// their names and the number of `VUID-VkImageMemoryBarrier(2)-oldLayout-*` that says so.
fn layout_needs(layout: ImageLayout) -> Option<(u64, &'static str, &'static str)> {
    const DS: &str = "VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT";
    Some(match layout {
        ImageLayout::ColorAttachmentOptimal => (
            COLOR_ATTACHMENT,
            "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT",
            "01208",
        ),
        ImageLayout::DepthStencilAttachmentOptimal => (DEPTH_STENCIL_ATTACHMENT, DS, "01209"),
        ImageLayout::DepthStencilReadOnlyOptimal => (DEPTH_STENCIL_ATTACHMENT, DS, "01210"),
        ImageLayout::ShaderReadOnlyOptimal => (
            SAMPLED | INPUT_ATTACHMENT,
            "VK_IMAGE_USAGE_SAMPLED_BIT or VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT",
            "01211",
        ),
        ImageLayout::TransferSrcOptimal => {
            (TRANSFER_SRC, "VK_IMAGE_USAGE_TRANSFER_SRC_BIT", "01212")
        }
        ImageLayout::TransferDstOptimal => {
            (TRANSFER_DST, "VK_IMAGE_USAGE_TRANSFER_DST_BIT", "01213")
        }
        ImageLayout::DepthReadOnlyStencilAttachmentOptimal => {
            (DEPTH_STENCIL_ATTACHMENT, DS, "01658")
        }
        ImageLayout::DepthAttachmentStencilReadOnlyOptimal => {
            (DEPTH_STENCIL_ATTACHMENT, DS, "01659")
        }
        _ => return None,
    })
}

/// The image barriers of `vkCmdPipelineBarrier` (`v2`: `vkCmdPipelineBarrier2`) call
/// `command` that transition an image from or to a layout its usage does not allow, or to
/// `UNDEFINED` or `PREINITIALIZED` (`-newLayout-01198`: FFmpeg hands unused planes over so).
pub fn barrier_usage(
    command: &str,
    v2: bool,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let (barriers, structure) = if v2 {
        (
            args.get("pDependencyInfo")?.list("pImageMemoryBarriers")?,
            "VkImageMemoryBarrier2",
        )
    } else {
        (args.list("pImageMemoryBarriers")?, "VkImageMemoryBarrier")
    };
    let mut out = Vec::new();
    for (i, b) in barriers.iter().enumerate() {
        let (old, new) = (b.get("oldLayout")?.layout()?, b.get("newLayout")?.layout()?);
        let ownership =
            b.get("srcQueueFamilyIndex")?.u64()? != b.get("dstQueueFamilyIndex")?.u64()?;
        // The rule holds for a layout transition or a queue family ownership transfer.
        if old == new && !ownership {
            continue;
        }
        if matches!(new, ImageLayout::Undefined | ImageLayout::Preinitialized) {
            out.push(ValidUsageFinding {
                vuid: format!("VUID-{structure}-newLayout-01198"),
                command: command.to_owned(),
                detail: format!(
                    "pImageMemoryBarriers[{i}].newLayout {}: a transition cannot go to it",
                    new.name()
                ),
            });
        }
        let Some(image) = objects.images.get(&b.get("image")?.handle()?) else {
            continue;
        };
        for (member, layout) in [("oldLayout", old), ("newLayout", new)] {
            let Some((bits, names, number)) = layout_needs(layout) else {
                continue;
            };
            if image.usage & bits == 0 {
                out.push(ValidUsageFinding {
                    vuid: format!("VUID-{structure}-oldLayout-{number}"),
                    command: command.to_owned(),
                    detail: format!(
                        "pImageMemoryBarriers[{i}].{member} {}: the image was created without {names} (usage {:#x})",
                        layout.name(),
                        image.usage
                    ),
                });
            }
        }
    }
    Ok(out)
}

/// An image argument of a transfer command: its name, the usage bit it needs, and the VUID
/// (without `VUID-`) that says so.
type ImageArgument = (&'static str, u64, &'static str);

/// The images a transfer command (its name `call`) reads or writes: the argument (inside
/// `info`, the `*Info2` structure, for the `2` commands), the usage bit it needs and the VUID.
fn transfer_images(call: &str) -> Option<(Option<&'static str>, &'static [ImageArgument])> {
    const COPY: &[ImageArgument] = &[
        ("srcImage", TRANSFER_SRC, "vkCmdCopyImage-srcImage-00126"),
        ("dstImage", TRANSFER_DST, "vkCmdCopyImage-dstImage-00131"),
    ];
    const COPY2: &[ImageArgument] = &[
        ("srcImage", TRANSFER_SRC, "VkCopyImageInfo2-srcImage-00126"),
        ("dstImage", TRANSFER_DST, "VkCopyImageInfo2-dstImage-00131"),
    ];
    const BLIT: &[ImageArgument] = &[
        ("srcImage", TRANSFER_SRC, "vkCmdBlitImage-srcImage-00219"),
        ("dstImage", TRANSFER_DST, "vkCmdBlitImage-dstImage-00224"),
    ];
    const BLIT2: &[ImageArgument] = &[
        ("srcImage", TRANSFER_SRC, "VkBlitImageInfo2-srcImage-00219"),
        ("dstImage", TRANSFER_DST, "VkBlitImageInfo2-dstImage-00224"),
    ];
    Some(match call {
        "vkCmdCopyImage" => (None, COPY),
        "vkCmdCopyImage2" | "vkCmdCopyImage2KHR" => (Some("pCopyImageInfo"), COPY2),
        "vkCmdBlitImage" => (None, BLIT),
        "vkCmdBlitImage2" | "vkCmdBlitImage2KHR" => (Some("pBlitImageInfo"), BLIT2),
        "vkCmdCopyBufferToImage" => (
            None,
            &[(
                "dstImage",
                TRANSFER_DST,
                "vkCmdCopyBufferToImage-dstImage-00177",
            )],
        ),
        "vkCmdCopyBufferToImage2" | "vkCmdCopyBufferToImage2KHR" => (
            Some("pCopyBufferToImageInfo"),
            &[(
                "dstImage",
                TRANSFER_DST,
                "VkCopyBufferToImageInfo2-dstImage-00177",
            )],
        ),
        "vkCmdCopyImageToBuffer" => (
            None,
            &[(
                "srcImage",
                TRANSFER_SRC,
                "vkCmdCopyImageToBuffer-srcImage-00186",
            )],
        ),
        "vkCmdCopyImageToBuffer2" | "vkCmdCopyImageToBuffer2KHR" => (
            Some("pCopyImageToBufferInfo"),
            &[(
                "srcImage",
                TRANSFER_SRC,
                "VkCopyImageToBufferInfo2-srcImage-00186",
            )],
        ),
        "vkCmdClearColorImage" => (
            None,
            &[("image", TRANSFER_DST, "vkCmdClearColorImage-image-00002")],
        ),
        _ => return None,
    })
}

/// The images transfer command `command` (named `call`) reads or writes without the
/// `TRANSFER_SRC` or `TRANSFER_DST` usage it needs.
fn transfer_usage(
    call: &str,
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let mut out = Vec::new();
    let Some((info, images)) = transfer_images(call) else {
        return Ok(out);
    };
    let holder = holder(args, info)?;
    for &(member, bit, vuid) in images {
        let Some(image) = objects.images.get(&holder.get(member)?.handle()?) else {
            continue;
        };
        if image.usage & bit == 0 {
            let name = if bit == TRANSFER_SRC {
                "VK_IMAGE_USAGE_TRANSFER_SRC_BIT"
            } else {
                "VK_IMAGE_USAGE_TRANSFER_DST_BIT"
            };
            out.push(ValidUsageFinding {
                vuid: format!("VUID-{vuid}"),
                command: command.to_owned(),
                detail: format!(
                    "{member}: the image was created without {name} (usage {:#x})",
                    image.usage
                ),
            });
        }
    }
    Ok(out)
}

/// `vkCreateFramebuffer` call `command`: each attachment its render pass uses as a colour or
/// resolve attachment (`VUID-VkFramebufferCreateInfo-pAttachments-00877`), depth/stencil
/// attachment (`-02633`) or input attachment (`-00879`) whose image was created without that
/// usage. An imageless framebuffer names no views here.
pub fn framebuffer_usage(
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    const IMAGELESS: u64 = 0x1;
    let ci = args.get("pCreateInfo")?;
    let mut out = Vec::new();
    if ci.get("flags")?.u64()? & IMAGELESS != 0 {
        return Ok(out);
    }
    let Some(pass) = objects.render_passes.get(&ci.get("renderPass")?.handle()?) else {
        return Ok(out);
    };
    const COLOR: (u64, &str, &str) = (
        COLOR_ATTACHMENT,
        "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT",
        "00877",
    );
    const DEPTH: (u64, &str, &str) = (
        DEPTH_STENCIL_ATTACHMENT,
        "VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT",
        "02633",
    );
    const INPUT: (u64, &str, &str) = (
        INPUT_ATTACHMENT,
        "VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT",
        "00879",
    );
    // Each attachment with every role a subpass gives it, once.
    let mut roles = std::collections::BTreeSet::new();
    for s in &pass.subpasses {
        let colors = s.colors.iter().chain(&s.resolves).map(|&(a, _)| (a, COLOR));
        let depth = s.depth.iter().map(|&(a, _)| (a, DEPTH));
        let inputs = s.inputs.iter().map(|&(a, _)| (a, INPUT));
        roles.extend(colors.chain(depth).chain(inputs));
    }
    let views = ci.list("pAttachments")?;
    for (a, (bits, names, number)) in roles {
        let Some(view) = views.get(a as usize) else {
            continue;
        };
        let Some(image) = objects
            .views
            .get(&view.handle()?)
            .and_then(|v| objects.images.get(&v.image))
        else {
            continue;
        };
        if image.usage & bits == 0 {
            out.push(ValidUsageFinding {
                vuid: format!("VUID-VkFramebufferCreateInfo-pAttachments-{number}"),
                command: command.to_owned(),
                detail: format!(
                    "pAttachments[{a}]: the render pass uses it as an attachment that needs {names}, which its image was created without (usage {:#x})",
                    image.usage
                ),
            });
        }
    }
    Ok(out)
}

/// What a layout in a render pass (an attachment's initial or final layout, or a subpass's
/// reference) needs of its framebuffer image's usage at `vkCmdBeginRenderPass` (`v2`: the
/// `2` command): the bits (any of them), their names and the VUID number.
fn begin_layout_needs(layout: ImageLayout, v2: bool) -> Option<(u64, &'static str, &'static str)> {
    const DS: &str = "VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT";
    let pick = |one: &'static str, two: &'static str| if v2 { two } else { one };
    Some(match layout {
        ImageLayout::ColorAttachmentOptimal => (
            COLOR_ATTACHMENT,
            "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT",
            pick("00895", "03094"),
        ),
        ImageLayout::DepthStencilAttachmentOptimal | ImageLayout::DepthStencilReadOnlyOptimal => {
            (DEPTH_STENCIL_ATTACHMENT, DS, pick("00896", "03096"))
        }
        ImageLayout::ShaderReadOnlyOptimal => (
            SAMPLED | INPUT_ATTACHMENT,
            "VK_IMAGE_USAGE_SAMPLED_BIT or VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT",
            pick("00897", "03097"),
        ),
        ImageLayout::TransferSrcOptimal => (
            TRANSFER_SRC,
            "VK_IMAGE_USAGE_TRANSFER_SRC_BIT",
            pick("00898", "03098"),
        ),
        ImageLayout::TransferDstOptimal => (
            TRANSFER_DST,
            "VK_IMAGE_USAGE_TRANSFER_DST_BIT",
            pick("00899", "03099"),
        ),
        ImageLayout::DepthReadOnlyStencilAttachmentOptimal
        | ImageLayout::DepthAttachmentStencilReadOnlyOptimal => {
            (DEPTH_STENCIL_ATTACHMENT, DS, pick("01758", "03100"))
        }
        _ => return None,
    })
}

/// `vkCmdBeginRenderPass` (`v2`: `vkCmdBeginRenderPass2`) call `command`: each framebuffer
/// attachment whose render pass puts it in a layout (initial, final, or a subpass's reference)
/// that its image's usage does not allow. An imageless framebuffer's views come with the
/// begin, and are not checked here.
pub fn begin_usage(
    command: &str,
    v2: bool,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let begin = args.get("pRenderPassBegin")?;
    let mut out = Vec::new();
    let (Some(pass), Some(framebuffer)) = (
        objects
            .render_passes
            .get(&begin.get("renderPass")?.handle()?),
        objects
            .framebuffers
            .get(&begin.get("framebuffer")?.handle()?),
    ) else {
        return Ok(out);
    };
    // Every layout each attachment is given, once per rule it breaks.
    let mut layouts: Vec<(u32, ImageLayout)> = Vec::new();
    for (a, d) in pass.attachments.iter().enumerate() {
        layouts.extend(
            [d.initial, d.final_layout]
                .into_iter()
                .flatten()
                .map(|l| (a as u32, l)),
        );
    }
    for s in &pass.subpasses {
        let refs = s
            .colors
            .iter()
            .chain(&s.resolves)
            .chain(&s.depth)
            .chain(&s.inputs);
        layouts.extend(refs.filter_map(|&(a, l)| Some((a, l?))));
    }
    let mut seen = std::collections::BTreeSet::new();
    let structure = if v2 {
        "vkCmdBeginRenderPass2"
    } else {
        "vkCmdBeginRenderPass"
    };
    for (a, layout) in layouts {
        let Some((bits, names, number)) = begin_layout_needs(layout, v2) else {
            continue;
        };
        let Some(image) = framebuffer
            .attachments
            .get(a as usize)
            .and_then(|view| objects.views.get(view))
            .and_then(|v| objects.images.get(&v.image))
        else {
            continue;
        };
        if image.usage & bits == 0 && seen.insert((a, number)) {
            out.push(ValidUsageFinding {
                vuid: format!("VUID-{structure}-initialLayout-{number}"),
                command: command.to_owned(),
                detail: format!(
                    "pAttachments[{a}]: the render pass puts it in {} but its image was created without {names} (usage {:#x})",
                    layout.name(),
                    image.usage
                ),
            });
        }
    }
    Ok(out)
}
