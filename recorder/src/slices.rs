//! Parallel tasks that each own consecutive ranges of several arrays, handed out by
//! splitting the arrays in halves (rayon::join) — safe, and without allocating.

use std::ops::{Add, Range};

/// What tasks return: counts that add up.
pub trait Sum: Send + Default + Add<Output = Self> {}

impl<T: Send + Default + Add<Output = T>> Sum for T {}

/// Mutable arrays that split together: a slice, a pair of them, or a struct of them (named
/// fields: `slices_indexed_alike!` for slices indexed alike, `pieces_at!` for pieces split at
/// positions of their own).
pub trait Pieces: Sized + Send {
    /// A position in each array.
    type At: Copy + Send + Sync;
    /// Splits at `at`, this piece starting at `from`.
    fn split(self, from: Self::At, at: Self::At) -> (Self, Self);
}

impl<T: Send> Pieces for &mut [T] {
    type At = usize;
    fn split(self, from: usize, at: usize) -> (Self, Self) {
        self.split_at_mut(at - from)
    }
}

impl<A: Pieces, B: Pieces> Pieces for (A, B) {
    type At = (A::At, B::At);
    fn split(self, from: Self::At, at: Self::At) -> (Self, Self) {
        let (a0, a1) = self.0.split(from.0, at.0);
        let (b0, b1) = self.1.split(from.1, at.1);
        ((a0, b0), (a1, b1))
    }
}

/// Implements [`Pieces`] for a struct of mutable slices indexed alike (one position in all
/// of them): `slices_indexed_alike!(Name { field, … })`, the struct taking one lifetime.
macro_rules! slices_indexed_alike {
    ($name:ident { $($field:ident),+ $(,)? }) => {
        impl $crate::slices::Pieces for $name<'_> {
            type At = usize;
            fn split(self, from: usize, at: usize) -> (Self, Self) {
                $(let $field = self.$field.split_at_mut(at - from);)+
                ($name { $($field: $field.0),+ }, $name { $($field: $field.1),+ })
            }
        }
    };
}
pub(crate) use slices_indexed_alike;

/// Implements [`Pieces`] for a struct of pieces split at positions of their own, named by the
/// fields of a struct of positions: `pieces_at!(Name at Start { field: position, … })`, the
/// pieces struct taking one lifetime, the fields split in the order given.
macro_rules! pieces_at {
    ($name:ident at $start:ident { $($field:ident: $at:ident),+ $(,)? }) => {
        impl $crate::slices::Pieces for $name<'_> {
            type At = $start;
            fn split(self, from: $start, at: $start) -> (Self, Self) {
                $(let $field = $crate::slices::Pieces::split(self.$field, from.$at, at.$at);)+
                ($name { $($field: $field.0),+ }, $name { $($field: $field.1),+ })
            }
        }
    };
}
pub(crate) use pieces_at;

/// Runs `work(task, pieces)` for every task of `tasks`, in parallel, and sums the results
/// (from `R::default()`).
/// Task `k`'s pieces start at `start(k)` and reach the next task's start (the last task's,
/// the arrays' end); `start` must not decrease and `origin` is where the arrays begin.
/// What a task does with its pieces does not depend on how the tasks were shared out.
pub fn for_each_task<P: Pieces, R: Sum>(
    arrays: P,
    origin: P::At,
    tasks: Range<usize>,
    start: &(impl Fn(usize) -> P::At + Sync),
    work: &(impl Fn(usize, P) -> R + Sync),
) -> R {
    if tasks.is_empty() {
        return R::default();
    }
    let first = start(tasks.start);
    let (_, pieces) = arrays.split(origin, first);
    split_tasks(pieces, first, tasks, start, work)
}

fn split_tasks<P: Pieces, R: Sum>(
    pieces: P,
    from: P::At,
    tasks: Range<usize>,
    start: &(impl Fn(usize) -> P::At + Sync),
    work: &(impl Fn(usize, P) -> R + Sync),
) -> R {
    if tasks.len() == 1 {
        return work(tasks.start, pieces);
    }
    let mid = tasks.start + tasks.len() / 2;
    let at = start(mid);
    let (left, right) = pieces.split(from, at);
    let (a, b) = rayon::join(
        || split_tasks(left, from, tasks.start..mid, start, work),
        || split_tasks(right, at, mid..tasks.end, start, work),
    );
    a + b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_task_gets_its_ranges_of_every_array() {
        let mut a: Vec<u32> = (0..10).collect();
        let mut b: Vec<u32> = (100..120).collect();
        // task k owns a[2k + 1 ..] and b[4k ..], up to the next task's start
        let seen = std::sync::Mutex::new(Vec::new());
        let total: u64 = for_each_task(
            (&mut a[..], &mut b[..]),
            (0, 0),
            0..4,
            &|k| (2 * k + 1, 4 * k),
            &|k, (pa, pb): (&mut [u32], &mut [u32])| {
                seen.lock()
                    .unwrap()
                    .push((k, pa[0], pa.len(), pb[0], pb.len()));
                pa[0] = 0;
                1
            },
        );
        assert_eq!(total, 4);
        let mut seen = seen.into_inner().unwrap();
        seen.sort();
        assert_eq!(
            seen,
            vec![
                (0, 1, 2, 100, 4),
                (1, 3, 2, 104, 4),
                (2, 5, 2, 108, 4),
                (3, 7, 3, 112, 8)
            ]
        );
        assert_eq!(a, vec![0, 0, 2, 0, 4, 0, 6, 0, 8, 9]);
    }

    /// Named pieces split at named positions, as the tasks of the list and contact stages.
    struct Named<'a> {
        a: &'a mut [u32],
        b: &'a mut [u32],
    }

    #[derive(Debug, Clone, Copy, Default)]
    struct NamedAt {
        in_a: usize,
        in_b: usize,
    }

    pieces_at!(Named at NamedAt { a: in_a, b: in_b });

    #[test]
    fn named_pieces_split_at_their_own_positions() {
        let mut a: Vec<u32> = (0..10).collect();
        let mut b: Vec<u32> = (100..120).collect();
        // task k owns a[3k ..] and b[5k ..], up to the next task's start
        let seen = std::sync::Mutex::new(Vec::new());
        let start = |k: usize| NamedAt {
            in_a: 3 * k,
            in_b: 5 * k,
        };
        let total: u64 = for_each_task(
            Named {
                a: &mut a[..],
                b: &mut b[..],
            },
            NamedAt::default(),
            1..4,
            &start,
            &|k, Named { a, b }: Named| {
                seen.lock().unwrap().push((k, a[0], a.len(), b[0], b.len()));
                1
            },
        );
        assert_eq!(total, 3);
        let mut seen = seen.into_inner().unwrap();
        seen.sort();
        assert_eq!(
            seen,
            vec![(1, 3, 3, 105, 5), (2, 6, 3, 110, 5), (3, 9, 1, 115, 5)]
        );
    }
}
