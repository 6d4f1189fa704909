//! Small helpers shared by the I/O code: atomic file writes, whole ([`write_atomic`],
//! [`write_atomic_nosync`]) or streamed ([`AtomicFile`]), and the record of what a run wrote
//! into its output folder ([`OutputManifest`]).  The capped readers of input files and the
//! quoting of input in messages are internal to the crate.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Writes `contents` to `path` atomically: a temporary file in the same directory is written,
/// flushed and renamed over `path`, so a reader never sees a half-written file and a failed
/// run leaves no output behind.  The file's mode is 0666 less the umask, as for any file a
/// program creates.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    write_via_temp(path, contents, true)
}

/// As [`write_atomic`] (temporary file + rename, so a reader never sees a half-written
/// file) but without `fsync`: for the many small per-dataset files of a batch, where a
/// flush to disk per file costs more than the computation.  After a crash such a file may
/// be missing or empty, never partial-but-plausible; rerun the batch.
pub fn write_atomic_nosync(path: &Path, contents: &[u8]) -> Result<()> {
    write_via_temp(path, contents, false)
}

/// Refuses an output path that exists and is not a regular file (a device such as
/// `/dev/null`, a FIFO, a socket): the atomic rename would replace it with a regular file.
pub fn check_not_special(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Err(Error::Input {
            path: path.to_path_buf(),
            msg: "is a device, FIFO or socket, not a regular file; rshape writes results to regular files only: give a file name".into(),
        }),
        _ => Ok(()),
    }
}

fn write_via_temp(path: &Path, contents: &[u8], sync: bool) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    (file.out.write_all(contents)).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    file.finish(sync)
}

/// A file written in pieces and published atomically: the bytes go to a temporary file in
/// the target's directory; [`commit`](Self::commit) flushes, syncs and renames it over the
/// target.  Dropped without `commit` (an error, a panic) or killed, the run leaves at most
/// an unnamed temporary file, never a truncated file under the final name.
pub struct AtomicFile {
    path: std::path::PathBuf,
    out: std::io::BufWriter<tempfile::NamedTempFile>,
}

impl AtomicFile {
    /// Starts writing `path` (its directory is created if needed).
    pub fn create(path: &Path) -> Result<Self> {
        check_not_special(path)?;
        let dir = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        // Created with mode 0666 less the umask, as `File::create` would (0644 under umask
        // 022); tempfile's default 0600 would survive the rename and hide results from
        // colleagues and web servers.
        let mut builder = tempfile::Builder::new();
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = builder.tempfile_in(dir).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            out: std::io::BufWriter::with_capacity(1 << 16, tmp),
        })
    }

    /// The writer of the contents.
    pub fn writer(&mut self) -> &mut impl Write {
        &mut self.out
    }

    /// Flushes, syncs and renames the file to its final name.
    pub fn commit(self) -> Result<()> {
        self.finish(true)
    }

    fn finish(self, sync: bool) -> Result<()> {
        let io = |source| Error::Io {
            path: self.path.clone(),
            source,
        };
        let tmp = self.out.into_inner().map_err(|e| io(e.into_error()))?;
        if sync {
            tmp.as_file().sync_all().map_err(io)?;
        }
        record(&self.path);
        tmp.persist(&self.path).map_err(|e| io(e.error))?;
        Ok(())
    }
}

/// The output folder of the run in progress and its open manifest, while recording.
static RECORDING: std::sync::Mutex<Option<(std::path::PathBuf, std::fs::File)>> =
    std::sync::Mutex::new(None);

/// Appends `path` to the manifest of the run in progress, before the file takes its name,
/// so that even a run killed right after the rename is listed.
fn record(path: &Path) {
    let mut guard = RECORDING.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((dir, manifest)) = guard.as_mut() {
        let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        if let Ok(rel) = abs.strip_prefix(&*dir) {
            // Best effort: a manifest that cannot grow only means a later run clears less.
            let _ = writeln!(manifest, "{}", rel.display());
        }
    }
}

/// What a run wrote into its output folder, so that a re-run into the same folder never
/// mixes old and new files.  [`begin`](Self::begin) deletes the files the previous run
/// listed in `DIR/rshape-outputs.txt` (only those: files of other origin are never
/// touched), then lists each file this run writes there before it takes its final name.
/// A run that fails or is killed thus leaves complete files of its own, never stale ones,
/// and the next run clears them.
pub struct OutputManifest {
    /// The manifest file.
    list: std::path::PathBuf,
    /// The folders `begin` created, deepest first: removed again when the run wrote
    /// nothing (a failed run leaves no empty `out/` behind).
    created: Vec<std::path::PathBuf>,
}

impl OutputManifest {
    /// The manifest's file name inside the output folder.
    pub const FILE: &'static str = "rshape-outputs.txt";

