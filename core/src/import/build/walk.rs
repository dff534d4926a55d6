//! Walking a submitted command buffer's recorded commands into passes: render pass
//! instances and their subpasses (continued by the secondary command buffers executed inside
//! them), draws, dispatches, transfers and barriers, within the import's work limit; work
//! the replay cannot reproduce is refused with its command and pass.

use super::*;

impl Builder {
    /// Walks one command buffer's commands into passes. A secondary command buffer executed
    /// inside a render pass instance continues it (`inherited`: the instance, the subpass and
    /// its pass), as `VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT` says.
    pub(super) fn walk<'a>(
        &mut self,
        known: Known<'a>,
        queue: u64,
        recording: &'a Recording,
        depth: u32,
        inherited: Option<(&'a RenderInstance, usize, Option<usize>)>,
    ) {
        let Known {
            objects,
            pipelines,
            recordings,
        } = known;
        let mut compute: Option<usize> = None;
        let mut render = inherited;
        for (i, cmd) in recording.cmds.iter().enumerate() {
            let origin = work_origin(recording, i, cmd);
            if !matches!(cmd, Cmd::Dispatch(_)) {
                compute = None;
            }
            if self.emitting() && !self.fits(cmd) {
                continue;
            }
            match cmd {
                Cmd::BeginLabel(l) => self.labels.entry(queue).or_default().push(l.clone()),
                Cmd::EndLabel => {
                    if self.labels.entry(queue).or_default().pop().is_none() {
                        self.note("debug label ends without a begin: ignored");
                    }
                }
                Cmd::Barrier(bs) => {
                    let converted = self.barriers(objects, bs);
                    self.pend(queue, converted);
                }
                Cmd::BeginRender(ri) => {
                    let converted = self.barriers(objects, &ri.begin_barriers);
                    self.pend(queue, converted);
                    let pass = self.raster(objects, queue, ri, 0);
                    if ri.layers > 1 {
                        self.refuse(
                            queue,
                            recording.at.get(i),
                            &format!(
                                "layered rendering ({} framebuffer layers; the replay renders one layer of each attachment)",
                                ri.layers
                            ),
                        );
                    }
                    render = Some((ri, 0, pass));
                }
                Cmd::NextSubpass => {
                    if let Some((ri, sub, pass)) = render.take() {
                        self.resolves(objects, queue, ri, sub, pass);
                        let next = self.raster(objects, queue, ri, sub + 1);
                        render = Some((ri, sub + 1, next));
                    }
                }
                Cmd::EndRender => {
                    if let Some((ri, sub, pass)) = render.take() {
                        self.resolves(objects, queue, ri, sub, pass);
                        let converted = self.barriers(objects, &ri.end_barriers);
                        self.pend(queue, converted);
                    }
                }
                Cmd::Draw(d) => match render {
                    Some((_, _, Some(pass))) => {
                        if let Some(why) = unpacked_records(d) {
                            self.refuse_in(Some(pass), recording.at.get(i), &why);
                        }
                        if let Some(why) = unread_state(d, pipelines) {
                            self.refuse_in(Some(pass), recording.at.get(i), &why);
                        }
                        self.draw(objects, pipelines, pass, d);
                    }
                    Some((_, _, None)) => {}
                    None => self.refuse(
                        queue,
                        recording.at.get(i),
                        "draws outside a render pass instance",
                    ),
                },
                Cmd::ClearAttachments(c) => match render {
                    Some((ri, sub, Some(pass))) => {
                        if let Err(why) = self.attachment_clear(objects, (ri, sub, pass), c) {
                            self.refuse_in(
                                Some(pass),
                                recording.at.get(i),
                                &format!("vkCmdClearAttachments: {why}"),
                            );
                        }
                    }
                    Some((_, _, None)) => {}
                    None => self.refuse(
                        queue,
                        recording.at.get(i),
                        "attachment clears outside a render pass instance",
                    ),
                },
                Cmd::Refused(name) => {
                    let why = match crate::coverage::command(name) {
                        Some(crate::coverage::Verdict::Refused(why)) => why,
                        _ => "not in the coverage table",
                    };
                    let pass = render.and_then(|r| r.2);
                    self.refuse_in(
                        pass.or(self.last_pass_on.get(&queue).copied()),
                        recording.at.get(i),
                        &format!("{name}: {why}"),
                    );
                }
                Cmd::Dispatch(d) => {
                    let pass = match compute {
                        Some(p) => Some(p),
                        None => self.new_pass(objects, queue, PassKind::Compute, "dispatch"),
                    };
                    compute = pass;
                    if let Some(p) = pass {
                        self.dispatch(objects, pipelines, p, d);
                    }
                }
                Cmd::Transfer(t) => self.transfer(objects, queue, t),
                Cmd::Execute(list) => {
                    if depth >= MAX_EXECUTE_DEPTH {
                        self.refuse(
                            queue,
                            recording.at.get(i),
                            "secondary command buffers nested too deep",
                        );
                        continue;
                    }
                    for cb in list {
                        match recordings.get(cb) {
                            Some(r) => self.walk(known, queue, r, depth + 1, render),
                            None => self.refuse(
                                queue,
                                recording.at.get(i),
                                "executed command buffers the stream never recorded (their work is not in the capture)",
                            ),
                        }
                    }
                }
            }
            if let Some(origin) = origin.filter(|_| self.emitting())
                && let Some(&pass) = self.last_pass_on.get(&queue)
            {
                self.pass_of_command.insert(origin.index, pass);
            }
        }
    }

