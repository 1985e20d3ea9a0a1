//! `msp serve`: a folder over HTTP, on the loopback address unless another
//! is named — the browser tuner that `bash scripts/web DIR` builds. A static
//! file server and no more: GET and HEAD of the files inside the folder (a
//! path that leaves it, by `..` or a link, is not found), one request at a
//! time, each connection closed after its answer.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::cli::ServeArgs;
use crate::error::CliError;

/// The longest request line and headers read (a browser's are far shorter).
const REQUEST_CAP: u64 = 16 * 1024;

pub(crate) fn serve(a: &ServeArgs) -> Result<(), CliError> {
    let root = a
        .dir
        .canonicalize()
        .map_err(|e| CliError::Input(format!("{}: {e}", a.dir.display())))?;
    if !root.join("index.html").is_file() {
        return Err(CliError::Input(format!(
            "{} has no index.html: build the page into it with `bash scripts/web {}`",
            a.dir.display(),
            a.dir.display()
        )));
    }
    let listener = TcpListener::bind((a.bind, a.port))
        .map_err(|e| CliError::Runtime(format!("cannot listen on {}:{}: {e}", a.bind, a.port)))?;
    let addr = listener
        .local_addr()
        .map_err(|e| CliError::Runtime(e.to_string()))?;
    crate::export::outln!(
        "serving {} at http://{addr}/ (Ctrl-C stops)",
        root.display()
    )?;
    std::io::stdout()
        .flush()
        .map_err(|e| CliError::Runtime(e.to_string()))?;
    for stream in listener.incoming().flatten() {
        // a client that goes away mid-request is its own affair
        let _ = answer(stream, &root);
    }
    Ok(())
}

/// One request, one answer.
fn answer(mut s: TcpStream, root: &Path) -> std::io::Result<()> {
    s.set_read_timeout(Some(Duration::from_secs(5)))?;
    s.set_write_timeout(Some(Duration::from_secs(30)))?;
    let mut reader = BufReader::new(s.try_clone()?.take(REQUEST_CAP));
    let mut line = String::new();
    reader.read_line(&mut line)?;
    loop {
        let mut header = String::new();
        if reader.read_line(&mut header)? == 0 || header.trim().is_empty() {
            break;
        }
    }
    let mut words = line.split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    let head = method == "HEAD";
    if method != "GET" && !head {
        return reply(
            &mut s,
            "405 Method Not Allowed",
            "text/plain",
            b"GET only\n",
            head,
        );
    }
    let path = target.split(['?', '#']).next().unwrap_or("/");
    let Some(path) = decoded(path) else {
        return reply(&mut s, "400 Bad Request", "text/plain", b"bad path\n", head);
    };
    match file_of(root, &path).and_then(|f| std::fs::read(&f).ok().map(|b| (f, b))) {
        Some((f, body)) => reply(&mut s, "200 OK", content_type(&f), &body, head),
        None => reply(&mut s, "404 Not Found", "text/plain", b"not found\n", head),
    }
}

/// `%XX` escapes decoded; `None` for a malformed one or text that is not UTF-8.
fn decoded(path: &str) -> Option<String> {
    let bytes = path.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The file a path names inside `root` (a folder: its index.html); `None`
/// for one outside it, by `..` or by a link, or for no file.
fn file_of(root: &Path, path: &str) -> Option<PathBuf> {
    let mut p = root.to_path_buf();
    for part in path.split('/') {
        match part {
            "" | "." => {}
            ".." => return None,
            _ if part.contains('\\') || part.contains('\0') => return None,
            _ => p.push(part),
        }
    }
    if p.is_dir() {
        p.push("index.html");
    }
    let real = p.canonicalize().ok()?;
    (real.starts_with(root) && real.is_file()).then_some(real)
}

/// The media type of a file by its extension (a module script and the
/// WebAssembly module need theirs: browsers refuse them otherwise).
fn content_type(f: &Path) -> &'static str {
    match f.extension().and_then(|e| e.to_str()).unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "wasm" => "application/wasm",
        "css" => "text/css; charset=utf-8",
        "json" => "application/json",
        "svg" => "image/svg+xml",
        "png" => "image/png",
        "csv" | "txt" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

fn reply(
    s: &mut TcpStream,
    status: &str,
    kind: &str,
    body: &[u8],
    head: bool,
) -> std::io::Result<()> {
    write!(
        s,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nX-Content-Type-Options: nosniff\r\nCache-Control: no-cache\r\nConnection: close\r\n\r\n",
        body.len()
    )?;
    if !head {
        s.write_all(body)?;
    }
    s.flush()
}
