//! The tracked subresources' states, with the execution dependencies of buffer and image
//! barriers applied to them lazily. A barrier's memory dependency is limited to its
//! resources, its execution dependency is not: it orders every earlier access to anything.
//! Applied eagerly, each barrier would visit every tracked subresource, and a frame of many
//! resources and many barriers would take their product (a capture of 30,000 buffers and
//! 15,000 barriers took 9 s). Instead each state remembers how many dependencies it has
//! seen and takes the ones since when it is next looked at, in one step, whatever their
//! number (`Chains`).
//!
//! Why one step is exact: a dependency adds its second scope to an access's ordered stages
//! when its first scope meets the access's stage or stages already ordered after it. That
//! rule distributes over unions of stages, and so does any sequence of dependencies, so what
//! a sequence orders after a set of stages is the union of what it orders after each stage
//! alone. And starting earlier in the sequence orders a superset. So for each pair of stages
//! `(b, t)` one number says everything: the dependencies a chain from `b` must start before
//! to reach `t` (`reach[b][t]`, updated in 64 x (first + second scope) steps per barrier).

use super::super::HashMap;
use super::state::{Dep, State};
use super::{Key, S};

/// For each pair of stage bits `(b, t)`: an access at `b` made before dependency `i` is
/// ordered before `t` by the dependencies since it iff `i < reach[b][t]`.
#[derive(Clone, Debug)]
pub(super) struct Chains {
    reach: Box<[[u64; 64]; 64]>,
    /// Dependencies so far.
    len: u64,
}

impl Default for Chains {
    fn default() -> Self {
        Chains {
            reach: Box::new([[0; 64]; 64]),
            len: 0,
        }
    }
}

/// The set bits of a stage mask, lowest first.
fn bits(s: S) -> impl Iterator<Item = usize> {
    let mut m = s.bits();
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let b = m.trailing_zeros() as usize;
            m &= m - 1;
            b
        })
    })
}

impl Chains {
    /// Dependency number `len` (its first and second synchronization scopes).
    fn push(&mut self, src: S, dst: S) {
        let next = self.len + 1;
        for row in self.reach.iter_mut() {
            // The latest start from which the chain from this row's stage meets `src`.
            let mut start = 0;
            for s in bits(src) {
                start = start.max(row[s]);
            }
            if start == 0 {
                continue;
            }
            for t in bits(dst) {
                row[t] = row[t].max(start);
            }
        }
        // A chain from a stage `src` names meets it whenever it starts: before this one.
        for b in bits(src) {
            let row = &mut self.reach[b];
            for t in bits(dst) {
                row[t] = next;
            }
        }
        self.len = next;
    }

    /// The stages the dependencies since number `since` order after `stages`.
    fn ordered(&self, since: u64, stages: S) -> S {
        let mut out = 0u64;
        for b in bits(stages) {
            let row = &self.reach[b];
            for (t, &upto) in row.iter().enumerate() {
                out |= u64::from(since < upto) << t;
            }
        }
        S::from_bits(out)
    }

    /// `st`, last brought up to date at dependency `since`, brought up to date now.
    fn catch_up(&self, since: &mut u64, st: &mut State) {
        if *since == self.len {
            return;
        }
        if let Some(w) = &mut st.write {
            w.exec |= self.ordered(*since, w.access.stage | w.exec);
        }
        for r in &mut st.reads {
            r.exec |= self.ordered(*since, r.access.stage | r.exec);
        }
        *since = self.len;
    }
}

/// One subresource's state and the dependencies it has seen.
#[derive(Clone, Debug, Default)]
struct Tracked {
    since: u64,
    state: State,
}

/// Every tracked subresource's state, each up to date whenever it is handed out.
#[derive(Debug, Default)]
pub(super) struct States {
    map: HashMap<Key, Tracked>,
    chains: Chains,
}

impl States {
    /// `key`'s state, made (empty) if it is not tracked yet.
    pub(super) fn entry(&mut self, key: Key) -> &mut State {
        let len = self.chains.len;
        let t = self.map.entry(key).or_insert_with(|| Tracked {
            since: len,
            state: State::default(),
        });
        self.chains.catch_up(&mut t.since, &mut t.state);
        &mut t.state
    }

    pub(super) fn get_mut(&mut self, key: &Key) -> Option<&mut State> {
        let t = self.map.get_mut(key)?;
        self.chains.catch_up(&mut t.since, &mut t.state);
        Some(&mut t.state)
    }

    pub(super) fn get(&mut self, key: &Key) -> Option<&State> {
        self.get_mut(key).map(|s| &*s)
    }

    /// Every state (in no particular order).
    pub(super) fn values_mut(&mut self) -> impl Iterator<Item = &mut State> {
        let chains = &self.chains;
        self.map.values_mut().map(move |t| {
            chains.catch_up(&mut t.since, &mut t.state);
            &mut t.state
        })
    }

    pub(super) fn keys(&self) -> impl Iterator<Item = &Key> {
        self.map.keys()
    }

    /// `to` starts as a copy of `from`'s state, where `from` is tracked (a buffer range
    /// split in two).
    pub(super) fn copy(&mut self, from: Key, to: Key) {
        if let Some(st) = self.get(&from).cloned() {
            let since = self.chains.len;
            self.map.insert(to, Tracked { since, state: st });
        }
    }

    /// A barrier on `own`, whose states it has updated itself (its memory dependency and
    /// layout transition): its execution dependency `d` now orders every other state.
    pub(super) fn order_all_but(&mut self, own: &[Key], d: &Dep) {
        self.chains.push(d.src, d.dst);
        let len = self.chains.len;
        for key in own {
            if let Some(t) = self.map.get_mut(key) {
                t.since = len;
            }
        }
    }

    #[cfg(test)]
    pub(super) fn insert(&mut self, key: Key, state: State) {
        let since = self.chains.len;
        self.map.insert(key, Tracked { since, state });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dependencies applied one by one, as `State::order` does, against the chains'
    /// one step, for every start and every stage the dependencies name.
    #[test]
    fn one_step_orders_what_each_dependency_in_turn_orders() {
        let st = |b: u32| S::from_bits(1 << b);
        // Chains that meet, that start after their link, and that loop back.
        let deps = [
            (st(1) | st(2), st(3)),
            (st(5), st(6)),
            (st(3), st(4) | st(5)),
            (st(6), st(1)),
            (st(7), st(8)),
            (st(4), st(7)),
            (st(2), st(2)),
        ];
        let mut chains = Chains::default();
        for &(src, dst) in &deps {
            chains.push(src, dst);
        }
        for since in 0..=deps.len() {
            for start in 0..10u32 {
                for extra in [S::EMPTY, st(6), st(4) | st(9)] {
                    let stage = st(start);
                    let mut exec = extra;
                    for &(src, dst) in &deps[since..] {
                        if src.intersects(stage) || exec.intersects(src) {
                            exec |= dst;
                        }
                    }
                    let lazy = extra | chains.ordered(since as u64, stage | extra);
                    assert_eq!(
                        lazy, exec,
                        "from stage {start} with {extra:?} after {since}"
                    );
                }
            }
        }
    }
}
