//! Valid usage of shader code: every module's SPIR-V against the rules of the SPIR-V and
//! Vulkan specifications (`VkShaderModuleCreateInfo::pCode` must be valid SPIR-V), as
//! SPIRV-Tools' validator checks them. The Khronos layer runs the same validator at each
//! `vkCreateShaderModule`, with options the device's version and enabled features give (the
//! target environment, the block layouts the device allows, `LocalSizeId`); the same options
//! are taken here from the stream's `vkCreateInstance` and `vkCreateDevice`, so that a module
//! the device accepts is not called invalid. A finding is not a refusal: a module a driver
//! takes still replays where wgpu takes it.
//!
//! The validator is the installed `spirv-val` (Debian's `spirv-tools`), run once per distinct
//! module, in the background on as many threads as there are cores while the import reads on: the `spirv-tools` crate either builds
//! SPIRV-Tools' C++ from source (minutes on a two-core machine, for every clean build) or,
//! with its `use-installed-tools` feature, runs this same program. Where it is not installed
//! the import says the code went unchecked.

use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex, mpsc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::capture::format::ValidUsageFinding;

/// The layer's id for the rule (the specification's statement has none in the layer's
/// version the corpus is checked with; newer layers say `VUID-VkShaderModuleCreateInfo-pCode-08737`).
pub const VUID: &str = "UNASSIGNED-CoreValidation-Shader-InconsistentSpirv";

/// Longest one module may take to validate: past it the module is said unchecked, so that no
/// code can hold the import.
const TIME_LIMIT: Duration = Duration::from_secs(20);

/// What the device allows, as the validator's options.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rules {
    /// `VkApplicationInfo::apiVersion`'s minor version (Vulkan 1.x); 0 when not given.
    pub api_minor: u32,
    /// `VK_KHR_spirv_1_4` enabled (SPIR-V 1.4 on Vulkan 1.1).
    pub spirv_1_4: bool,
    pub scalar_block_layout: bool,
    pub uniform_buffer_standard_layout: bool,
    pub workgroup_scalar_block_layout: bool,
    /// `maintenance4`: the `LocalSizeId` execution mode is allowed.
    pub maintenance4: bool,
}

impl Rules {
    /// Takes an enabled feature of `vkCreateDevice`'s chain, by its member name.
    pub fn enable(&mut self, feature: &str) {
        match feature {
            "scalarBlockLayout" => self.scalar_block_layout = true,
            "uniformBufferStandardLayout" => self.uniform_buffer_standard_layout = true,
            "workgroupMemoryExplicitLayoutScalarBlockLayout" => {
                self.workgroup_scalar_block_layout = true;
            }
            "maintenance4" => self.maintenance4 = true,
            _ => {}
        }
    }

    /// The feature members `enable` takes.
    pub const FEATURES: [&'static str; 4] = [
        "scalarBlockLayout",
        "uniformBufferStandardLayout",
        "workgroupMemoryExplicitLayoutScalarBlockLayout",
        "maintenance4",
    ];

    /// `spirv-val`'s arguments for these rules, the code read from standard input.
    fn arguments(self) -> Vec<&'static str> {
        let env = match self.api_minor {
            0 => "vulkan1.0",
            1 if self.spirv_1_4 => "vulkan1.1spv1.4",
            1 => "vulkan1.1",
            2 => "vulkan1.2",
            _ => "vulkan1.3",
        };
        let mut args = vec!["--target-env", env];
        for (on, flag) in [
            (self.scalar_block_layout, "--scalar-block-layout"),
            (
                self.uniform_buffer_standard_layout,
                "--uniform-buffer-standard-layout",
            ),
            (
                self.workgroup_scalar_block_layout,
                "--workgroup-scalar-block-layout",
            ),
            (self.maintenance4, "--allow-localsizeid"),
        ] {
            if on {
                args.push(flag);
            }
        }
        args.push("-");
        args
    }
}

/// What validating one module gave.
#[derive(Debug, PartialEq, Eq)]
enum Verdict {
    Valid,
    /// The validator's first error, as the layer words it.
    Invalid(String),
    /// Not checked, and why.
    Unchecked(String),
}

/// Most distinct modules one import validates: each is a process of its own, and a stream
/// of a million modules must not hold the import for hours.
const MAX_DISTINCT: usize = 4096;

type Job = (usize, Vec<u8>, Rules);

/// Modules validated in the background while the import reads on: each distinct code goes
/// to the validator as soon as the stream creates it, on threads of its own (one per core),
/// and the verdicts are gathered when the import finishes. Equal code is validated once.
#[derive(Default)]
pub struct Checker {
    /// Each distinct code's slot.
    distinct: HashMap<Vec<u8>, usize>,
    /// Each module's slot.
    modules: BTreeMap<u64, usize>,
    /// Slots past `MAX_DISTINCT`, not validated.
    over: Vec<usize>,
    jobs: Option<mpsc::Sender<Job>>,
    workers: Vec<JoinHandle<Vec<(usize, Verdict)>>>,
}

