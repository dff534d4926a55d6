//! The queue-side calls of a stream: submissions (each command buffer's recording built into
//! passes and checked for hazards), image acquires, host waits and presents.

use super::*;

impl Importer {
    pub(super) fn submit(&mut self, call: &Call, args: &Arg<'_>, v2: bool) -> Got<()> {
        let origin = Origin::call(&call.name, call.index);
        // The two submit structures differ only in where the handles sit.
        let (waits, cbs, signals) = if v2 {
            (
                ("pWaitSemaphoreInfos", Some("semaphore")),
                ("pCommandBufferInfos", Some("commandBuffer")),
                ("pSignalSemaphoreInfos", Some("semaphore")),
            )
        } else {
            (
                ("pWaitSemaphores", None),
                ("pCommandBuffers", None),
                ("pSignalSemaphores", None),
            )
        };
        let queue = args.get("queue")?.handle()?;
        let fence = args.opt("fence").map_or(Ok(0), |f| f.handle())?;
        for s in args.list("pSubmits")? {
            let handles = |(key, field): (&str, Option<&str>)| -> Got<Vec<u64>> {
                s.list(key)?
                    .iter()
                    .map(|i| match field {
                        Some(f) => i.get(f)?.handle(),
                        None => i.handle(),
                    })
                    .collect()
            };
            let (waits, cbs, signals) = (handles(waits)?, handles(cbs)?, handles(signals)?);
            // The stages each wait blocks: its own stage mask in the `2` structure, the
            // parallel pWaitDstStageMask list in the first.
            let masks: Vec<PipelineStages> = if v2 {
                s.list("pWaitSemaphoreInfos")?
                    .iter()
                    .map(|i| i.get("stageMask")?.stages())
                    .collect::<Got<_>>()?
            } else {
                s.list("pWaitDstStageMask")?
                    .iter()
                    .map(Arg::stages)
                    .collect::<Got<_>>()?
            };
            // A timeline semaphore's values: in each info of the `2` structure, in a
            // VkTimelineSemaphoreSubmitInfo in the first's chain.
            let values = |key: &str, list: &str| -> Vec<Option<u64>> {
                if v2 {
                    return s
                        .list(list)
                        .unwrap_or_default()
                        .iter()
                        .map(|i| i.opt("value").and_then(|v| v.u64().ok()))
                        .collect();
                }
                let mut next = s.opt("pNext");
                while let Some(n) = next {
                    if let Ok(v) = n.list(key)
                        && !v.is_empty()
                    {
                        return v.iter().map(|x| x.u64().ok()).collect();
                    }
                    next = n.opt("pNext");
                }
                Vec::new()
            };
            let timeline = |sems: &[u64], values: Vec<Option<u64>>| -> Vec<Option<u64>> {
                sems.iter()
                    .enumerate()
                    .map(|(i, sem)| {
                        if self.objects.timeline.contains(sem) {
                            values.get(i).copied().flatten()
                        } else {
                            None
                        }
                    })
                    .collect()
            };
            let wait_values = timeline(
                &waits,
                values("pWaitSemaphoreValues", "pWaitSemaphoreInfos"),
            );
            let signal_values = timeline(
                &signals,
                values("pSignalSemaphoreValues", "pSignalSemaphoreInfos"),
            );
            // Walked three times over (passes, synchronization, earlier transfers), with
            // secondary command buffers expanded: sized first, so that a few kilobytes of
            // nested vkCmdExecuteCommands cannot ask for billions of steps.
            let walk = record::expanded(&self.recordings, &cbs);
            if walk > MAX_SUBMIT_COMMANDS || self.walked.saturating_add(walk) > MAX_WALKED {
                self.builder.note(format!(
                    "submissions of over {MAX_SUBMIT_COMMANDS} commands (secondary command buffers expanded), or past {MAX_WALKED} in all: not walked"
                ));
                // What it did to image layouts is not known either.
                self.sync.layouts_unknown();
                continue;
            }
            self.walked += walk;
            self.submitted_in_frame |= !cbs.is_empty();
            if self.keep_submitted_before && !self.builder.emitting() {
                self.submitted_before.extend(&cbs);
            }
            if self.builder.emitting() {
                let timed_waits: Vec<(u64, PipelineStages, Option<u64>)> = waits
                    .iter()
                    .zip(
                        masks
                            .iter()
                            .chain(std::iter::repeat(&PipelineStages::ALL_COMMANDS)),
                    )
                    .zip(&wait_values)
                    .map(|((w, m), v)| (*w, *m, *v))
                    .collect();
                let timed_signals: Vec<(u64, Option<u64>)> =
                    signals.iter().copied().zip(signal_values).collect();
                self.sync.submit(
                    &self.objects,
                    &self.pipelines,
                    &self.recordings,
                    &timed_waits,
                    &cbs,
                    &timed_signals,
                    fence,
                    (
                        queue,
                        self.objects.queues.get(&queue).map(|(family, _)| *family),
                    ),
                    &origin,
                );
            }
            self.builder.submit(
                build::Known {
                    objects: &self.objects,
                    pipelines: &self.pipelines,
                    recordings: &self.recordings,
                },
                queue,
                &waits,
                &cbs,
                &signals,
            );
        }
        Ok(())
    }

