//! The end of an import: the frames selected, what was left out, the hazards placed on their
//! passes, late findings, the Vulkan objects and contents attached, and the summary; or why
//! nothing was imported.

use std::collections::BTreeMap;

use super::*;

/// The frames imported: the selection, which must lie within the frames the stream holds.
fn selected_frames(
    file: &str,
    options: &ImportOptions,
    frames: u32,
) -> Result<(u32, u32), ImportError> {
    // A selection past the last frame is only known once the whole stream is read.
    match options.frames {
        Some((a, b)) if b >= frames => Err(ImportError::Stream {
            file: file.to_owned(),
            message: format!(
                "{} asked for, but the stream holds {frames} frame(s) (0..{})",
                if a == b {
                    format!("frame {a} was")
                } else {
                    format!("frames {a}-{b} were")
                },
                frames - 1
            ),
        }),
        Some(selected) => Ok(selected),
        None => Ok((0, frames - 1)),
    }
}

/// What was left out while reading (with the line it first happened on), then while building.
pub(super) fn skipped_while_reading(imp: &Importer) -> Vec<Skipped> {
    let mut skipped: Vec<Skipped> = imp
        .skipped
        .iter()
        .map(|(what, (count, line))| Skipped {
            what: what.clone(),
            count: *count,
            first_line: Some(*line),
        })
        .collect();
    skipped.extend(imp.builder.notes.iter().map(|(what, count)| Skipped {
        what: what.clone(),
        count: *count,
        first_line: None,
    }));
    skipped
}

/// The error for a stream that submitted nothing in the selected frames, with the first
/// things left out, which are usually why.
fn nothing_submitted(
    file: &str,
    selected: (u32, u32),
    frames: u32,
    calls: u64,
    skipped: &[Skipped],
) -> ImportError {
    let left_out = if skipped.is_empty() {
        String::new()
    } else {
        let first: Vec<String> = skipped
            .iter()
            .take(4)
            .map(|k| match k.first_line {
                Some(l) => format!("line {l}: {}", k.what),
                None => k.what.clone(),
            })
            .collect();
        format!("; left out: {}", first.join("; "))
    };
    ImportError::Stream {
        file: file.to_owned(),
        message: format!(
            "no submitted work to import in frame(s) {}-{} of {} ({} calls read){left_out}",
            selected.0, selected.1, frames, calls
        ),
    }
}

/// Why the imported frames do not replay, from the work the builder refused: each kind with
/// its command and pass, the first few of them.
fn refusal(refused: &BTreeMap<String, u64>) -> Option<String> {
    const SHOWN: usize = 6;
    if refused.is_empty() {
        return None;
    }
    let mut parts: Vec<String> = refused
        .iter()
        .take(SHOWN)
        .map(|(what, n)| match n {
            1 => what.clone(),
            n => format!("{what} ({n} times)"),
        })
        .collect();
    if refused.len() > SHOWN {
        parts.push(format!("and {} more", refused.len() - SHOWN));
    }
    Some(format!(
        "the frames run work the replay cannot reproduce: {}",
        parts.join("; ")
    ))
}

/// Each hazard on the pass its command's work went into, or its barrier did.
fn on_their_passes(
    builder: &Builder,
    found: Vec<(Origin, crate::capture::format::SyncHazard)>,
) -> Vec<crate::capture::format::SyncHazard> {
    let mut barrier_pass: HashMap<&str, usize> = HashMap::default();
    if !found.is_empty() {
        for (i, pass) in builder.passes.iter().enumerate() {
            for b in &pass.barriers {
                if let Some(v) = &b.vulkan {
                    barrier_pass.entry(v.origin.as_str()).or_insert(i);
                }
            }
        }
    }
    let mut hazards = Vec::with_capacity(found.len());
    for (origin, mut h) in found {
        let pass = match origin.attachment {
            None => builder.pass_of_command.get(&origin.index).copied(),
            Some(_) => None,
        };
        h.pass = pass
            .or_else(|| barrier_pass.get(h.command.as_str()).copied())
            .map(|i| builder.passes[i].name.clone());
        hazards.push(h);
    }
    hazards
}

/// Pipelines and samplers the work names that the stream never created are taken off it;
/// how many descriptors lost their sampler.
fn forget_unknown_objects(
    capture: &mut RawCapture,
    vulkan: &crate::capture::format::VulkanObjects,
) -> u64 {
    let known: std::collections::BTreeSet<String> =
        vulkan.pipelines.iter().map(|p| p.name.clone()).collect();
    let samplers: std::collections::BTreeSet<String> =
        vulkan.samplers.iter().map(|s| s.name.clone()).collect();
    let mut unknown_samplers = 0u64;
    for pass in &mut capture.passes {
        let named = pass
            .draws
            .iter_mut()
            .map(|d| (&mut d.pipeline, &mut d.vulkan_state))
            .chain(
                pass.dispatches
                    .iter_mut()
                    .map(|d| (&mut d.pipeline, &mut d.vulkan_state)),
            );
        for (p, state) in named {
            if p.as_ref().is_some_and(|n| !known.contains(n)) {
                *p = None;
            }
            for d in &mut state.descriptors {
                if d.sampler.as_ref().is_some_and(|n| !samplers.contains(n)) {
                    d.sampler = None;
                    unknown_samplers += 1;
                }
            }
        }
    }
    unknown_samplers
}

