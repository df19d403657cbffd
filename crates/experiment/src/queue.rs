//! One queue for the work of several sweeps (`reproduce` runs five experiments and a table
//! sweep at once): every item, a lane group or a computation beside them, is taken by the
//! next free thread, the most costly first. That is list scheduling in decreasing order
//! (Graham 1969: for items of known cost, within 4/3 of the shortest schedule; here the costs
//! are estimates, and a sweep's read-out runs inside its last item), where items taken in any
//! other order leave a long group to start late and run alone.

use crate::mutex::lock;
use crate::prepared::PreparedSweep;
use crate::table_sweep::PreparedTables;
use gyroemu_board::Probe;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// A piece of work.
pub type Item<'s> = Box<dyn FnOnce() + Send + 's>;

/// Runs `items` (each with its cost, in any unit common to all) on the current rayon pool,
/// the most costly first (ties in the given order), and returns when every item has run.
pub fn run_longest_first<'s>(mut items: Vec<(f64, Item<'s>)>) {
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    // Shared by the workers, which the scope keeps for as long as the items' borrows.
    let queue = Arc::new(Mutex::new(items.into_iter()));
    let threads = rayon::current_num_threads();
    rayon::scope(|s| {
        for _ in 0..threads {
            let queue = queue.clone();
            s.spawn(move |_| loop {
                let next = lock(&queue).next();
                let Some((_, item)) = next else { break };
                item();
            });
        }
    });
}

/// The items of `n` lane groups, group `g` costing `cost(g)` and run by `run(g)`;
/// `then` runs once right after the last of them, on the thread that ran it (so a sweep is
/// finished as soon as its groups are, while other items still run), or at once, in an item
/// of its own, when there is no group to run.
fn group_items<'s>(
    n: usize,
    cost: impl Fn(usize) -> f64,
    run: impl Fn(usize) + Send + Sync + 's,
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
        return vec![(0.0, Box::new(done))];
    }
    let (run, done) = (Arc::new(run), Arc::new(done));
    (0..n)
        .map(|g| {
            let (run, done) = (run.clone(), done.clone());
            let item: Item<'s> = Box::new(move || {
                run(g);
                done();
            });
            (cost(g), item)
        })
        .collect()
}

/// The items of `sweep`'s lane groups, each costing its input samples times `per_sample`
/// (the chain's relative cost per sample), followed by `then` (`group_items`). The group
/// that records the dump writes it (and runs `on_dump_early`) as soon as its windows are
/// recorded, on its own thread, then goes on: every thread has items to run, so nothing is
/// gained by handing the writing to another, and the dump is written before the sweep's
/// last item finishes it.
pub fn sweep_items<'s>(
    sweep: &'s PreparedSweep<'s>,
    per_sample: f64,
    then: Option<&'s (dyn Fn() + Sync)>,
) -> Vec<(f64, Item<'s>)> {
    let run = move |g: usize| sweep.run_group(g, &|p: &Probe| sweep.write_early_dump(p));
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
    let run = move |g: usize| tables.run_group(g);
    let cost = |g: usize| tables.group_samples(g) as f64 * per_sample;
    group_items(tables.groups(), cost, run, then)
}
