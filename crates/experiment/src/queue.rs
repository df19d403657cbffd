//! One queue for the work of several sweeps (`reproduce` runs five experiments and a table
//! sweep at once): every item, a lane group or a computation beside them, is taken by the
//! next free thread, the most costly first. That is list scheduling in decreasing order
//! (Graham 1969): the run ends within 4/3 of the shortest possible schedule, and in practice
//! within the last small item, where items taken in any other order leave a long group to
//! start late and run alone.

use crate::prepared::PreparedSweep;
use crate::table_sweep::PreparedTables;
use gyroemu_board::Probe;
use std::sync::Mutex;

/// A piece of work; it may spawn more into the queue's scope (a dump to write), which runs
/// between items.
pub type Item<'s> = Box<dyn FnOnce(&rayon::Scope<'s>) + Send + 's>;

/// Runs `items` (each with its cost, in any unit common to all) on the current rayon pool,
/// the most costly first (ties in the given order), and returns when every item and what
/// they spawned has run.
pub fn run_longest_first<'s>(mut items: Vec<(f64, Item<'s>)>) {
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    // Shared by the workers, which the scope keeps for as long as the items' borrows.
    let queue = std::sync::Arc::new(Mutex::new(items.into_iter()));
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

/// The items of `sweep`'s lane groups, each costing its input samples times `per_sample`
/// (the chain's relative cost per sample).
pub fn sweep_items<'s>(sweep: &'s PreparedSweep<'s>, per_sample: f64) -> Vec<(f64, Item<'s>)> {
    (0..sweep.groups())
        .map(|g| {
            let item: Item<'s> = Box::new(move |s: &rayon::Scope<'s>| {
                let hand_on = |p: &Probe| {
                    let p = p.clone();
                    s.spawn(move |_| sweep.write_early_dump(&p));
                };
                sweep.run_group(g, &hand_on);
            });
            (sweep.group_samples(g) as f64 * per_sample, item)
        })
        .collect()
}

/// The items of the table sweeps' lane groups, costed as [`sweep_items`].
pub fn table_items<'s>(tables: &'s PreparedTables, per_sample: f64) -> Vec<(f64, Item<'s>)> {
    (0..tables.groups())
        .map(|g| {
            let item: Item<'s> = Box::new(move |_: &rayon::Scope<'s>| tables.run_group(g));
            (tables.group_samples(g) as f64 * per_sample, item)
        })
        .collect()
}
