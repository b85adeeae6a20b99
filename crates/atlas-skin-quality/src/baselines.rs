//! The other tools' rows of `shared/data/BASELINES.md`.

use crate::bench_baselines::{BaselineTable, CharacterBaselines, Figures};
use anyhow::{bail, Context, Result};

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

/// The rows as a [`BaselineTable`] (one character per model, tools in the order they first
/// appear), so the corpus is scored like the benchmark characters. A model a tool has no
/// row for counts as a failure of that tool.
pub fn table(rows: &[BaselineRow]) -> Result<BaselineTable> {
    let mut table = BaselineTable {
        tools: Vec::new(),
        characters: Vec::new(),
    };
    for row in rows {
        if !table.tools.contains(&row.tool) {
            table.tools.push(row.tool.clone());
        }
        if table.character(&row.model).is_none() {
            table.characters.push(CharacterBaselines {
                name: row.model.clone(),
                vertices: row.cells[1].parse().ok(),
                joints: row.cells[2].parse().ok(),
                pieces: None,
                tools: Vec::new(),
            });
        }
    }
    for character in &mut table.characters {
        for tool in &table.tools {
            let row = rows
                .iter()
                .find(|r| r.model == character.name && &r.tool == tool);
            character.tools.push(match row {
                None => None,
                Some(row) => Some(Figures {
                    deform_mean: row.deform_mean,
                    deform_max: row.deform_max,
                    l1_mean: row.cells[5].parse().with_context(|| {
                        format!(
                            "BASELINES.md, {} {}: L1 mean {:?}",
                            row.model, tool, row.cells[5]
                        )
                    })?,
                    bleed: row.bleed,
                }),
            });
        }
    }
    Ok(table)
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
    fn rows_become_a_table_of_characters() {
        let table = table(&parse_baselines(SAMPLE).unwrap()).unwrap();
        assert_eq!(table.tools, ["heat", "bbw"]);
        let names: Vec<&str> = table.characters.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["cesiumman", "makehuman"]);
        let cesiumman = &table.characters[0];
        assert_eq!(
            (cesiumman.vertices, cesiumman.joints),
            (Some(3273), Some(19))
        );
        assert_eq!(cesiumman.tools[0].unwrap().l1_mean, 0.337);
        assert_eq!(cesiumman.tools[1], None);
        assert_eq!(table.characters[1].tools[1].unwrap().deform_max, 0.076);
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
