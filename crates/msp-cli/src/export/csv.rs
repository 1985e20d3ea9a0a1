//! CSV: the signals of a run, comparisons and sweeps.

use msp::study::RunOutput;

use super::{fmt_f, Content};

/// The CSV: `t,r,y,u,d`, `d_out` when there is an output disturbance, then the
/// controller's internal signals; written row by row into the file.
pub(crate) fn run_csv(out: &RunOutput) -> Content<'_> {
    Content::Stream(Box::new(|w| out.result.write_csv(w)))
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
        .map(|r| r.metrics.fields().map(|(k, _)| k).collect())
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
        rec.extend(r.metrics.fields().map(|(_, v)| fmt_f(v)));
        rec.push(fmt_f(r.max_abs_u));
        w.write_record(&rec)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
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
