//! The per-character table of `shared/data/bench/BASELINES.md`: for every benchmark
//! character, what each other tool (Blender's bone heat, a nearest-bone method) reached, or
//! that it failed. The clean corpus's table ([`crate::baselines`]) converts to the same
//! [`BaselineTable`], so both are scored by one code path.

use anyhow::{bail, Context, Result};

/// The figures BASELINES.md gives one tool (or atlas-skin) on one character: deformation
/// error under random poses (mean and max, × diagonal), weight L1 (mean of per-vertex
/// Σ|w_ref − w|) and bleeding (`None` where the table has no figure).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Figures {
    pub deform_mean: f64,
    pub deform_max: f64,
    pub l1_mean: f64,
    pub bleed: Option<f64>,
}

/// One character's row: its facts and each tool's figures, `None` where the tool failed.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterBaselines {
    /// As the table names it, e.g. `rignet-val/426.glb` (a path under `bench/`).
    pub name: String,
    /// `None` where the table gives no number (KayKit: "see kaykit/").
    pub vertices: Option<usize>,
    pub joints: Option<usize>,
    /// As written (a number, or a range such as `18–31`).
    pub pieces: Option<String>,
    /// Per tool of [`BaselineTable::tools`], in that order.
    pub tools: Vec<Option<Figures>>,
}

/// Every character's row, and the tools in column order.
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineTable {
    pub tools: Vec<String>,
    pub characters: Vec<CharacterBaselines>,
}

impl BaselineTable {
    /// The row of the character named `name`.
    pub fn character(&self, name: &str) -> Option<&CharacterBaselines> {
        self.characters.iter().find(|c| c.name == name)
    }
}

/// The suffix of a tool column's header: `heat: deform mean / max, L1, bleed`.
const TOOL_HEADER: &str = ": deform mean / max, L1, bleed";

/// Reads the table whose header starts with `| character |`; tool columns are those whose
/// header ends with `TOOL_HEADER`, cells `MEAN / MAX, L1, BLEED` or `failed`.
pub fn parse_bench_baselines(text: &str) -> Result<BaselineTable> {
    let mut header: Option<Vec<String>> = None;
    let mut table = BaselineTable {
        tools: Vec::new(),
        characters: Vec::new(),
    };
    for (index, line) in text.lines().enumerate() {
        let line_no = index + 1;
        let line = line.trim();
        if !line.starts_with('|') {
            header = None;
            continue;
        }
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        if cells.first() == Some(&"character") {
            if !table.tools.is_empty() {
                bail!("BASELINES.md line {line_no}: a second per-character table");
            }
            table.tools = cells
                .iter()
                .filter_map(|c| c.strip_suffix(TOOL_HEADER).map(str::to_string))
                .collect();
            if table.tools.is_empty() {
                bail!("BASELINES.md line {line_no}: the per-character table has no tool column");
            }
            header = Some(cells.iter().map(|c| c.to_string()).collect());
            continue;
        }
        let Some(header) = &header else { continue };
        if cells
            .iter()
            .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
        {
            continue;
        }
        if cells.len() != header.len() {
            bail!(
                "BASELINES.md line {line_no}: {} cells, the header has {}",
                cells.len(),
                header.len()
            );
        }
        let column = |name: &str| header.iter().position(|h| h == name).map(|i| cells[i]);
        let count = |name: &str| -> Result<Option<usize>> {
            match column(name) {
                Some(cell) if cell.chars().all(|c| c.is_ascii_digit()) && !cell.is_empty() => {
                    Ok(Some(cell.parse()?))
                }
                _ => Ok(None),
            }
        };
        let mut tools = Vec::new();
        for tool in &table.tools {
            let cell = column(&format!("{tool}{TOOL_HEADER}")).unwrap_or_default();
            tools.push(
                parse_tool_cell(cell)
                    .with_context(|| format!("BASELINES.md line {line_no}, {tool}"))?,
            );
        }
        table.characters.push(CharacterBaselines {
            name: cells[0].to_string(),
            vertices: count("vertices")?,
            joints: count("joints")?,
            pieces: column("pieces").map(str::to_string),
            tools,
        });
    }
    if table.characters.is_empty() {
        bail!("BASELINES.md has no per-character table (a header starting with `| character |`)");
    }
    Ok(table)
}

