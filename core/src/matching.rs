//! Pairing the passes of two frames: by identity first (a key such as queue, marker path and
//! name, plus which occurrence of that key a pass is), then the leftovers by a signature (kind,
//! queue, written resources) where exactly one pass on each side has it: a rename. The timing
//! diff and the structural diff pair passes alike and differ only in what the key holds.

use std::collections::BTreeMap;

/// Pairs of (A index, B index) plus what only one side has.
#[derive(Debug, Default, PartialEq)]
pub struct Matching {
    pub pairs: Vec<(usize, usize)>,
    /// Pairs matched as renames (a subset of `pairs`).
    pub renamed: Vec<(usize, usize)>,
    pub added: Vec<usize>,
    pub removed: Vec<usize>,
}

/// Each item's key with its occurrence number (1 for the first item with that key).
fn occurrences<T, K: Ord + Clone>(items: &[T], key: &impl Fn(&T) -> K) -> Vec<(K, usize)> {
    let mut seen: BTreeMap<K, usize> = BTreeMap::new();
    items
        .iter()
        .map(|item| {
            let k = key(item);
            let n = seen.entry(k.clone()).or_default();
            *n += 1;
            (k, *n)
        })
        .collect()
}

/// Matches items by `key` and occurrence, then unmatched ones by `signature` when it is
/// unambiguous on both sides (items without a signature are never renames).
pub fn match_items<T, K: Ord + Clone, S: Ord>(
    a: &[T],
    b: &[T],
    key: impl Fn(&T) -> K,
    signature: impl Fn(&T) -> Option<S>,
) -> Matching {
    let (ka, kb) = (occurrences(a, &key), occurrences(b, &key));
    let index_b: BTreeMap<&(K, usize), usize> =
        kb.iter().enumerate().map(|(i, k)| (k, i)).collect();
    let mut m = Matching::default();
    let mut used_b = vec![false; b.len()];
    let mut unmatched_a = Vec::new();
    for (i, k) in ka.iter().enumerate() {
        match index_b.get(k) {
            Some(&j) => {
                m.pairs.push((i, j));
                used_b[j] = true;
            }
            None => unmatched_a.push(i),
        }
    }
    let mut by_signature_b: BTreeMap<S, Vec<usize>> = BTreeMap::new();
    for (j, item) in b.iter().enumerate().filter(|(j, _)| !used_b[*j]) {
        if let Some(s) = signature(item) {
            by_signature_b.entry(s).or_default().push(j);
        }
    }
    let mut by_signature_a: BTreeMap<S, Vec<usize>> = BTreeMap::new();
    for &i in &unmatched_a {
        if let Some(s) = signature(&a[i]) {
            by_signature_a.entry(s).or_default().push(i);
        }
    }
    for i in unmatched_a {
        let unique =
            signature(&a[i]).and_then(|s| match (by_signature_a.get(&s), by_signature_b.get(&s)) {
                (Some(ia), Some(jb)) if ia.len() == 1 && jb.len() == 1 => Some(jb[0]),
                _ => None,
            });
        match unique {
            Some(j) => {
                m.pairs.push((i, j));
                m.renamed.push((i, j));
                used_b[j] = true;
            }
            None => m.removed.push(i),
        }
    }
    m.added = (0..b.len()).filter(|&j| !used_b[j]).collect();
    m.pairs.sort_unstable();
    m
}
