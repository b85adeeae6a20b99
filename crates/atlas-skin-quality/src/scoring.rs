//! Scoring a candidate against the baselines, character by character and in aggregate: the
//! aggregate row of `bench/BASELINES.md`, the better of the baselines per character, and
//! the goal lines of issue 13.

use crate::bench_baselines::{BaselineTable, CharacterBaselines, Figures};
use crate::stats::{average, median};
use serde::{Deserialize, Serialize};

/// A character is "far worse" when its mean or max deformation error exceeds its better
/// baseline's by more than this factor (issue 13: "by more than 50%").
pub const FAR_WORSE_RATIO: f64 = 1.5;

/// One character as scored: its baseline row and the candidate's figures (`None`: the
/// candidate failed on it).
#[derive(Debug, Clone, Copy)]
pub struct Pair<'a> {
    pub baselines: &'a CharacterBaselines,
    pub ours: Option<Figures>,
}

/// The aggregate row of BASELINES.md over a set of characters, for one tool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Aggregate {
    pub scored: usize,
    pub failed: usize,
    pub deform_mean_average: Option<f64>,
    pub deform_mean_median: Option<f64>,
    pub deform_max_average: Option<f64>,
    pub deform_max_median: Option<f64>,
    pub l1_average: Option<f64>,
    /// Over the scored characters that have a bleeding figure.
    pub bleed_average: Option<f64>,
}

/// Averages and medians over the scored results (`None` = failed, counted apart).
pub fn aggregate(results: &[Option<Figures>]) -> Aggregate {
    let scored: Vec<&Figures> = results.iter().flatten().collect();
    let column = |f: fn(&Figures) -> f64| scored.iter().map(|s| f(s)).collect::<Vec<f64>>();
    let means = column(|f| f.deform_mean);
    let maxes = column(|f| f.deform_max);
    let bleeds: Vec<f64> = scored.iter().filter_map(|s| s.bleed).collect();
    Aggregate {
        scored: scored.len(),
        failed: results.len() - scored.len(),
        deform_mean_average: average(&means),
        deform_mean_median: median(&means),
        deform_max_average: average(&maxes),
        deform_max_median: median(&maxes),
        l1_average: average(&column(|f| f.l1_mean)),
        bleed_average: average(&bleeds),
    }
}

/// The aggregate of each baseline tool over `pairs`, in the table's tool order.
pub fn baseline_aggregates(table: &BaselineTable, pairs: &[Pair]) -> Vec<(String, Aggregate)> {
    table
        .tools
        .iter()
        .enumerate()
        .map(|(t, tool)| {
            let results: Vec<Option<Figures>> =
                pairs.iter().map(|p| p.baselines.tools[t]).collect();
            (tool.clone(), aggregate(&results))
        })
        .collect()
}

/// The lower mean and the lower max of the tools that gave a result on this character
/// (each column on its own, as BASELINES.md's "better of the two"); `None` when none did.
pub fn better_baseline(character: &CharacterBaselines) -> Option<(f64, f64)> {
    let scored: Vec<&Figures> = character.tools.iter().flatten().collect();
    (!scored.is_empty()).then(|| {
        (
            scored
                .iter()
                .map(|f| f.deform_mean)
                .fold(f64::INFINITY, f64::min),
            scored
                .iter()
                .map(|f| f.deform_max)
                .fold(f64::INFINITY, f64::min),
        )
    })
}

/// BASELINES.md's "better of the two per character, averaged over the characters where
/// both gave a result", and the candidate's average over the same characters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BetterBaseline {
    /// Characters where every baseline gave a result.
    pub characters: usize,
    pub baseline_mean: Option<f64>,
    pub baseline_max: Option<f64>,
    /// Of those, the characters the candidate scored, and its averages over them.
    pub ours_scored: usize,
    pub ours_mean: Option<f64>,
    pub ours_max: Option<f64>,
}