/// What attaching a binary capture's contents and shader code to the capture made.
struct Attached {
    side_files: Vec<SideFile>,
    modules: usize,
    contents: ContentsSummary,
    notes: Vec<String>,
}

/// The contents a binary capture holds, packed into one side file and matched to the
/// capture's resources (with the buffers uploads read from), and its shader modules, one
/// side file each.
fn attach(
    x: Extras<'_>,
    names: &BTreeMap<u64, String>,
    objects: &Objects,
    capture: &mut RawCapture,
    uploads: Vec<(String, Vec<u8>)>,
) -> Attached {
    let mut pack = contents::Pack::new(&format!("{}.contents", x.stem));
    let ((resources, bytes), notes) = x.contents.attach(names, objects, capture, &mut pack);
    let contents = ContentsSummary {
        resources,
        bytes,
        memory_writes: x.contents.fills,
    };
    for (name, bytes) in uploads {
        let size = bytes.len() as u64;
        let offset = pack.add(bytes);
        capture
            .resources
            .push(emit::upload_buffer(&name, size, (&pack.path, offset)));
    }
    let mut side_files: Vec<SideFile> = pack.into_side_file().into_iter().collect();
    let modules = std::mem::take(&mut x.contents.modules);
    let count = modules.len();
    for (handle, bytes) in modules {
        side_files.push(SideFile::one(
            format!("{}.shaders/module_{handle}.spv", x.stem),
            bytes,
        ));
    }
    Attached {
        side_files,
        modules: count,
        contents,
        notes,
    }
}

/// Something left out `count` times, if any were.
fn counted(what: &str, count: u64) -> Option<Skipped> {
    (count > 0).then(|| Skipped {
        what: what.to_owned(),
        count,
        first_line: None,
    })
}

/// A note of the import, once.
fn note(what: String) -> Skipped {
    Skipped {
        what,
        count: 1,
        first_line: None,
    }
}

/// Findings made once the stream is read: the SPIR-V of modules the route did not hand over
/// as it read, then descriptors whose image the command buffer left in another layout.
fn late_findings(
    imp: &mut Importer,
    extras: Option<&Extras<'_>>,
    hazards: &[crate::capture::format::SyncHazard],
) -> (Vec<crate::capture::format::ValidUsageFinding>, Vec<String>) {
    let (mut found, mut notes) = (Vec::new(), Vec::new());
    if let Some(x) = extras {
        for (h, code) in &x.contents.modules {
            imp.spirv.submit(*h, code, imp.objects.spirv);
        }
        let checker = std::mem::take(&mut imp.spirv);
        (found, notes) = checker.findings(&imp.module_calls);
    }
    found.extend(valid_usage_descriptors::layout_mismatches(hazards));
    (found, notes)
}

/// How many passes of each kind the capture has.
fn passes_by_kind(capture: &RawCapture) -> BTreeMap<String, usize> {
    let mut by_kind = BTreeMap::new();
    for p in &capture.passes {
        *by_kind.entry(p.kind.as_str().to_owned()).or_default() += 1;
    }
    by_kind
}

/// Where each shader module's side file goes, by handle.
fn module_files(extras: Option<&Extras<'_>>) -> BTreeMap<u64, String> {
    match extras {
        Some(x) => x
            .contents
            .modules
            .keys()
            .map(|h| (*h, format!("{}.shaders/module_{h}.spv", x.stem)))
            .collect(),
        None => BTreeMap::new(),
    }
}

