//! Everything `msp` writes: files atomically, standard output without
//! panicking, and one module per format.

use std::io::Write;
use std::path::{Path, PathBuf};

use msp::poly::fmt_num;
use serde_json::Value;

use crate::error::CliError;

pub(crate) mod csv;
pub(crate) mod json;
pub(crate) mod svg;
pub(crate) mod text;

/// The files one command writes: all of them or none.
///
/// [`Outputs::plan`] checks every path before anything is computed (no two
/// the same, each directory present); [`Outputs::commit`] writes each file
/// to a temporary created exclusively beside it (an unpredictable name,
/// `O_EXCL`, no symlink followed) and only when every one is written renames
/// them into place. A failure leaves the old files as they were and no
/// temporary behind. The path `-` is standard output (as for most Unix
/// tools), written after the files.
pub(crate) struct Outputs<'a> {
    files: Vec<(PathBuf, Content<'a>)>,
    stdout: Option<Content<'a>>,
}

/// What one output holds: its bytes, or a writer of them that streams into
/// the file (a run's CSV goes from the recorded columns straight to the
/// temporary: the text, about 2.5 times the size of the columns, is never
/// held in memory).
pub(crate) enum Content<'a> {
    Bytes(Vec<u8>),
    Stream(Box<WriteFn<'a>>),
}

/// A writer of an output's bytes.
pub(crate) type WriteFn<'a> = dyn FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a;

impl Content<'_> {
    /// Writes the content to `w` (buffered when it streams).
    fn write_to(self, w: &mut dyn Write) -> std::io::Result<()> {
        match self {
            Content::Bytes(b) => w.write_all(&b),
            Content::Stream(f) => {
                let mut buf = std::io::BufWriter::with_capacity(1 << 16, w);
                f(&mut buf)?;
                buf.flush()
            }
        }
    }
}

impl From<Vec<u8>> for Content<'_> {
    fn from(b: Vec<u8>) -> Self {
        Content::Bytes(b)
    }
}

/// The temporaries being written now: an interrupt removes them.
static PENDING: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Installs the SIGINT/SIGTERM handler: the temporaries of an atomic write
/// in progress are removed, and `msp` exits with status 130 (no output file
/// is half-written: the finished ones were renamed into place whole, the
/// others are not there).
pub(crate) fn remove_temporaries_on_interrupt() {
    let _ = ctrlc::set_handler(|| {
        // the lock is kept to the exit: no temporary is made after this
        let list = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        for p in list.iter() {
            let _ = std::fs::remove_file(p);
        }
        std::process::exit(130);
    });
}

/// The prefix of this process's temporaries: `.msp-PID-`.
fn temp_prefix() -> String {
    format!(".msp-{}-", std::process::id())
}

/// The random part of a temporary's name: this many letters and digits.
const TEMP_RANDOM: usize = 12;

/// Where an output goes: the file to replace atomically (a symbolic link's
/// target, so that the link stays a link), or a file written in place (a
/// device, a FIFO, anything under `/dev` or `/proc`, such as `/dev/stdout`
/// or a `/proc/self/fd/N` link: renaming over those would replace the
/// system's link or the redirection's file).
enum Target {
    Replace(PathBuf),
    InPlace(PathBuf),
}

fn target_of(path: &Path) -> Result<Target, String> {
    let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    // a link into /proc or /dev may lead to no path (a pipe's fd): written in place
    let resolved = if link {
        std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
    } else {
        path.to_path_buf()
    };
    // every hop of a chain of links: one through /dev or /proc (a link to
    // /proc/self/fd/1) is the redirection's file, written in place
    let mut hops = vec![std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())];
    let mut at = path.to_path_buf();
    for _ in 0..40 {
        let Ok(next) = std::fs::read_link(&at) else {
            break;
        };
        at = parent(&at).join(next);
        hops.push(at.clone());
    }
    hops.push(resolved.clone());
    let system = hops
        .iter()
        .any(|p| p.starts_with("/dev") || p.starts_with("/proc"));
    let special = std::fs::metadata(&resolved).is_ok_and(|m| !m.is_file() && !m.is_dir());
    if system || special {
        return Ok(Target::InPlace(path.to_path_buf()));
    }
    if link && !resolved.is_absolute() {
        return Err(format!("the link {} leads nowhere", path.display()));
    }
    if link && std::fs::canonicalize(path).is_err() {
        return Err(format!("the link {} leads nowhere", path.display()));
    }
    Ok(Target::Replace(resolved))
}

