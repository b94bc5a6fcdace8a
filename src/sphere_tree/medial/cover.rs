//! Phase 4 of the medial builder: the greedy weighted set cover of the pieces by the candidates,
//! lazily evaluated over exact integer gains, and the per-leaf cost λ that fits it to the budget.

use std::{cmp::Ordering, collections::BinaryHeap};

use super::candidates::Candidates;

/// Heap entry: priority (an upper bound on the candidate's key), candidate.
#[derive(PartialEq)]
pub(super) struct Entry(f64, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // Ties go to the lower index, for determinism.
        self.0.total_cmp(&o.0).then(o.1.cmp(&self.1))
    }
}

/// What the greedy cover keeps current: each candidate's gain as a sum of increments.
///
/// The candidates of one medial ball cover nested prefixes of one run of the pool, so candidate k
/// of a group covers the increments of the group's candidates up to k. Pieces weigh their area in
/// whole units (2⁻⁴⁰ of the tooth's area, at least one), so that gains are exact integers: when a
/// piece is covered its weight leaves every increment that holds it, and a gain is zero exactly
/// when all its pieces are covered.
pub(super) struct GainIndex {
    /// The groups (one per medial ball): their candidates are `first..end`.
    pub(super) groups: Vec<(u32, u32)>,
    /// Per candidate: its group.
    pub(super) group: Vec<u32>,
    /// Per candidate: the weight of the pieces its increment adds to the group's previous one.
    pub(super) increment: Vec<u64>,
    /// Per piece: its weight.
    pub(super) weight: Vec<u64>,
    /// Per piece: the candidates whose increment holds it (`owners[start[i]..start[i + 1]]`).
    pub(super) start: Vec<u32>,
    pub(super) owners: Vec<u32>,
}

