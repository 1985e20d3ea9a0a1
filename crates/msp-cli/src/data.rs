//! The CSV files `msp` reads: step-test data (`msp identify`) and sweep
//! shards (`msp sweep --merge`).
//!
//! Self-contained (only `csv` and `std`), so that the fuzz target
//! `fuzz/fuzz_targets/csv.rs` compiles this very file. Every error is a
//! message naming the file (`name`) and, where there is one, the row and
//! the column.

use std::io::Read;

/// The three columns of a step test.
#[derive(Debug, Default)]
pub(crate) struct StepData {
    pub(crate) t: Vec<f64>,
    pub(crate) u: Vec<f64>,
    pub(crate) y: Vec<f64>,
}

/// Reads a step test's time, input and output columns by their header names
/// (`time`: `t` or `time` when `None`); every cell must be a finite number.
pub(crate) fn read_step_data<R: Read>(
    src: R,
    name: &str,
    time: Option<&str>,
    input: &str,
    output: &str,
) -> Result<StepData, String> {
    let mut cols = read_columns(
        src,
        name,
        &[
            Column::time(time),
            Column::named("--input", input),
            Column::named("--output", output),
        ],
    )?
    .into_iter();
    Ok(StepData {
        t: cols.next().unwrap_or_default(),
        u: cols.next().unwrap_or_default(),
        y: cols.next().unwrap_or_default(),
    })
}

/// A column asked for by name: the flag that names it, the header names
/// accepted (the first is the one an error names), and whether it may be
/// absent (then it is read as empty).
pub(crate) struct Column<'a> {
    pub(crate) flag: &'a str,
    pub(crate) names: Vec<&'a str>,
    pub(crate) optional: bool,
}

impl<'a> Column<'a> {
    /// The time column: `col`, or `t` or `time`.
    pub(crate) fn time(col: Option<&'a str>) -> Self {
        Column {
            flag: "--time",
            names: col.map_or_else(|| vec!["t", "time"], |c| vec![c]),
            optional: false,
        }
    }
    /// A required column of the header `col`, named by `flag`.
    pub(crate) fn named(flag: &'a str, col: &'a str) -> Self {
        Column {
            flag,
            names: vec![col],
            optional: false,
        }
    }
    /// The same, read as empty when the file has none.
    pub(crate) fn optional(mut self) -> Self {
        self.optional = true;
        self
    }
}

/// The most numbers [`read_columns`] keeps: 64 Mi (512 MiB of `f64`, 1 GiB
/// while a column doubles).
const KEPT_CAP: u64 = 1 << 26;

/// Reads the columns `want` by their header names; every cell of them must
/// be a finite number (the error names the row and the column).
pub(crate) fn read_columns<R: Read>(
    src: R,
    name: &str,
    want: &[Column<'_>],
) -> Result<Vec<Vec<f64>>, String> {
    let mut r = csv::Reader::from_reader(src);
    let head = r.headers().map_err(|e| format!("{name}: {e}"))?.clone();
    let find = |col: &str| head.iter().position(|h| h.trim() == col);
    let mut at = Vec::with_capacity(want.len());
    for c in want {
        let pos = c.names.iter().find_map(|n| find(n));
        // a name given to two columns: which one is meant is not ours to guess
        if let Some(p) = pos {
            let named = head.get(p).map(str::trim).unwrap_or("");
            if let Some(q) = head.iter().skip(p + 1).position(|h| h.trim() == named) {
                return Err(format!(
                    "{name}: two columns are named '{named}' (columns {} and {}): rename one",
                    p + 1,
                    p + q + 2
                ));
            }
        }
        match (pos, c.optional) {
            (Some(p), _) => at.push(Some(p)),
            (None, true) => at.push(None),
            (None, false) => {
                // the header's names, the first twenty of a wide one
                let names: Vec<&str> = head.iter().map(str::trim).take(20).collect();
                let more = head.len().saturating_sub(names.len());
                let rest = if more > 0 {
                    format!(", … and {more} more")
                } else {
                    String::new()
                };
                return Err(format!(
                    "{name}: no column '{}' ({} names it; the columns are: {}{rest})",
                    c.names.first().copied().unwrap_or(""),
                    c.flag,
                    names.join(", ")
                ));
            }
        }
    }
    let mut out: Vec<Vec<f64>> = vec![Vec::new(); want.len()];
    // what is kept is counted, not the bytes read: a short line of text
    // makes a number of eight bytes
    let mut kept = 0u64;
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| format!("{name}: {e}"))?;
        for (col, pos) in out.iter_mut().zip(&at) {
            let Some(c) = *pos else { continue };
            kept += 1;
            if kept > KEPT_CAP {
                return Err(format!(
                    "{name}: more than {KEPT_CAP} numbers in the columns read (1 GiB with their growth): a larger input is refused"
                ));
            }
            if col.len() == col.capacity() {
                col.try_reserve(col.len().max(1024))
                    .map_err(|e| format!("{name}: the numbers read do not fit in memory: {e}"))?;
            }
            let v = rec
                .get(c)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{name}: row {}: not a finite number in column {}",
                        line + 2,
                        c + 1
                    )
                })?;
            col.push(v);
        }
    }
    Ok(out)
}

