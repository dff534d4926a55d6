//! Loading a module and looking things up in it. rspirv's `dr::Module` keeps instructions in
//! section order but forgets where each one came from and offers no lookup by id, so both
//! reflection and rewriting go through this: the loader remembers the word offset of every
//! instruction that defines an id (errors point into the original file), and `Index` maps ids to
//! their global definitions and to the decorations that apply to them, decoration groups
//! included.

use std::collections::HashMap;

use rspirv::binary::{Consumer, ParseAction, ParseState};
use rspirv::dr::{Instruction, Loader, Module, ModuleHeader, Operand};
use rspirv::spirv::{Decoration, Op, Word};

use super::SpirvError;

/// Words in the module header (magic, version, generator, bound, schema).
pub(super) const HEADER_WORDS: usize = 5;

/// Deeper than any real type (a few levels of struct and array); a cycle in malformed input
/// would otherwise recurse until the stack runs out.
pub(super) const MAX_TYPE_DEPTH: usize = 64;

/// A module as loaded, with where its instructions were in the input.
pub(super) struct Loaded {
    pub module: Module,
    /// Word offset of the instruction defining each result id.
    pub offsets: HashMap<Word, usize>,
    /// Word offset of each OpEntryPoint, in `module.entry_points` order.
    pub entry_offsets: Vec<usize>,
}

/// Wraps rspirv's loader to follow the position in the word stream: the parser reports some
/// errors as byte offsets and loader errors with none, while the instruction that failed always
/// starts right after the last one consumed.
struct Tracking<'w> {
    inner: Loader,
    words: &'w [u32],
    /// Where the next instruction starts.
    next: usize,
    /// Set when the inner loader refused something, with the word offset it refused.
    refused_at: Option<usize>,
    offsets: HashMap<Word, usize>,
    entry_offsets: Vec<usize>,
}

impl Consumer for Tracking<'_> {
    fn initialize(&mut self) -> ParseAction {
        self.inner.initialize()
    }

    fn finalize(&mut self) -> ParseAction {
        let action = self.inner.finalize();
        if matches!(action, ParseAction::Error(_)) {
            self.refused_at = Some(self.words.len());
        }
        action
    }

    fn consume_header(&mut self, header: ModuleHeader) -> ParseAction {
        self.inner.consume_header(header)
    }

    fn consume_instruction(&mut self, inst: Instruction) -> ParseAction {
        let at = self.next;
        // The parser has already checked the word count is non-zero and fits.
        let count = self.words.get(at).map_or(1, |w| (w >> 16).max(1) as usize);
        self.next = at.saturating_add(count);
        if let Some(id) = inst.result_id {
            self.offsets.entry(id).or_insert(at);
        }
        if inst.class.opcode == Op::EntryPoint {
            self.entry_offsets.push(at);
        }
        let action = self.inner.consume_instruction(inst);
        if matches!(action, ParseAction::Error(_)) {
            self.refused_at = Some(at);
        }
        action
    }
}

/// Checks the header and loads the module, converting rspirv's errors to `Malformed` with the
/// word offset of the instruction at fault.
pub(super) fn load(words: &[u32]) -> Result<Loaded, SpirvError> {
    let Some(header) = words.get(..HEADER_WORDS) else {
        return Err(SpirvError::Malformed {
            at_word: words.len(),
            detail: format!(
                "a module starts with a {HEADER_WORDS}-word header; this one has {} words",
                words.len()
            ),
        });
    };
    if header[0] != rspirv::spirv::MAGIC_NUMBER {
        return Err(SpirvError::BadMagic { found: header[0] });
    }
    let mut tracking = Tracking {
        inner: Loader::new(),
        words,
        next: HEADER_WORDS,
        refused_at: None,
        offsets: HashMap::new(),
        entry_offsets: Vec::new(),
    };
    if let Err(state) = rspirv::binary::parse_words(words, &mut tracking) {
        let at_word = match state {
            ParseState::ConsumerError(_) => tracking.refused_at.unwrap_or(tracking.next),
            ParseState::HeaderIncomplete(_) | ParseState::HeaderIncorrect => 0,
            _ => tracking.next,
        };
        return Err(SpirvError::Malformed {
            at_word,
            detail: state.to_string(),
        });
    }
    let Tracking {
        inner,
        offsets,
        entry_offsets,
        ..
    } = tracking;
    let mut module = inner.module();
    // rspirv stamps its own generator on the header; the module still comes from the
    // application's compiler, and tools key workarounds on that.
    if let Some(h) = module.header.as_mut() {
        h.generator = header[2];
    }
    Ok(Loaded {
        module,
        offsets,
        entry_offsets,
    })
}