impl Checker {
    /// Hands module `module`'s code to the validator, under `rules`; a module already given
    /// keeps its first code (a handle is not reused within what one import validates).
    pub fn submit(&mut self, module: u64, code: &[u8], rules: Rules) {
        if self.modules.contains_key(&module) {
            return;
        }
        if let Some(&slot) = self.distinct.get(code) {
            self.modules.insert(module, slot);
            return;
        }
        let slot = self.distinct.len();
        self.distinct.insert(code.to_vec(), slot);
        self.modules.insert(module, slot);
        if slot >= MAX_DISTINCT {
            self.over.push(slot);
            return;
        }
        let jobs = self.jobs.get_or_insert_with(|| {
            let (tx, rx) = mpsc::channel::<Job>();
            let rx = Arc::new(Mutex::new(rx));
            let n = std::thread::available_parallelism().map_or(1, usize::from);
            self.workers = (0..n)
                .map(|_| {
                    let rx = Arc::clone(&rx);
                    std::thread::spawn(move || {
                        let mut done = Vec::new();
                        loop {
                            let job = match rx.lock() {
                                Ok(r) => r.recv(),
                                Err(_) => break,
                            };
                            let Ok((slot, code, rules)) = job else { break };
                            done.push((slot, validate(&code, rules)));
                        }
                        done
                    })
                })
                .collect();
            tx
        });
        // A worker that has stopped leaves the module unchecked, and says so at the end.
        let _ = jobs.send((slot, code.to_vec(), rules));
    }

    /// The findings, at each module's creating call (`calls`: `vkCreateShaderModule #N`; a
    /// module without one at its handle), in the order of the calls, and notes on what went
    /// unchecked.
    pub fn findings(
        mut self,
        calls: &BTreeMap<u64, String>,
    ) -> (Vec<ValidUsageFinding>, Vec<String>) {
        drop(self.jobs.take());
        let mut verdicts: HashMap<usize, Verdict> = HashMap::new();
        for w in self.workers.drain(..) {
            verdicts.extend(w.join().unwrap_or_default());
        }
        for slot in &self.over {
            verdicts.insert(
                *slot,
                Verdict::Unchecked(format!(
                    "the capture has more than {MAX_DISTINCT} distinct modules, and only that many are validated"
                )),
            );
        }
        let index = |command: &str| {
            command
                .rsplit_once('#')
                .and_then(|(_, n)| n.parse::<u64>().ok())
                .unwrap_or(u64::MAX)
        };
        let mut list: Vec<(String, usize)> = self
            .modules
            .iter()
            .map(|(h, slot)| {
                let command = calls
                    .get(h)
                    .cloned()
                    .unwrap_or_else(|| format!("vkCreateShaderModule (module {h})"));
                (command, *slot)
            })
            .collect();
        list.sort_by_key(|(command, _)| index(command));
        let mut findings = Vec::new();
        let mut notes = Vec::new();
        for (command, slot) in list {
            match verdicts.get(&slot) {
                Some(Verdict::Valid) => {}
                Some(Verdict::Invalid(message)) => findings.push(ValidUsageFinding {
                    vuid: VUID.to_owned(),
                    command,
                    detail: format!("SPIR-V module not valid: {message}"),
                }),
                Some(Verdict::Unchecked(why)) => {
                    notes.push(format!("the SPIR-V of {command} was not validated: {why}"));
                }
                None => notes.push(format!(
                    "the SPIR-V of {command} was not validated: the validator's thread stopped"
                )),
            }
        }
        // One note where the validator is missing, not one per module.
        notes.dedup_by(|a, b| a.split_once(": ").map(|x| x.1) == b.split_once(": ").map(|x| x.1));
        (findings, notes)
    }
}

/// One module through `spirv-val`.
fn validate(code: &[u8], rules: Rules) -> Verdict {
    let child = Command::new("spirv-val")
        .args(rules.arguments())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Verdict::Unchecked("spirv-val (SPIRV-Tools) is not installed".to_owned());
        }
        Err(e) => return Verdict::Unchecked(format!("spirv-val did not start: {e}")),
    };
    // The validator reads all of its input before it answers, so writing first cannot
    // block on a full output pipe.
    let wrote = child.stdin.take().map(|mut s| s.write_all(code));
    let started = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if started.elapsed() > TIME_LIMIT => {
                let _ = child.kill();
                let _ = child.wait();
                return Verdict::Unchecked(format!(
                    "spirv-val took over {} s",
                    TIME_LIMIT.as_secs()
                ));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(1)),
            Err(e) => return Verdict::Unchecked(format!("spirv-val failed: {e}")),
        }
    };
    if let Some(Err(e)) = wrote {
        return Verdict::Unchecked(format!("the code could not be given to spirv-val: {e}"));
    }
    if status.success() {
        return Verdict::Valid;
    }
    let output = child
        .wait_with_output()
        .map(|o| {
            let mut text = String::from_utf8_lossy(&o.stderr).into_owned();
            text.push_str(&String::from_utf8_lossy(&o.stdout));
            text
        })
        .unwrap_or_default();
    Verdict::Invalid(first_error(&output))
}

