//! Running a frame: encode every pass with its timestamps, submit, read the times back, and
//! when the frame's error scope caught something, find the pass that caused it.

#[allow(unused_imports)]
use super::*;

impl Session {
    /// Encodes every pass of one frame (up to `stop_after`) and submits it without waiting:
    /// the CPU side of a replay, which the benchmark measures. Times carry CPU encode time only.
    pub fn submit_frame(
        &mut self,
        frame_constants: &Params,
        stop_after: Option<usize>,
        with_timestamps: bool,
    ) -> Result<Vec<PassTime>, ReplayError> {
        let parity = self.parity(self.frames_run);
        for (i, m) in self.modules.iter().enumerate() {
            if let Some((buffer, size)) = &m.frame_buffer {
                let mut bytes =
                    uniforms::pack(&m.reflection.module, "frame", frame_constants, false).map_err(
                        |source| ReplayError::Params {
                            pass: format!("(frame constants in {})", self.plan.shaders[i].name),
                            source,
                        },
                    )?;
                bytes.resize(*size as usize, 0);
                self.queue.write_buffer(buffer, 0, &bytes);
            }
        }
        let last = stop_after
            .unwrap_or(self.plan.passes.len().saturating_sub(1))
            .min(self.plan.passes.len().saturating_sub(1));
        let mut command_buffers = Vec::new();
        let mut times = Vec::new();
        // One error scope for the frame keeps encoding cheap; if it catches anything, each pass
        // is encoded again in its own scope to name the one at fault.
        let frame_scope = scope(&self.device);
        let timestamps = self.timestamps.as_ref().filter(|_| with_timestamps);
        let inside_encoders = timestamps.is_some_and(|t| t.2);
        for i in 0..=last.min(self.plan.passes.len().saturating_sub(1)) {
            if self.plan.passes.is_empty() {
                break;
            }
            let start = Instant::now();
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some(&self.plan.passes[i].name),
                });
            let stamps = timestamps.map(|(set, _, _)| (set, 2 * i as u32));
            self.encode(i, parity, &mut encoder, stamps, inside_encoders)?;
            command_buffers.push(encoder.finish());
            let cpu_ns = start.elapsed().as_nanos() as u64;
            times.push(PassTime {
                gpu_ns: None,
                cpu_ns,
                gpu_start_ns: None,
            });
        }
        if let Some((set, buffer, _)) = timestamps {
            let mut resolve_encoder =
                self.device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("timestamps"),
                    });
            let count = (2 * times.len() as u32).max(2);
            resolve_encoder.resolve_query_set(set, 0..count, buffer, 0);
            command_buffers.push(resolve_encoder.finish());
        }
        self.queue.submit(command_buffers);
        if let Some(message) = close(frame_scope) {
            return Err(self.attribute(parity, last, with_timestamps).unwrap_or(
                ReplayError::Gpu {
                    pass: "(frame)".into(),
                    message,
                },
            ));
        }
        self.frames_run += 1;
        Ok(times)
    }

    /// Runs one frame with the given frame constants (by member name), stopping after pass
    /// `stop_after` when given: encodes and submits, waits for the GPU, and returns per-pass
    /// times (GPU times from the timestamp pairs where the adapter has them).
    pub fn run_frame(
        &mut self,
        frame_constants: &Params,
        stop_after: Option<usize>,
    ) -> Result<Vec<PassTime>, ReplayError> {
        let mut times = self.submit_frame(frame_constants, stop_after, true)?;
        let inside_encoders = self.timestamps.as_ref().is_some_and(|t| t.2);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| ReplayError::DeviceLost(e.to_string()))?;
        if let Some((_, buffer, _)) = &self.timestamps {
            let bytes = crate::readback::read_buffer(
                &self.device,
                &self.queue,
                buffer,
                (2 * times.len() as u64).max(2) * 8,
                "timestamps",
            )?;
            let ticks: Vec<u64> = bytes
                .chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().unwrap_or_default()))
                .collect();
            let period = f64::from(self.timestamp_period);
            let origin = ticks
                .iter()
                .step_by(2)
                .copied()
                .filter(|&t| t != 0)
                .min()
                .unwrap_or(0);
            for (i, t) in times.iter_mut().enumerate() {
                let (a, b) = (ticks[2 * i], ticks[2 * i + 1]);
                let kind = &self.plan.passes[i].op;
                let stamped =
                    matches!(kind, PassOp::Raster(_) | PassOp::Compute(_)) || inside_encoders;
                if stamped && b >= a && a != 0 {
                    t.gpu_ns = Some(((b - a) as f64 * period) as u64);
                    t.gpu_start_ns = Some(((a - origin) as f64 * period) as u64);
                }
            }
        }
        self.check_faults(&format!("frame {}", self.frames_run))?;
        Ok(times)
    }

    /// Encodes passes `0..=last` again, each in its own error scope and without submitting,
    /// and returns the first pass's error (encoding is deterministic, so it recurs).
    pub(super) fn attribute(
        &self,
        parity: usize,
        last: usize,
        with_timestamps: bool,
    ) -> Option<ReplayError> {
        let timestamps = self.timestamps.as_ref().filter(|_| with_timestamps);
        let inside_encoders = timestamps.is_some_and(|t| t.2);
        for i in 0..=last.min(self.plan.passes.len().saturating_sub(1)) {
            let guards = scope(&self.device);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some(&self.plan.passes[i].name),
                });
            let stamps = timestamps.map(|(set, _, _)| (set, 2 * i as u32));
            let encoded = self.encode(i, parity, &mut encoder, stamps, inside_encoders);
            drop(encoder.finish());
            let scoped = close(guards);
            if let Err(e) = encoded {
                return Some(e);
            }
            if let Some(message) = scoped {
                return Some(ReplayError::Gpu {
                    pass: self.plan.passes[i].name.clone(),
                    message,
                });
            }
        }
        None
    }
}