pub fn better_of_baselines(pairs: &[Pair]) -> BetterBaseline {
    let all_scored: Vec<&Pair> = pairs
        .iter()
        .filter(|p| p.baselines.tools.iter().all(Option::is_some))
        .collect();
    let best: Vec<(f64, f64)> = all_scored
        .iter()
        .filter_map(|p| better_baseline(p.baselines))
        .collect();
    let ours: Vec<&Figures> = all_scored.iter().filter_map(|p| p.ours.as_ref()).collect();
    BetterBaseline {
        characters: all_scored.len(),
        baseline_mean: average(&best.iter().map(|b| b.0).collect::<Vec<_>>()),
        baseline_max: average(&best.iter().map(|b| b.1).collect::<Vec<_>>()),
        ours_scored: ours.len(),
        ours_mean: average(&ours.iter().map(|f| f.deform_mean).collect::<Vec<_>>()),
        ours_max: average(&ours.iter().map(|f| f.deform_max).collect::<Vec<_>>()),
    }
}

/// A character whose error exceeds its better baseline's by more than [`FAR_WORSE_RATIO`],
/// or where the candidate failed (ratios `None`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FarWorse {
    pub name: String,
    /// Ours over the better baseline's, mean and max.
    pub mean_ratio: Option<f64>,
    pub max_ratio: Option<f64>,
}

/// How a candidate compares with one tool over the characters that tool scored; a
/// character where the candidate failed counts as a loss.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Wins {
    pub tool: String,
    pub characters: usize,
    pub mean: usize,
    pub max: usize,
}

/// The goal lines of issue 13 over the characters that have a baseline result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Goals {
    /// Characters where some baseline gave a result (the denominator of the shares).
    pub characters: usize,
    /// Characters whose mean is lower than every baseline's that gave a result.
    pub lower_mean_than_all: usize,
    pub lower_max_than_all: usize,
    pub far_worse: Vec<FarWorse>,
    pub wins: Vec<Wins>,
}

