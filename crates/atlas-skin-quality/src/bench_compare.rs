//! `--compare OLD.json`: what changed between two benchmark runs, character by character
//! (which got better or worse on mean and max) and in aggregate, scored against the same
//! baseline tables.

use crate::bench_baselines::{BaselineTable, Figures};
use crate::bench_characters::Set;
use crate::bench_page::{change, opt, percent};
use crate::bench_run::BenchmarkRun;
use crate::scoring::{aggregate, better_of_baselines, goals};
use crate::stats::average;
use std::fmt::Write;

/// Relative changes smaller than this are "unchanged" (JSON round trips and summation
/// order; the pipeline and the poses are deterministic).
pub const UNCHANGED: f64 = 1e-6;

/// How one figure moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    Better,
    Worse,
    Unchanged,
}

pub fn direction(old: f64, new: f64) -> Direction {
    if (new - old).abs() <= UNCHANGED * old.abs().max(new.abs()) {
        Direction::Unchanged
    } else if new < old {
        Direction::Better
    } else {
        Direction::Worse
    }
}

/// One character in both runs.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterChange {
    pub name: String,
    /// `None` where that run failed on it.
    pub old: Option<Figures>,
    pub new: Option<Figures>,
}

impl CharacterChange {
    /// Mean and max directions, when both runs scored it.
    pub fn directions(&self) -> Option<(Direction, Direction)> {
        let (old, new) = (self.old?, self.new?);
        Some((
            direction(old.deform_mean, new.deform_mean),
            direction(old.deform_max, new.deform_max),
        ))
    }

    /// The larger relative worsening of mean and max (negative: both improved), for sorting.
    fn worst_change(&self) -> f64 {
        match (self.old, self.new) {
            (Some(o), Some(n)) => {
                (n.deform_mean / o.deform_mean).max(n.deform_max / o.deform_max) - 1.0
            }
            _ => 0.0,
        }
    }
}

/// The characters of `set` that both runs have, in the new run's order.
pub fn character_changes(old: &BenchmarkRun, new: &BenchmarkRun, set: Set) -> Vec<CharacterChange> {
    new.of(set)
        .into_iter()
        .filter_map(|n| {
            let o = old.find(set, &n.name)?;
            Some(CharacterChange {
                name: n.name.clone(),
                old: o.figures(),
                new: n.figures(),
            })
        })
        .collect()
}

/// The printed comparison of both sets.
pub fn render(
    old: &BenchmarkRun,
    new: &BenchmarkRun,
    tables: &[(Set, &BaselineTable)],
    old_name: &str,
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Compared with {old_name} (commit {}) → this run (commit {}):",
        old.commit, new.commit
    );
    if !old.settings.same_main_poses(&new.settings) {
        let seeds = |s: &crate::bench_run::Settings| {
            format!("{} poses from seed {}", s.poses, s.first_seed)
        };
        let _ = writeln!(
            out,
            "(the runs' eval settings differ: {} → {}; the changes below mix the weights' and \
             the poses')",
            seeds(&old.settings),
            seeds(&new.settings)
        );
    }
    for &(set, table) in tables {
        let changes = character_changes(old, new, set);
        if changes.is_empty() {
            continue;
        }
        let _ = writeln!(
            out,
            "\n{}:",
            match set {
                Set::Bench => "bench",
                Set::Train => "rignet-train",
                Set::Check => "rignet-check",
                Set::Models => "models (clean corpus)",
            }
        );
        aggregate_lines(&mut out, old, new, set, table);
        character_lines(&mut out, &changes);
        for (run, word) in [(old, "only in the old run"), (new, "only in this run")] {
            let other = if std::ptr::eq(run, old) { new } else { old };
            let only: Vec<&str> = run
                .of(set)
                .iter()
                .filter(|c| other.find(set, &c.name).is_none())
                .map(|c| c.name.as_str())
                .collect();
            if !only.is_empty() {
                let _ = writeln!(out, "  {word}: {}", only.join(", "));
            }
        }
    }
    out
}

