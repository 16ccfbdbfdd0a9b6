//! The lookups of the value-reference arrays a master sends again and again: the rows of
//! the last few `fmi2GetReal`/`fmi2SetReal` arrays, kept with the instance.

use crate::decl::{BaseType, Declaration, HotRow};
#[cfg(doc)]
use crate::model::Model;

/// The value references of the last `fmi2GetReal` or `fmi2SetReal` call and their rows
/// of the declaration: a master sends the same arrays at every communication point, so
/// the lookups run once per array, not once per value and call. Only the lookups are
/// kept: every check still runs on every value of every call.
pub(super) struct CallMemo<B> {
    vrs: Vec<u32>,
    pub(super) rows: Vec<MemoRow<B>>,
    /// Whether the model may refuse one of them ([`Model::setter_may_refuse`]).
    pub(super) may_refuse: bool,
}

#[derive(Clone, Copy)]
pub(super) struct MemoRow<B> {
    pub(super) row: usize,
    pub(super) hot: HotRow<B>,
}

/// Longest call whose lookups are kept (the memo is allocated once, with the instance).
const MEMO_CAPACITY: usize = 64;
/// Arrays kept per direction (a master reads an instance's connected outputs and its
/// recorded variables in two calls, say).
const MEMO_ARRAYS: usize = 4;

/// The last [`MEMO_ARRAYS`] arrays, the oldest replaced first.
pub(super) struct CallMemos<B> {
    pub(super) arrays: [CallMemo<B>; MEMO_ARRAYS],
    next: usize,
}

impl<B: Copy> CallMemos<B> {
    pub(super) fn new() -> Self {
        CallMemos { arrays: std::array::from_fn(|_| CallMemo::new()), next: 0 }
    }

    /// The kept array equal to `vrs`.
    #[inline]
    pub(super) fn find(&self, vrs: &[u32]) -> Option<usize> {
        self.arrays.iter().position(|m| m.matches(vrs))
    }

    /// Keeps the lookups of `vrs` in place of the oldest.
    pub(super) fn fill(&mut self, d: &Declaration<B>, vrs: &[u32], may_refuse: impl Fn(B) -> bool) {
        self.arrays[self.next].fill(d, vrs, may_refuse);
        self.next = (self.next + 1) % MEMO_ARRAYS;
    }
}

impl<B: Copy> CallMemo<B> {
    fn new() -> Self {
        CallMemo { vrs: Vec::with_capacity(MEMO_CAPACITY), rows: Vec::with_capacity(MEMO_CAPACITY), may_refuse: true }
    }

    #[inline]
    fn matches(&self, vrs: &[u32]) -> bool {
        !self.vrs.is_empty() && self.vrs.as_slice() == vrs
    }

    /// Keeps the lookups of `vrs` (all known Reals: the caller checked).
    fn fill(&mut self, d: &Declaration<B>, vrs: &[u32], may_refuse: impl Fn(B) -> bool) {
        self.vrs.clear();
        self.rows.clear();
        if vrs.len() > MEMO_CAPACITY {
            return;
        }
        for &vr in vrs {
            let Some(row) = d.row(BaseType::Real, vr) else {
                self.vrs.clear();
                self.rows.clear();
                return;
            };
            self.rows.push(MemoRow { row, hot: *d.hot(row) });
        }
        self.vrs.extend_from_slice(vrs);
        self.may_refuse = self.rows.iter().any(|r| may_refuse(r.hot.binding));
    }
}
