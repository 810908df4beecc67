//! `campaign merge`: one campaign's results from its shards' (each a `results.json` or the
//! folder holding it), with the shards' kept mission folders copied in, so the merged
//! folder stands alone. The shards must be of the same campaign and not overlap.

use std::path::{Path, PathBuf};

use super::run::{CampaignResults, RESULTS_FORMAT, read_results, write_results};

/// Merges the results at `inputs` into `out` (its `results.json` and `missions/`).
pub fn merge(inputs: &[PathBuf], out: &Path) -> anyhow::Result<CampaignResults> {
    anyhow::ensure!(!inputs.is_empty(), "nothing to merge");
    // Every input read and joined first: a refused merge copies nothing.
    let mut merged: Option<CampaignResults> = None;
    let mut folders = Vec::new();
    for input in inputs {
        let r = read_results(input)?;
        let from = if input.is_dir() {
            input.clone()
        } else {
            input.parent().map_or_else(PathBuf::new, Path::to_path_buf)
        };
        folders.push((from, r.clone()));
        merged = Some(match merged {
            None => r,
            Some(m) => join(m, r, input)?,
        });
    }
    let mut merged = merged.ok_or_else(|| anyhow::anyhow!("nothing to merge"))?;
    std::fs::create_dir_all(out.join("missions"))?;
    for (from, r) in &folders {
        copy_kept(r, from, out)?;
    }
    merged.format = RESULTS_FORMAT;
    merged.shards.sort_by_key(|s| (s.of, s.index));
    merged.runs.sort_by_key(|r| (r.shard.of, r.shard.index));
    merged.outcomes.sort_by_key(|o| o.index);
    write_results(out, &merged)?;
    Ok(merged)
}

/// `a` and `b` as one: the same campaign, no shard or mission twice.
fn join(
    mut a: CampaignResults,
    b: CampaignResults,
    file: &Path,
) -> anyhow::Result<CampaignResults> {
    anyhow::ensure!(
        a.spec == b.spec,
        "{}: another campaign (its seed, count, filter, yardstick, planner configuration or \
         independent solver's settings differ)",
        file.display()
    );
    for s in &b.shards {
        anyhow::ensure!(
            !a.shards.contains(s),
            "{}: shard {}/{} is already merged",
            file.display(),
            s.index,
            s.of
        );
    }
    for o in &b.outcomes {
        anyhow::ensure!(
            a.outcomes.iter().all(|x| x.index != o.index),
            "{}: mission {} ({}) is in two shards",
            file.display(),
            o.index,
            o.name
        );
    }
    a.shards.extend(b.shards);
    a.runs.extend(b.runs);
    a.outcomes.extend(b.outcomes);
    Ok(a)
}

/// Copies each kept mission folder of `r` (relative to `from`) into `out`.
fn copy_kept(r: &CampaignResults, from: &Path, out: &Path) -> anyhow::Result<()> {
    for kept in r.outcomes.iter().filter_map(|o| o.kept.as_deref()) {
        let (src, dst) = (from.join(kept), out.join(kept));
        if src == dst || !src.is_dir() {
            continue;
        }
        std::fs::create_dir_all(&dst)?;
        for entry in std::fs::read_dir(&src)? {
            let entry = entry?;
            if entry.file_type()?.is_file() {
                std::fs::copy(entry.path(), dst.join(entry.file_name()))?;
            }
        }
    }
    Ok(())
}
