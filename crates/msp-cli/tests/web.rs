//! The browser tuner's engine (`crates/msp-web`, here compiled natively)
//! gives the CLI's numbers: for each scenario, its pairs keyed by the long
//! flags, the page's `design` report is `msp run --report`'s document, key
//! for key and bit for bit, its CSV is `msp run -o`'s, and the command it
//! shows runs to the same report. (In the browser the engine runs as
//! WebAssembly, whose `sin`/`exp` may round a last bit differently from the
//! host's C library; `scripts/web-test` compares the page there.)

mod common;

use common::msp;
use serde_json::Value;

/// Scenarios across plant kinds, schemes, tunings and the scenario keys.
fn scenarios() -> Vec<Vec<(&'static str, &'static str)>> {
    vec![
        vec![("plant", "0.2/s*e^-7.4s"), ("controller", "smith")],
        vec![("plant", "0.2/s*e^-7.4s")],
        vec![
            ("plant", "0.2/s*e^-7.4s"),
            ("controller", "karan-dey"),
            ("lambda", "5.233"),
        ],
        vec![
            ("plant", "1.6e^-6s/(10s+1)"),
            ("controller", "filtered-smith"),
            ("target", "ms=1.4"),
            ("noise", "0.02"),
            ("seed", "3"),
        ],
        vec![
            ("plant", "5.6e^-93.9s/(40.2s+1)"),
            ("controller", "pi"),
            ("target", "wc=0.006,pm=60"),
        ],
        vec![
            ("plant", "2.3e^-8s/(15s+1)"),
            ("controller", "smith"),
            ("lambda", "8"),
            ("ts", "0.1"),
            ("duration", "900"),
            ("setpoint", "1@0"),
            ("setpoint", "0@600"),
            ("disturbance", "input:0.2@300"),
            ("event", "450:plant-dead-time=11"),
            ("umin", "-1"),
            ("umax", "1.5"),
        ],
        vec![
            ("plant", "e^-2s/(2s-1)"),
            ("controller", "fsp"),
            ("duration", "40"),
        ],
        vec![
            ("plant", "e^-5s/((10s+1)(2s+1))"),
            ("controller", "pid"),
            ("rule", "simc"),
            ("quantization", "0.001"),
        ],
    ]
}

fn request(pairs: &[(&str, &str)]) -> String {
    serde_json::to_string(pairs).unwrap()
}

/// `msp run` of the pairs: its report and its CSV.
fn cli(pairs: &[(&str, &str)]) -> (Value, Vec<u8>) {
    let dir = tempfile::tempdir().unwrap();
    let (report, csv) = (dir.path().join("r.json"), dir.path().join("r.csv"));
    let mut cmd = msp();
    cmd.arg("run");
    for (k, v) in pairs {
        cmd.arg(format!("--{k}")).arg(v);
    }
    cmd.arg("--report")
        .arg(&report)
        .arg("-o")
        .arg(&csv)
        .arg("-q");
    cmd.assert().success();
    let r = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    (r, std::fs::read(&csv).unwrap())
}

#[test]
fn the_page_reports_what_msp_run_reports() {
    for pairs in scenarios() {
        let req = request(&pairs);
        let page = msp_web::design_of(&req, true).unwrap_or_else(|e| panic!("{pairs:?}: {e:?}"));
        let (report, csv) = cli(&pairs);
        assert_eq!(
            serde_json::to_value(&page.report).unwrap(),
            report,
            "{pairs:?}"
        );
        assert_eq!(
            msp_web::csv_of(&req).unwrap().as_bytes(),
            &csv[..],
            "{pairs:?}"
        );
        // the drawn signals are the run's samples (every k-th, and the last)
        let rows: Vec<&str> = std::str::from_utf8(&csv).unwrap().lines().skip(1).collect();
        assert_eq!(page.report.samples, rows.len(), "{pairs:?}");
        let last: Vec<f64> = rows[rows.len() - 1]
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(page.signals.t.last(), Some(&last[0]));
        assert_eq!(page.signals.y.last(), Some(&last[2]));
        assert!(page.signals.t.len() <= msp_web::DRAWN + 1);
    }
}

#[test]
fn the_command_the_page_shows_reruns_the_design() {
    for pairs in scenarios() {
        let page = msp_web::design_of(&request(&pairs), true).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let report = dir.path().join("r.json");
        let bin = assert_cmd::cargo::cargo_bin("msp");
        let rest = page
            .command
            .strip_prefix("msp run")
            .expect("the command is msp run");
        let line = format!(
            "'{}' run{rest} --report '{}' -q -o /dev/null",
            bin.display(),
            report.display()
        );
        let ok = std::process::Command::new("sh")
            .arg("-c")
            .arg(&line)
            .status()
            .unwrap();
        assert!(ok.success(), "{line}");
        let r: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
        assert_eq!(serde_json::to_value(&page.report).unwrap(), r, "{line}");
    }
}

