//! Rigid bindings judged both ways (issue 42, item 6): a character skinned by `atlas-skin
//! skin` with the default (smooth) binding and with `--binding rigid`, each file judged by
//! `atlas-skin eval --json` against the artist weights of the character's own file, and
//! the share of its vertices bound to exactly one joint with weight 1. The `rigid-binding`
//! tool prints the table of the rigidly bound characters ([`table`]); the benchmark can
//! judge any character both ways with [`judge_both_ways`].

use crate::bench_characters::Character;
use crate::run::{run_eval, run_skin};
use anyhow::{Context, Result};
use atlas_skin_runtime::VertexWeights;
use serde::Serialize;
use std::ffi::OsString;
use std::path::Path;

/// One skinned file against the artist weights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Judged {
    /// `eval`'s deformation error under its random poses (LBS): mean and max over vertices.
    pub deform_mean: f64,
    pub deform_max: f64,
    /// `eval`'s mean weight L1 per vertex.
    pub l1: f64,
    /// Share of the file's vertices bound to exactly one joint with weight 1
    /// ([`one_joint_share`]).
    pub one_joint: f64,
}

/// A character judged both ways.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BothWays {
    /// As [`Character::name`]: `rignet-train/10021.glb`.
    pub name: String,
    pub vertices: usize,
    pub smooth: Judged,
    pub rigid: Judged,
}

impl BothWays {
    /// Whether the rigid binding deforms closer to the artist's than the smooth one.
    pub fn rigid_better(&self) -> bool {
        self.rigid.deform_mean < self.smooth.deform_mean
    }
}

/// The binding flags of each way, as `atlas-skin skin` takes them.
const WAYS: [(&str, &[&str]); 2] = [("smooth", &[]), ("rigid", &["--binding", "rigid"])];

/// Skins `character` both ways with the `atlas-skin` binary `exe` (files under `work`, one
/// folder per character) and judges each file against the artist weights.
pub fn judge_both_ways(exe: &Path, character: &Character, work: &Path) -> Result<BothWays> {
    let folder = work.join(character.name.replace('/', "-"));
    std::fs::create_dir_all(&folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    let mut judged = Vec::with_capacity(WAYS.len());
    let mut vertices = 0;
    for (way, flags) in WAYS {
        let candidate = folder.join(format!("{way}.glb"));
        let mut args = character.skin_args.clone();
        args.extend(flags.iter().map(OsString::from));
        let run = run_skin(exe, &args, &candidate, &folder.join(format!("{way}.json")))?;
        let binding = run.report["binding"].as_str();
        anyhow::ensure!(
            binding == Some(way),
            "{}: the report says binding {binding:?}, expected {way:?}",
            character.name
        );
        vertices = run.report["counts"]["vertices"].as_u64().unwrap_or(0) as usize;
        let evaluation = run_eval(
            exe,
            &character.reference_args,
            &candidate,
            character.prune_reference,
            0,
            0,
            false,
        )?;
        let ours = atlas_skin_io::load_character(&candidate, &Default::default())
            .with_context(|| format!("cannot read {}", candidate.display()))?;
        let weights = ours
            .reference_weights
            .with_context(|| format!("{} has no weights", candidate.display()))?;
        judged.push(Judged {
            deform_mean: evaluation.deform_random.mean,
            deform_max: evaluation.deform_random.max,
            l1: evaluation.weights_l1.mean,
            one_joint: one_joint_share(&weights),
        });
    }
    Ok(BothWays {
        name: character.name.clone(),
        vertices,
        smooth: judged[0],
        rigid: judged[1],
    })
}

/// Share of the rows of `weights` with exactly one positive weight, equal to 1 (0 without
/// rows).
pub fn one_joint_share(weights: &VertexWeights) -> f64 {
    let rows = weights.vertex_count();
    let single = (0..rows)
        .filter(|&v| {
            let mut positive = weights.row(v).filter(|&(_, w)| w > 0.0);
            matches!((positive.next(), positive.next()), (Some((_, w)), None) if w == 1.0)
        })
        .count();
    if rows == 0 {
        0.0
    } else {
        single as f64 / rows as f64
    }
}

/// What the table sums up: how many characters, on how many the rigid binding deforms
/// closer to the artist's, on how many every vertex has one joint, and the mean of each
/// figure over the characters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    pub characters: usize,
    pub rigid_better: usize,
    pub rigid_all_one_joint: usize,
    pub smooth: Judged,
    pub rigid: Judged,
}