/// An existing file this user may not write is not replaced (as `cp` would
/// not): writing it through a rename would step over its permissions. Nor
/// is one that belongs to another user (also for root): the file put in
/// its place would be this user's, and writing into it in place (as `cp`
/// does) could leave it half-written; msp never changes a file's owner.
fn check_writable(path: &Path) -> Result<(), String> {
    if let Err(e) = std::fs::OpenOptions::new().write(true).open(path) {
        if e.kind() == std::io::ErrorKind::PermissionDenied {
            return Err(format!(
                "{}: permission denied (the file is not writable for you)",
                path.display()
            ));
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let me = std::fs::metadata("/proc/self").map(|m| m.uid());
        if let (Ok(me), Ok(m)) = (me, std::fs::metadata(path)) {
            if m.uid() != me {
                return Err(format!(
                    "{}: it belongs to another user (uid {}); msp replaces a file whole, and the new one would be yours: write it elsewhere",
                    path.display(),
                    m.uid()
                ));
            }
        }
    }
    Ok(())
}

/// Opens a file written in place; a FIFO without a reader is an error,
/// not a wait that never ends.
fn open_in_place(path: &Path) -> std::io::Result<std::fs::File> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::FileTypeExt;
        use std::os::unix::fs::OpenOptionsExt;
        if std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) {
            // O_NONBLOCK: the open fails with ENXIO when nobody reads
            let probe = std::fs::OpenOptions::new()
                .write(true)
                .custom_flags(0o4000)
                .open(path)
                .map_err(|e| {
                    std::io::Error::new(e.kind(), format!("a FIFO nobody reads from ({e})"))
                })?;
            // a reader is there: the blocking open returns at once
            let f = std::fs::OpenOptions::new().write(true).open(path);
            drop(probe);
            return f;
        }
    }
    std::fs::OpenOptions::new().write(true).open(path)
}

/// Whether a path given to a flag means standard output: `-` (as for most
/// Unix tools), `/dev/stdout`, `/proc/self/fd/1`, or a link that leads to
/// one of them. Such an output is written to the process's standard output,
/// after the files, never renamed over (that would replace the system's link
/// or the redirection's file).
pub(crate) fn is_stdout(path: &Path) -> bool {
    let named = |p: &Path| {
        p.as_os_str() == "-"
            || p == Path::new("/dev/stdout")
            || p == Path::new("/proc/self/fd/1")
            || p == Path::new("/dev/fd/1")
    };
    if named(path) {
        return true;
    }
    let mut at = path.to_path_buf();
    for _ in 0..40 {
        let Ok(next) = std::fs::read_link(&at) else {
            return false;
        };
        at = parent(&at).join(next);
        if named(&at) {
            return true;
        }
    }
    false
}

/// A file as every spelling of it resolves (`x.csv`, `sub/../x.csv`, a link
/// to it), or as its directory does for one not yet there.
fn resolved(path: &Path) -> PathBuf {
    let dir = parent(path);
    std::fs::canonicalize(path)
        .or_else(|_| {
            std::fs::canonicalize(&dir).map(|d| match path.file_name() {
                Some(f) => d.join(f),
                None => d,
            })
        })
        .unwrap_or_else(|_| path.to_path_buf())
}

/// A device (`/dev/null`, a terminal), which any number of outputs may
/// name: writing it replaces nothing.
fn is_device(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device())
}

impl<'a> Outputs<'a> {
    /// Checks the paths of a command's outputs (`None` for one not asked for).
    pub(crate) fn plan(paths: &[(&str, Option<&PathBuf>)]) -> Result<Self, CliError> {
        Self::plan_reading(paths, &[])
    }