/// The capture and summary from everything the importer gathered.
pub(super) fn finish(
    mut imp: Importer,
    read: Read,
    file: &str,
    options: &ImportOptions,
    extras: Option<Extras<'_>>,
) -> Result<Imported, ImportError> {
    // Reading ends early only once the selection is done.
    let stopped_after_selection = imp.builder.done();
    if imp.submitted_in_frame {
        imp.builder.end_frame();
    }
    let frames = imp.builder.frames_seen.max(1);
    let selected = selected_frames(file, options, frames)?;
    imp.builder.drop_trailing_host_writes();
    imp.builder.note_trailing_barriers();
    let mut skipped = skipped_while_reading(&imp);
    let refused = refusal(&imp.builder.refused);
    let (draws, dispatches, recorded_barriers) = (
        imp.builder.draws,
        imp.builder.dispatches,
        imp.builder.recorded_barriers,
    );
    let stem = std::path::Path::new(file).file_stem().map_or_else(
        || "imported".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    imp.builder.keep_alive(&imp.objects);
    let names = imp.builder.names.clone();
    let imp_checked = imp.sync.enabled();
    let (found, hazards_dropped) = imp.sync.hazards(|h| names.get(&h).cloned());
    let hazards = on_their_passes(&imp.builder, found);
    skipped.extend(counted(
        "synchronization hazards past the first 10000 (not listed)",
        hazards_dropped,
    ));
    let mut valid_usage = std::mem::take(&mut imp.valid_usage);
    if imp_checked {
        let (found, notes) = late_findings(&mut imp, extras.as_ref(), &hazards);
        valid_usage.extend(found);
        skipped.extend(notes.into_iter().map(note));
    }
    valid_usage.truncate(MAX_FINDINGS);
    let valid_usage_count = valid_usage.len();
    let pipelines_used = std::mem::take(&mut imp.builder.pipelines_used);
    let uploads = std::mem::take(&mut imp.builder.uploads);
    let views_used = std::mem::take(&mut imp.builder.views_used);
    let emitted = emit::emit(
        imp.builder,
        &imp.objects,
        &stem,
        file,
        &read.tool,
        imp.hidden_blocks,
    );
    skipped.extend(emitted.notes.iter().cloned().map(note));
    let mut not_modelled = imp.not_modelled;
    for (kind, n) in read.other {
        *not_modelled.entry(kind).or_default() += n;
    }
    let mut capture = emitted.capture;
    let module_files = module_files(extras.as_ref());
    let (mut vulkan, vulkan_notes) = imp.pipelines.emit(&pipelines_used, &module_files);
    vulkan.image_views = views_used.into_values().collect();
    skipped.extend(vulkan_notes.into_iter().map(note));
    // A pipeline whose creation the stream does not hold is named in a note, not by draws.
    // So is a sampler whose creation it does not hold.
    let unknown_samplers = forget_unknown_objects(&mut capture, &vulkan);
    skipped.extend(counted(
        "descriptors naming samplers the stream never created: sampler left out",
        unknown_samplers,
    ));
    capture.vulkan = (vulkan != Default::default()).then_some(vulkan);
    let hazard_count = hazards.len();
    if let Some(source) = &mut capture.source {
        source.sync_hazards = imp_checked.then_some(hazards);
        source.valid_usage = imp_checked.then(|| std::mem::take(&mut valid_usage));
    }
    let mut side_files = Vec::new();
    let (mut shader_modules, mut contents) = (None, None);
    if let Some(x) = extras {
        let attached = attach(x, &names, &imp.objects, &mut capture, uploads);
        side_files = attached.side_files;
        shader_modules = Some(attached.modules);
        contents = Some(attached.contents);
        skipped.extend(attached.notes.into_iter().map(note));
        // The binary capture holds the code and the contents: the frame replays, unless it
        // runs work the replay cannot reproduce.
        if let Some(source) = &mut capture.source {
            source.not_replayable = None;
        }
    }
    if let Some(why) = refused
        && let Some(source) = &mut capture.source
    {
        source.not_replayable = Some(match source.not_replayable.take() {
            Some(first) => format!("{first}; and {why}"),
            None => why,
        });
    }
    let not_replayable = capture
        .source
        .as_ref()
        .and_then(|s| s.not_replayable.clone());
    emit::flags_from_use(&mut capture);
    if capture.passes.is_empty() {
        return Err(nothing_submitted(
            file, selected, frames, imp.calls, &skipped,
        ));
    }
    let summary = Summary {
        file: file.to_owned(),
        tool: read.tool,
        dialect: imp.dialect.unwrap_or("0.9.x").to_owned(),
        lines: read.lines,
        calls: imp.calls,
        frames_in_stream: frames,
        stopped_after_selection,
        frames_imported: selected,
        passes: capture.passes.len(),
        passes_by_kind: passes_by_kind(&capture),
        draws,
        dispatches,
        images: emitted.images,
        buffers: emitted.buffers,
        heaps: capture.heaps.len(),
        queues: capture.queues.len(),
        recorded_barriers,
        sync_hazards: hazard_count,
        valid_usage: valid_usage_count,
        fences: capture.fences.len(),
        skipped,
        not_modelled,
        pipelines: capture.vulkan.as_ref().map_or(0, |v| v.pipelines.len()),
        shader_modules,
        contents,
        not_replayable,
    };
    Ok(Imported {
        capture,
        summary,
        side_files,
    })
}