#[test]
fn a_draft_is_the_design_without_the_advice() {
    for pairs in scenarios() {
        let req = request(&pairs);
        let full = serde_json::to_value(msp_web::design_of(&req, true).unwrap()).unwrap();
        let draft = serde_json::to_value(msp_web::design_of(&req, false).unwrap()).unwrap();
        for key in [
            "controller",
            "robustness",
            "stability",
            "metrics",
            "events",
            "ts",
        ] {
            assert_eq!(
                full["report"][key], draft["report"][key],
                "{key} of {pairs:?}"
            );
        }
        assert_eq!(full["signals"], draft["signals"]);
        assert_eq!(full["response"], draft["response"]);
        // the warnings say the same, the draft's without the better tuning
        let (fw, dw) = (
            full["report"]["warnings"].as_array().unwrap(),
            draft["report"]["warnings"].as_array().unwrap(),
        );
        assert_eq!(fw.len(), dw.len());
        for (f, d) in fw.iter().zip(dw) {
            let (f, d) = (f.as_str().unwrap(), d.as_str().unwrap());
            assert_eq!(
                f.split("; --lambda").next().unwrap().split("; no λ").next(),
                Some(d),
                "{pairs:?}"
            );
        }
    }
}

/// The loop response's own identities: `|L(jωc)| = 1` at the report's
/// gain crossover and `∠L(jωc) = pm − 180°` (mod 360°) there, each read
/// off the grid by interpolation in `log ω` (the grid's step is 1.2 %).
#[test]
fn the_drawn_response_crosses_where_the_margins_say() {
    for pairs in scenarios() {
        let page = msp_web::design_of(&request(&pairs), true).unwrap();
        let r = page.report.robustness.expect("a single loop has margins");
        if !r.wcp.is_finite() || page.report.stable != Some(true) {
            continue;
        }
        let w = &page.response.w;
        let i = w
            .iter()
            .position(|x| *x > r.wcp)
            .expect("wcp inside the grid");
        let f = (r.wcp.ln() - w[i - 1].ln()) / (w[i].ln() - w[i - 1].ln());
        let at = |v: &[f64]| v[i - 1] + f * (v[i] - v[i - 1]);
        let db = at(&page.response.magnitude_db);
        assert!(db.abs() < 0.02, "{pairs:?}: |L(jwc)| = {db} dB");
        let turn = (at(&page.response.phase) + 180.0 - r.pm).rem_euclid(360.0);
        let off = turn.min(360.0 - turn);
        assert!(off < 0.5, "{pairs:?}: phase at wc off by {off} degrees");
        let ts = serde_json::to_value(&page.report).unwrap()["ts"]
            .as_f64()
            .unwrap();
        assert!(*w.last().unwrap() < std::f64::consts::PI / ts);
    }
}

#[test]
fn the_page_says_what_the_cli_says_of_bad_input() {
    let bad = msp_web::design_of(&request(&[("plant", "0.2/s*e^-7.4")]), true).unwrap_err();
    assert_eq!((bad.key.as_str(), bad.column), ("plant", Some(13)));
    let cli = common::stderr_of(["run", "--plant", "0.2/s*e^-7.4"], 2);
    assert!(
        cli.contains(&bad.message) && cli.contains("column 13"),
        "{cli}"
    );
    let info: Value = serde_json::from_str(&msp_web::plant("1/(s+1")).unwrap();
    assert_eq!(info["ok"], false);
    assert!(info["column"].as_u64().is_some());
    for (pairs, key, says) in [
        (
            vec![("plant", "1/s"), ("speed", "2")],
            "speed",
            "unknown key",
        ),
        (vec![("plant", "1/s"), ("ts", "x")], "ts", "not a number"),
        (
            vec![("plant", "1/s"), ("ts", "1"), ("ts", "2")],
            "ts",
            "twice",
        ),
        (
            vec![("plant", "1/s"), ("controller", "nope")],
            "controller",
            "nope",
        ),
        (vec![("plant", "[1/s, 0; 0, 1/s]")], "plant", "matrix"),
        (vec![("ts", "1")], "plant", "give a plant"),
    ] {
        let e = msp_web::design_of(&request(&pairs), true).unwrap_err();
        assert_eq!(e.key, key, "{pairs:?}");
        assert!(e.message.contains(says), "{pairs:?}: {}", e.message);
    }
    // a scenario the engine refuses is refused by the CLI with the same words
    let pairs = [("plant", "1.6e^-6s/(10s+1)"), ("controller", "karan-dey")];
    let e = msp_web::design_of(&request(&pairs), true).unwrap_err();
    let cli = common::stderr_of(
        ["run", "--plant", pairs[0].1, "--controller", pairs[1].1],
        2,
    );
    assert!(cli.contains(&e.message), "{}\n{cli}", e.message);
}