    /// `vkAcquireNextImage(2)KHR`: the image it handed over, and the semaphore and fence
    /// that order the presentation engine's read of it.
    pub(super) fn acquire(&mut self, call: &Call, args: &Arg<'_>, v2: bool) -> Got<()> {
        let info = if v2 { args.get("pAcquireInfo")? } else { *args };
        let swapchain = info.get("swapchain")?.handle()?;
        let index = args.get("pImageIndex")?.u32()?;
        let semaphore = info.get("semaphore")?.handle()?;
        let fence = info.get("fence")?.handle()?;
        let image = self
            .objects
            .swapchain_images
            .get(&swapchain)
            .and_then(|images| images.get(index as usize))
            .copied();
        if let Some(image) = image.filter(|_| self.builder.emitting()) {
            let command = Origin::call(&call.name, call.index);
            self.sync
                .acquire(&self.objects, image, (semaphore, fence), &command);
        }
        Ok(())
    }

    /// A host wait that succeeded: what it waited for is complete.
    pub(super) fn host_wait(&mut self, args: &Arg<'_>, wait: calls::Wait) -> Got<()> {
        if !self.builder.emitting() {
            return Ok(());
        }
        match wait {
            calls::Wait::Fences => {
                let fences: Vec<u64> = args
                    .list("pFences")?
                    .iter()
                    .map(Arg::handle)
                    .collect::<Got<_>>()?;
                let all = args.get("waitAll")?.u64()? != 0;
                self.sync.host_wait(&fences, &[], all);
            }
            calls::Wait::Semaphores => {
                let info = args.get("pWaitInfo")?;
                let values = info.list("pValues").unwrap_or_default();
                let sems: Vec<(u64, Option<u64>)> = info
                    .list("pSemaphores")?
                    .iter()
                    .enumerate()
                    .map(|(i, s)| Ok((s.handle()?, values.get(i).and_then(|v| v.u64().ok()))))
                    .collect::<Got<_>>()?;
                // VK_SEMAPHORE_WAIT_ANY_BIT
                let all = info.get("flags")?.u64()? & 1 == 0;
                self.sync.host_wait(&[], &sems, all);
            }
            calls::Wait::Idle => self.sync.idle(),
        }
        Ok(())
    }

    pub(super) fn present(&mut self, call: &Call, args: &Arg<'_>) -> Got<()> {
        let queue = args.get("queue")?.handle()?;
        let info = args.get("pPresentInfo")?;
        let waits: Vec<u64> = info
            .list("pWaitSemaphores")?
            .iter()
            .map(Arg::handle)
            .collect::<Got<_>>()?;
        let chains = info.list("pSwapchains")?;
        let indices = info.list("pImageIndices")?;
        let images = chains
            .iter()
            .zip(&indices)
            .map(|(c, i)| Ok((c.handle()?, i.u32()?)))
            .collect::<Got<Vec<_>>>()?;
        let command = Origin::call(&call.name, call.index);
        if self.builder.emitting() {
            let swapchain_images: Vec<u64> = images
                .iter()
                .filter_map(|(c, i)| self.objects.swapchain_images.get(c)?.get(*i as usize))
                .copied()
                .collect();
            self.sync
                .present(&self.objects, &waits, &swapchain_images, &command);
        }
        self.builder
            .present(&self.objects, queue, &waits, &images, &command);
        self.submitted_in_frame = false;
        Ok(())
    }
}