/// An operand as a 32-bit literal.
pub(super) fn literal(op: Option<&Operand>) -> Option<u32> {
    match op {
        Some(Operand::LiteralBit32(v)) => Some(*v),
        _ => None,
    }
}

/// An operand as an id.
pub(super) fn id_ref(op: Option<&Operand>) -> Option<Word> {
    match op {
        Some(Operand::IdRef(v)) => Some(*v),
        _ => None,
    }
}

/// Global definitions and decorations by id.
pub(super) struct Index<'m> {
    /// Types, constants and global variables.
    pub globals: HashMap<Word, &'m Instruction>,
    /// Decorations (from OpDecorate, directly or through a decoration group) by target.
    decorations: HashMap<Word, Vec<&'m Instruction>>,
    /// Member decorations by (struct, member).
    member_decorations: HashMap<(Word, u32), Vec<&'m Instruction>>,
    /// Targets that take decorations through OpGroupDecorate or OpGroupMemberDecorate.
    pub grouped: HashMap<Word, Word>,
    offsets: &'m HashMap<Word, usize>,
}

impl<'m> Index<'m> {
    pub fn new(loaded: &'m Loaded) -> Self {
        let module = &loaded.module;
        let mut globals = HashMap::new();
        for inst in &module.types_global_values {
            if let Some(id) = inst.result_id {
                globals.entry(id).or_insert(inst);
            }
        }
        let mut decorations: HashMap<Word, Vec<&Instruction>> = HashMap::new();
        let mut member_decorations: HashMap<(Word, u32), Vec<&Instruction>> = HashMap::new();
        for inst in &module.annotations {
            match inst.class.opcode {
                Op::Decorate => {
                    if let Some(target) = id_ref(inst.operands.first()) {
                        decorations.entry(target).or_default().push(inst);
                    }
                }
                Op::MemberDecorate => {
                    if let (Some(target), Some(member)) = (
                        id_ref(inst.operands.first()),
                        literal(inst.operands.get(1)),
                    ) {
                        member_decorations
                            .entry((target, member))
                            .or_default()
                            .push(inst);
                    }
                }
                _ => {}
            }
        }
        // A group's decorations apply to each of its targets. OpDecorate on a group stays
        // listed under the group too; nothing looks groups up by their own id.
        let mut grouped = HashMap::new();
        for inst in &module.annotations {
            let Some(group) = id_ref(inst.operands.first()) else {
                continue;
            };
            match inst.class.opcode {
                Op::GroupDecorate => {
                    let of_group = decorations.get(&group).cloned().unwrap_or_default();
                    for target in inst.operands.iter().skip(1) {
                        if let Operand::IdRef(target) = target {
                            grouped.insert(*target, group);
                            decorations
                                .entry(*target)
                                .or_default()
                                .extend(of_group.iter().copied());
                        }
                    }
                }
                Op::GroupMemberDecorate => {
                    let of_group = decorations.get(&group).cloned().unwrap_or_default();
                    for pair in inst.operands.get(1..).unwrap_or_default().chunks_exact(2) {
                        if let [Operand::IdRef(target), Operand::LiteralBit32(member)] = pair {
                            grouped.insert(*target, group);
                            member_decorations
                                .entry((*target, *member))
                                .or_default()
                                .extend(of_group.iter().copied());
                        }
                    }
                }
                _ => {}
            }
        }
        Index {
            globals,
            decorations,
            member_decorations,
            grouped,
            offsets: &loaded.offsets,
        }
    }