/// `0.0093 / 0.118, 0.552, 0.118` → figures; `failed` → `None`.
fn parse_tool_cell(cell: &str) -> Result<Option<Figures>> {
    if cell == "failed" {
        return Ok(None);
    }
    let malformed = || format!("{cell:?} is not `MEAN / MAX, L1, BLEED` nor `failed`");
    let (mean, rest) = cell.split_once('/').with_context(malformed)?;
    let numbers: Vec<&str> = rest.split(',').map(str::trim).collect();
    let [max, l1, bleed] = numbers[..] else {
        bail!(malformed());
    };
    let number = |s: &str| s.trim().parse::<f64>().with_context(malformed);
    Ok(Some(Figures {
        deform_mean: number(mean)?,
        deform_max: number(max)?,
        l1_mean: number(l1)?,
        bleed: Some(number(bleed)?),
    }))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small table: a heat failure, a row without a vertex count.
    pub(crate) const SAMPLE: &str = "# title\n\n\
| tool | characters scored | failed |\n|---|---|---|\n| heat | 2 | 1 |\n\n\
| character | vertices | joints | pieces | artist binding | heat: deform mean / max, L1, bleed | euclid: deform mean / max, L1, bleed |\n\
|---|---|---|---|---|---|---|\n\
| rignet-val/1.glb | 488 | 18 | 2 | smooth | 0.0093 / 0.118, 0.552, 0.118 | 0.0176 / 0.267, 0.605, 0.136 |\n\
| rignet-val/2.glb | 817 | 16 | 1 | rigid | failed | 0.0163 / 0.120, 1.337, 0.310 |\n\
| kaykit/Knight.glb | see kaykit/ | 23 | 18–31 | smooth | 0.0178 / 0.554, 0.752, 0.236 | 0.0161 / 0.212, 0.672, 0.208 |\n\
\nafter\n";

    #[test]
    fn rows_tools_and_failed_cells_are_read() {
        let table = parse_bench_baselines(SAMPLE).unwrap();
        assert_eq!(table.tools, ["heat", "euclid"]);
        assert_eq!(table.characters.len(), 3);
        let first = &table.characters[0];
        assert_eq!(
            (first.name.as_str(), first.vertices, first.joints),
            ("rignet-val/1.glb", Some(488), Some(18))
        );
        assert_eq!(
            first.tools[0],
            Some(Figures {
                deform_mean: 0.0093,
                deform_max: 0.118,
                l1_mean: 0.552,
                bleed: Some(0.118)
            })
        );
        assert_eq!(table.characters[1].tools[0], None);
        assert_eq!(table.characters[1].tools[1].unwrap().l1_mean, 1.337);
        let knight = table.character("kaykit/Knight.glb").unwrap();
        assert_eq!(knight.vertices, None);
        assert_eq!(knight.pieces.as_deref(), Some("18–31"));
    }

    #[test]
    fn malformed_tables_are_errors_naming_the_line() {
        assert!(parse_bench_baselines("no table here").is_err());
        let bad = SAMPLE.replace("0.0176 / 0.267", "0.0176 0.267");
        let error = format!("{:#}", parse_bench_baselines(&bad).unwrap_err());
        assert!(
            error.contains("line 9") && error.contains("euclid"),
            "{error}"
        );
        let short = SAMPLE.replace("| 2 | smooth |", "| smooth |");
        assert!(parse_bench_baselines(&short).is_err());
        let number = SAMPLE.replace("0.552", "fast");
        assert!(parse_bench_baselines(&number).is_err());
    }
}
