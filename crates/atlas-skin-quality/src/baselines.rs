//! The other tools' rows of `shared/data/BASELINES.md`.

use anyhow::{bail, Result};

/// Cells of the baseline table, in order: model, verts, joints, tool, time s, L1 mean,
/// L1 p95, dom., deform mean, deform max, anim mean, anim max, bleed.
pub const COLUMNS: usize = 13;

/// One tool on one model, as BASELINES.md gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineRow {
    /// The corpus folder name (`makehuman (body)` in the file is `makehuman`).
    pub model: String,
    pub tool: String,
    /// All cells as written, for printing the row unchanged.
    pub cells: Vec<String>,
    pub deform_mean: f64,
    pub deform_max: f64,
    /// `None` where the file has no figure (`—`).
    pub bleed: Option<f64>,
}

/// Reads the rows of the markdown table whose header starts with `| model |`.
pub fn parse_baselines(text: &str) -> Result<Vec<BaselineRow>> {
    let mut rows = Vec::new();
    let mut in_table = false;
    for (index, line) in text.lines().enumerate() {
        let line = line.trim();
        if !line.starts_with('|') {
            in_table = false;
            continue;
        }
        let cells: Vec<String> = line
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_string())
            .collect();
        if cells.first().map(String::as_str) == Some("model") {
            in_table = cells.len() == COLUMNS;
            continue;
        }
        if !in_table
            || cells
                .iter()
                .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
        {
            continue;
        }
        if cells.len() != COLUMNS {
            bail!(
                "BASELINES.md line {}: {} cells, expected {COLUMNS}",
                index + 1,
                cells.len()
            );
        }
        let number = |column: usize| -> Result<Option<f64>> {
            match cells[column].as_str() {
                "—" | "-" => Ok(None),
                cell => match cell.parse() {
                    Ok(value) => Ok(Some(value)),
                    Err(_) => bail!("BASELINES.md line {}: {cell:?} is not a number", index + 1),
                },
            }
        };
        let required = |column: usize| -> Result<f64> {
            match number(column)? {
                Some(value) => Ok(value),
                None => bail!(
                    "BASELINES.md line {}: column {} is empty",
                    index + 1,
                    column + 1
                ),
            }
        };
        rows.push(BaselineRow {
            model: cells[0]
                .split_whitespace()
                .next()
                .unwrap_or_default()
                .to_string(),
            tool: cells[3].clone(),
            deform_mean: required(8)?,
            deform_max: required(9)?,
            bleed: number(12)?,
            cells,
        });
    }
    if rows.is_empty() {
        bail!("BASELINES.md has no table of tool rows");
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "intro\n\n\
| model | verts | joints | tool | time s | L1 mean | L1 p95 | dom. | deform mean | deform max | anim mean | anim max | bleed |\n\
|---|---|---|---|---|---|---|---|---|---|---|---|---|\n\
| cesiumman | 3273 | 19 | heat | 0.04 | 0.337 | 1.623 | 0.85 | 0.0042 | 0.075 | 0.0019 | 0.038 | 0.001 |\n\
| makehuman (body) | 13380 | 163 | bbw | 198 | 0.695 | 2.000 | 0.65 | 0.0054 | 0.076 | — | — | 0.014 |\n\
\nafter\n| a | b |\n";

    #[test]
    fn rows_are_read_with_their_cells() {
        let rows = parse_baselines(SAMPLE).unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(
            (rows[0].model.as_str(), rows[0].tool.as_str()),
            ("cesiumman", "heat")
        );
        assert_eq!((rows[0].deform_mean, rows[0].deform_max), (0.0042, 0.075));
        assert_eq!(rows[1].model, "makehuman");
        assert_eq!(rows[1].cells[10], "—");
        assert_eq!(rows[1].bleed, Some(0.014));
    }

    #[test]
    fn malformed_tables_are_errors() {
        assert!(parse_baselines("no table").is_err());
        let bad = SAMPLE.replace("0.0042", "fast");
        assert!(parse_baselines(&bad).is_err());
    }

    #[test]
    fn the_real_file_parses() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/BASELINES.md"
        );
        let text = std::fs::read_to_string(path).expect("the corpus is missing: ../shared/data");
        let rows = parse_baselines(&text).unwrap();
        assert_eq!(rows.len(), 15);
        assert!(rows
            .iter()
            .any(|r| r.model == "simpleskin" && r.tool == "euclid"));
    }
}