    /// Clears the files of the previous run in `dir` and starts recording this run's.
    pub fn begin(dir: &Path) -> Result<Self> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io { path, source }
        };
        let created: Vec<std::path::PathBuf> = dir
            .ancestors()
            .filter(|a| !a.as_os_str().is_empty())
            .take_while(|a| !a.exists())
            .map(Path::to_path_buf)
            .collect();
        std::fs::create_dir_all(dir).map_err(|source| create_dir_error(dir, source))?;
        let dir = std::path::absolute(dir).map_err(io(dir))?;
        let list = dir.join(Self::FILE);
        if let Ok(old) = std::fs::read_to_string(&list) {
            for rel in old.lines().map(Path::new) {
                // Only plain relative paths inside the folder.
                if rel
                    .components()
                    .all(|c| matches!(c, std::path::Component::Normal(_)))
                {
                    match std::fs::remove_file(dir.join(rel)) {
                        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                            return Err(io(&dir.join(rel))(e))
                        }
                        _ => {}
                    }
                }
            }
        }
        let manifest = std::fs::File::create(&list).map_err(io(&list))?;
        *RECORDING.lock().unwrap_or_else(|e| e.into_inner()) = Some((dir, manifest));
        Ok(Self { list, created })
    }
}

impl Drop for OutputManifest {
    fn drop(&mut self) {
        if let Some((_, manifest)) = RECORDING.lock().unwrap_or_else(|e| e.into_inner()).take() {
            let _ = manifest.sync_all();
        }
        // Nothing written (the run failed before its first output): no empty manifest and
        // no folder of ours stays behind.  `remove_dir` only removes empty folders.
        if std::fs::metadata(&self.list).is_ok_and(|m| m.len() == 0) {
            let _ = std::fs::remove_file(&self.list);
            for d in &self.created {
                let _ = std::fs::remove_dir(d);
            }
        }
    }
}

/// The error of creating an output folder: `create_dir_all` reports `NotFound` where a
/// parent is not a place for folders at all (under `/proc`, a file, …), which would read as
/// "not found: check the path"; name what failed instead.
fn create_dir_error(dir: &Path, source: std::io::Error) -> Error {
    let parent_exists = dir
        .ancestors()
        .skip(1)
        .find(|a| a.exists() || a.as_os_str().is_empty())
        .is_some_and(|a| !a.as_os_str().is_empty() && a.is_dir());
    if source.kind() == std::io::ErrorKind::NotFound && parent_exists {
        return Error::Input {
            path: dir.to_path_buf(),
            msg: "the folder cannot be created there (the file system refuses new folders): choose a writable location".into(),
        };
    }
    Error::Io {
        path: dir.to_path_buf(),
        source,
    }
}

/// Opens `path` for reading, refusing anything but a regular file (after symlinks): a FIFO
/// without a writer would block forever, and `/dev/zero` or `/dev/urandom` never end.
pub(crate) fn open_regular(path: &Path) -> Result<std::fs::File> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(io(std::io::Error::from(std::io::ErrorKind::IsADirectory)));
    }
    if !meta.is_file() {
        return Err(Error::Input {
            path: path.to_path_buf(),
            msg: format!(
                "not a regular file ({}): give a file on disk",
                file_kind(&meta)
            ),
        });
    }
    std::fs::File::open(path).map_err(io)
}

/// Reads a whole regular file ([`open_regular`]) of at most `cap` bytes.
pub(crate) fn read_regular(path: &Path, cap: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let file = open_regular(path)?;
    let mut bytes = Vec::new();
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if bytes.len() as u64 > cap {
        return Err(Error::Input {
            path: path.to_path_buf(),
            msg: format!("larger than {} MB: is this the right file?", cap >> 20),
        });
    }
    Ok(bytes)
}

/// Largest config, controller or `r.json` read whole.
pub(crate) const MAX_TEXT_FILE: u64 = 64 << 20;

/// Largest data file read whole (closed-loop data, noise std files, envelope files; the
/// FRF files of `envelope` are streamed and have no such cap).
pub(crate) const MAX_DATA_FILE: u64 = 1 << 30;

fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = meta;
    "not a file"
}

/// Input text quoted in a message: at most [`ECHO_CHARS`] characters, `…` marking a cut,
/// so a huge field never becomes a huge message.
pub(crate) fn echo(s: &str) -> String {
    match s.char_indices().nth(ECHO_CHARS) {
        Some((k, _)) => format!("{}…", &s[..k]),
        None => s.to_string(),
    }
}

/// Characters of input quoted in a message ([`echo`]).
pub(crate) const ECHO_CHARS: usize = 40;

/// A whole UTF-8 text file (a regular file of at most [`MAX_TEXT_FILE`] bytes).
pub(crate) fn read_text_file(path: &Path) -> Result<String> {
    String::from_utf8(read_regular(path, MAX_TEXT_FILE)?).map_err(|_| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::from(std::io::ErrorKind::InvalidData),
    })
}