pub fn goals(table: &BaselineTable, pairs: &[Pair]) -> Goals {
    let mut goals = Goals {
        characters: 0,
        lower_mean_than_all: 0,
        lower_max_than_all: 0,
        far_worse: Vec::new(),
        wins: Vec::new(),
    };
    for pair in pairs {
        let Some((best_mean, best_max)) = better_baseline(pair.baselines) else {
            continue;
        };
        goals.characters += 1;
        let name = pair.baselines.name.clone();
        let Some(ours) = pair.ours else {
            goals.far_worse.push(FarWorse {
                name,
                mean_ratio: None,
                max_ratio: None,
            });
            continue;
        };
        goals.lower_mean_than_all += usize::from(ours.deform_mean < best_mean);
        goals.lower_max_than_all += usize::from(ours.deform_max < best_max);
        let (mean_ratio, max_ratio) = (ours.deform_mean / best_mean, ours.deform_max / best_max);
        if mean_ratio > FAR_WORSE_RATIO || max_ratio > FAR_WORSE_RATIO {
            goals.far_worse.push(FarWorse {
                name,
                mean_ratio: Some(mean_ratio),
                max_ratio: Some(max_ratio),
            });
        }
    }
    goals.wins = table
        .tools
        .iter()
        .enumerate()
        .map(|(t, tool)| {
            let mut wins = Wins {
                tool: tool.clone(),
                characters: 0,
                mean: 0,
                max: 0,
            };
            for pair in pairs {
                let Some(theirs) = pair.baselines.tools[t] else {
                    continue;
                };
                wins.characters += 1;
                if let Some(ours) = pair.ours {
                    wins.mean += usize::from(ours.deform_mean < theirs.deform_mean);
                    wins.max += usize::from(ours.deform_max < theirs.deform_max);
                }
            }
            wins
        })
        .collect();
    goals
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_baselines::{parse_bench_baselines, tests::SAMPLE};

    fn figures(deform_mean: f64, deform_max: f64) -> Figures {
        Figures {
            deform_mean,
            deform_max,
            l1_mean: 0.5,
            bleed: Some(0.1),
        }
    }

    fn close(a: Option<f64>, b: f64) -> bool {
        a.is_some_and(|a| (a - b).abs() < 1e-12)
    }

    #[test]
    fn aggregates_count_failures_apart() {
        let a = aggregate(&[
            Some(figures(0.01, 0.1)),
            None,
            Some(figures(0.03, 0.5)),
            Some(Figures {
                bleed: None,
                ..figures(0.02, 0.2)
            }),
        ]);
        assert_eq!((a.scored, a.failed), (3, 1));
        assert!(close(a.deform_mean_average, 0.02));
        assert!(close(a.deform_mean_median, 0.02));
        assert!(close(a.deform_max_average, 0.8 / 3.0));
        assert!(close(a.deform_max_median, 0.2));
        assert!(close(a.l1_average, 0.5));
        assert!(close(a.bleed_average, 0.1));
        let empty = aggregate(&[None]);
        assert_eq!(
            (empty.scored, empty.failed, empty.deform_mean_median),
            (0, 1, None)
        );
    }

    #[test]
    fn better_baseline_goals_and_wins() {
        let table = parse_bench_baselines(SAMPLE).unwrap();
        // 1.glb: heat .0093/.118, euclid .0176/.267 → better .0093/.118.
        // 2.glb: heat failed, euclid .0163/.120 → better .0163/.120.
        // Knight: heat .0178/.554, euclid .0161/.212 → better .0161/.212.
        let ours = [
            Some(figures(0.0090, 0.200)), // lower mean than both; max 1.69× → far worse
            None,                         // failed: a loss everywhere, listed as far worse
            Some(figures(0.0170, 0.100)), // mean between the two; lowest max
        ];
        let pairs: Vec<Pair> = table
            .characters
            .iter()
            .zip(ours)
            .map(|(baselines, ours)| Pair { baselines, ours })
            .collect();

        let better = better_of_baselines(&pairs);
        assert_eq!((better.characters, better.ours_scored), (2, 2));
        assert!(close(better.baseline_mean, (0.0093 + 0.0161) / 2.0));
        assert!(close(better.baseline_max, (0.118 + 0.212) / 2.0));
        assert!(close(better.ours_mean, (0.0090 + 0.0170) / 2.0));
        assert!(close(better.ours_max, 0.15));

        let g = goals(&table, &pairs);
        assert_eq!(
            (g.characters, g.lower_mean_than_all, g.lower_max_than_all),
            (3, 1, 1)
        );
        let names: Vec<&str> = g.far_worse.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["rignet-val/1.glb", "rignet-val/2.glb"]);
        assert!(close(g.far_worse[0].max_ratio, 0.2 / 0.118));
        assert_eq!(g.far_worse[1].mean_ratio, None);
        let wins: Vec<(&str, usize, usize, usize)> = g
            .wins
            .iter()
            .map(|w| (w.tool.as_str(), w.characters, w.mean, w.max))
            .collect();
        assert_eq!(wins, [("heat", 2, 2, 1), ("euclid", 3, 1, 2)]);

        let aggregates = baseline_aggregates(&table, &pairs);
        assert_eq!(aggregates[0].0, "heat");
        assert_eq!((aggregates[0].1.scored, aggregates[0].1.failed), (2, 1));
        assert!(close(aggregates[1].1.deform_mean_median, 0.0163));
    }

    /// Recomputing BASELINES.md's aggregate lines from its per-character rows gives the
    /// file's own figures: the parser and the aggregation agree with whoever wrote it.
    #[test]
    fn the_real_bench_file_reproduces_its_aggregates() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/bench/BASELINES.md"
        );
        let text = std::fs::read_to_string(path)
            .expect("the benchmark characters are missing: ../shared/data/bench");
        let table = parse_bench_baselines(&text).unwrap();
        assert_eq!(table.tools, ["heat", "euclid"]);
        assert_eq!(table.characters.len(), 64);
        let pairs: Vec<Pair> = table
            .characters
            .iter()
            .map(|baselines| Pair {
                baselines,
                ours: None,
            })
            .collect();
        let rows: Vec<String> = baseline_aggregates(&table, &pairs)
            .iter()
            .map(|(tool, a)| {
                format!(
                    "| {tool} | {} | {} | {:.4} / {:.4} | {:.3} / {:.3} | {:.3} | {:.3} |",
                    a.scored,
                    a.failed,
                    a.deform_mean_average.unwrap(),
                    a.deform_mean_median.unwrap(),
                    a.deform_max_average.unwrap(),
                    a.deform_max_median.unwrap(),
                    a.l1_average.unwrap(),
                    a.bleed_average.unwrap()
                )
            })
            .collect();
        for row in &rows {
            assert!(text.contains(row.as_str()), "{row} is not in BASELINES.md");
        }
        let better = better_of_baselines(&pairs);
        let line = format!(
            "averaged over the {} characters where both gave a result: deform mean {:.4}, max {:.3}.",
            better.characters,
            better.baseline_mean.unwrap(),
            better.baseline_max.unwrap()
        );
        assert!(text.contains(&line), "{line} is not in BASELINES.md");
    }
}
