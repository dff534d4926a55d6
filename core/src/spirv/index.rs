//! Loading a module and looking things up in it. rspirv's `dr::Module` keeps instructions in
//! section order but forgets where each one came from and offers no lookup by id, so both
//! reflection and rewriting go through this: the loader remembers the word offset of every
//! instruction that defines an id (errors point into the original file), and `Index` maps ids to
//! their global definitions and to the decorations that apply to them, decoration groups
//! included.

use std::collections::HashMap;

use rspirv::binary::{Consumer, ParseAction, ParseState};
use rspirv::dr::{Instruction, Loader, Module, ModuleHeader, Operand};
use rspirv::grammar::OperandKind;
use rspirv::spirv::{Decoration, Op, Word};

use super::SpirvError;

use super::HEADER_WORDS;

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

/// The words with every `OpSource` whose language this SPIR-V grammar does not know said to
/// be of an unknown language (0), or `None` where there is none. The language is debug
/// information drivers ignore; SPIRV-Tools and rspirv reject a value they do not know (a
/// newer language, or a compiler's own), which would refuse a module a driver runs. The
/// words keep their places. Runs after `check_stream`, which bounds every instruction.
fn known_source_language(words: &[u32]) -> Option<Vec<u32>> {
    let mut out: Option<Vec<u32>> = None;
    let mut at = HEADER_WORDS;
    while let Some(&first) = words.get(at) {
        let count = ((first >> 16) as usize).max(1);
        if first & 0xffff == Op::Source as u32
            && count >= 2
            && let Some(&language) = words.get(at + 1)
            && rspirv::spirv::SourceLanguage::from_u32(language).is_none()
        {
            out.get_or_insert_with(|| words.to_vec())[at + 1] = 0;
        }
        at += count;
    }
    out
}

/// Checks the header and loads the module, converting rspirv's errors to `Malformed` with the
/// word offset of the instruction at fault.
pub(super) fn load(words: &[u32]) -> Result<Loaded, SpirvError> {
    let Some(&[magic, _version, generator, _bound, _schema]) = words.get(..HEADER_WORDS) else {
        return Err(SpirvError::Malformed {
            at_word: words.len(),
            detail: format!(
                "a module starts with a {HEADER_WORDS}-word header; this one has {} words",
                words.len()
            ),
        });
    };
    if magic != rspirv::spirv::MAGIC_NUMBER {
        return Err(SpirvError::BadMagic { found: magic });
    }
    check_stream(words)?;
    let relabelled = known_source_language(words);
    let words = relabelled.as_deref().unwrap_or(words);
    let split = super::specop::split_spec_ops(words)?;
    let original = |at: usize| split.as_ref().map_or(at, |s| s.original(at));
    let words = split.as_ref().map_or(words, |s| s.words.as_slice());
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
            at_word: original(at_word),
            detail: state.to_string(),
        });
    }
    let Tracking {
        inner,
        mut offsets,
        mut entry_offsets,
        ..
    } = tracking;
    if split.is_some() {
        offsets.values_mut().for_each(|at| *at = original(*at));
        entry_offsets.iter_mut().for_each(|at| *at = original(*at));
    }
    let mut module = inner.module();
    // rspirv stamps its own generator on the header; the module still comes from the
    // application's compiler, and tools key workarounds on that.
    if let Some(h) = module.header.as_mut() {
        h.generator = generator;
    }
    check_ids(&module, words[3], &offsets)?;
    Ok(Loaded {
        module,
        offsets,
        entry_offsets,
    })
}

/// Every id is defined once and below the header's bound, and every id an instruction uses
/// is defined somewhere in the module (forward references, to functions and labels, are
/// SPIR-V's own). A driver trusts all of this; a damaged module breaks it first.
fn check_ids(
    module: &Module,
    bound: u32,
    offsets: &HashMap<Word, usize>,
) -> Result<(), SpirvError> {
    let at = |id: Word| offsets.get(&id).copied().unwrap_or(HEADER_WORDS);
    let mut defined = std::collections::HashSet::new();
    for inst in module.all_inst_iter() {
        if let Some(id) = inst.result_id {
            if id == 0 || id >= bound {
                return Err(SpirvError::Malformed {
                    at_word: at(id),
                    detail: format!("id %{id} is outside the header's bound {bound}"),
                });
            }
            if !defined.insert(id) {
                return Err(SpirvError::Malformed {
                    at_word: at(id),
                    detail: format!("id %{id} is defined twice"),
                });
            }
        }
    }
    for inst in module.all_inst_iter() {
        let used = inst
            .result_type
            .into_iter()
            .chain(inst.operands.iter().filter_map(|o| match o {
                Operand::IdRef(id) | Operand::IdScope(id) | Operand::IdMemorySemantics(id) => {
                    Some(*id)
                }
                _ => None,
            }));
        for id in used {
            if !defined.contains(&id) {
                return Err(SpirvError::Malformed {
                    at_word: inst.result_id.map_or(HEADER_WORDS, at),
                    detail: format!("{:?} uses %{id}, which nothing defines", inst.class.opcode),
                });
            }
        }
    }
    Ok(())
}

