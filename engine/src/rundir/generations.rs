//! `generations.csv`: per generation of an evolved stage and its
//! ancestors, the statistics and the best individual's events; written
//! from the checkpoint's history ([`generations_csv`]) and read back by
//! one typed reader ([`parse_generations`]).
//!
//! Its header is its schema (version 1: the columns below, and a
//! `best_variant_NAME` column per variant of the stage). The columns are
//! found by name; those after `mean` are absent in files written before
//! them (`None`).

use std::fmt::Write as _;
use std::path::Path;

use shaping_runtime::evolve::GenStats;

use crate::error::{Error, ErrorKind, Result};

/// `generations.csv`: one row per generation of the stage and its ancestors.
/// A stage with variants adds a column `best_variant_NAME` per variant
/// (`variants`, the stage's, in declaration order): the best individual's
/// fitness in that variant, empty where the generation did not draw it (or
/// in a row of an ancestor without those variants).
pub fn generations_csv(history: &[GenStats], variants: &[String]) -> String {
    let mut s = String::from(
        "stage,generation,stage_generation,best,mean,worst,best_index,best_recharges,best_grips,best_releases_outside",
    );
    for v in variants {
        let _ = write!(s, ",best_variant_{v}");
    }
    s.push('\n');
    for h in history {
        let _ = write!(
            s,
            "{},{},{},{:.6},{:.6},{:.6},{},{},{},{}",
            h.stage,
            h.generation,
            h.stage_generation,
            h.best,
            h.mean,
            h.worst,
            h.best_index,
            h.best_recharges,
            h.best_grips,
            h.best_releases_outside
        );
        let mine = h.best_variants.len() == variants.len();
        for i in 0..variants.len() {
            match h.best_variants.get(i).copied().flatten().filter(|_| mine) {
                Some(f) => _ = write!(s, ",{f:.6}"),
                None => s.push(','),
            }
        }
        s.push('\n');
    }
    s
}

/// A `generations.csv` read back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Generations {
    /// The stage's variants (the `best_variant_NAME` columns), in order.
    pub variants: Vec<String>,
    pub rows: Vec<GenRow>,
}

/// One row of `generations.csv`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GenRow {
    pub stage: String,
    pub generation: u32,
    pub stage_generation: u32,
    pub best: f32,
    pub mean: f32,
    pub worst: Option<f32>,
    pub best_index: Option<u64>,
    pub best_recharges: Option<u64>,
    pub best_grips: Option<u64>,
    pub best_releases_outside: Option<u64>,
    /// The best's fitness per variant (`None`: not drawn that generation).
    pub best_variants: Vec<Option<f32>>,
}

/// Parses `generations.csv` (columns found by name; `path` names the file
/// in errors, with the line and the column of a damaged cell).
pub fn parse_generations(text: &str, path: &Path) -> Result<Generations> {
    let bad = |what: String| Error::new(ErrorKind::Corrupt, format!("error: `{}` {what}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').map(str::trim).collect();
    let find = |name: &str| header.iter().position(|h| *h == name);
    let col = |name: &str| find(name).ok_or_else(|| bad(format!("has no column `{name}` in its header")));
    let (cs, cg, csg, cb, cm) =
        (col("stage")?, col("generation")?, col("stage_generation")?, col("best")?, col("mean")?);
    let optional = ["worst", "best_index", "best_recharges", "best_grips", "best_releases_outside"].map(find);
    let variant_cols: Vec<(usize, String)> = header
        .iter()
        .enumerate()
        .filter_map(|(c, h)| Some((c, h.strip_prefix("best_variant_")?.to_string())))
        .collect();
    let mut out =
        Generations { variants: variant_cols.iter().map(|(_, n)| n.clone()).collect(), rows: Vec::new() };
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let at = |what: String| bad(format!("line {}: {what}", i + 2));
        let cell = |c: usize| {
            cells
                .get(c)
                .copied()
                .ok_or_else(|| at(format!("has {} cells, column `{}` is missing", cells.len(), header[c])))
        };
        let int = |c: usize| {
            let s = cell(c)?;
            s.parse::<u64>().map_err(|_| at(format!("`{s}` in column `{}` is not a count", header[c])))
        };
        let num = |c: usize| {
            let s = cell(c)?;
            s.parse::<f32>().map_err(|_| at(format!("`{s}` in column `{}` is not a number", header[c])))
        };
        let small = |c: usize| {
            u32::try_from(int(c)?).map_err(|_| at(format!("column `{}` is out of range", header[c])))
        };
        let [worst, index, recharges, grips, releases] = optional;
        out.rows.push(GenRow {
            stage: cell(cs)?.to_string(),
            generation: small(cg)?,
            stage_generation: small(csg)?,
            best: num(cb)?,
            mean: num(cm)?,
            worst: worst.map(num).transpose()?,
            best_index: index.map(int).transpose()?,
            best_recharges: recharges.map(int).transpose()?,
            best_grips: grips.map(int).transpose()?,
            best_releases_outside: releases.map(int).transpose()?,
            best_variants: variant_cols
                .iter()
                .map(|&(c, _)| match cell(c)? {
                    "" => Ok(None),
                    _ => num(c).map(Some),
                })
                .collect::<Result<_>>()?,
        });
    }
    Ok(out)
}