impl GainIndex {
    pub(super) fn new(c: &Candidates, area: &[f32]) -> Self {
        let total: f64 = area.iter().map(|&a| a.max(0.0) as f64).sum();
        let unit = if total > 0.0 {
            2f64.powi(40) / total
        } else {
            1.0
        };
        let weight: Vec<u64> = area
            .iter()
            .map(|&a| ((a.max(0.0) as f64 * unit).round() as u64).max(1))
            .collect();
        let mut groups: Vec<(u32, u32)> = Vec::new();
        let mut group = Vec::with_capacity(c.list.len());
        let mut increment = Vec::with_capacity(c.list.len());
        let mut count = vec![0u32; area.len() + 1];
        let mut runs = Vec::with_capacity(c.list.len());
        for (k, x) in c.list.iter().enumerate() {
            let from = match k.checked_sub(1).map(|j| &c.list[j]) {
                Some(prev) if prev.first == x.first && prev.len <= x.len => {
                    groups.last_mut().expect("a group has begun").1 = k as u32 + 1;
                    prev.len
                }
                _ => {
                    groups.push((k as u32, k as u32 + 1));
                    0
                }
            };
            group.push(groups.len() as u32 - 1);
            let run = x.first as usize + from as usize..(x.first + x.len) as usize;
            increment.push(
                c.pool[run.clone()]
                    .iter()
                    .map(|&i| weight[i as usize])
                    .sum(),
            );
            for &i in &c.pool[run.clone()] {
                count[i as usize + 1] += 1;
            }
            runs.push(run);
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut owners = vec![0u32; count[area.len()] as usize];
        for (k, run) in runs.into_iter().enumerate() {
            for &i in &c.pool[run] {
                owners[fill[i as usize] as usize] = k as u32;
                fill[i as usize] += 1;
            }
        }
        Self {
            groups,
            group,
            increment,
            weight,
            start: count,
            owners,
        }
    }
}

/// Greedy weighted set cover: repeatedly the candidate with the most newly covered area per
/// (cost + λ), ties to the lower index; returns the chosen candidates in order.
///
/// Gains are kept exact as pieces are covered ([`GainIndex`]), and the heap is lazy (Minoux's
/// accelerated greedy) with one entry per medial ball, keyed by its best candidate: a gain only
/// falls, so a stored key is an upper bound; the top ball's candidates are re-keyed together
/// (their gains are running sums of the group's increments), and its best is taken when it still
/// beats the next bound, which makes it the true best without re-keying every candidate that
/// shares a newly covered piece. A ball whose candidate is taken goes back in the heap, since its
/// larger candidates may still cover more.
pub(super) fn greedy(c: &Candidates, index: &GainIndex, lambda: f64) -> Vec<u32> {
    let mut increment = index.increment.clone();
    // A group's best candidate now: the most gain per (cost + λ), ties to the lower index.
    let best = |increment: &[u64], group: u32| -> Option<Entry> {
        let (first, end) = index.groups[group as usize];
        let mut gain = 0u64;
        let mut best: Option<Entry> = None;
        for k in first..end {
            gain += increment[k as usize];
            if gain > 0 {
                let entry = Entry(
                    gain as f64 / (c.list[k as usize].cost + lambda).max(1e-12),
                    k,
                );
                if best.as_ref().is_none_or(|b| entry > *b) {
                    best = Some(entry);
                }
            }
        }
        best
    };
    let mut heap: BinaryHeap<Entry> = (0..index.groups.len() as u32)
        .filter_map(|g| best(&increment, g))
        .collect();
    let mut open = vec![true; index.weight.len()];
    let mut uncovered = open.len();
    let mut chosen = Vec::new();
    while uncovered > 0 {
        let Some(Entry(_, k)) = heap.pop() else {
            break;
        };
        let group = index.group[k as usize];
        let Some(entry) = best(&increment, group) else {
            continue;
        };
        if heap.peek().is_some_and(|top| *top > entry) {
            heap.push(entry);
            continue;
        }
        let k = entry.1 as usize;
        let x = &c.list[k];
        for &i in &c.pool[x.first as usize..(x.first + x.len) as usize] {
            let i = i as usize;
            if open[i] {
                open[i] = false;
                uncovered -= 1;
                for &j in &index.owners[index.start[i] as usize..index.start[i + 1] as usize] {
                    increment[j as usize] -= index.weight[i];
                }
            }
        }
        chosen.push(k as u32);
        // The group's larger candidates may still cover more.
        if let Some(entry) = best(&increment, group) {
            heap.push(entry);
        }
    }
    chosen
}

/// The greedy cover, pruned, with a per-leaf cost λ that brings its size just under the budget,
/// by a search on log λ against log size that stops once a cover uses at least 95 % of the
/// budget.
///
/// The first λ is predicted without a cover ([`predicted_lambda`]). Where even a tiny λ is
/// predicted to fit, or the first cover is under 95 % of the budget before any was over it,
/// λ = 0 is tried and taken if it fits (its cover is then the largest); in the first case its
/// cover gives the guess instead: its mean cost scaled by (its size / target)^1.6. Later runs
/// follow the size as a power of λ (exponent about −1/2, measured on teeth) until a bracket is
/// found, then interpolate within the tightest bracket.
pub(super) fn choose(c: &Candidates, area: &[f32], max_leaves: usize) -> Vec<u32> {
    const RUNS: usize = 10;
    let index = GainIndex::new(c, area);
    // The over-budget cover with the fewest spheres, for when the budget is met only past a
    // cliff (see the end).
    let smallest_over: std::cell::RefCell<Option<Vec<u32>>> = Default::default();
    let run = |lambda: f64| {
        let mut chosen = greedy(c, &index, lambda);
        prune(c, &mut chosen, area.len());
        if chosen.len() > max_leaves {
            let mut over = smallest_over.borrow_mut();
            if over.as_ref().is_none_or(|o| chosen.len() < o.len()) {
                *over = Some(chosen.clone());
            }
        }
        chosen
    };
    let target = max_leaves as f64 * 0.985;
    // (λ, size) of the tightest infeasible and feasible runs.
    let mut over: (f64, f64) = (0.0, f64::INFINITY);
    let mut lambda = match predicted_lambda(c, &index, target) {
        Some(lambda) => lambda,
        None => {
            let first = run(0.0);
            if first.len() <= max_leaves {
                return first;
            }
            over.1 = first.len() as f64;
            let mean_cost =
                first.iter().map(|&k| c.list[k as usize].cost).sum::<f64>() / first.len() as f64;
            (mean_cost * (first.len() as f64 / target).powf(1.6)).max(1e-12)
        }
    };
    let scale = lambda;
    let mut under: Option<(f64, f64)> = None;
    let mut best: Vec<u32> = Vec::new();
    for _ in 0..RUNS {
        let chosen = run(lambda);
        let n = chosen.len() as f64;
        if chosen.len() <= max_leaves {
            if under.is_none_or(|u| lambda < u.0) {
                under = Some((lambda, n));
            }
            if chosen.len() > best.len() {
                best = chosen;
            }
            if best.len() as f64 >= 0.95 * max_leaves as f64 {
                break;
            }
            if over.1.is_infinite() {
                // Nothing was over the budget yet: λ = 0 may fit, and then its cover is the
                // largest.
                let zero = run(0.0);
                if zero.len() <= max_leaves {
                    return zero;
                }
                over = (0.0, zero.len() as f64);
            }
        } else if lambda > over.0 {
            over = (lambda, n);
        }
        lambda = match under {
            Some(u) if over.0 > 0.0 => {
                let t = (over.1.ln() - target.ln()) / (over.1.ln() - u.1.ln()).max(1e-9);
                (over.0.ln() + t.clamp(0.05, 0.95) * (u.0.ln() - over.0.ln())).exp()
            }
            Some(u) => u.0 * (u.1 / target).powf(2.0),
            None => over.0 * (over.1 / target).powf(2.0),
        };
    }
    if best.is_empty() {
        // The budget was never met: raise λ until it is, then bisect back towards the largest λ
        // that was over budget, keeping the largest cover that fits.
        let mut lo = over.0.max(scale).max(1e-12);
        let mut hi = lo;
        loop {
            hi *= 4.0;
            let chosen = run(hi);
            if chosen.len() <= max_leaves {
                best = chosen;
                break;
            }
            lo = hi;
        }
        for _ in 0..RUNS {
            let mid = (lo * hi).sqrt();
            let chosen = run(mid);
            if chosen.len() <= max_leaves {
                hi = mid;
                if chosen.len() > best.len() {
                    best = chosen;
                }
            } else {
                lo = mid;
            }
        }
    }
    // A cliff: where medial balls cover the surface poorly, the cover can jump from over the
    // budget straight to the one sphere around everything as λ grows. Then the smallest cover
    // over the budget is kept instead, if it is within twice the budget: the builder drops the
    // spheres holding the least surface down to the budget and the exact cover gives their
    // surface to the others.
    if max_leaves >= 64
        && best.len() * 4 < max_leaves
        && let Some(over) = smallest_over.into_inner()
        && over.len() <= 2 * max_leaves
    {
        return over;
    }
    best
}

/// Overlap of a greedy cover at the λ that fits: its size times the mean weight of each medial
/// ball's best candidate at that λ, over the surface weight. Measured on the `normal` teeth at
/// depth 4 as 2.55–2.83.
pub(super) const COVER_OVERLAP: f64 = 2.7;

/// The λ whose cover is predicted to have `target` spheres, or None when a tiny λ is predicted to
/// fit (then λ = 0 may). Each medial ball's candidates are scored alone, without the greedy's
/// interplay: at λ the ball's best candidate has the most weight per (cost + λ), and the cover is
/// predicted to need [`COVER_OVERLAP`] × (surface weight) / (mean weight of the best candidates)
/// spheres, which falls as λ grows. Solved by bisection on log λ.
pub(super) fn predicted_lambda(c: &Candidates, index: &GainIndex, target: f64) -> Option<f64> {
    const STEPS: usize = 14;
    // Candidate weights: prefix sums of each group's increments.
    let mut weight = Vec::with_capacity(c.list.len());
    for &(first, end) in &index.groups {
        let mut sum = 0.0;
        for k in first..end {
            sum += index.increment[k as usize] as f64;
            weight.push(sum);
        }
    }
    let groups = &index.groups;
    if groups.is_empty() {
        return None;
    }
    let total: f64 = index.weight.iter().map(|&w| w as f64).sum();
    let needed = COVER_OVERLAP * total / target;
    let mean_best = |lambda: f64| {
        groups
            .iter()
            .map(|&(a, b)| {
                let mut best = (0.0f64, f64::NEG_INFINITY);
                for k in a as usize..b as usize {
                    let score = weight[k] / (c.list[k].cost + lambda).max(1e-300);
                    if score > best.1 {
                        best = (weight[k], score);
                    }
                }
                best.0
            })
            .sum::<f64>()
            / groups.len() as f64
    };
    let costs = c.list.iter().map(|x| x.cost).filter(|&x| x > 0.0);
    let (lo_cost, hi_cost) = costs.fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
    if !(lo_cost.is_finite() && hi_cost > 0.0) {
        return None;
    }
    let (mut lo, mut hi) = ((lo_cost * 1e-3).ln(), (hi_cost * 1e3).ln());
    if mean_best(lo.exp()) >= needed || mean_best(hi.exp()) < needed {
        return None;
    }
    for _ in 0..STEPS {
        let mid = 0.5 * (lo + hi);
        if mean_best(mid.exp()) >= needed {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi.exp())
}

/// Drops chosen spheres whose pieces are all covered by others, costliest first.
pub(super) fn prune(c: &Candidates, chosen: &mut Vec<u32>, pieces: usize) {
    let members = |k: u32| {
        let x = &c.list[k as usize];
        &c.pool[x.first as usize..(x.first + x.len) as usize]
    };
    let mut count = vec![0u32; pieces];
    for &k in chosen.iter() {
        for &i in members(k) {
            count[i as usize] += 1;
        }
    }
    let mut order = chosen.clone();
    order.sort_by(|&a, &b| {
        c.list[b as usize]
            .cost
            .total_cmp(&c.list[a as usize].cost)
            .then(a.cmp(&b))
    });
    let mut dropped = Vec::new();
    for k in order {
        if members(k).iter().all(|&i| count[i as usize] >= 2) {
            for &i in members(k) {
                count[i as usize] -= 1;
            }
            dropped.push(k);
        }
    }
    chosen.retain(|k| !dropped.contains(k));
}
