//! `vkCmd*` calls: the valid-usage statements a command breaks as it is recorded, its
//! recording into its command buffer, and what a draw or dispatch then needs of the state
//! the command buffer holds (sets bound, dynamic states declared, filters the device has).

use super::Call;
use super::calls::CmdFunc;
use super::value::{Arg, Got};
use super::{
    Importer, valid_usage, valid_usage_descriptors, valid_usage_filters, valid_usage_sets,
};

impl Importer {
    pub(super) fn cmd_call(&mut self, cmd: CmdFunc, call: &Call, args: &Arg<'_>) -> Got<bool> {
        if self.checks_valid_usage() {
            let command = format!("{} #{}", call.name, call.index);
            let found = match cmd {
                CmdFunc::PipelineBarrier | CmdFunc::PipelineBarrier2 => {
                    let v2 = matches!(cmd, CmdFunc::PipelineBarrier2);
                    valid_usage::barrier_usage(&command, v2, args, &self.objects)
                }
                CmdFunc::PushDescriptorSet => {
                    valid_usage::descriptor_usage(&command, args, &self.objects)
                }
                // A call too malformed to check is left to the recording below.
                CmdFunc::PushDescriptorSetWithTemplate => args
                    .get("descriptorUpdateTemplate")
                    .and_then(|t| t.handle())
                    .and_then(|t| {
                        let data = args.get("pData")?;
                        valid_usage::template_usage(&command, t, &data, &self.objects)
                    }),
                CmdFunc::BeginRenderPass => {
                    let v2 = call.name.contains('2');
                    let mut found = valid_usage::begin_usage(&command, v2, args, &self.objects)
                        .unwrap_or_default();
                    let clears =
                        valid_usage::clear_values(&call.name, &command, args, &self.objects);
                    found.extend(clears.unwrap_or_default());
                    Ok(found)
                }
                _ => valid_usage::command_usage(&call.name, &command, args, &self.objects),
            };
            // A call too malformed to check is skipped by the recording below.
            self.valid_usage.extend(found.unwrap_or_default());
        }
        let cb = args.get("commandBuffer")?.handle()?;
        let spare = &mut self.spare;
        let recording = self
            .recordings
            .entry(cb)
            .or_insert_with(|| spare.pop().unwrap_or_default());
        let recorded = recording.record(cmd, &call.name, call.index, args, &self.objects);
        if let Some(compute) = cmd.work_point()
            && recorded.is_ok()
            && self.checks_valid_usage()
            && let Some(recording) = self.recordings.get(&cb)
        {
            let found = valid_usage_sets::draw_usage(
                &call.name,
                call.index,
                compute,
                recording,
                &self.pipelines,
                self.in_snapshot,
            );
            self.valid_usage.extend(found);
            if !compute {
                let found = valid_usage_sets::undeclared_states(
                    &call.name,
                    call.index,
                    recording,
                    &self.pipelines,
                );
                self.valid_usage.extend(found);
            }
            let found = valid_usage_filters::draw_filters(
                &call.name,
                call.index,
                compute,
                recording,
                &self.pipelines,
                &self.objects,
            );
            self.valid_usage.extend(found);
            let found = valid_usage_descriptors::null_descriptors(
                &call.name,
                call.index,
                compute,
                recording,
                &self.pipelines,
                &self.objects,
            );
            self.valid_usage.extend(found);
        }
        recorded
    }
}