/// rspirv's parser trusts two things it reads and panics when they are wrong: that an
/// instruction's word count stays inside the stream (when it decodes a string), and that
/// OpSpecConstantOp names an instruction whose operands it can decode on their own. Input
/// breaking either is malformed anyway, so it is refused before rspirv sees it.
fn check_stream(words: &[u32]) -> Result<(), SpirvError> {
    let mut at = HEADER_WORDS;
    while let Some(&first) = words.get(at) {
        let count = (first >> 16) as usize;
        let malformed = |detail: String| SpirvError::Malformed {
            at_word: at,
            detail,
        };
        if count == 0 {
            return Err(malformed("an instruction of 0 words".to_owned()));
        }
        let end = at.saturating_add(count);
        if end > words.len() {
            return Err(malformed(format!(
                "an instruction of {count} words runs past the end of the module ({} words)",
                words.len()
            )));
        }
        if first & 0xffff == Op::SpecConstantOp as u32
            && let Some(computed) = words
                .get(at + 3)
                .and_then(|op| rspirv::grammar::INSTRUCTION_TABLE.lookup_opcode(*op))
            && computed.operands.iter().any(|o| {
                matches!(
                    o.kind,
                    OperandKind::LiteralContextDependentNumber
                        | OperandKind::LiteralSpecConstantOpInteger
                        | OperandKind::PairLiteralIntegerIdRef
                )
            })
        {
            return Err(malformed(format!(
                "OpSpecConstantOp cannot compute Op{}",
                computed.opname
            )));
        }
        at = end;
    }
    Ok(())
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
    /// The operands after the decoration of each OpDecorate, by (target, decoration); the first
    /// one wins where a malformed module repeats a decoration.
    decorations: HashMap<(Word, Decoration), &'m [Operand]>,
    /// The same for OpMemberDecorate, by (struct, member, decoration).
    member_decorations: HashMap<(Word, u32, Decoration), &'m [Operand]>,
    /// The decoration groups applied to a target (OpGroupDecorate). A group's decorations are
    /// looked up through it rather than copied to each target, which would take the product of
    /// the two counts.
    groups: HashMap<Word, Vec<Word>>,
    /// The decoration groups applied to a struct member (OpGroupMemberDecorate).
    member_groups: HashMap<(Word, u32), Vec<Word>>,
    names: HashMap<Word, &'m str>,
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
        let mut decorations = HashMap::new();
        let mut member_decorations = HashMap::new();
        let mut groups: HashMap<Word, Vec<Word>> = HashMap::new();
        let mut member_groups: HashMap<(Word, u32), Vec<Word>> = HashMap::new();
        for inst in &module.annotations {
            let ops = inst.operands.as_slice();
            match (inst.class.opcode, ops) {
                (Op::Decorate, [Operand::IdRef(target), Operand::Decoration(d), rest @ ..]) => {
                    decorations.entry((*target, *d)).or_insert(rest);
                }
                (
                    Op::MemberDecorate,
                    [
                        Operand::IdRef(target),
                        Operand::LiteralBit32(member),
                        Operand::Decoration(d),
                        rest @ ..,
                    ],
                ) => {
                    member_decorations
                        .entry((*target, *member, *d))
                        .or_insert(rest);
                }
                (Op::GroupDecorate, [Operand::IdRef(group), targets @ ..]) => {
                    for target in targets {
                        if let Operand::IdRef(target) = target {
                            groups.entry(*target).or_default().push(*group);
                        }
                    }
                }
                (Op::GroupMemberDecorate, [Operand::IdRef(group), pairs @ ..]) => {
                    for pair in pairs.chunks_exact(2) {
                        if let [Operand::IdRef(target), Operand::LiteralBit32(member)] = pair {
                            member_groups
                                .entry((*target, *member))
                                .or_default()
                                .push(*group);
                        }
                    }
                }
                _ => {}
            }
        }
        let mut names = HashMap::new();
        for inst in &module.debug_names {
            if let (Op::Name, [Operand::IdRef(id), Operand::LiteralString(name)]) =
                (inst.class.opcode, inst.operands.as_slice())
                && !name.is_empty()
            {
                names.entry(*id).or_insert(name.as_str());
            }
        }
        Index {
            globals,
            decorations,
            member_decorations,
            groups,
            member_groups,
            names,
            offsets: &loaded.offsets,
        }
    }

    /// Whether `id` takes decorations from a decoration group.
    pub fn is_grouped(&self, id: Word) -> bool {
        self.groups.contains_key(&id)
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
        self.decorations.get(&(id, d)).copied().or_else(|| {
            self.groups
                .get(&id)?
                .iter()
                .find_map(|group| self.decorations.get(&(*group, d)).copied())
        })
    }

    pub fn has_decoration(&self, id: Word, d: Decoration) -> bool {
        self.decoration(id, d).is_some()
    }

    /// A decoration's single literal value.
    pub fn decoration_literal(&self, id: Word, d: Decoration) -> Option<u32> {
        self.decoration(id, d).and_then(|ops| literal(ops.first()))
    }

    pub fn member_decoration(&self, id: Word, member: u32, d: Decoration) -> Option<&'m [Operand]> {
        self.member_decorations
            .get(&(id, member, d))
            .copied()
            .or_else(|| {
                self.member_groups
                    .get(&(id, member))?
                    .iter()
                    .find_map(|group| self.decorations.get(&(*group, d)).copied())
            })
    }

    /// The OpName of `id`, when it has a non-empty one.
    pub fn name(&self, id: Word) -> Option<&'m str> {
        self.names.get(&id).copied()
    }
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

/// The result type of every value the module's functions compute, by id.
pub(super) fn result_types(module: &Module) -> HashMap<Word, Word> {
    module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .filter_map(|i| Some((i.result_id?, i.result_type?)))
        .collect()
}
