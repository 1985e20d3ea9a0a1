//! The CSV readers of `msp identify` and `msp sweep --merge` never panic:
//! any bytes give data or a message naming the file, and data that reads
//! identifies to a finite model or a typed error.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
#[path = "../../crates/msp-cli/src/data.rs"]
mod data;

fuzz_target!(|bytes: &[u8]| {
    match data::read_step_data(bytes, "in.csv", None, "u", "y") {
        Ok(d) => {
            assert!(d.t.len() == d.u.len() && d.u.len() == d.y.len());
            assert!(d.t.iter().chain(&d.u).chain(&d.y).all(|v| v.is_finite()));
            if d.t.len() <= 20_000 {
                for kind in [msp::ident::ModelKind::Fopdt, msp::ident::ModelKind::Ipdt] {
                    if let Ok(fit) = msp::ident::identify_step(kind, &d.t, &d.u, &d.y) {
                        let (ps, n) = fit.model.params();
                        assert!(ps.iter().take(n).all(|(_, v)| v.is_finite()));
                    }
                }
            }
        }
        Err(e) => assert!(e.starts_with("in.csv: ")),
    }
    // two shards: the bytes split at the first 0xFF
    let cut = bytes.iter().position(|b| *b == 0xFF).unwrap_or(bytes.len());
    let (a, b) = bytes.split_at(cut);
    let b = b.get(1..).unwrap_or(&[]);
    if let Ok(merged) = data::merge_sweeps(vec![("a.csv".to_string(), a), ("b.csv".to_string(), b)]) {
        // the merge reads back as a CSV with every row once
        let mut r = csv::ReaderBuilder::new().flexible(true).from_reader(merged.as_slice());
        let mut seen = std::collections::HashSet::new();
        for rec in r.records().flatten() {
            if let Some(i) = rec.get(0).and_then(|x| x.parse::<usize>().ok()) {
                assert!(seen.insert(i), "run {i} twice");
            }
        }
    }
});
