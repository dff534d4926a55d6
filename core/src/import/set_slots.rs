//! The descriptor sets a command buffer has bound at a bind point, as the pipeline layouts
//! they were bound with define them, and whether those a pipeline uses are bound through
//! layouts compatible with its own (`valid_usage_sets` turns that into findings).
//!
//! Binding follows the specification's "disturbing" rule (Pipeline Layout Compatibility): a
//! bind through a layout keeps the sets below it only where that layout is compatible for
//! them, and those above it only where it is compatible for the last set it binds. A set is
//! known by its compatibility id: two pipeline layouts are compatible for set N when their set
//! layouts 0 to N are defined identically and their push-constant ranges are the same, so a
//! layout's id for set N stands for exactly that (see `Pipelines::compat_ids`).

use std::collections::BTreeSet;

/// One set slot: the compatibility id of the layout it was last touched through, and
/// whether a set is bound there.
#[derive(Clone, Copy, Debug, Default)]
struct Slot {
    compat: u64,
    bound: bool,
}

/// The sets bound at one bind point of one command buffer.
#[derive(Clone, Debug, Default)]
pub struct SetSlots {
    /// The pipeline layout of the last bind (named in findings).
    layout: u64,
    sets: Vec<Slot>,
    /// A bind went through a layout the stream never created: nothing is said.
    unknown: bool,
}

/// What a draw or dispatch finds wrong with the sets bound for its pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetProblem {
    /// The highest set the pipeline uses is not bound through a layout compatible for it;
    /// `layout` is the pipeline layout of the last bind (0: none).
    Incompatible { set: u32, layout: u64 },
    /// A set the pipeline uses is not bound (it was disturbed, or never bound).
    NotBound { set: u32 },
}

impl SetSlots {
    /// Sets `first..first + count` bound through pipeline layout `layout`, whose
    /// compatibility ids per set are `compat` (`None`: a layout the stream never created).
    pub fn bind(&mut self, layout: u64, compat: Option<&[u64]>, first: u32, count: u32) {
        let Some(compat) = compat else {
            self.unknown = true;
            return;
        };
        let (first, count) = (first as usize, count as usize);
        let Some(last) = (first + count).checked_sub(1) else {
            return;
        };
        self.layout = layout;
        // An id past the layout's sets (an invalid bind) matches nothing.
        let id = |i: usize| compat.get(i).copied().unwrap_or(u64::MAX);
        let mut keep = first + count;
        if last >= self.sets.len() {
            self.sets.resize(keep, Slot::default());
        } else if self.sets[last].compat == id(last) {
            // Compatible for the last set bound, so for every set below it and the ones
            // above stay.
            keep = self.sets.len();
        }
        self.sets.truncate(keep);
        for (i, slot) in self.sets.iter_mut().enumerate().take(first) {
            if slot.compat != id(i) {
                *slot = Slot {
                    compat: id(i),
                    bound: false,
                };
            }
        }
        for i in first..=last {
            self.sets[i] = Slot {
                compat: id(i),
                bound: true,
            };
        }
    }

    /// What is wrong with the sets bound for a pipeline whose layout's compatibility ids
    /// are `compat` and whose shaders statically use the sets `used`; empty when nothing is
    /// known to be wrong. As the validation layer checks it: the highest set used first
    /// (a layout compatible for it is compatible for all below), then each used set bound.
    pub fn check(&self, compat: &[u64], used: &BTreeSet<u32>) -> Vec<SetProblem> {
        let Some(&max) = used.last() else {
            return Vec::new();
        };
        if self.unknown {
            return Vec::new();
        }
        let Some(&want) = compat.get(max as usize) else {
            // The pipeline's own layout lacks the set: its creation was invalid, said there.
            return Vec::new();
        };
        if self.sets.get(max as usize).is_none_or(|s| s.compat != want) {
            return vec![SetProblem::Incompatible {
                set: max,
                layout: self.layout,
            }];
        }
        used.iter()
            .filter(|&&s| !self.sets.get(s as usize).is_some_and(|slot| slot.bound))
            .map(|&set| SetProblem::NotBound { set })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn used(sets: &[u32]) -> BTreeSet<u32> {
        sets.iter().copied().collect()
    }

    #[test]
    fn nothing_bound_is_incompatible_with_layout_zero() {
        let slots = SetSlots::default();
        assert_eq!(
            slots.check(&[7], &used(&[0])),
            vec![SetProblem::Incompatible { set: 0, layout: 0 }]
        );
        assert!(slots.check(&[7], &used(&[])).is_empty());
    }

    #[test]
    fn a_compatible_bind_satisfies_and_an_incompatible_one_disturbs_below() {
        let mut slots = SetSlots::default();
        // Layout A: ids 1, 2 for sets 0, 1. Both bound.
        slots.bind(10, Some(&[1, 2]), 0, 2);
        assert!(slots.check(&[1, 2], &used(&[0, 1])).is_empty());
        // Layout B differs for set 0 already (ids 3, 4): binding set 1 through it
        // disturbs set 0, which stays unbound though the compatibility now matches B.
        slots.bind(11, Some(&[3, 4]), 1, 1);
        assert_eq!(
            slots.check(&[3, 4], &used(&[0, 1])),
            vec![SetProblem::NotBound { set: 0 }]
        );
        // A pipeline of layout A is now incompatible for set 1.
        assert_eq!(
            slots.check(&[1, 2], &used(&[1])),
            vec![SetProblem::Incompatible { set: 1, layout: 11 }]
        );
    }

    #[test]
    fn sets_above_survive_a_bind_compatible_for_the_last_set() {
        let mut slots = SetSlots::default();
        slots.bind(10, Some(&[1, 2, 3]), 0, 3);
        // Same definitions for set 0 through another layout: sets 1 and 2 stay.
        slots.bind(12, Some(&[1, 5]), 0, 1);
        assert!(slots.check(&[1, 2, 3], &used(&[0, 2])).is_empty());
        // A bind incompatible for its last set drops those above it.
        slots.bind(13, Some(&[9]), 0, 1);
        assert_eq!(
            slots.check(&[1, 2, 3], &used(&[2])),
            vec![SetProblem::Incompatible { set: 2, layout: 13 }]
        );
    }

    #[test]
    fn an_unknown_layout_silences_the_check() {
        let mut slots = SetSlots::default();
        slots.bind(10, None, 0, 1);
        assert!(slots.check(&[1], &used(&[0])).is_empty());
    }
}