    /// [`Outputs::plan`] for a command that also reads `inputs` (`--input`,
    /// `--scenario`): an output that names an input is refused, naming
    /// both — msp never writes over what it reads.
    pub(crate) fn plan_reading(
        paths: &[(&str, Option<&PathBuf>)],
        inputs: &[(&str, Option<&PathBuf>)],
    ) -> Result<Self, CliError> {
        let read: Vec<(PathBuf, &str)> = inputs
            .iter()
            .filter_map(|(flag, p)| {
                p.filter(|p| !is_stdout(p) && !is_device(p))
                    .map(|p| (resolved(p), *flag))
            })
            .collect();
        let mut seen: Vec<(PathBuf, &str)> = Vec::new();
        for (flag, path) in paths {
            let Some(path) = path else { continue };
            if is_stdout(path) {
                if let Some((_, other)) = seen.iter().find(|(k, _)| is_stdout(k)) {
                    return Err(CliError::Input(format!(
                        "{other} and {flag} both name standard output (-)"
                    )));
                }
                seen.push((path.to_path_buf(), flag));
                continue;
            }
            let dir = parent(path);
            if !dir.is_dir() {
                return Err(CliError::Input(format!(
                    "{flag} {}: the directory {} does not exist",
                    path.display(),
                    dir.display()
                )));
            }
            if path.is_dir() {
                return Err(CliError::Input(format!(
                    "{flag} {}: is a directory",
                    path.display()
                )));
            }
            // a device takes any number of outputs
            if is_device(path) {
                continue;
            }
            // the same file by any spelling: `x.csv`, `sub/../x.csv`, a link to it
            let key = resolved(path);
            if let Some((_, input)) = read.iter().find(|(k, _)| *k == key) {
                return Err(CliError::Input(format!(
                    "{flag} {} is the file {input} reads: choose another output (msp never writes over its input)",
                    path.display()
                )));
            }
            if let Some((_, other)) = seen.iter().find(|(k, _)| *k == key) {
                return Err(CliError::Input(format!(
                    "{other} and {flag} name the same file {}",
                    path.display()
                )));
            }
            seen.push((key, flag));
        }
        Ok(Outputs {
            files: Vec::new(),
            stdout: None,
        })
    }

    /// Adds a file to write.
    pub(crate) fn add(&mut self, path: &Path, content: impl Into<Content<'a>>) {
        let content = content.into();
        if is_stdout(path) {
            self.stdout = Some(content);
            return;
        }
        self.files.push((path.to_path_buf(), content));
    }

    /// Adds a file to write, or prints the content now when no path was
    /// given (`-o` absent: the CSV goes to standard output).
    pub(crate) fn add_or_print(
        &mut self,
        path: Option<&PathBuf>,
        content: impl Into<Content<'a>>,
    ) -> Result<(), CliError> {
        match path {
            Some(p) if !is_stdout(p) => {
                self.add(p, content);
                Ok(())
            }
            _ => print_content(content.into()),
        }
    }

    /// Writes every file: all to temporaries first, then the renames.
    pub(crate) fn commit(self) -> Result<(), CliError> {
        let mut staged = Vec::with_capacity(self.files.len());
        let mut devices = Vec::new();
        for (path, content) in self.files {
            let fail = |e: std::io::Error| {
                CliError::Runtime(format!("cannot write {}: {e}", path.display()))
            };
            let target = match target_of(&path) {
                Ok(Target::Replace(t)) => t,
                Ok(Target::InPlace(t)) => {
                    devices.push((t, content));
                    continue;
                }
                Err(why) => return Err(CliError::Input(format!("cannot write {why}"))),
            };
            if target.exists() {
                check_writable(&target)
                    .map_err(|why| CliError::Input(format!("cannot write {why}")))?;
            }
            let mut builder = tempfile::Builder::new();
            let prefix = temp_prefix();
            builder
                .prefix(&prefix)
                .suffix(".tmp")
                .rand_bytes(TEMP_RANDOM);
            // the file gets the mode `File::create` would give it (0666 less
            // the umask), or the permission bits of the file it replaces —
            // never a set-user-ID, set-group-ID or sticky bit
            #[cfg(unix)]
            let mode = {
                use std::os::unix::fs::PermissionsExt;
                std::fs::metadata(&target).map_or(0o666, |m| m.permissions().mode()) & 0o777
            };
            let dir = parent(&target);
            // the name joins the list before the file exists, under the
            // list's lock: an interrupt (whose handler takes the lock)
            // finds every temporary there is, and none is made after it
            let mut tmp = builder
                .make_in(&dir, |name| {
                    let mut list = PENDING.lock().unwrap_or_else(|e| e.into_inner());
                    list.push(name.to_path_buf());
                    let mut open = std::fs::OpenOptions::new();
                    open.write(true).create_new(true);
                    #[cfg(unix)]
                    std::os::unix::fs::OpenOptionsExt::mode(&mut open, mode);
                    let made = open.open(name);
                    if made.is_err() {
                        list.pop();
                    }
                    made
                })
                .map_err(fail)?;
            content.write_to(&mut tmp).map_err(fail)?;
            tmp.as_file().sync_all().map_err(fail)?;
            staged.push((tmp, target));
        }
        for (path, content) in devices {
            let written = open_in_place(&path).and_then(|mut f| content.write_to(&mut f));
            match written {
                Ok(()) => {}
                // a reader that went away ends the output quietly, as for `-o -`
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
                    return Err(CliError::BrokenPipe)
                }
                Err(e) => {
                    return Err(CliError::Runtime(format!(
                        "cannot write {}: {e}",
                        path.display()
                    )))
                }
            }
        }
        // every file is written: now the renames (a dropped temporary deletes itself)
        let renamed = staged.into_iter().try_for_each(|(tmp, path)| {
            tmp.persist(&path).map(|_| ()).map_err(|e| {
                CliError::Runtime(format!("cannot write {}: {}", path.display(), e.error))
            })
        });
        if let Ok(mut list) = PENDING.lock() {
            list.clear();
        }
        renamed?;
        match self.stdout {
            Some(content) => print_content(content),
            None => Ok(()),
        }
    }
}

