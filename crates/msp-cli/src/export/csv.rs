//! CSV: the signals of a run, comparisons and sweeps.

use msp::study::RunOutput;

use super::fmt_f;
use crate::error::CliError;

/// The CSV: `t,r,y,u,d`, `d_out` when there is an output disturbance, then the
/// controller's internal signals.
pub(crate) fn csv_bytes(out: &RunOutput) -> std::io::Result<Vec<u8>> {
    let mut v = Vec::with_capacity(out.result.t.len() * 64);
    out.result.write_csv(&mut v)?;
    Ok(v)
}

/// One CSV for a comparison: `t,r`, then `NAME.y,NAME.u,NAME.SIGNAL…` per controller.
pub(crate) fn compare_csv(runs: &[&RunOutput]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::WriterBuilder::new()
        .flexible(false)
        .from_writer(Vec::new());
    let Some(first) = runs.first() else {
        return w.into_inner().map_err(|e| csv::Error::from(e.into_error()));
    };
    let mut header = vec!["t".to_string(), "r".to_string(), "d".to_string()];
    for r in runs {
        header.push(format!("{}.y", r.controller));
        header.push(format!("{}.u", r.controller));
        for (n, _) in &r.result.signals {
            header.push(format!("{}.{n}", r.controller));
        }
    }
    w.write_record(&header)?;
    let rows = runs.iter().map(|r| r.result.t.len()).max().unwrap_or(0);
    let get = |v: &Vec<f64>, i: usize| v.get(i).map_or(String::new(), |x| fmt_f(*x));
    for i in 0..rows {
        let mut row = vec![
            get(&first.result.t, i),
            get(&first.result.r, i),
            get(&first.result.d, i),
        ];
        for r in runs {
            row.push(get(&r.result.y, i));
            row.push(get(&r.result.u, i));
            for (_, v) in &r.result.signals {
                row.push(get(v, i));
            }
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

pub(crate) const SWEEP_HEAD: &[&str] = &["index", "gain", "delay", "tau", "stable"];

/// One CSV row per run: the perturbation, the verdict, the metrics and the largest |u|.
pub(crate) fn sweep_csv(rows: &[msp::sweep::SweepRow]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::with_capacity(rows.len() * 200));
    let mut header: Vec<&str> = SWEEP_HEAD.to_vec();
    let names: Vec<&str> = rows
        .first()
        .map(|r| r.metrics.fields().iter().map(|(k, _)| *k).collect())
        .unwrap_or_default();
    header.extend(&names);
    header.push("max_abs_u");
    w.write_record(&header)?;
    for r in rows {
        let mut rec = vec![
            r.index.to_string(),
            fmt_f(r.gain),
            fmt_f(r.delay),
            fmt_f(r.tau),
            r.stable.to_string(),
        ];
        rec.extend(r.metrics.fields().iter().map(|(_, v)| fmt_f(*v)));
        rec.push(fmt_f(r.max_abs_u));
        w.write_record(&rec)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// Concatenates shard CSVs (same header) and orders the rows by index.
pub(crate) fn merge_sweeps(paths: &[std::path::PathBuf]) -> Result<Vec<u8>, CliError> {
    let mut header: Option<csv::StringRecord> = None;
    let mut rows: Vec<(usize, csv::StringRecord)> = Vec::new();
    // which file each run index came from: a shard given twice is an error
    let mut from: std::collections::HashMap<usize, &std::path::Path> =
        std::collections::HashMap::new();
    for p in paths {
        let mut r = csv::Reader::from_path(p)
            .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?;
        let h = r
            .headers()
            .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?
            .clone();
        match &header {
            None => header = Some(h),
            Some(first) if *first != h => {
                return Err(CliError::Input(format!(
                    "{}: its columns differ from the first file's",
                    p.display()
                )))
            }
            Some(_) => {}
        }
        for rec in r.records() {
            let rec = rec.map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?;
            let idx: usize = rec.get(0).and_then(|x| x.parse().ok()).ok_or_else(|| {
                CliError::Input(format!("{}: a row without an index", p.display()))
            })?;
            if let Some(first) = from.insert(idx, p) {
                return Err(CliError::Input(format!(
                    "run {idx} is in both {} and {}: is a shard given twice?",
                    first.display(),
                    p.display()
                )));
            }
            rows.push((idx, rec));
        }
    }
    rows.sort_by_key(|(i, _)| *i);
    let mut w = csv::Writer::from_writer(Vec::new());
    if let Some(h) = header {
        w.write_record(&h)
            .map_err(|e| CliError::Runtime(e.to_string()))?;
    }
    for (_, r) in rows {
        w.write_record(&r)
            .map_err(|e| CliError::Runtime(e.to_string()))?;
    }
    w.into_inner().map_err(|e| CliError::Runtime(e.to_string()))
}

/// A CSV of named columns of equal length.
pub(crate) fn columns_bytes(cols: &[(&str, &[f64])]) -> Vec<u8> {
    let mut v = Vec::new();
    let names: Vec<&str> = cols.iter().map(|(n, _)| *n).collect();
    v.extend_from_slice(names.join(",").as_bytes());
    v.push(b'\n');
    let rows = cols.iter().map(|(_, c)| c.len()).min().unwrap_or(0);
    for i in 0..rows {
        let row: Vec<String> = cols
            .iter()
            .map(|(_, c)| c.get(i).map_or(String::new(), |x| fmt_f(*x)))
            .collect();
        v.extend_from_slice(row.join(",").as_bytes());
        v.push(b'\n');
    }
    v
}