/// The [`Summary`] of `results` (`None` when empty).
pub fn summarize(results: &[BothWays]) -> Option<Summary> {
    if results.is_empty() {
        return None;
    }
    let n = results.len() as f64;
    let mean = |way: fn(&BothWays) -> Judged| {
        let sum = |f: fn(&Judged) -> f64| results.iter().map(|r| f(&way(r))).sum::<f64>() / n;
        Judged {
            deform_mean: sum(|j| j.deform_mean),
            deform_max: sum(|j| j.deform_max),
            l1: sum(|j| j.l1),
            one_joint: sum(|j| j.one_joint),
        }
    };
    Some(Summary {
        characters: results.len(),
        rigid_better: results.iter().filter(|r| r.rigid_better()).count(),
        rigid_all_one_joint: results.iter().filter(|r| r.rigid.one_joint == 1.0).count(),
        smooth: mean(|r| r.smooth),
        rigid: mean(|r| r.rigid),
    })
}

/// The figures of both ways side by side, `smooth → rigid`: deform mean, deform max, L1,
/// one-joint share.
fn side_by_side(smooth: &Judged, rigid: &Judged) -> [String; 4] {
    [
        format!("{:.4} → {:.4}", smooth.deform_mean, rigid.deform_mean),
        format!("{:.4} → {:.4}", smooth.deform_max, rigid.deform_max),
        format!("{:.3} → {:.3}", smooth.l1, rigid.l1),
        format!(
            "{:.1}% → {:.1}%",
            100.0 * smooth.one_joint,
            100.0 * rigid.one_joint
        ),
    ]
}

/// The markdown table of `results` under `title`: one row per character (deform mean and
/// max, L1, one-joint share, smooth → rigid), then the summary line.
pub fn table(title: &str, results: &[BothWays]) -> String {
    let mut out = format!(
        "### {title}\n\n| character | vertices | deform mean smooth → rigid | ratio | deform max \
         smooth → rigid | L1 smooth → rigid | one joint smooth → rigid |\n| --- | --- | --- | \
         --- | --- | --- | --- |\n"
    );
    for r in results {
        let [mean, max, l1, one_joint] = side_by_side(&r.smooth, &r.rigid);
        let ratio = r.rigid.deform_mean / r.smooth.deform_mean;
        out += &format!(
            "| {} | {} | {mean} | {ratio:.2} | {max} | {l1} | {one_joint} |\n",
            r.name, r.vertices
        );
    }
    if let Some(s) = summarize(results) {
        let [mean, max, l1, one_joint] = side_by_side(&s.smooth, &s.rigid);
        out += &format!(
            "\n{title}: {} characters; rigid deform mean below smooth on {} ({:.1}%); every \
             vertex on one joint with weight 1 in {} rigid files; averages smooth → rigid: \
             deform mean {mean}, max {max}, L1 {l1}, one joint {one_joint}\n",
            s.characters,
            s.rigid_better,
            100.0 * s.rigid_better as f64 / s.characters as f64,
            s.rigid_all_one_joint,
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn judged(deform_mean: f64, one_joint: f64) -> Judged {
        Judged {
            deform_mean,
            deform_max: 2.0 * deform_mean,
            l1: 0.5,
            one_joint,
        }
    }

    #[test]
    fn rows_with_one_joint_of_weight_one_are_counted() {
        let weights = VertexWeights::from_rows([
            vec![(0, 1.0)],
            // Padded as the glTF writer pads.
            vec![(2, 1.0), (0, 0.0), (0, 0.0), (0, 0.0)],
            vec![(0, 0.5), (1, 0.5)],
            vec![(2, 0.9995), (1, 0.0005)],
            vec![],
        ]);
        assert_eq!(one_joint_share(&weights), 0.4);
        assert_eq!(
            one_joint_share(&VertexWeights::from_rows(Vec::<Vec<(u32, f32)>>::new())),
            0.0
        );
    }

    #[test]
    fn the_summary_counts_the_characters_the_rigid_binding_improves() {
        let results = [
            BothWays {
                name: "a".into(),
                vertices: 10,
                smooth: judged(0.02, 0.5),
                rigid: judged(0.01, 1.0),
            },
            BothWays {
                name: "b".into(),
                vertices: 10,
                smooth: judged(0.01, 0.7),
                rigid: judged(0.03, 0.99),
            },
        ];
        let s = summarize(&results).unwrap();
        assert_eq!(
            (s.characters, s.rigid_better, s.rigid_all_one_joint),
            (2, 1, 1)
        );
        assert!((s.rigid.deform_mean - 0.02).abs() < 1e-12);
        assert!((s.smooth.one_joint - 0.6).abs() < 1e-12);
        assert!(summarize(&[]).is_none());
        let text = table("tune", &results);
        assert!(
            text.contains("| a | 10 | 0.0200 → 0.0100 | 0.50 |"),
            "{text}"
        );
        assert!(
            text.contains("rigid deform mean below smooth on 1 (50.0%)"),
            "{text}"
        );
    }
}
