//! A parallel chunk's layers, handed to its worker one at a time, so that a worker that has
//! finished its own chunk can take over the tail of another's.
//!
//! One chunk per thread, cut where the survey puts half the work, finishes together only when
//! the threads run equally fast, and virtual CPUs often do not: the extraction then waits for
//! the slow one. Rayon's own work stealing cannot help: a chunk is one sweep, whose
//! layers must run in order on one thread. So the chunk's worker claims each layer here, and a
//! thief can move the chunk's end down to a layer not yet claimed; the worker, at its next
//! claim, hands over the room for the layers it gave up, and the thief sweeps them as a chunk of
//! their own. The mesh is the same: a chunk boundary anywhere stitches exactly.

use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Instant;

/// One chunk's layers and the hand-over of its tail's room (`R`).
pub(crate) struct Claims<R> {
    /// The chunk's first layer.
    start: usize,
    state: Mutex<State<R>>,
    handed: Condvar,
}

struct State<R> {
    /// The next layer to hand out.
    next: usize,
    /// The end of the layers the chunk's worker sweeps: its chunk's end until a thief cuts it.
    end: usize,
    /// When the chunk's worker began: a chunk no worker has begun may be waiting in the
    /// would-be thief's own queue, and is not cut.
    began: Option<Instant>,
    tail: Tail<R>,
}

enum Tail<R> {
    /// Not cut.
    Whole,
    /// Cut at `end`; the worker hands the tail's room over at its next claim.
    Asked,
    Handed(R),
    /// The thief has it, or the worker stopped on an error before handing it over.
    Gone,
}

/// What a thief knows when it decides where to cut a chunk.
pub(crate) struct Progress {
    /// The chunk's first layer, the next layer its worker will claim, and the chunk's end.
    pub start: usize,
    pub next: usize,
    pub end: usize,
    /// Seconds since the chunk's worker began.
    pub seconds: f64,
}

impl<R> Claims<R> {
    /// The claims of layers `z0..z1`.
    pub fn new((z0, z1): (usize, usize)) -> Self {
        Claims {
            start: z0,
            state: Mutex::new(State {
                next: z0,
                end: z1,
                began: None,
                tail: Tail::Whole,
            }),
            handed: Condvar::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, State<R>> {
        // A poisoned lock means a worker panicked, and that panic is on its way.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Called by the chunk's worker as it begins; the guard releases a waiting thief if the
    /// worker stops early (an error or a panic) without handing over the tail's room.
    pub fn begin(&self) -> Worker<'_, R> {
        self.lock().began = Some(Instant::now());
        Worker(self)
    }

    /// The chunk's next layer, or `None` when its worker is done. If a thief has cut the chunk
    /// since the last claim, `split(next, end)` first makes the room for the tail from `end` on
    /// out of the worker's own (while the thief waits in [`Claims::take`]).
    pub fn claim(&self, split: impl FnOnce(usize, usize) -> R) -> Option<usize> {
        let mut s = self.lock();
        if let Tail::Asked = s.tail {
            s.tail = Tail::Handed(split(s.next, s.end));
            self.handed.notify_all();
        }
        (s.next < s.end).then(|| {
            s.next += 1;
            s.next - 1
        })
    }

    /// Cuts the chunk where `cut` says, if its worker has begun, no one has cut it yet and `cut`
    /// finds a cut worth making: returns the tail's layers, which the caller then sweeps, with
    /// the room from [`Claims::take`].
    pub fn steal(&self, cut: impl FnOnce(Progress) -> Option<usize>) -> Option<(usize, usize)> {
        let mut s = self.lock();
        let began = s.began?;
        if !matches!(s.tail, Tail::Whole) {
            return None;
        }
        let at = cut(Progress {
            start: self.start,
            next: s.next,
            end: s.end,
            seconds: began.elapsed().as_secs_f64(),
        })?;
        // The worker has not claimed `at` (it is past `next`), and will stop before it.
        debug_assert!(s.next < at && at < s.end);
        let tail = (at, s.end);
        s.end = at;
        s.tail = Tail::Asked;
        Some(tail)
    }

    /// Waits for the room of the tail this thread cut; `None` if the worker stopped on an error
    /// instead (the extraction fails with it).
    pub fn take(&self) -> Option<R> {
        let mut s = self.lock();
        while let Tail::Asked = s.tail {
            s = self.handed.wait(s).unwrap_or_else(|p| p.into_inner());
        }
        match core::mem::replace(&mut s.tail, Tail::Gone) {
            Tail::Handed(room) => Some(room),
            _ => None,
        }
    }

    /// Layers not yet handed out, if the chunk may still be cut.
    pub fn left(&self) -> Option<(usize, usize)> {
        let s = self.lock();
        (s.began.is_some() && matches!(s.tail, Tail::Whole)).then_some((s.next, s.end))
    }
}

/// The chunk's worker, for as long as it sweeps (see [`Claims::begin`]).
pub(crate) struct Worker<'c, R>(&'c Claims<R>);

impl<R> Drop for Worker<'_, R> {
    fn drop(&mut self) {
        let mut s = self.0.lock();
        if let Tail::Asked = s.tail {
            s.tail = Tail::Gone;
            self.0.handed.notify_all();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Claims;
    use std::vec::Vec;

    /// A chunk cut while its worker sweeps: the worker claims every layer before the cut once,
    /// in order, and none after it; the thief, waiting on another thread, gets the room the
    /// worker split off at its first claim after the cut, not before; a second cut is refused.
    #[test]
    fn a_cut_chunk_hands_over_its_tail() {
        let claims = Claims::new((3, 20));
        assert!(claims.steal(|_| Some(10)).is_none(), "not begun");
        let worker = claims.begin();
        let mut layers = Vec::new();
        let mut split = None;
        std::thread::scope(|scope| {
            let mut thief = None;
            while let Some(k) = claims.claim(|next, end| {
                split = Some((next, end));
                "room"
            }) {
                layers.push(k);
                if k == 5 {
                    let cut = claims.steal(|p| {
                        assert_eq!((p.next, p.end), (6, 20));
                        Some(12)
                    });
                    assert_eq!(cut, Some((12, 20)));
                    assert!(claims.steal(|_| Some(15)).is_none(), "cut once");
                    let waiting = scope.spawn(|| claims.take());
                    std::thread::sleep(std::time::Duration::from_millis(20));
                    assert!(!waiting.is_finished(), "handed over before the next claim");
                    thief = Some(waiting);
                }
            }
            let room = thief.map(|t| t.join().unwrap());
            assert_eq!(room, Some(Some("room")));
        });
        drop(worker);
        assert_eq!(layers, (3..12).collect::<Vec<_>>());
        assert_eq!(split, Some((6, 12)));
        assert!(claims.take().is_none(), "taken once");
    }

    /// A worker that stops before its next claim (an error) releases the waiting thief.
    #[test]
    fn a_stopped_worker_releases_the_thief() {
        let claims: Claims<&str> = Claims::new((0, 10));
        let worker = claims.begin();
        assert_eq!(claims.claim(|_, _| "room"), Some(0));
        assert_eq!(claims.steal(|_| Some(5)), Some((5, 10)));
        std::thread::scope(|scope| {
            let thief = scope.spawn(|| claims.take());
            drop(worker);
            assert!(thief.join().unwrap().is_none());
        });
    }
}