/// `error: line 6: Invalid source language operand: 10` -> `Invalid source language operand:
/// 10`: the validator's first message without its position, as the layer quotes it.
fn first_error(output: &str) -> String {
    let line = output
        .lines()
        .find(|l| l.starts_with("error:"))
        .or_else(|| output.lines().find(|l| !l.trim().is_empty()))
        .unwrap_or("spirv-val rejected the module without a message");
    let message = line.strip_prefix("error:").unwrap_or(line).trim_start();
    match message
        .strip_prefix("line ")
        .and_then(|r| r.split_once(": "))
    {
        Some((n, rest)) if n.chars().all(|c| c.is_ascii_digit()) => rest.to_owned(),
        _ => message.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal valid compute module: OpCapability Shader, OpMemoryModel Logical GLSL450,
    /// an entry point `main` with LocalSize 1 1 1, a void function.
    fn compute(extra_source_language: Option<u32>) -> Vec<u8> {
        let mut w: Vec<u32> = vec![0x0723_0203, 0x0001_0000, 0, 6, 0];
        let op = |n: u16, words: &[u32]| {
            let mut v = vec![((words.len() as u32 + 1) << 16) | u32::from(n)];
            v.extend_from_slice(words);
            v
        };
        w.extend(op(17, &[1])); // OpCapability Shader
        w.extend(op(14, &[0, 1])); // OpMemoryModel Logical GLSL450
        // OpEntryPoint GLCompute %1 "main"
        w.extend(op(15, &[5, 1, u32::from_le_bytes(*b"main"), 0]));
        w.extend(op(16, &[1, 17, 1, 1, 1])); // OpExecutionMode %1 LocalSize 1 1 1
        if let Some(lang) = extra_source_language {
            w.extend(op(3, &[lang, 100])); // OpSource
        }
        w.extend(op(19, &[2])); // %2 = OpTypeVoid
        w.extend(op(33, &[3, 2])); // %3 = OpTypeFunction %2
        w.extend(op(54, &[2, 1, 0, 3])); // %1 = OpFunction %2 None %3
        w.extend(op(248, &[4])); // %4 = OpLabel
        w.extend(op(253, &[])); // OpReturn
        w.extend(op(56, &[])); // OpFunctionEnd
        w.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    #[test]
    fn arguments_follow_the_device() {
        let mut r = Rules::default();
        assert_eq!(r.arguments(), ["--target-env", "vulkan1.0", "-"]);
        r.api_minor = 1;
        r.spirv_1_4 = true;
        r.enable("scalarBlockLayout");
        r.enable("maintenance4");
        r.enable("robustBufferAccess");
        assert_eq!(
            r.arguments(),
            [
                "--target-env",
                "vulkan1.1spv1.4",
                "--scalar-block-layout",
                "--allow-localsizeid",
                "-"
            ]
        );
        r.api_minor = 3;
        assert_eq!(r.arguments()[1], "vulkan1.3");
    }

    #[test]
    fn the_validators_first_error_is_quoted_without_its_line() {
        assert_eq!(
            first_error(
                "error: line 6: Invalid source language operand: 10\n  OpSource Unknown(10) 100\n"
            ),
            "Invalid source language operand: 10"
        );
        assert_eq!(
            first_error("error: ID 4 has not been defined\n"),
            "ID 4 has not been defined"
        );
        assert_eq!(
            first_error(""),
            "spirv-val rejected the module without a message"
        );
    }

    /// Needs `spirv-val` (CI installs spirv-tools): a valid module has no finding; the same
    /// module with a source language the validator does not know has one, at its call, with
    /// the validator's message; equal code is validated once but reported at every call.
    #[test]
    fn modules_are_validated_by_spirv_val() {
        let good = compute(None);
        let bad = compute(Some(999));
        let mut checker = Checker::default();
        // Given out of the calls' order: the findings come in it.
        checker.submit(30, &bad, Rules::default());
        checker.submit(10, &good, Rules::default());
        checker.submit(20, &bad, Rules::default());
        checker.submit(20, &good, Rules::default());
        let calls = BTreeMap::from([
            (10, "vkCreateShaderModule #3".to_owned()),
            (20, "vkCreateShaderModule #5".to_owned()),
            (30, "vkCreateShaderModule #9".to_owned()),
        ]);
        assert_eq!(checker.distinct.len(), 2, "equal code validated once");
        let (findings, notes) = checker.findings(&calls);
        assert!(notes.is_empty(), "{notes:?}");
        let at: Vec<_> = findings.iter().map(|f| f.command.as_str()).collect();
        assert_eq!(at, ["vkCreateShaderModule #5", "vkCreateShaderModule #9"]);
        assert_eq!(findings[0].vuid, VUID);
        assert!(
            findings[0]
                .detail
                .starts_with("SPIR-V module not valid: Invalid source language operand: 999"),
            "{}",
            findings[0].detail
        );
    }
}
