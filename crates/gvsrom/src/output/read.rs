//! Reading back a file of an output: only a regular file is opened. A FIFO, device, socket or
//! directory in its place is refused before it is opened (opening a FIFO waits for a writer that
//! never comes; a device may never end), and the opened file is checked again, so one swapped in
//! between the check and the open is refused too. [`super::verify_dir`] and the loaders of datasets,
//! models and arrays read through here, also for older outputs whose manifest lists no files.

use std::fs::{self, File, FileType, OpenOptions};
use std::io::{self, Read};
use std::path::Path;

/// What `ft` is, for an error: "a regular file", "a directory", "a FIFO (named pipe)", ….
pub fn file_kind(ft: &FileType) -> &'static str {
    if ft.is_file() {
        "a regular file"
    } else if ft.is_dir() {
        "a directory"
    } else if ft.is_symlink() {
        "a symbolic link"
    } else {
        special_kind(ft)
    }
}

#[cfg(unix)]
fn special_kind(ft: &FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if ft.is_fifo() {
        "a FIFO (named pipe)"
    } else if ft.is_char_device() {
        "a character device"
    } else if ft.is_block_device() {
        "a block device"
    } else if ft.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_ft: &FileType) -> &'static str {
    "a special file"
}

/// Why [`open_regular`] refused a path: what it is instead of a regular file ([`file_kind`]). The
/// payload of its [`io::ErrorKind::InvalidInput`] error; [`not_regular_kind`] gets it back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotRegular(pub &'static str);

impl std::fmt::Display for NotRegular {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "it is {}, not a regular file", self.0)
    }
}

impl std::error::Error for NotRegular {}

/// The error of a path that is not a regular file: `it is a FIFO (named pipe), not a regular file`.
fn not_regular(ft: &FileType) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, NotRegular(file_kind(ft)))
}

/// What the path was ("a FIFO (named pipe)", "a directory", …) if `e` is the refusal of
/// [`open_regular`] (or the readers built on it) of a path that is not a regular file; `None` for
/// any other error (missing, no permission, …).
pub fn not_regular_kind(e: &io::Error) -> Option<&'static str> {
    e.get_ref()?.downcast_ref::<NotRegular>().map(|n| n.0)
}

/// Opens `path` (a link followed) for reading if it is a regular file; otherwise an
/// [`io::ErrorKind::InvalidInput`] error saying what it is. Never blocks on a FIFO.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let ft = fs::metadata(path)?.file_type();
    if !ft.is_file() {
        return Err(not_regular(&ft));
    }
    let mut options = OpenOptions::new();
    options.read(true);
    // a FIFO swapped in after the check is opened at once instead of waiting for a writer (no effect
    // on a regular file), and refused below
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let ft = file.metadata()?.file_type();
    if !ft.is_file() {
        return Err(not_regular(&ft));
    }
    Ok(file)
}

/// The bytes of the regular file `path` ([`open_regular`]).
pub fn read_regular(path: &Path) -> io::Result<Vec<u8>> {
    let mut bytes = vec![];
    open_regular(path)?.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// The text of the regular file `path` ([`open_regular`]), which must be UTF-8.
pub fn read_regular_to_string(path: &Path) -> io::Result<String> {
    let mut text = String::new();
    open_regular(path)?.read_to_string(&mut text)?;
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn sandbox(name: &str) -> PathBuf {
        super::super::test_util::sandbox("read", name)
    }

    #[test]
    fn a_regular_file_is_read_and_anything_else_refused_saying_what_it_is() {
        let d = sandbox("kinds");
        fs::write(d.join("a.txt"), "text").unwrap();
        assert_eq!(read_regular_to_string(&d.join("a.txt")).unwrap(), "text");
        assert_eq!(read_regular(&d.join("a.txt")).unwrap(), b"text");
        let e = read_regular(&d).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert_eq!(e.to_string(), "it is a directory, not a regular file");
        assert_eq!(not_regular_kind(&e), Some("a directory"));
        let e = read_regular(&d.join("missing")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound);
        assert_eq!(not_regular_kind(&e), None);
        #[cfg(unix)]
        {
            let e = read_regular(Path::new("/dev/null")).unwrap_err();
            assert_eq!(
                e.to_string(),
                "it is a character device, not a regular file"
            );
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_fifo_is_refused_without_waiting_for_a_writer() {
        let d = sandbox("fifo");
        let pipe = d.join("p");
        super::super::test_util::fifo(&pipe);
        // no writer ever opens it: a plain open would block this test forever
        let e = read_regular(&pipe).unwrap_err();
        assert_eq!(
            e.to_string(),
            "it is a FIFO (named pipe), not a regular file"
        );
        assert_eq!(not_regular_kind(&e), Some("a FIFO (named pipe)"));
    }
}
