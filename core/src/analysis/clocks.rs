//! Happens-before between passes as vector clocks, for the hazard checker and the schedule.
//!
//! Passes on one queue run in order, so the passes of a queue that happen before a given pass
//! are always a prefix of that queue: one position per queue (a vector clock) describes them
//! exactly. That costs passes x queues words, where a bitset per pass costs passes^2 bits
//! (800 MB at 80,000 passes), and answers "does `a` happen before `b`" with one comparison.

use super::model::{MPass, MQueue};

/// For every pass, per queue, the position of the latest pass on that queue that happens
/// before it or is it.
#[derive(Debug)]
pub struct Clocks {
    queues: usize,
    queue_of: Vec<MQueue>,
    /// Each pass's position on its queue (`None` for passes outside the order).
    position: Vec<Option<u32>>,
    /// Pass-major: `clock[p * queues + q]`, `None` where nothing on `q` precedes `p`.
    clock: Vec<Option<u32>>,
}

impl Clocks {
    /// Builds the clocks of the passes in `order` (topological for queue order and for every
    /// edge `preds` gives): `queue_of` gives each pass's queue (less than `queues`), `preds`
    /// the passes each pass waits for besides the one before it on its queue (fences, data
    /// dependencies).
    pub fn new(
        queues: usize,
        queue_of: Vec<MQueue>,
        order: &[MPass],
        preds: impl Fn(MPass) -> Vec<MPass>,
    ) -> Self {
        let n = queue_of.len();
        let queues = queues.max(1);
        let mut clocks = Clocks {
            queues,
            position: vec![None; n],
            clock: vec![None; n.saturating_mul(queues)],
            queue_of,
        };
        let mut last_on_queue: Vec<Option<MPass>> = vec![None; queues];
        let mut next_position: Vec<u32> = vec![0; queues];
        let mut c: Vec<Option<u32>> = vec![None; queues];
        for &p in order {
            let pi = p.index();
            let Some(&q) = clocks.queue_of.get(pi) else {
                continue;
            };
            let q = q.index().min(queues - 1);
            match last_on_queue[q] {
                Some(prev) => c.copy_from_slice(clocks.row(prev.index())),
                None => c.fill(None),
            }
            for a in preds(p) {
                if a.index() < n {
                    for (mine, theirs) in c.iter_mut().zip(clocks.row(a.index())) {
                        *mine = (*mine).max(*theirs);
                    }
                }
            }
            c[q] = Some(next_position[q]);
            clocks.position[pi] = Some(next_position[q]);
            next_position[q] += 1;
            last_on_queue[q] = Some(p);
            clocks.clock[pi * queues..(pi + 1) * queues].copy_from_slice(&c);
        }
        clocks
    }

    fn row(&self, p: usize) -> &[Option<u32>] {
        &self.clock[p * self.queues..(p + 1) * self.queues]
    }

    /// Whether `a` strictly happens before `b`.
    pub fn before(&self, a: MPass, b: MPass) -> bool {
        let (a, b) = (a.index(), b.index());
        if a == b {
            return false;
        }
        let (Some(Some(pos)), Some(&q)) = (self.position.get(a), self.queue_of.get(a)) else {
            return false;
        };
        let q = q.index().min(self.queues - 1);
        self.clock
            .get(b * self.queues + q)
            .copied()
            .flatten()
            .is_some_and(|latest| *pos <= latest)
    }

    /// Whether `a` happens before `b` or is `b`.
    pub fn before_or_same(&self, a: MPass, b: MPass) -> bool {
        a == b || self.before(a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the transitive closure computed the slow way, on random queue assignments
    /// and random forward edges.
    #[test]
    fn clocks_match_the_transitive_closure() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % m
        };
        for _ in 0..200 {
            let n = 1 + next(24) as usize;
            let queues = 1 + next(3) as usize;
            let queue_of: Vec<MQueue> =
                (0..n).map(|_| MQueue(next(queues as u64) as u32)).collect();
            let mut preds: Vec<Vec<MPass>> = vec![Vec::new(); n];
            for (b, list) in preds.iter_mut().enumerate().skip(1) {
                for _ in 0..next(3) {
                    list.push(MPass(next(b as u64) as u32));
                }
            }
            let order: Vec<MPass> = MPass::range(n).collect();
            let clocks = Clocks::new(queues, queue_of.clone(), &order, |p| {
                preds[p.index()].clone()
            });
            // Slow closure: reach[b] = set of a with a -> b.
            let mut reach: Vec<Vec<bool>> = Vec::with_capacity(n);
            for b in 0..n {
                let mut direct: Vec<usize> = preds[b].iter().map(|a| a.index()).collect();
                direct.extend((0..b).rfind(|&a| queue_of[a] == queue_of[b]));
                let mut mine = vec![false; n];
                for a in direct {
                    mine[a] = true;
                    for (x, &r) in reach[a].iter().enumerate() {
                        mine[x] |= r;
                    }
                }
                reach.push(mine);
            }
            for (b, row) in reach.iter().enumerate() {
                for (a, &expected) in row.iter().enumerate() {
                    assert_eq!(
                        clocks.before(MPass::new(a), MPass::new(b)),
                        expected,
                        "{a} -> {b} in {queue_of:?} {preds:?}"
                    );
                }
            }
        }
    }
}
