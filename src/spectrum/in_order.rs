//! Folding results computed in parallel into a running state in the order of their indices.
//!
//! Floating-point sums depend on their order. Realizations are transformed by whichever thread
//! is free, but each is added to the running sums only after every realization before it, so
//! the sums are the same bits on any thread count, and for any way the same realizations were
//! requested (one call or several). No thread waits for another: a finished result that
//! cannot be added yet is parked, and whichever thread adds the one before it adds it too.

use std::collections::BTreeMap;
use std::sync::{Mutex, MutexGuard, PoisonError, TryLockError};

/// A running state and the results parked until their turn.
pub(crate) struct InOrder<T, S> {
    /// The index of the next result to fold in, and the state.
    adder: Mutex<(usize, S)>,
    parked: Mutex<BTreeMap<usize, T>>,
}

impl<T, S> InOrder<T, S> {
    /// A state whose next result is the one of index `next`.
    pub(crate) fn new(next: usize, state: S) -> Self {
        Self {
            adder: Mutex::new((next, state)),
            parked: Mutex::new(BTreeMap::new()),
        }
    }

    /// Offers the result of index `index`, and folds in with `fold` every result whose turn
    /// has come, unless another thread is folding (it then folds this one too).
    pub(crate) fn offer(&self, index: usize, result: T, mut fold: impl FnMut(&mut S, T)) {
        lock(&self.parked).insert(index, result);
        loop {
            let mut adder = match self.adder.try_lock() {
                Ok(adder) => adder,
                Err(TryLockError::WouldBlock) => return,
                Err(TryLockError::Poisoned(p)) => p.into_inner(),
            };
            let (next, state) = &mut *adder;
            loop {
                let Some(result) = lock(&self.parked).remove(next) else {
                    break;
                };
                fold(state, result);
                *next += 1;
            }
            let next = *next;
            drop(adder);
            // A result offered while this thread held the adder found it busy and was left
            // parked: look once more now that it is free.
            if !lock(&self.parked).contains_key(&next) {
                return;
            }
        }
    }

    /// How many results are parked, waiting for an earlier one.
    pub(crate) fn parked(&self) -> usize {
        lock(&self.parked).len()
    }

    /// The index of the next result to fold in (every result before it has been) and the
    /// state; results still parked are dropped.
    pub(crate) fn into_inner(self) -> (usize, S) {
        self.adder
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner)
    }
}

/// The guarded value, also when another thread panicked while holding the lock: that panic is
/// reported where it happened, not a second time here.
pub(super) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Results offered in any order from any thread are folded in index order, each once.
    #[test]
    fn results_are_folded_in_index_order() {
        let count = 2000;
        let in_order = InOrder::new(0, Vec::new());
        // A permutation scattering neighbours (1231 is prime to 2000), offered from the
        // pool's threads.
        let order: Vec<usize> = (0..count).map(|i| i * 1231 % count).collect();
        let mut seen = order.clone();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), count, "every index offered once");
        order.par_iter().for_each(|&i| {
            in_order.offer(i, i, |folded: &mut Vec<usize>, r| folded.push(r));
        });
        let (next, folded) = in_order.into_inner();
        assert_eq!(next, count);
        assert!(folded.iter().enumerate().all(|(i, &r)| i == r));
    }

    /// A missing result holds back every later one: they stay parked and are not folded.
    #[test]
    fn a_gap_holds_back_the_results_after_it() {
        let in_order = InOrder::new(5, 0usize);
        for i in [5, 6, 8, 9] {
            in_order.offer(i, i, |sum: &mut usize, r| *sum += r);
        }
        assert_eq!(in_order.parked(), 2);
        let (next, sum) = in_order.into_inner();
        assert_eq!((next, sum), (7, 11));
    }
}