/// The directory a file is written in.
fn parent(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// [`print`] for an output's content (streamed through a buffer).
pub(crate) fn print_content(content: Content<'_>) -> Result<(), CliError> {
    match content {
        Content::Bytes(b) => print(&b),
        stream => {
            let mut out = std::io::stdout().lock();
            stream
                .write_to(&mut out)
                .and_then(|()| out.flush())
                .map_err(|e| CliError::stdout(&e))
        }
    }
}

/// Writes `bytes` to standard output and flushes: a closed pipe becomes
/// [`CliError::BrokenPipe`], any other failure (`> /dev/full`) a runtime error.
pub(crate) fn print(bytes: &[u8]) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(|e| CliError::stdout(&e))
}

/// Prints `value` as pretty JSON on standard output (`--json`).
pub(crate) fn print_json<T: serde::Serialize>(value: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| CliError::Runtime(e.to_string()))?;
    print_line(format_args!("{text}"))
}

/// One line of text to standard output, as [`print`].
pub(crate) fn print_line(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    print(format!("{args}\n").as_bytes())
}

/// A message for the user on standard error. A failure to write it (a closed
/// or full standard error) is ignored: the exit status still tells.
pub(crate) fn note(args: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "{args}");
}

/// `println!` that returns a [`CliError`] instead of panicking.
macro_rules! outln {
    ($($t:tt)*) => {
        $crate::export::print_line(format_args!($($t)*))
    };
}
pub(crate) use outln;

/// `eprintln!` that never panics.
macro_rules! noteln {
    ($($t:tt)*) => {
        $crate::export::note(format_args!($($t)*))
    };
}
pub(crate) use noteln;

/// Shortest round-trip formatting of a float.
pub(crate) fn fmt_f(v: f64) -> String {
    format!("{v}")
}

/// A JSON number, or null for NaN/infinity.
pub(crate) fn num(v: f64) -> Value {
    serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
}

/// `kp=0.0764 ti=40.2 …` for summaries.
pub(crate) fn params_line(p: &msp::registry::Params) -> String {
    p.iter()
        .map(|(k, v)| format!("{k}={}", fmt_sig(v)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A relative change as a signed percentage: `+10`, `-5`, `0`.
pub(crate) fn pct(x: f64) -> String {
    let v = fmt_sig(100.0 * x);
    if x > 0.0 {
        format!("+{v}")
    } else {
        v
    }
}

/// Four significant digits.
pub(crate) fn fmt_sig(v: f64) -> String {
    // a figure that does not exist (of a diverged loop, a response that
    // never settles, a crossover that is not there) is a dash, as null is
    // in JSON; an infinite margin stays `inf`
    if v.is_nan() {
        return "—".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    fmt_num(msp::poly::round_sig(v, 5))
}

/// Runs `work`; when it takes more than a second and standard error is a
/// terminal, a spinner with the elapsed time says `what` is running (the
/// long runs of `run`, `compare`, `margins` and `autotune`; `sweep` has its
/// own progress bar); `quiet` (`-q`) draws nothing. Ctrl-C stops it as any
/// command.
pub(crate) fn busy<T: Send>(what: &str, quiet: bool, work: impl FnOnce() -> T + Send) -> T {
    use std::io::IsTerminal;
    if quiet || !std::io::stderr().is_terminal() {
        return work();
    }
    let done = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            let start = std::time::Instant::now();
            while start.elapsed() < std::time::Duration::from_secs(1) {
                if done.load(std::sync::atomic::Ordering::Relaxed) {
                    return;
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            let bar = indicatif::ProgressBar::new_spinner();
            bar.set_style(
                indicatif::ProgressStyle::with_template("{spinner} {msg} {elapsed}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
            );
            bar.set_message(what.to_string());
            bar.enable_steady_tick(std::time::Duration::from_millis(100));
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            bar.finish_and_clear();
        });
        let out = work();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        out
    })
}