fn aggregate_lines(
    out: &mut String,
    old: &BenchmarkRun,
    new: &BenchmarkRun,
    set: Set,
    table: &BaselineTable,
) {
    let (old_pairs, new_pairs) = (old.pairs(set, table), new.pairs(set, table));
    let figures = |pairs: &[crate::scoring::Pair]| -> Vec<Option<Figures>> {
        pairs.iter().map(|p| p.ours).collect()
    };
    let (a, b) = (
        aggregate(&figures(&old_pairs)),
        aggregate(&figures(&new_pairs)),
    );
    let line = |out: &mut String, label: &str, x: Option<f64>, y: Option<f64>, d: usize| {
        let _ = writeln!(
            out,
            "  {label:<34} {} → {} ({})",
            opt(x, d),
            opt(y, d),
            change(x, y)
        );
    };
    let _ = writeln!(
        out,
        "  characters with baselines: scored {} → {}, failed {} → {}",
        a.scored, b.scored, a.failed, b.failed
    );
    line(
        out,
        "deform mean average",
        a.deform_mean_average,
        b.deform_mean_average,
        4,
    );
    line(
        out,
        "deform mean median",
        a.deform_mean_median,
        b.deform_mean_median,
        4,
    );
    line(
        out,
        "deform max average",
        a.deform_max_average,
        b.deform_max_average,
        3,
    );
    line(
        out,
        "deform max median",
        a.deform_max_median,
        b.deform_max_median,
        3,
    );
    line(out, "L1 average", a.l1_average, b.l1_average, 3);
    line(out, "bleed average", a.bleed_average, b.bleed_average, 3);
    let (x, y) = (
        better_of_baselines(&old_pairs),
        better_of_baselines(&new_pairs),
    );
    if y.characters > 0 {
        let _ = writeln!(
            out,
            "  on the {} characters every baseline scored (better baselines {} / {}): mean {} → \
             {}, max {} → {}",
            y.characters,
            opt(y.baseline_mean, 4),
            opt(y.baseline_max, 3),
            opt(x.ours_mean, 4),
            opt(y.ours_mean, 4),
            opt(x.ours_max, 3),
            opt(y.ours_max, 3)
        );
    }
    let (g, h) = (goals(table, &old_pairs), goals(table, &new_pairs));
    let _ = writeln!(
        out,
        "  mean lower than every baseline: {} → {} of {}; max: {} → {}; far worse than the \
         better baseline: {} → {}",
        g.lower_mean_than_all,
        h.lower_mean_than_all,
        h.characters,
        g.lower_max_than_all,
        h.lower_max_than_all,
        g.far_worse.len(),
        h.far_worse.len()
    );
    for &seed in &new.settings.other_seeds {
        if !old.settings.other_seeds.contains(&seed) {
            continue;
        }
        let (g, h) = (
            goals(table, &old.pairs_under(seed, set, table)),
            goals(table, &new.pairs_under(seed, set, table)),
        );
        let _ = writeln!(
            out,
            "    under the poses from seed {seed}: mean lower {} → {}; max lower {} → {}; far \
             worse {} → {}",
            g.lower_mean_than_all,
            h.lower_mean_than_all,
            g.lower_max_than_all,
            h.lower_max_than_all,
            g.far_worse.len(),
            h.far_worse.len()
        );
    }
    let fallback = |run: &BenchmarkRun| {
        let shares: Vec<f64> = run
            .of(set)
            .iter()
            .filter_map(|c| Some(c.scored()?.skin.fallback_share()))
            .collect();
        average(&shares).map_or_else(|| "—".to_string(), percent)
    };
    let _ = writeln!(
        out,
        "  fallback vertices, average share: {} → {}",
        fallback(old),
        fallback(new)
    );
}

