//! Running a frame: encode every pass with its timestamps, submit, read the times back, and
//! when the frame's error scope caught something, find the pass that caused it.

use std::time::Instant;

use framelab_core::plan::Params;
use framelab_core::uniforms;

use super::{PassTime, ReplayError, Session, close, counters, scope, stamps};
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
        self.write_frame_constants(frame_constants)?;
        let last = stop_after
            .unwrap_or(self.plan.passes.len().saturating_sub(1))
            .min(self.plan.passes.len().saturating_sub(1));
        let mut command_buffers = Vec::new();
        let mut times = Vec::new();
        // One error scope for the frame keeps encoding cheap; if it catches anything, each pass
        // is encoded again in its own scope to name the one at fault.
        let frame_scope = scope(&self.device);
        let timestamps = self.timestamps.as_ref().filter(|_| with_timestamps);
        let inside_encoders = timestamps.is_some_and(|t| t.inside_encoders);
        self.stamp_plan = timestamps
            .map(|t| t.plan(&self.plan.passes, last))
            .unwrap_or_default();
        let statistics = self.statistics.as_ref().filter(|_| self.counting);
        self.count_plan = statistics
            .map(|_| counters::Statistics::plan(&self.plan.passes, last))
            .unwrap_or_default();
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
            let stamps = timestamps.and_then(|t| self.stamp_plan.stamps(t, i));
            let stat = statistics.and_then(|s| s.query(&self.count_plan, i));
            self.encode(i, parity, &mut encoder, stamps, inside_encoders, stat)?;
            command_buffers.push(encoder.finish());
            let cpu_ns = start.elapsed().as_nanos() as u64;
            times.push(PassTime {
                cpu_ns,
                ..PassTime::default()
            });
        }
        if let Some(t) = timestamps.filter(|_| self.stamp_plan.count > 0) {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("timestamps"),
                });
            t.resolve(&mut encoder, &self.stamp_plan);
            command_buffers.push(encoder.finish());
        }
        if let Some(s) = statistics.filter(|_| self.count_plan.count > 0) {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("pipeline statistics"),
                });
            s.resolve(&mut encoder, &self.count_plan);
            command_buffers.push(encoder.finish());
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

    fn write_frame_constants(&self, frame_constants: &Params) -> Result<(), ReplayError> {
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
        Ok(())
    }

    /// Starts a frame replayed a pass at a time ([`Session::submit_pass`], then
    /// [`Session::end_frame`]), so a caller can look at the frame between passes: the
    /// inspector keeps each pass's outputs as it finishes.
    pub fn begin_frame(&mut self, frame_constants: &Params) -> Result<(), ReplayError> {
        self.write_frame_constants(frame_constants)
    }

    /// Encodes and submits plan pass `i` of the frame begun, without timestamps, and waits for
    /// it; a validation error names the pass.
    pub fn submit_pass(&mut self, i: usize) -> Result<(), ReplayError> {
        let Some(pass) = self.plan.passes.get(i) else {
            return Ok(());
        };
        let name = pass.name.clone();
        let parity = self.parity(self.frames_run);
        let guards = scope(&self.device);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(&name) });
        let encoded = self.encode(i, parity, &mut encoder, None, false, None);
        let commands = encoder.finish();
        if encoded.is_ok() {
            self.queue.submit([commands]);
        }
        let scoped = close(guards);
        encoded?;
        if let Some(message) = scoped {
            return Err(ReplayError::Gpu {
                pass: name,
                message,
            });
        }
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| ReplayError::DeviceLost(e.to_string()))?;
        self.check_faults(&format!("pass \"{name}\""))
    }

    /// Like [`Session::submit_pass`], encoding only the pass's draws or dispatches up to index
    /// `step` (the frame as of that draw, for a frame debugger's draw view).
    pub fn submit_pass_until(&mut self, i: usize, step: usize) -> Result<(), ReplayError> {
        self.step_limit.set(Some(step));
        let submitted = self.submit_pass(i);
        self.step_limit.set(None);
        submitted
    }

    /// Ends the frame begun: the next frame swaps the history copies.
    pub fn end_frame(&mut self) {
        self.frames_run += 1;
    }

    /// Runs one frame with the given frame constants (by member name), stopping after pass
    /// `stop_after` when given: encodes and submits, waits for the GPU, and returns per-pass
    /// times (GPU times from the timestamps where the adapter has them; see `stamps`).
    pub fn run_frame(
        &mut self,
        frame_constants: &Params,
        stop_after: Option<usize>,
    ) -> Result<Vec<PassTime>, ReplayError> {
        let mut times = self.submit_frame(frame_constants, stop_after, true)?;
        match &self.timestamps {
            // Mapping the stamps waits for the frame.
            Some(t) if self.stamp_plan.count > 0 => {
                let ticks = t.read(&self.device, &self.stamp_plan)?;
                let period = f64::from(self.timestamp_period);
                stamps::times_from_ticks(&self.stamp_plan, &ticks, period, &mut times);
            }
            _ => {
                self.device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .map_err(|e| ReplayError::DeviceLost(e.to_string()))?;
            }
        }
        if let Some(s) = self.statistics.as_ref().filter(|_| self.counting) {
            let counts = s.read(&self.device, &self.count_plan)?;
            for (t, c) in times.iter_mut().zip(counts) {
                t.counters = c;
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
        let inside_encoders = timestamps.is_some_and(|t| t.inside_encoders);
        let statistics = self.statistics.as_ref().filter(|_| self.counting);
        for i in 0..=last.min(self.plan.passes.len().saturating_sub(1)) {
            let guards = scope(&self.device);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some(&self.plan.passes[i].name),
                });
            let stamps = timestamps.and_then(|t| self.stamp_plan.stamps(t, i));
            let stat = statistics.and_then(|s| s.query(&self.count_plan, i));
            let encoded = self.encode(i, parity, &mut encoder, stamps, inside_encoders, stat);
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