/// Merges the CSVs of a sweep's shards (`--shard I/N`) into one, rows in
/// run-index order. The files must have the same columns, and a run index
/// found twice (a shard given twice) is an error.
pub(crate) fn merge_sweeps<R: Read>(sources: Vec<(String, R)>) -> Result<Vec<u8>, String> {
    let mut header: Option<csv::StringRecord> = None;
    let mut rows: Vec<(usize, csv::StringRecord)> = Vec::new();
    // which file each run index came from
    let mut from: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    let names: Vec<String> = sources.iter().map(|(n, _)| n.clone()).collect();
    for (k, (name, src)) in sources.into_iter().enumerate() {
        let mut r = csv::Reader::from_reader(src);
        let h = r.headers().map_err(|e| format!("{name}: {e}"))?.clone();
        match &header {
            None => header = Some(h),
            Some(first) if *first != h => {
                return Err(format!("{name}: its columns differ from the first file's"))
            }
            Some(_) => {}
        }
        for rec in r.records() {
            let rec = rec.map_err(|e| format!("{name}: {e}"))?;
            let idx: usize = rec
                .get(0)
                .and_then(|x| x.parse().ok())
                .ok_or_else(|| format!("{name}: a row without an index"))?;
            if let Some(first) = from.insert(idx, k) {
                let first = names.get(first).map_or("", String::as_str);
                return Err(format!(
                    "run {idx} is in both {first} and {name}: is a shard given twice?"
                ));
            }
            rows.push((idx, rec));
        }
    }
    rows.sort_by_key(|(i, _)| *i);
    let mut w = csv::Writer::from_writer(Vec::new());
    if let Some(h) = header {
        w.write_record(&h).map_err(|e| e.to_string())?;
    }
    for (_, r) in rows {
        w.write_record(&r).map_err(|e| e.to_string())?;
    }
    w.into_inner().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2000, .. ProptestConfig::default() })]
        /// Any bytes read to data of three equal finite columns or to a
        /// message naming the file; merging any two byte strings never panics
        /// and never repeats a run (the fuzz target `csv` at length).
        #[test]
        fn the_readers_take_any_bytes(a in proptest::collection::vec(any::<u8>(), 0..200),
                                      b in proptest::collection::vec(any::<u8>(), 0..200)) {
            match read_step_data(a.as_slice(), "in.csv", None, "u", "y") {
                Ok(d) => {
                    prop_assert!(d.t.len() == d.u.len() && d.u.len() == d.y.len());
                    prop_assert!(d.t.iter().chain(&d.u).chain(&d.y).all(|v| v.is_finite()));
                }
                Err(e) => prop_assert!(e.starts_with("in.csv: ")),
            }
            let _ = merge_sweeps(vec![("a".to_string(), a.as_slice()), ("b".to_string(), b.as_slice())]);
        }

        /// Well-formed step data reads back exactly.
        #[test]
        fn step_data_reads_back(rows in proptest::collection::vec((-1e6f64..1e6, -1e6f64..1e6, -1e6f64..1e6), 0..50)) {
            let mut text = String::from("y, t ,u\n");
            for (t, u, y) in &rows {
                text.push_str(&format!("{y},{t},{u}\n"));
            }
            let d = read_step_data(text.as_bytes(), "in.csv", None, "u", "y").unwrap();
            prop_assert_eq!(d.t, rows.iter().map(|r| r.0).collect::<Vec<_>>());
            prop_assert_eq!(d.u, rows.iter().map(|r| r.1).collect::<Vec<_>>());
            prop_assert_eq!(d.y, rows.iter().map(|r| r.2).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_shard_given_twice_is_named() {
        let shard = "index,gain\n0,1\n1,2\n";
        let e = merge_sweeps(vec![
            ("a.csv".to_string(), shard.as_bytes()),
            ("a.csv".to_string(), shard.as_bytes()),
        ])
        .unwrap_err();
        assert_eq!(
            e,
            "run 0 is in both a.csv and a.csv: is a shard given twice?"
        );
    }
}
