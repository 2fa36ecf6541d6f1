//! Splitting a fixed list of tasks over processes, and merging the parts:
//! the shard I/O of `pushval report` and `pushval study`.
//!
//! A computation that can be split is a fixed list of tasks (fixed by its
//! grid, `--quick` or full), each named by a key and reduced to a row of
//! numbers. `--shard K/N` computes the K-th of N contiguous parts of the
//! list; `--shard hash:K/N` the tasks whose key hashes to K (FNV-1a, mod N),
//! so adding tasks moves no others between shards (as cargo-nextest's
//! `hash:` partitions do). Without `--shard`, a Slurm array task
//! (`SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_COUNT`, `SLURM_ARRAY_TASK_MIN`)
//! picks its own part ([`Shard::from_env`]). Each part is written to
//! `OUT/parts/NAME-K-of-N.csv`; `--merge` reads the N parts back into the
//! rows of every task, from which the caller builds exactly the files a
//! single run writes.
//!
//! # Format
//!
//! A part file is a header line
//! `# pushval TAG part K/N grid=GRID tasks=T split=range|hash hash=H version=V`
//! (T the length of the whole list, H the FNV-1a hash of its keys, V the
//! pushval version), then one CSV record per task of the part,
//! `index,value,...` (records of different lengths: the `csv` crate's
//! flexible records), with the numbers in Rust's shortest round-trip form (so a merge
//! reproduces the single run's numbers exactly; `NaN` and `inf` as Rust
//! prints them). A merge refuses parts of another grid, hash, version or
//! split, a task in two parts or in none, and names the missing shards.

use std::ops::Range;
use std::path::Path;
use std::str::FromStr;

use anyhow::{bail, Context};

use crate::outdir::num;

/// One part of N of a task list: `K/N` (contiguous) or `hash:K/N` (by the
/// hash of each task's key), with 1 ≤ K ≤ N.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
    /// Tasks chosen by the hash of their key, not by position.
    pub by_hash: bool,
}

impl Shard {
    /// The part a Slurm array task computes: K = `SLURM_ARRAY_TASK_ID` −
    /// `SLURM_ARRAY_TASK_MIN` + 1 (MIN 0 when unset), N =
    /// `SLURM_ARRAY_TASK_COUNT`, by hash. None outside an array job.
    pub fn from_env() -> anyhow::Result<Option<Shard>> {
        let var = |name: &str| std::env::var(name).ok();
        let (Some(id), Some(count)) = (var("SLURM_ARRAY_TASK_ID"), var("SLURM_ARRAY_TASK_COUNT"))
        else {
            return Ok(None);
        };
        let num = |name: &str, v: &str| {
            v.trim()
                .parse::<usize>()
                .map_err(|_| anyhow::anyhow!("{name}={v}: not a task number"))
        };
        let min = var("SLURM_ARRAY_TASK_MIN").map_or(Ok(0), |m| num("SLURM_ARRAY_TASK_MIN", &m))?;
        let (id, n) = (
            num("SLURM_ARRAY_TASK_ID", &id)?,
            num("SLURM_ARRAY_TASK_COUNT", &count)?,
        );
        if id < min || id - min >= n {
            bail!("SLURM_ARRAY_TASK_ID={id} is outside the array's {n} tasks from {min} (SLURM_ARRAY_TASK_MIN)");
        }
        Ok(Some(Shard {
            k: id - min + 1,
            n,
            by_hash: true,
        }))
    }

    /// The indices of the tasks (named by `keys`) in this part.
    pub fn indices(&self, keys: &[String]) -> Vec<usize> {
        if self.by_hash {
            (0..keys.len())
                .filter(|&i| (fnv1a(&keys[i]) % self.n as u64) as usize == self.k - 1)
                .collect()
        } else {
            shard_range(keys.len(), *self).collect()
        }
    }

    fn split(&self) -> &'static str {
        if self.by_hash {
            "hash"
        } else {
            "range"
        }
    }
}

/// FNV-1a, 64 bits: a hash that is the same on every machine and version.
pub fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The hash of a task list: FNV-1a of its keys, one a line, in hex.
pub fn grid_hash(keys: &[String]) -> String {
    format!("{:016x}", fnv1a(&keys.join("\n")))
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (by_hash, s) = match s.strip_prefix("hash:") {
            Some(rest) => (true, rest),
            None => (false, s),
        };
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("expected K/N (e.g. 2/8), got '{s}'"))?;
        let k: usize = k.trim().parse().map_err(|_| format!("bad K in '{s}'"))?;
        let n: usize = n.trim().parse().map_err(|_| format!("bad N in '{s}'"))?;
        if n == 0 || k == 0 || k > n {
            return Err(format!("need 1 <= K <= N, got '{s}'"));
        }
        Ok(Self { k, n, by_hash })
    }
}

