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

/// The items of `n` lane groups, group `g` costing `cost(g)` and run by `run(g, scope)`;
/// `then` runs once right after the last of them, on the thread that ran it (so a sweep is
/// finished as soon as its groups are, while other items still run), or at once, in an item
/// of its own, when there is no group to run.
fn group_items<'s>(
    n: usize,
    cost: impl Fn(usize) -> f64,
    run: impl Fn(usize, &rayon::Scope<'s>) + Send + Sync + 's,
    then: Option<&'s (dyn Fn() + Sync)>,
) -> Vec<(f64, Item<'s>)> {
    let left = Arc::new(AtomicUsize::new(n.max(1)));
    let done = move || {
        if left.fetch_sub(1, Ordering::AcqRel) == 1 {
            if let Some(f) = then {
                f();
            }
        }
    };
    if n == 0 {
        return vec![(0.0, Box::new(move |_: &rayon::Scope<'s>| done()))];
    }
    let (run, done) = (Arc::new(run), Arc::new(done));
    (0..n)
        .map(|g| {
            let (run, done) = (run.clone(), done.clone());
            let item: Item<'s> = Box::new(move |s: &rayon::Scope<'s>| {
                run(g, s);
                done();
            });
            (cost(g), item)
        })
        .collect()
}

/// The items of `sweep`'s lane groups, each costing its input samples times `per_sample`
/// (the chain's relative cost per sample), followed by `then` ([`group_items`]).
pub fn sweep_items<'s>(
    sweep: &'s PreparedSweep<'s>,
    per_sample: f64,
    then: Option<&'s (dyn Fn() + Sync)>,
) -> Vec<(f64, Item<'s>)> {
    let run = move |g: usize, s: &rayon::Scope<'s>| {
        let hand_on = |p: &Probe| {
            let p = p.clone();
            s.spawn(move |_| sweep.write_early_dump(&p));
        };
        sweep.run_group(g, &hand_on);
    };
    let cost = |g: usize| sweep.group_samples(g) as f64 * per_sample;
    group_items(sweep.groups(), cost, run, then)
}

/// The items of the table sweeps' lane groups, costed and followed by `then` as in
/// [`sweep_items`].
pub fn table_items<'s>(
    tables: &'s PreparedTables,
    per_sample: f64,
    then: Option<&'s (dyn Fn() + Sync)>,
) -> Vec<(f64, Item<'s>)> {
    let run = move |g: usize, _: &rayon::Scope<'s>| tables.run_group(g);
    let cost = |g: usize| tables.group_samples(g) as f64 * per_sample;
    group_items(tables.groups(), cost, run, then)
}
