//! A persistent map from variable indexes to values: a radix trie of small
//! fixed-width nodes, copied along one path per insert.
//!
//! Why not a general persistent hash map: variables are dense small integers,
//! so they can index the trie directly (no hashing, no collision handling),
//! and an update copies only `WIDTH` slots per level — a handful of words
//! instead of the wide nodes a general HAMT copies. Clones are O(1) (one
//! reference count); lookups are `height` array hops.

use std::sync::Arc;

const BITS: u32 = 3;
const WIDTH: usize = 1 << BITS;
const MASK: u32 = (WIDTH as u32) - 1;

enum Node<V> {
    Leaf([Option<V>; WIDTH]),
    Inner([Option<Arc<Node<V>>>; WIDTH]),
}

impl<V: Clone> Clone for Node<V> {
    /// Slot by slot into an array of `None`s. The derived clone went
    /// through an iterator adapter with an out-of-line call per slot that
    /// returned the slot through the stack, and the wider load that copied
    /// it on stalled on the narrower stores (store forwarding): copying
    /// leaves on every commit was a tenth of zebra's time.
    #[inline]
    fn clone(&self) -> Self {
        match self {
            Node::Leaf(slots) => {
                let mut out: [Option<V>; WIDTH] = Default::default();
                for (o, s) in out.iter_mut().zip(slots) {
                    if let Some(v) = s {
                        *o = Some(v.clone());
                    }
                }
                Node::Leaf(out)
            }
            Node::Inner(children) => {
                let mut out: [Option<Arc<Node<V>>>; WIDTH] = Default::default();
                for (o, c) in out.iter_mut().zip(children) {
                    if let Some(c) = c {
                        *o = Some(Arc::clone(c));
                    }
                }
                Node::Inner(out)
            }
        }
    }
}

/// A persistent `u32 -> V` map (see the module docs).
///
/// Invariant: every key below `WIDTH.pow(height)` is addressed by its base-`WIDTH`
/// digits, most significant first, from `root`; `len` counts the `Some` leaf slots.
#[derive(Clone)]
pub(crate) struct VarMap<V> {
    root: Option<Arc<Node<V>>>,
    height: u32,
    /// 32 bits, beside `height`: the map is part of every search state,
    /// which is moved often, and four billion bindings would not fit in
    /// memory anyway.
    len: u32,
}

impl<V> Default for VarMap<V> {
    fn default() -> Self {
        VarMap {
            root: None,
            height: 1,
            len: 0,
        }
    }
}

impl<V: Clone> VarMap<V> {
    pub fn len(&self) -> usize {
        self.len as usize
    }

    fn capacity_bits(&self) -> u32 {
        self.height * BITS
    }

    #[inline]
    pub fn get(&self, key: u32) -> Option<&V> {
        let bits = self.capacity_bits();
        if bits < 32 && key >> bits != 0 {
            return None;
        }
        let mut node = self.root.as_deref()?;
        let mut shift = bits - BITS;
        loop {
            let i = ((key >> shift) & MASK) as usize;
            match node {
                Node::Inner(children) => {
                    node = children[i].as_deref()?;
                    shift -= BITS;
                }
                Node::Leaf(slots) => return slots[i].as_ref(),
            }
        }
    }

    /// Grows the trie until `key` is addressable.
    #[inline]
    fn reach(&mut self, key: u32) {
        while self.capacity_bits() < 32 && key >> self.capacity_bits() != 0 {
            if let Some(old) = self.root.take() {
                let mut children: [Option<Arc<Node<V>>>; WIDTH] = Default::default();
                children[0] = Some(old);
                self.root = Some(Arc::new(Node::Inner(children)));
            }
            self.height += 1;
        }
    }

    /// Inserts every `(key, value)` of `items`, in order (a later
    /// duplicate wins); `max` is at least every key. Consecutive keys that
    /// fall in the same leaf — most of a unification's bindings: a
    /// pattern's variables, one house's fields — reuse the leaf reached for
    /// the first of them, so the path to it is made unique (an atomic
    /// compare-and-swap per node, and a copy where it is shared) once, not
    /// once per key.
    #[inline]
    pub fn insert_many(&mut self, max: u32, items: impl IntoIterator<Item = (u32, V)>) {
        self.reach(max);
        let height = self.height;
        let root = self.root.get_or_insert_with(|| Arc::new(empty(height)));
        let root = Arc::make_mut(root);
        let mut added = 0;
        let mut cur: Option<(u32, &mut [Option<V>; WIDTH])> = None;
        for (k, value) in items {
            let prefix = k >> BITS;
            if cur.as_ref().map(|c| c.0) != Some(prefix) {
                cur = Some((prefix, leaf_mut(root, k, height)));
            }
            if let Some((_, slots)) = cur.as_mut() {
                let slot = &mut slots[(k & MASK) as usize];
                if slot.is_none() {
                    added += 1;
                }
                *slot = Some(value);
            }
        }
        self.len = self.len.saturating_add(added);
    }

    #[inline]
    pub fn insert(&mut self, key: u32, value: V) {
        self.reach(key);
        let height = self.height;
        let root = self.root.get_or_insert_with(|| Arc::new(empty(height)));
        let mut node = Arc::make_mut(root);
        let mut level = height;
        loop {
            let shift = (level - 1) * BITS;
            let i = ((key >> shift) & MASK) as usize;
            match node {
                Node::Leaf(slots) => {
                    if slots[i].is_none() {
                        self.len = self.len.saturating_add(1);
                    }
                    slots[i] = Some(value);
                    return;
                }
                Node::Inner(children) => {
                    level -= 1;
                    let child = children[i].get_or_insert_with(|| Arc::new(empty(level)));
                    node = Arc::make_mut(child);
                }
            }
        }
    }