/// What names a split computation in its part files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Parts<'a> {
    /// What the header calls it, e.g. `report sweep` or `study idioms`.
    pub tag: &'a str,
    /// File name stem of its parts, e.g. `sweep` (`parts/sweep-K-of-N.csv`).
    pub stem: &'a str,
    /// The grid's name, `full` or `quick`: parts of different grids never merge.
    pub grid: &'a str,
    /// The hash of the task list's keys ([`grid_hash`]).
    pub hash: String,
}

/// The grid name of a run: `quick` or `full`.
pub fn grid_name(quick: bool) -> &'static str {
    if quick {
        "quick"
    } else {
        "full"
    }
}

/// The part `shard` of `n` tasks: contiguous, sizes differing by at most one.
pub fn shard_range(n: usize, shard: Shard) -> Range<usize> {
    let lo = (shard.k - 1) * n / shard.n;
    let hi = shard.k * n / shard.n;
    lo..hi
}

impl Parts<'_> {
    /// File name of a part, relative to the output folder.
    pub fn file_name(&self, shard: Shard) -> String {
        format!("parts/{}-{}-of-{}.csv", self.stem, shard.k, shard.n)
    }

    /// The part file of `rows`, the results of the tasks `indices` of a
    /// list of `total` tasks (see the module's format).
    pub fn text(&self, total: usize, indices: &[usize], rows: &[Vec<f64>], shard: Shard) -> String {
        let mut s = format!(
            "# pushval {} part {}/{} grid={} tasks={} split={} hash={} version={}\n",
            self.tag,
            shard.k,
            shard.n,
            self.grid,
            total,
            shard.split(),
            self.hash,
            env!("CARGO_PKG_VERSION")
        );
        let mut w = csv::WriterBuilder::new()
            .flexible(true)
            .from_writer(Vec::new());
        for (&idx, row) in indices.iter().zip(rows) {
            let fields = std::iter::once(idx.to_string()).chain(row.iter().map(|v| num(*v)));
            // Writing into memory fails only on a full heap.
            w.write_record(fields).expect("writing CSV into memory");
        }
        let records = w.into_inner().expect("flushing CSV into memory");
        s.push_str(std::str::from_utf8(&records).expect("CSV of str fields is UTF-8"));
        s
    }

    /// Reads every part in `OUT/parts/` and returns the rows of all `total`
    /// tasks. `width(i)` is the number of values task `i` has, where fixed.
    /// Refuses parts of another grid or split, a task in two parts, and a
    /// missing part.
    pub fn merge(
        &self,
        out: &Path,
        total: usize,
        width: impl Fn(usize) -> Option<usize>,
    ) -> anyhow::Result<Vec<Vec<f64>>> {
        let dir = out.join("parts");
        let prefix = format!("{}-", self.stem);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .with_context(|| format!("reading {} (run the shards first)", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(&prefix) && n.ends_with(".csv"))
            })
            .collect();
        files.sort();
        if files.is_empty() {
            bail!(
                "no part files ({}-K-of-N.csv) in {}",
                self.stem,
                dir.display()
            );
        }
        let mut rows: Vec<Option<Vec<f64>>> = vec![None; total];
        let mut seen: Vec<(usize, usize, bool)> = Vec::new();
        let head_prefix = format!("# pushval {} part ", self.tag);
        for f in &files {
            let text =
                std::fs::read_to_string(f).with_context(|| format!("reading {}", f.display()))?;
            let (head, body) = text.split_once('\n').unwrap_or((&text, ""));
            let bad = || anyhow::anyhow!("{}: not a {} part file", f.display(), self.tag);
            let rest = head.strip_prefix(&head_prefix).ok_or_else(bad)?;
            let mut it = rest.split_whitespace();
            let kn: Shard = it
                .next()
                .ok_or_else(bad)?
                .parse()
                .map_err(|e: String| anyhow::anyhow!("{}: {e}", f.display()))?;
            let grid = it
                .next()
                .and_then(|s| s.strip_prefix("grid="))
                .ok_or_else(bad)?;
            let n_tasks: usize = it
                .next()
                .and_then(|s| s.strip_prefix("tasks="))
                .and_then(|s| s.parse().ok())
                .ok_or_else(bad)?;
            if grid != self.grid || n_tasks != total {
                bail!(
                    "{}: computed on the {grid} grid ({n_tasks} tasks), but this merge wants the {} grid ({} tasks); pass --quick consistently",
                    f.display(),
                    self.grid,
                    total
                );
            }
            let field = |name: &str| {
                rest.split_whitespace()
                    .find_map(|w| w.strip_prefix(name))
                    .unwrap_or("")
                    .to_string()
            };
            let (split, hash, version) = (field("split="), field("hash="), field("version="));
            if hash != self.hash {
                bail!(
                    "{}: computed for a task list with hash {hash}, this one has {}: the grid or the study changed; run the shards again",
                    f.display(),
                    self.hash
                );
            }
            if version != env!("CARGO_PKG_VERSION") {
                bail!(
                    "{}: written by pushval {version}, this is {}",
                    f.display(),
                    env!("CARGO_PKG_VERSION")
                );
            }
            seen.push((kn.k, kn.n, split == "hash"));
            let mut reader = csv::ReaderBuilder::new()
                .has_headers(false)
                .flexible(true)
                .from_reader(body.as_bytes());
            for record in reader.records() {
                let record = record.with_context(|| format!("{}: not CSV", f.display()))?;
                // The header line is line 1 of the file.
                let ln = record.position().map_or(0, |p| p.line()) + 1;
                let mut fields = record.iter();
                let idx: usize = fields
                    .next()
                    .and_then(|s| s.parse().ok())
                    .with_context(|| format!("{}: line {ln}: bad index", f.display()))?;
                let vals: Vec<f64> = fields
                    .map(|s| s.parse::<f64>())
                    .collect::<Result<_, _>>()
                    .with_context(|| format!("{}: line {ln}: bad number", f.display()))?;
                let slot = rows
                    .get_mut(idx)
                    .with_context(|| format!("{}: task {idx} out of range", f.display()))?;
                if width(idx).is_some_and(|w| w != vals.len()) {
                    bail!("{}: task {idx} has {} values", f.display(), vals.len());
                }
                if slot.is_some() {
                    bail!("{}: task {idx} appears in two parts", f.display());
                }
                *slot = Some(vals);
            }
        }
        let (n, by_hash) = (seen[0].1, seen[0].2);
        if seen.iter().any(|&(_, m, h)| m != n || h != by_hash) {
            bail!(
                "{} holds parts of different splits ({:?}); remove the stale ones",
                dir.display(),
                seen
            );
        }
        let missing: Vec<String> = (1..=n)
            .filter(|k| !seen.iter().any(|s| s.0 == *k))
            .map(|k| format!("{}{k}/{n}", if by_hash { "hash:" } else { "" }))
            .collect();
        if !missing.is_empty() {
            bail!(
                "missing shards {} of {} in {} (run them with --shard)",
                missing.join(", "),
                self.stem,
                dir.display()
            );
        }
        rows.into_iter()
            .enumerate()
            .map(|(i, r)| r.with_context(|| format!("task {i} is in no part")))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A part file holds rows of different widths and every f64 a row can
    /// hold (NaN, ±inf, −0, subnormal), and a merge gives them back bit
    /// for bit; a part whose record does not parse is refused naming its
    /// line.
    #[test]
    fn parts_round_trip_through_csv_records() {
        let dir = tempfile::tempdir().unwrap();
        let keys: Vec<String> = (0..3).map(|i| i.to_string()).collect();
        let parts = Parts {
            tag: "test",
            stem: "t",
            grid: grid_name(true),
            hash: grid_hash(&keys),
        };
        let rows = vec![
            vec![0.1, f64::NAN, f64::INFINITY],
            vec![-0.0, 5e-324],
            vec![f64::NEG_INFINITY, 1.0 / 3.0, -2.5e300, 7.0],
        ];
        let whole = Shard {
            k: 1,
            n: 1,
            by_hash: false,
        };
        let text = parts.text(3, &[0, 1, 2], &rows, whole);
        let mut lines = text.lines().skip(1);
        assert_eq!(lines.next(), Some("0,0.1,NaN,inf"));
        assert!(lines.next().is_some_and(|l| l.starts_with("1,-0,0.000")));
        std::fs::create_dir_all(dir.path().join("parts")).unwrap();
        let file = dir.path().join(parts.file_name(whole));
        std::fs::write(&file, &text).unwrap();
        let back = parts.merge(dir.path(), 3, |_| None).unwrap();
        for (a, b) in rows.iter().zip(&back) {
            let bits = |r: &[f64]| r.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(a), bits(b));
        }
        std::fs::write(&file, text.replace("NaN,inf", "NaN,x")).unwrap();
        let err = parts.merge(dir.path(), 3, |_| None).unwrap_err();
        assert!(format!("{err:#}").contains("line 2: bad number"), "{err:#}");
    }
}
