//! Everything `msp` reads: files with a size cap, and special files that can
//! neither hang the command nor fill its memory.
//!
//! A regular file is read up to a cap (a scenario file is small; a CSV may be
//! large but not endless). A pipe, FIFO or character device is opened without
//! blocking (a FIFO with no writer cannot stall the open) and read with a
//! timeout between chunks of data, under the same cap: `/dev/zero` ends in the
//! cap's error, a FIFO nobody writes to in the timeout's error. Data with a NUL
//! byte is no text: it is refused at once.

use std::io::{ErrorKind, Read};
use std::path::Path;
use std::time::{Duration, Instant};

use crate::error::CliError;

/// The most a scenario file may hold.
pub(crate) const SCENARIO_CAP: u64 = 16 << 20;
/// The most a CSV file may hold.
pub(crate) const CSV_CAP: u64 = 1 << 30;
/// How long a pipe may stay silent before the read gives up.
const SILENCE: Duration = Duration::from_secs(10);

/// Linux's `O_NONBLOCK` (the flag's value on every Linux architecture but
/// Alpha, PA-RISC and SPARC, none of which this is built for).
#[cfg(target_os = "linux")]
const O_NONBLOCK: i32 = 0o4000;

/// A reader of an input: its bytes up to the cap, text only, a pipe with a
/// timeout between chunks.
pub(crate) struct Input {
    inner: std::fs::File,
    name: String,
    cap: u64,
    read: u64,
    special: bool,
    fifo: bool,
}

/// Opens `path` (named `name` in messages) for reading under `cap` bytes.
pub(crate) fn open(path: &Path, name: &str, cap: u64) -> Result<Input, CliError> {
    let fail = |e: std::io::Error| CliError::Input(format!("cannot read {name}: {e}"));
    let meta = std::fs::metadata(path).map_err(fail)?;
    if meta.is_dir() {
        return Err(CliError::Input(format!(
            "cannot read {name}: it is a directory"
        )));
    }
    if meta.is_file() && meta.len() > cap {
        return Err(too_large(name, cap));
    }
    let special = !meta.is_file();
    #[cfg(unix)]
    let fifo = {
        use std::os::unix::fs::FileTypeExt;
        meta.file_type().is_fifo()
    };
    #[cfg(not(unix))]
    let fifo = false;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(target_os = "linux")]
    if special {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(O_NONBLOCK);
    }
    let inner = options.open(path).map_err(fail)?;
    Ok(Input {
        inner,
        name: name.to_string(),
        cap,
        read: 0,
        special,
        fifo,
    })
}

fn too_large(name: &str, cap: u64) -> CliError {
    CliError::Input(format!(
        "cannot read {name}: it holds more than {} MiB, more than such a file may",
        cap >> 20
    ))
}

impl Input {
    /// Everything as text (UTF-8).
    pub(crate) fn text(mut self) -> Result<String, CliError> {
        let mut bytes = Vec::new();
        self.read_to_end(&mut bytes)
            .map_err(|e| CliError::Input(e.to_string()))?;
        String::from_utf8(bytes).map_err(|_| {
            CliError::Input(format!("cannot read {}: it is not UTF-8 text", self.name))
        })
    }
}

impl Input {
    /// A pause of a pipe or FIFO with no data yet: an error once it has
    /// been silent for [`SILENCE`].
    fn wait(&self, started: Instant) -> std::io::Result<()> {
        if started.elapsed() > SILENCE {
            return Err(std::io::Error::new(
                ErrorKind::TimedOut,
                format!(
                    "cannot read {}: no data came for {} s (a pipe or FIFO nobody writes to?)",
                    self.name,
                    SILENCE.as_secs()
                ),
            ));
        }
        std::thread::sleep(Duration::from_millis(5));
        Ok(())
    }
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let err = |kind: ErrorKind, msg: String| std::io::Error::new(kind, msg);
        let started = Instant::now();
        loop {
            match self.inner.read(buf) {
                // a FIFO whose writer has not come yet reads as closed: wait for it
                Ok(0) if self.fifo && self.read == 0 && !buf.is_empty() => self.wait(started)?,
                Ok(n) => {
                    let got = buf.get(..n).unwrap_or(&[]);
                    if got.contains(&0) {
                        return Err(err(
                            ErrorKind::InvalidData,
                            format!(
                                "cannot read {}: it holds binary data (a NUL byte), not text",
                                self.name
                            ),
                        ));
                    }
                    self.read = self.read.saturating_add(n as u64);
                    if self.read > self.cap {
                        return Err(err(
                            ErrorKind::InvalidData,
                            format!(
                                "cannot read {}: it holds more than {} MiB, more than such a file may",
                                self.name,
                                self.cap >> 20
                            ),
                        ));
                    }
                    return Ok(n);
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock && self.special => {
                    self.wait(started)?
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(err(e.kind(), format!("cannot read {}: {e}", self.name))),
            }
        }
    }
}