    /// The leaf that holds `key`, if it exists.
    #[inline]
    fn leaf(&self, key: u32) -> Option<&[Option<V>; WIDTH]> {
        let bits = self.capacity_bits();
        if bits < 32 && key >> bits != 0 {
            return None;
        }
        let mut node = self.root.as_deref()?;
        let mut shift = bits - BITS;
        loop {
            match node {
                Node::Inner(children) => {
                    node = children[((key >> shift) & MASK) as usize].as_deref()?;
                    shift -= BITS;
                }
                Node::Leaf(slots) => return Some(slots),
            }
        }
    }

    /// Calls `f` on every entry, in key order.
    pub fn for_each<'a>(&'a self, mut f: impl FnMut(u32, &'a V)) {
        fn walk<'a, V>(node: &'a Node<V>, prefix: u32, f: &mut impl FnMut(u32, &'a V)) {
            match node {
                Node::Leaf(slots) => {
                    for (i, s) in slots.iter().enumerate() {
                        if let Some(v) = s {
                            f(prefix << BITS | i as u32, v);
                        }
                    }
                }
                Node::Inner(children) => {
                    for (i, c) in children.iter().enumerate() {
                        if let Some(c) = c {
                            walk(c, prefix << BITS | i as u32, f);
                        }
                    }
                }
            }
        }
        if let Some(root) = &self.root {
            walk(root, 0, &mut f);
        }
    }
}

/// Lookups that remember the last leaf they reached: a walk along a list
/// built by a relation looks up runs of neighbouring variables (each cell's
/// head and tail were made by one `fresh`), which mostly share a leaf, so
/// most lookups cost one index instead of a descent from the root.
pub(crate) struct LeafCache<'a, V> {
    prefix: u32,
    leaf: Option<&'a [Option<V>; WIDTH]>,
}

impl<'a, V: Clone> LeafCache<'a, V> {
    pub fn new() -> Self {
        LeafCache {
            prefix: 0,
            leaf: None,
        }
    }

    /// `map.get(key)`; `map` must be the same map on every call.
    #[inline]
    pub fn get(&mut self, map: &'a VarMap<V>, key: u32) -> Option<&'a V> {
        if let Some(leaf) = self.leaf
            && key >> BITS == self.prefix
        {
            return leaf[(key & MASK) as usize].as_ref();
        }
        let leaf = map.leaf(key)?;
        self.prefix = key >> BITS;
        self.leaf = Some(leaf);
        leaf[(key & MASK) as usize].as_ref()
    }
}

/// The leaf that holds `key`, below `node` at `level` (the root's level is
/// the trie's height), every node on the way made unique. Inlined into
/// `insert_many`, which calls it for nearly every binding (a unification's
/// bindings alternate between leaves): 2 % of zebra's instructions.
#[inline(always)]
fn leaf_mut<V: Clone>(mut node: &mut Node<V>, key: u32, mut level: u32) -> &mut [Option<V>; WIDTH] {
    loop {
        match node {
            Node::Leaf(slots) => return slots,
            Node::Inner(children) => {
                let i = ((key >> ((level - 1) * BITS)) & MASK) as usize;
                level -= 1;
                let child = children[i].get_or_insert_with(|| Arc::new(empty(level)));
                node = Arc::make_mut(child);
            }
        }
    }
}

fn empty<V>(level: u32) -> Node<V> {
    if level <= 1 {
        Node::Leaf(Default::default())
    } else {
        Node::Inner(Default::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    proptest! {
        #[test]
        fn behaves_like_a_map_and_stays_persistent(
            ops in prop::collection::vec((0u32..5000, any::<u16>()), 0..200),
        ) {
            let mut m: VarMap<u16> = VarMap::default();
            let mut model = BTreeMap::new();
            let mut snapshots = Vec::new();
            for (k, v) in ops {
                snapshots.push((m.clone(), model.clone()));
                m.insert(k, v);
                model.insert(k, v);
            }
            for (snap, want) in snapshots.iter().chain([(m.clone(), model.clone())].iter()) {
                prop_assert_eq!(snap.len(), want.len());
                for (k, v) in want {
                    prop_assert_eq!(snap.get(*k), Some(v));
                }
                let mut seen = Vec::new();
                snap.for_each(|k, v| seen.push((k, *v)));
                let want_list: Vec<(u32, u16)> = want.iter().map(|(k, v)| (*k, *v)).collect();
                prop_assert_eq!(seen, want_list);
                prop_assert_eq!(snap.get(99_999), None);
                // The leaf cache answers as `get` does, whatever the order.
                let mut cache = LeafCache::new();
                for k in (0..64u32).chain([4_999, 8, 9, 4_096, 99_999, 7]) {
                    prop_assert_eq!(cache.get(snap, k), snap.get(k));
                }
            }
        }
    }

    #[test]
    fn large_keys() {
        let mut m = VarMap::default();
        m.insert(u32::MAX, 1u8);
        m.insert(0, 2u8);
        assert_eq!(m.get(u32::MAX), Some(&1));
        assert_eq!(m.get(0), Some(&2));
        assert_eq!(m.get(7), None);
        assert_eq!(m.len(), 2);
    }
}
