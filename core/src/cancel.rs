//! The one cancellation token of every long computation — analysis, seamless-image synthesis,
//! rendering in pieces, sample batches: set by whoever no longer wants the result (a client that
//! went away, a removed texture, a stopping service) or by a deadline, and asked between steps.
//! A token may hang off others (set when any of them is) and carry a deadline, so one token says
//! everything that may stop a piece of work.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use crate::error::{CoreError, Result};

/// A cancellation token: cheap to clone (clones share the flag), set once for good.
#[derive(Debug, Clone, Default)]
pub struct Cancel(Arc<Inner>);

#[derive(Debug, Default)]
struct Inner {
    set: AtomicBool,
    deadline: Option<Instant>,
    parents: Vec<Cancel>,
}

impl Cancel {
    /// A token that is set only by [`Cancel::set`].
    pub fn new() -> Cancel {
        Cancel::default()
    }

    /// A token set when any of `parents` is, once `deadline` has passed, or by its own
    /// [`Cancel::set`].
    pub fn within(parents: &[&Cancel], deadline: Option<Instant>) -> Cancel {
        Cancel(Arc::new(Inner {
            set: AtomicBool::new(false),
            deadline,
            parents: parents.iter().map(|&p| p.clone()).collect(),
        }))
    }

    /// Ask the work to stop.
    pub fn set(&self) {
        self.0.set.store(true, Ordering::Relaxed);
    }

    /// Whether the work should stop.
    pub fn is_set(&self) -> bool {
        self.0.set.load(Ordering::Relaxed) || self.past_deadline() || self.0.parents.iter().any(Cancel::is_set)
    }

    /// Whether this token's own deadline has passed.
    pub fn past_deadline(&self) -> bool {
        self.0.deadline.is_some_and(|d| Instant::now() >= d)
    }

    /// [`CoreError::Cancelled`] once the token is set.
    pub fn check(&self) -> Result<()> {
        if self.is_set() {
            Err(CoreError::Cancelled)
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_token_is_set_by_itself_its_parents_or_its_deadline() {
        let (a, b) = (Cancel::new(), Cancel::new());
        let child = Cancel::within(&[&a, &b], None);
        assert!(!child.is_set() && child.check().is_ok());
        b.set();
        assert!(child.is_set() && !a.is_set());
        assert!(matches!(child.check(), Err(CoreError::Cancelled)));
        let own = Cancel::within(&[&a], None);
        own.set();
        assert!(own.is_set() && !a.is_set(), "setting a child leaves its parents alone");
        let late = Cancel::within(&[], Some(Instant::now()));
        assert!(late.is_set() && late.past_deadline());
        let clone = a.clone();
        a.set();
        assert!(clone.is_set(), "clones share the flag");
    }
}
