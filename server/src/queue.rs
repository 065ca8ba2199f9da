//! The synthesis queue: permits to run on the pool, one per pool thread, handed out first come
//! first served while the queue is short and newest first once it is long (adaptive LIFO).
//!
//! A short queue is a burst (a viewer opening a view) and drains in order. A long queue means
//! sustained overload: serving the newest waiter keeps admitted requests fast while the oldest
//! ones run out of their queue-wait budget and are shed with a 503, instead of every admitted
//! request waiting out the whole queue.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use tokio::sync::oneshot;

/// The queue of one pool.
pub struct RunQueue {
    inner: Mutex<Inner>,
    /// Waiters beyond which the newest is served first.
    lifo_above: usize,
}

struct Inner {
    free: usize,
    waiting: VecDeque<oneshot::Sender<RunPermit>>,
}

/// Leave to run; gives the thread back to the queue when dropped — also when it is dropped
/// unseen, inside the channel of a waiter that gave up at the moment it was handed over.
pub struct RunPermit(Option<Arc<RunQueue>>);

impl Drop for RunPermit {
    fn drop(&mut self) {
        if let Some(q) = self.0.take() {
            RunQueue::release(&q);
        }
    }
}

impl RunQueue {
    /// A queue for `threads` pool threads, serving newest first beyond `lifo_above` waiters.
    pub fn new(threads: usize, lifo_above: usize) -> Arc<Self> {
        Arc::new(RunQueue { inner: Mutex::new(Inner { free: threads, waiting: VecDeque::new() }), lifo_above })
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        // Every critical section leaves `Inner` consistent, so a poisoned lock is still usable.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Wait at most `budget` for a thread; `None` when the budget ran out.
    pub async fn acquire(self: &Arc<Self>, budget: Duration) -> Option<RunPermit> {
        let rx = {
            let mut g = self.lock();
            if g.free > 0 {
                g.free -= 1;
                return Some(RunPermit(Some(self.clone())));
            }
            let (tx, rx) = oneshot::channel();
            g.waiting.retain(|tx| !tx.is_closed());
            g.waiting.push_back(tx);
            rx
        };
        // On timeout (or if this future is dropped) the receiver goes, and with it any permit
        // that was just handed over, which then releases itself to the next waiter.
        tokio::time::timeout(budget, rx).await.ok()?.ok()
    }

    /// Hand the thread to the next live waiter (oldest, or newest when the queue is long), or
    /// keep it free.
    fn release(this: &Arc<RunQueue>) {
        let mut g = this.lock();
        // Waiters that gave up (timed out, or their request was dropped) must not count towards
        // the queue's length, or a few of them would keep it "long" and newest-first for good.
        g.waiting.retain(|tx| !tx.is_closed());
        let mut permit = RunPermit(Some(this.clone()));
        loop {
            let next = if g.waiting.len() > this.lifo_above { g.waiting.pop_back() } else { g.waiting.pop_front() };
            match next {
                Some(tx) => match tx.send(permit) {
                    Ok(()) => return,
                    Err(back) => permit = back,
                },
                None => {
                    g.free += 1;
                    // Disarm: this permit's thread is now counted as free.
                    permit.0 = None;
                    return;
                }
            }
        }
    }

    /// Requests waiting for a thread.
    pub fn waiting(&self) -> usize {
        self.lock().waiting.iter().filter(|tx| !tx.is_closed()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Queue `n` waiters 20 ms apart (each holds its thread for `hold`); returns the order in
    /// which they were served and their tasks.
    async fn queue_waiters(
        q: &Arc<RunQueue>,
        n: usize,
        hold: Duration,
    ) -> (Arc<Mutex<Vec<usize>>>, Vec<tokio::task::JoinHandle<()>>) {
        let order = Arc::new(Mutex::new(Vec::new()));
        let mut tasks = Vec::new();
        for i in 0..n {
            let (q, order) = (q.clone(), order.clone());
            tasks.push(tokio::spawn(async move {
                let p = q.acquire(Duration::from_secs(5)).await.expect("served");
                order.lock().unwrap().push(i);
                tokio::time::sleep(hold).await;
                drop(p);
            }));
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        (order, tasks)
    }

    #[tokio::test]
    async fn short_queues_are_fifo_and_long_ones_serve_the_newest() {
        let q = RunQueue::new(1, 2);
        let running = q.acquire(Duration::from_secs(1)).await.expect("free thread");
        let (order, tasks) = queue_waiters(&q, 4, Duration::from_millis(5)).await;
        assert_eq!(q.waiting(), 4);
        drop(running);
        for t in tasks {
            t.await.unwrap();
        }
        // 4 waiting > 2: newest (3); then 3 waiting > 2: newest (2); then FIFO: 0, 1.
        assert_eq!(*order.lock().unwrap(), vec![3, 2, 0, 1]);
    }

    #[tokio::test]
    async fn a_permit_handed_to_a_waiter_that_gave_up_comes_back() {
        let q = RunQueue::new(1, 8);
        let running = q.acquire(Duration::from_secs(1)).await.expect("free thread");
        // A waiter that is dropped right after the thread is handed to it, before it looks.
        let waiter = {
            let q = q.clone();
            tokio::spawn(async move { q.acquire(Duration::from_secs(5)).await.map(|_| ()) })
        };
        tokio::time::sleep(Duration::from_millis(20)).await;
        // Hand the thread over, then cancel the waiter before it runs again to look.
        drop(running);
        waiter.abort();
        let _ = waiter.await;
        for _ in 0..3 {
            assert!(q.acquire(Duration::from_millis(50)).await.is_some(), "the thread was lost");
        }
    }

    #[tokio::test]
    async fn waiters_that_gave_up_do_not_keep_the_queue_long() {
        // Three waiters give up; afterwards two live ones must be served oldest first, as a
        // short queue is (lifo above 2: counting the dead, the queue would look long).
        let q = RunQueue::new(1, 2);
        let running = q.acquire(Duration::from_secs(1)).await.expect("free thread");
        for _ in 0..3 {
            assert!(q.acquire(Duration::from_millis(5)).await.is_none());
        }
        let (order, tasks) = queue_waiters(&q, 2, Duration::ZERO).await;
        assert_eq!(q.waiting(), 2);
        drop(running);
        for t in tasks {
            t.await.unwrap();
        }
        assert_eq!(*order.lock().unwrap(), vec![0, 1]);
    }

    #[tokio::test]
    async fn a_timed_out_waiter_does_not_swallow_the_thread() {
        let q = RunQueue::new(1, 8);
        let running = q.acquire(Duration::from_secs(1)).await.expect("free thread");
        assert!(q.acquire(Duration::from_millis(20)).await.is_none());
        drop(running);
        assert!(q.acquire(Duration::from_millis(20)).await.is_some());
    }
}
