//! One queue for the work of several sweeps (`reproduce` runs five experiments and a table
//! sweep at once): every item, a lane group or a computation beside them, is taken by the
//! next free thread, the most costly first. That is list scheduling in decreasing order
//! (Graham 1969): the run ends within 4/3 of the shortest possible schedule, and in practice
//! within the last small item, where items taken in any other order leave a long group to
//! start late and run alone.

use crate::prepared::PreparedSweep;
use crate::table_sweep::PreparedTables;
use gyroemu_board::Probe;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// A piece of work; it may spawn more into the queue's scope (a dump to write), which runs
/// between items.
pub type Item<'s> = Box<dyn FnOnce(&rayon::Scope<'s>) + Send + 's>;

/// Runs `items` (each with its cost, in any unit common to all) on the current rayon pool,
/// the most costly first (ties in the given order), and returns when every item and what
/// they spawned has run.
pub fn run_longest_first<'s>(mut items: Vec<(f64, Item<'s>)>) {
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    // Shared by the workers, which the scope keeps for as long as the items' borrows.
    let queue = Arc::new(Mutex::new(items.into_iter()));
    let threads = rayon::current_num_threads();
    rayon::scope(|s| {
        for _ in 0..threads {
            let queue = queue.clone();
            s.spawn(move |s| loop {
                let next = queue.lock().unwrap_or_else(|e| e.into_inner()).next();
                let Some((_, item)) = next else { break };
                item(s);
                // What the item spawned (a dump to write) before the next item.
                while let Some(rayon::Yield::Executed) = rayon::yield_local() {}
            });
        }
    });
}

/// Runs `then` once after the last of `n` items (each calls the returned closure when done),
/// on the thread that ran it: a sweep finished as soon as its groups are, while other items
/// still run.
fn countdown<'s>(n: usize, then: Option<&'s (dyn Fn() + Sync)>) -> impl Fn() + Send + Sync + 's {
    let left = Arc::new(AtomicUsize::new(n));
    move || {
        if left.fetch_sub(1, Ordering::AcqRel) == 1 {
            if let Some(f) = then {
                f();
            }
        }
    }
}

/// The items of `sweep`'s lane groups, each costing its input samples times `per_sample`
/// (the chain's relative cost per sample); `then` runs right after the last of them (at once,
/// in an item of its own, for a sweep with no group to run).
pub fn sweep_items<'s>(
    sweep: &'s PreparedSweep<'s>,
    per_sample: f64,
    then: Option<&'s (dyn Fn() + Sync)>,
) -> Vec<(f64, Item<'s>)> {
    let done = Arc::new(countdown(sweep.groups().max(1), then));
    if sweep.groups() == 0 {
        return vec![(0.0, Box::new(move |_: &rayon::Scope<'s>| done()))];
    }
    (0..sweep.groups())
        .map(|g| {
            let done = done.clone();
            let item: Item<'s> = Box::new(move |s: &rayon::Scope<'s>| {
                let hand_on = |p: &Probe| {
                    let p = p.clone();
                    s.spawn(move |_| sweep.write_early_dump(&p));
                };
                sweep.run_group(g, &hand_on);
                done();
            });
            (sweep.group_samples(g) as f64 * per_sample, item)
        })
        .collect()
}

/// The items of the table sweeps' lane groups, costed and followed by `then` as in
/// [`sweep_items`].
pub fn table_items<'s>(
    tables: &'s PreparedTables,
    per_sample: f64,
    then: Option<&'s (dyn Fn() + Sync)>,
) -> Vec<(f64, Item<'s>)> {
    let done = Arc::new(countdown(tables.groups().max(1), then));
    if tables.groups() == 0 {
        return vec![(0.0, Box::new(move |_: &rayon::Scope<'s>| done()))];
    }
    (0..tables.groups())
        .map(|g| {
            let done = done.clone();
            let item: Item<'s> = Box::new(move |_: &rayon::Scope<'s>| {
                tables.run_group(g);
                done();
            });
            (tables.group_samples(g) as f64 * per_sample, item)
        })
        .collect()
}