    /// Work of the imported frames the replay cannot reproduce: the frame does not replay,
    /// and `refused` says why, naming the command and the pass it was in (or the latest pass
    /// on `queue`).
    pub(in crate::import) fn refuse(&mut self, queue: u64, at: Option<&Origin>, what: &str) {
        let pass = self.last_pass_on.get(&queue).copied();
        self.refuse_in(pass, at, what);
    }

    /// Work past one of the import's ceilings is left out, so the frame as imported is not
    /// the frame: noted each time, and refused once, in the last pass imported, so that
    /// `replay` does not draw what is left as if it were all.
    pub(super) fn cut(&mut self, what: String) {
        if !self.notes.contains_key(&what) {
            self.refuse_in(self.passes.len().checked_sub(1), None, &what);
        }
        self.note(what);
    }

    fn refuse_in(&mut self, pass: Option<usize>, at: Option<&Origin>, what: &str) {
        if !self.emitting() {
            return;
        }
        let place = match pass {
            Some(p) => format!(" in or after pass \"{}\"", self.passes[p].name),
            None => " before the first pass".to_owned(),
        };
        let call = at.map(|o| format!(" ({o})")).unwrap_or_default();
        *self
            .refused
            .entry(format!("{what}{call}{place}"))
            .or_default() += 1;
    }

    /// Whether `cmd`'s work still fits in the import (`MAX_WORK`); noted where it does not.
    fn fits(&mut self, cmd: &Cmd) -> bool {
        let n = match cmd {
            Cmd::Draw(_) | Cmd::ClearAttachments(_) | Cmd::Dispatch(_) | Cmd::Transfer(_) => 1,
            Cmd::Barrier(bs) => bs.len() as u64,
            _ => return true,
        };
        if self.work.saturating_add(n) > MAX_WORK {
            self.cut(format!(
                "draws, dispatches, copies and barriers beyond the limit of {MAX_WORK}: not imported"
            ));
            return false;
        }
        self.work += n;
        true
    }
}

/// Why a draw whose count the GPU reads cannot replay: wgpu reads its records packed, one
/// after another; Vulkan's may be any multiple of four bytes apart. (With at most one record
/// the distance is never used.)
fn unpacked_records(d: &DrawCmd) -> Option<String> {
    let c = d.draw_count.as_ref()?;
    let size = if d.index_buffer.is_some() { 20 } else { 16 };
    (c.max_draws > 1 && c.stride != size).then(|| {
        format!(
            "an indirect draw count over records {} bytes apart (wgpu reads them packed, {size} bytes each)",
            c.stride
        )
    })
}

/// A draw whose pipeline takes a dynamic state that the command buffer last set with a call
/// the import could not read: the value it draws with is not known.
fn unread_state(d: &DrawCmd, pipelines: &Pipelines) -> Option<String> {
    let declared = pipelines.dynamic_states(d.pipeline?)?;
    let (state, why) = d
        .unread
        .iter()
        .find(|(s, _)| declared.iter().any(|x| crate::coverage::same_state(x, s)))?;
    Some(format!(
        "a draw whose pipeline takes {state} dynamically, last set by a call that could not be read ({why})"
    ))
}

/// The call a command of `recording` came from, for the commands whose work goes into the pass
/// last started on the queue once it is done.
fn work_origin<'a>(recording: &'a Recording, i: usize, cmd: &Cmd) -> Option<&'a Origin> {
    let work = matches!(
        cmd,
        Cmd::BeginRender(_)
            | Cmd::Draw(_)
            | Cmd::ClearAttachments(_)
            | Cmd::Dispatch(_)
            | Cmd::Transfer(_)
    );
    recording.at.get(i).filter(|_| work)
}