    /// Word offset of the instruction defining `id` (0 when it has none).
    pub fn offset(&self, id: Word) -> usize {
        self.offsets.get(&id).copied().unwrap_or(0)
    }

    /// The global defining `id`, which `user` (an id-defining instruction) refers to.
    pub fn def(&self, id: Word, user: Word) -> Result<&'m Instruction, SpirvError> {
        self.globals
            .get(&id)
            .copied()
            .ok_or_else(|| SpirvError::Malformed {
                at_word: self.offset(user),
                detail: format!("%{user} refers to %{id}, which is not a type, constant or global"),
            })
    }

    /// The global `id` refers to through operand `n`.
    pub fn operand_def(
        &self,
        inst: &Instruction,
        n: usize,
        user: Word,
    ) -> Result<&'m Instruction, SpirvError> {
        match id_ref(inst.operands.get(n)) {
            Some(id) => self.def(id, user),
            None => Err(self.malformed(user, format!("operand {n} is not an id"))),
        }
    }

    pub fn malformed(&self, id: Word, detail: String) -> SpirvError {
        SpirvError::Malformed {
            at_word: self.offset(id),
            detail: format!("%{id}: {detail}"),
        }
    }

    /// The extra operands of decoration `d` on `id`, if it is decorated so.
    pub fn decoration(&self, id: Word, d: Decoration) -> Option<&'m [Operand]> {
        decoration_in(self.decorations.get(&id), d)
    }

    pub fn has_decoration(&self, id: Word, d: Decoration) -> bool {
        self.decoration(id, d).is_some()
    }

    /// A decoration's single literal value.
    pub fn decoration_literal(&self, id: Word, d: Decoration) -> Option<u32> {
        self.decoration(id, d).and_then(|ops| literal(ops.first()))
    }

    pub fn member_decoration(&self, id: Word, member: u32, d: Decoration) -> Option<&'m [Operand]> {
        decoration_in(self.member_decorations.get(&(id, member)), d)
    }

    pub fn name(&self, module: &Module, id: Word) -> Option<String> {
        module.debug_names.iter().find_map(|inst| {
            if inst.class.opcode != Op::Name || id_ref(inst.operands.first()) != Some(id) {
                return None;
            }
            match inst.operands.get(1) {
                Some(Operand::LiteralString(s)) if !s.is_empty() => Some(s.clone()),
                _ => None,
            }
        })
    }
}

/// Finds decoration `d` in a list of OpDecorate / OpMemberDecorate instructions and returns the
/// operands after it. The position of the decoration operand differs between the two (and a
/// group's decoration names the group), so it is found by kind.
fn decoration_in<'m>(list: Option<&Vec<&'m Instruction>>, d: Decoration) -> Option<&'m [Operand]> {
    list?.iter().find_map(|inst| {
        let at = inst
            .operands
            .iter()
            .position(|op| matches!(op, Operand::Decoration(_)))?;
        match inst.operands.get(at) {
            Some(Operand::Decoration(found)) if *found == d => inst.operands.get(at + 1..),
            _ => None,
        }
    })
}

/// The first id the rewrite may allocate: past the header's bound and past every id the module
/// mentions, since a malformed header's bound may be too low. None when no id is left.
pub(super) fn first_free_id(module: &Module) -> Option<Word> {
    let mut max = module.header.as_ref().map_or(1, |h| h.bound.max(1)) - 1;
    for inst in module.all_inst_iter() {
        for id in inst.result_id.iter().chain(inst.result_type.iter()) {
            max = max.max(*id);
        }
        for op in &inst.operands {
            if let Operand::IdRef(id) | Operand::IdScope(id) | Operand::IdMemorySemantics(id) = op {
                max = max.max(*id);
            }
        }
    }
    max.checked_add(1)
}