fn character_lines(out: &mut String, changes: &[CharacterChange]) {
    let count = |pick: fn((Direction, Direction)) -> Direction, d: Direction| {
        changes
            .iter()
            .filter_map(CharacterChange::directions)
            .filter(|&ds| pick(ds) == d)
            .count()
    };
    for (label, pick) in [
        ("mean", (|d: (Direction, Direction)| d.0) as fn(_) -> _),
        ("max", |d: (Direction, Direction)| d.1),
    ] {
        let _ = writeln!(
            out,
            "  {label}: {} better, {} worse, {} unchanged",
            count(pick, Direction::Better),
            count(pick, Direction::Worse),
            count(pick, Direction::Unchanged)
        );
    }
    let mut moved: Vec<&CharacterChange> = changes
        .iter()
        .filter(|c| {
            c.directions()
                .is_some_and(|d| d != (Direction::Unchanged, Direction::Unchanged))
        })
        .collect();
    moved.sort_by(|a, b| b.worst_change().total_cmp(&a.worst_change()));
    let (worse, better): (Vec<&CharacterChange>, Vec<&CharacterChange>) =
        moved.into_iter().partition(|c| {
            c.directions()
                .is_some_and(|(m, x)| m == Direction::Worse || x == Direction::Worse)
        });
    for (title, list) in [
        ("worse (mean or max), worst first", worse),
        ("better", better),
    ] {
        if list.is_empty() {
            continue;
        }
        let _ = writeln!(out, "  {title}:");
        for c in list {
            let (Some(o), Some(n)) = (c.old, c.new) else {
                continue;
            };
            let _ = writeln!(
                out,
                "    {:<38} mean {:.4} → {:.4} ({:>7})  max {:.3} → {:.3} ({:>7})",
                c.name,
                o.deform_mean,
                n.deform_mean,
                change(Some(o.deform_mean), Some(n.deform_mean)),
                o.deform_max,
                n.deform_max,
                change(Some(o.deform_max), Some(n.deform_max))
            );
        }
    }
    for (label, pick) in [
        (
            "now failing",
            (|c: &CharacterChange| c.old.is_some() && c.new.is_none()) as fn(&_) -> bool,
        ),
        ("failing before, scored now", |c: &CharacterChange| {
            c.old.is_none() && c.new.is_some()
        }),
    ] {
        let names: Vec<&str> = changes
            .iter()
            .filter(|c| pick(c))
            .map(|c| c.name.as_str())
            .collect();
        if !names.is_empty() {
            let _ = writeln!(out, "  {label}: {}", names.join(", "));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_baselines::{parse_bench_baselines, tests::SAMPLE};
    use crate::bench_run::tests::{failed, run, scored};

    #[test]
    fn directions_allow_for_round_trips() {
        assert_eq!(direction(0.01, 0.009), Direction::Better);
        assert_eq!(direction(0.01, 0.011), Direction::Worse);
        assert_eq!(direction(0.01, 0.01 * (1.0 + 1e-9)), Direction::Unchanged);
    }

    #[test]
    fn better_worse_fixed_and_aggregates_are_listed() {
        let table = parse_bench_baselines(SAMPLE).unwrap();
        let old = run(
            "old1",
            vec![
                scored("rignet-val/1.glb", 0.0090, 0.200, 10),
                failed("rignet-val/2.glb"),
                scored("kaykit/Knight.glb", 0.0170, 0.100, 0),
                scored("gone.glb", 0.01, 0.1, 0),
            ],
        );
        let new = run(
            "new2",
            vec![
                scored("rignet-val/1.glb", 0.0080, 0.250, 0),
                scored("rignet-val/2.glb", 0.0100, 0.100, 0),
                scored("kaykit/Knight.glb", 0.0170, 0.100, 0),
            ],
        );
        let changes = character_changes(&old, &new, Set::Bench);
        assert_eq!(changes.len(), 3);
        assert_eq!(
            changes[0].directions(),
            Some((Direction::Better, Direction::Worse))
        );
        assert_eq!(changes[1].directions(), None);
        let text = render(&old, &new, &[(Set::Bench, &table)], "before.json");
        for expected in [
            "Compared with before.json (commit old1) → this run (commit new2):",
            "characters with baselines: scored 2 → 3, failed 1 → 0",
            "deform mean average                0.0130 → 0.0117 (−10.3%)",
            "deform max average                 0.150 → 0.150 (±0.0%)",
            "mean lower than every baseline: 1 → 2 of 3; max: 1 → 2; far worse than the better \
             baseline: 2 → 1",
            "fallback vertices, average share: 3.3% → 0.0%",
            "under the poses from seed 10: mean lower 1 → 2; max lower 1 → 2; far worse 2 → 1",
            "under the poses from seed 40: mean lower 1 → 2; max lower 1 → 2; far worse 2 → 1",
            "mean: 1 better, 0 worse, 1 unchanged",
            "max: 0 better, 1 worse, 1 unchanged",
            "worse (mean or max), worst first:\n    rignet-val/1.glb",
            "mean 0.0090 → 0.0080 ( −11.1%)  max 0.200 → 0.250 ( +25.0%)",
            "failing before, scored now: rignet-val/2.glb",
            "only in the old run: gone.glb",
        ] {
            assert!(text.contains(expected), "missing: {expected}\n\n{text}");
        }
        assert!(!text.contains("now failing"));
        assert!(!text.contains("settings differ"));
        // A run written before the other pose sets: the main figures compare, the others
        // are left out.
        let mut older = old.clone();
        older.settings.other_seeds.clear();
        let text = render(&older, &new, &[(Set::Bench, &table)], "before.json");
        assert!(!text.contains("settings differ"), "{text}");
        assert!(!text.contains("under the poses from seed"), "{text}");
        // Another seed is said.
        let mut reseeded = new.clone();
        reseeded.settings = crate::bench_run::Settings::of_eval_from(10, &[]);
        let text = render(&old, &reseeded, &[(Set::Bench, &table)], "before.json");
        assert!(
            text.contains(
                "the runs' eval settings differ: 10 poses from seed 0 → 10 poses from seed 10"
            ),
            "{text}"
        );
    }
}