#[test]
fn the_plant_call_lists_the_schemes_of_its_kind() {
    for (plant, kind, default) in [
        ("0.2/s*e^-7.4s", "integrating", "karan-dey"),
        ("1.6e^-6s/(10s+1)", "stable", "smith"),
        ("e^-2s/(2s-1)", "unstable", "fsp"),
    ] {
        let info: Value = serde_json::from_str(&msp_web::plant(plant)).unwrap();
        assert_eq!(info["kind"], kind);
        assert_eq!(info["default"], default);
        let names: Vec<&str> = info["schemes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["name"].as_str().unwrap())
            .collect();
        assert!(names.contains(&default), "{names:?}");
        // every scheme listed designs a loop for the plant, or says why not
        for name in names {
            let req = request(&[("plant", plant), ("controller", name), ("duration", "1")]);
            match msp_web::design_of(&req, false) {
                Ok(d) => assert_eq!(d.report.controller.name, name),
                Err(e) => assert!(!e.message.is_empty(), "{plant} {name}"),
            }
        }
    }
}

/// `msp serve DIR --port 0`: the address it prints, and the answer to one
/// raw HTTP request (status line, headers, body).
mod serve {
    use std::io::{BufRead, BufReader, Read, Write};
    use std::net::TcpStream;
    use std::process::{Child, Command, Stdio};

    pub struct Server {
        child: Child,
        pub addr: String,
    }

    impl Drop for Server {
        fn drop(&mut self) {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }

    pub fn start(dir: &std::path::Path) -> Server {
        let mut child = Command::new(assert_cmd::cargo::cargo_bin("msp"))
            .arg("serve")
            .arg(dir)
            .args(["--port", "0"])
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let addr = line
            .split("http://")
            .nth(1)
            .and_then(|r| r.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_string();
        assert!(addr.starts_with("127.0.0.1:"), "{addr}");
        Server { child, addr }
    }

    pub fn get(addr: &str, request: &str) -> (String, String, Vec<u8>) {
        let mut s = TcpStream::connect(addr).unwrap();
        s.write_all(request.as_bytes()).unwrap();
        let mut all = Vec::new();
        s.read_to_end(&mut all).unwrap();
        let split = all.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
        let head = String::from_utf8(all[..split].to_vec()).unwrap();
        let status = head.lines().next().unwrap().to_string();
        (status, head, all[split + 4..].to_vec())
    }
}

#[test]
fn msp_serve_serves_the_folder_and_nothing_outside_it() {
    let outer = tempfile::tempdir().unwrap();
    let dir = outer.path().join("site");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("index.html"), "<!doctype html><p>tuner</p>").unwrap();
    std::fs::write(dir.join("app.js"), "export {};").unwrap();
    std::fs::write(dir.join("m.wasm"), b"\0asm\x01\0\0\0").unwrap();
    std::fs::write(dir.join("sub/a b.css"), "p{}").unwrap();
    std::fs::write(outer.path().join("secret.txt"), "not for the page").unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(outer.path().join("secret.txt"), dir.join("link.txt")).unwrap();
    let srv = serve::start(&dir);
    let get = |path: &str| {
        serve::get(
            &srv.addr,
            &format!("GET {path} HTTP/1.1\r\nHost: x\r\n\r\n"),
        )
    };
    let (status, head, body) = get("/");
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(head.contains("Content-Type: text/html"), "{head}");
    assert_eq!(body, b"<!doctype html><p>tuner</p>");
    for (path, kind) in [
        ("/app.js?x=1", "text/javascript"),
        ("/m.wasm", "application/wasm"),
        ("/sub/a%20b.css", "text/css"),
    ] {
        let (status, head, _) = get(path);
        assert_eq!(status, "HTTP/1.1 200 OK", "{path}");
        assert!(
            head.contains(&format!("Content-Type: {kind}")),
            "{path}: {head}"
        );
    }
    for path in [
        "/../secret.txt",
        "/%2e%2e/secret.txt",
        "/sub/../../secret.txt",
        "/link.txt",
        "/nope.js",
        "/%zz",
    ] {
        let (status, _, body) = get(path);
        assert!(
            status.contains("404") || status.contains("400"),
            "{path}: {status}"
        );
        assert!(!String::from_utf8_lossy(&body).contains("not for the page"));
    }
    let (status, _, _) = serve::get(&srv.addr, "POST / HTTP/1.1\r\nContent-Length: 0\r\n\r\n");
    assert!(status.contains("405"), "{status}");
    let (status, head, body) = serve::get(&srv.addr, "HEAD /app.js HTTP/1.1\r\n\r\n");
    assert!(
        status.contains("200") && head.contains("Content-Length: 10"),
        "{head}"
    );
    assert!(body.is_empty());
}

#[test]
fn msp_serve_names_a_folder_it_cannot_serve() {
    let dir = tempfile::tempdir().unwrap();
    let cli = common::stderr_of(["serve", dir.path().to_str().unwrap()], 2);
    assert!(
        cli.contains("has no index.html") && cli.contains("scripts/web"),
        "{cli}"
    );
    let cli = common::stderr_of(["serve", "/no/such/folder"], 2);
    assert!(cli.contains("/no/such/folder"), "{cli}");
}
